//! Every figure a reader of the course sees is measured by the command that prints it (issue 57).
//!
//! A figure is written in a chapter by hand, so it drifts as the code improves. Each document of
//! docs/course has a table, `tests/figures/NAME.toml`, that says for each figure the words it
//! sits in, the command a student would run (as the document prints it, or its equivalent with
//! `--set` for an edit the document describes), and what of that command's output the figure is.
//! The test runs the commands with the `mirador` binary, reads the figure and fails when the
//! document and the program disagree by more than the last printed digit. Figures that no command
//! prints (the values a student sets, a time that depends on the machine, a count made by eye)
//! are listed as `given`, each with why; `tests/figures/README.md` says how to write both.
//!
//! A second test scans each document for every number a reader sees (in the prose, tables and
//! inline code, not in shell or formula blocks, nor in commands and paths) and fails on any that
//! is neither checked nor given.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use regex::Regex;
use serde::Deserialize;

/// One document's table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Table {
    #[serde(default)]
    figure: Vec<Figure>,
    #[serde(default)]
    given: Vec<Given>,
}

/// A figure and how it is measured.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Figure {
    /// The words around the figure, as the document has them (line breaks and runs of spaces
    /// count as one space); they must occur once.
    text: String,
    /// The figure as printed inside `text` (default: its first number). Several numbers, as in
    /// `(187, 137, 99)`, are compared one by one with as many read.
    value: Option<String>,
    /// The command, as a shell would run it (`mirador …`); images it writes go to a folder of the
    /// test's, and a later command names them as the document does.
    run: Option<String>,
    /// Commands run first (each once per document), for images a later reading names: the
    /// renders a `diff` compares.
    #[serde(default)]
    before: Vec<String>,
    /// What the figure is: `flip`, `out /REGEX/`, `pixel X,Y [IMAGE]`, `max [IMAGE]`,
    /// `count >LEVEL [IMAGE]`, or `calc EXPRESSION` (README.md lists them).
    read: String,
    /// The largest difference allowed; by default one unit of the figure's last digit.
    tolerance: Option<f64>,
}

/// Numbers that no command prints, and why.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Given {
    /// The words, as `Figure::text`; every number in them is accounted for.
    text: String,
    /// Why no command prints them: `input` (a value the reader sets or the scene holds), `time`
    /// (the machine's), `by eye`, `viewer`, `reference` (a chapter, a line, a date) or a sentence.
    why: String,
}

fn repository() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A document's text with every run of white space made one space, and for each byte of it the
/// byte of the document it came from.
struct Flat {
    text: String,
    origin: Vec<usize>,
}

fn flatten(document: &str) -> Flat {
    let (mut text, mut origin) = (String::new(), Vec::new());
    let mut space = false;
    for (i, c) in document.char_indices() {
        if c.is_whitespace() {
            space = true;
            continue;
        }
        if space && !text.is_empty() {
            text.push(' ');
            origin.push(i);
        }
        space = false;
        text.push(c);
        origin.extend(std::iter::repeat_n(i, c.len_utf8()));
    }
    Flat { text, origin }
}

fn flat_words(words: &str) -> String {
    words.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The one place `words` occurs in the document (flattened), as a byte range of the document.
fn locate(flat: &Flat, words: &str, document: &str) -> Result<std::ops::Range<usize>, String> {
    let words = flat_words(words);
    let mut found = flat.text.match_indices(&words).map(|(at, _)| at);
    let Some(at) = found.next() else {
        return Err(format!("{document}: the words \"{words}\" are not in it"));
    };
    if found.next().is_some() {
        return Err(format!("{document}: the words \"{words}\" occur more than once; quote more of them"));
    }
    Ok(flat.origin[at]..end_of(flat, at, &words))
}

/// The document's byte just past `words`, found at `at` of the flattened text: its last
/// character's start there, and that character's length (`°` is two bytes).
fn end_of(flat: &Flat, at: usize, words: &str) -> usize {
    let last = words.chars().next_back().map_or(1, char::len_utf8);
    flat.origin[at + words.len() - 1] + last
}

/// The numbers written in `text`: `1,368` is one number, `(187, 137, 99)` three; a sign (`-` or
/// `−`) counts where it starts the number.
fn numbers(text: &str) -> Vec<(std::ops::Range<usize>, f64)> {
    static NUMBER: std::sync::LazyLock<Regex> = std::sync::LazyLock::new(|| {
        Regex::new(r"(?:[-−])?\d{1,3}(?:,\d{3})+(?:\.\d+)?|(?:[-−])?\d+(?:\.\d+)?").unwrap()
    });
    NUMBER
        .find_iter(text)
        .map(|m| {
            let mut written = m.as_str();
            let mut start = m.start();
            let signed = written.starts_with(['-', '−']);
            // A sign after a letter or digit is a hyphen or a minus between terms, not the number's.
            let joined = text[..start].chars().next_back().is_some_and(|c| c.is_alphanumeric());
            if signed && joined {
                let sign = written.chars().next().unwrap().len_utf8();
                written = &written[sign..];
                start += sign;
            }
            let value = written.replace('−', "-").replace(',', "").parse().unwrap();
            (start..m.end(), value)
        })
        .collect()
}

/// One unit of the last digit `written` shows: 0.0001 for `0.0112`, 1 for `12,832`.
fn last_digit(written: &str) -> f64 {
    match written.split_once('.') {
        Some((_, decimals)) => 10f64.powi(-(decimals.len() as i32)),
        None => 1.0,
    }
}

/// What one command printed, and the folder its images went to.
struct Ran {
    printed: String,
    folder: PathBuf,
    image: Option<PathBuf>,
}

/// Runs `command` (a line beginning with `mirador`) in `folder`, with the repository's files
/// named by their full path; the same command runs once per document.
fn run<'a>(command: &str, folder: &Path, ran: &'a mut HashMap<String, Ran>) -> Result<&'a Ran, String> {
    if !ran.contains_key(command) {
        let printed = mirador::course::commands(&format!("```sh\n{command}\n```\n"));
        let [printed] = printed.as_slice() else {
            return Err(format!("`{command}` is not one command"));
        };
        // Variables set before the command, as a shell sets them: `WGPU_BACKEND=gl mirador …`.
        let variable = |word: &String| word.split_once('=').is_some_and(|(name, _)| is_variable_name(name));
        let set = printed.words.iter().take_while(|w| variable(w)).count();
        let environment: Vec<(String, String)> = printed.words[..set]
            .iter()
            .filter_map(|w| w.split_once('=').map(|(n, v)| (n.to_string(), v.to_string())))
            .collect();
        let Some((_, words)) = printed.words[set..].split_first().filter(|(p, _)| *p == "mirador") else {
            return Err(format!("`{command}` is not a mirador command"));
        };
        let mut image = None;
        let arguments: Vec<String> = words
            .iter()
            .enumerate()
            .map(|(i, word)| {
                let output = i > 0 && ["-o", "--output"].contains(&words[i - 1].as_str());
                if output {
                    image = Some(folder.join(word));
                }
                let ours = repository().join(word);
                if !output && !word.starts_with('-') && word.contains('/') && ours.exists() {
                    ours.display().to_string()
                } else {
                    word.clone()
                }
            })
            .collect();
        let out = Command::new(env!("CARGO_BIN_EXE_mirador"))
            .args(&arguments)
            .current_dir(folder)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .envs(environment)
            .output()
            .map_err(|e| format!("`{command}`: {e}"))?;
        let mut text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.push_str(&String::from_utf8_lossy(&out.stderr));
        if !out.status.success() {
            return Err(format!("`{command}` failed:\n{text}"));
        }
        ran.insert(command.to_string(), Ran { printed: text, folder: folder.to_path_buf(), image });
    }
    Ok(&ran[command])
}

/// Whether `name` is an environment variable's name as a shell reads one before a command.
fn is_variable_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_uppercase() || c == '_')
        && chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

/// The command whose raster image tells whether this CPU's lavapipe rounds as the course's did:
/// the volume stage composited, where another CPU draws 38 % of the pixels one level lower in red
/// (`tests/data/cross-cpu/README.md`).
const PROBE: &str = "compare assets/scenes/volume.toml --width 240 --height 150 --set volume.mode=\"composite\"";

/// Whether this machine draws the probe's raster image bit for bit as the machine the course's
/// figures were measured on (`tests/figures/course-cpu.png`): then every FLIP figure is held to
/// its last digit. On a CPU that rounds differently each is held to its last digit and its
/// [`rounding_share`], and the test says so. A probe that differs by more than rounding is stale
/// (the volume pass changed): the test stops and says how to make it again.
fn rounds_as_the_course() -> bool {
    static SAME: std::sync::LazyLock<bool> = std::sync::LazyLock::new(|| {
        let folder = std::env::temp_dir().join(format!("mirador-figures-probe-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let command = format!("mirador {PROBE} -o probe.png --raster-out raster.png");
        let mut ran = HashMap::new();
        run(&command, &folder, &mut ran).unwrap_or_else(|e| panic!("the probe: {e}"));
        let open = |path: &Path| image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
        let (ours, course) =
            (open(&folder.join("raster.png")), open(&repository().join("tests/figures/course-cpu.png")));
        let _ = std::fs::remove_dir_all(&folder);
        assert_eq!(ours.dimensions(), course.dimensions(), "tests/figures/course-cpu.png: not the probe's size");
        let apart =
            ours.pixels().zip(course.pixels()).map(|(p, q)| (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap());
        let farthest = apart.max().unwrap_or(0);
        assert!(
            farthest <= 2,
            "tests/figures/course-cpu.png is stale (a pixel {farthest} levels apart): make it again on the machine the \
             course is measured on with `mirador {PROBE} -o probe.png --raster-out tests/figures/course-cpu.png`"
        );
        if farthest > 0 {
            eprintln!(
                "this CPU rounds differently from the course's: FLIP figures are held to their rounding share too"
            );
        }
        farthest == 0
    });
    *SAME
}

/// How much of the FLIP a `compare` or `diff` printed (`under the mask`, where it has one) comes
/// from pixels within two levels of each other: its plain mean less its mean beyond rounding, both
/// of which it prints. That part is what another CPU, rounding its last bits differently, can move
/// (`tests/README.md`, "Image comparisons"): where the two images agree to rounding a figure is
/// held loosely, where they differ by more it is held to its digit.
fn rounding_share(printed: &str, under: &str) -> Result<f64, String> {
    let plain = captured(printed, &format!("FLIP mean{under}: ([0-9.]+)"))?;
    let beyond = captured(printed, &format!("FLIP mean{under} beyond rounding: ([0-9.]+)"))?;
    Ok((plain[0] - beyond[0]).max(0.0))
}

/// The image a reading names, or the one its command wrote.
fn image_of(ran: Option<&Ran>, named: Option<&str>) -> Result<image::RgbaImage, String> {
    let path = match (named, ran) {
        (Some(name), Some(ran)) => ran.folder.join(name),
        (None, Some(Ran { image: Some(path), .. })) => path.clone(),
        _ => return Err("the reading needs an image: a command with -o, or its name".into()),
    };
    image::open(&path).map(|i| i.to_rgba8()).map_err(|e| format!("{}: {e}", path.display()))
}

/// The numbers `read` takes from what `ran` printed or wrote.
fn reading(read: &str, ran: Option<&Ran>) -> Result<Vec<f64>, String> {
    let (kind, rest) = read.split_once(' ').unwrap_or((read, ""));
    let rest = rest.trim();
    let printed = || ran.map(|r| r.printed.as_str()).ok_or(format!("`{read}` needs a command"));
    match kind {
        "flip" => captured(printed()?, r"FLIP mean: ([0-9.]+)"),
        "out" => {
            let pattern = rest.strip_prefix('/').and_then(|r| r.strip_suffix('/'));
            captured(printed()?, pattern.ok_or(format!("`{read}`: write the pattern as /REGEX/"))?)
        }
        "pixel" => {
            let (at, name) = rest.split_once(' ').map_or((rest, None), |(a, n)| (a, Some(n)));
            let xy: Vec<u32> = at.split(',').filter_map(|v| v.trim().parse().ok()).collect();
            let [x, y] = xy[..] else { return Err(format!("`{read}`: write pixel X,Y")) };
            let image = image_of(ran, name)?;
            let p = image.get_pixel_checked(x, y).ok_or(format!("`{read}`: outside the image"))?;
            Ok(p.0[..3].iter().map(|&c| c as f64).collect())
        }
        "max" => {
            let image = image_of(ran, (!rest.is_empty()).then_some(rest))?;
            Ok(vec![image.pixels().flat_map(|p| p.0[..3].to_vec()).max().unwrap_or(0) as f64])
        }
        "count" => {
            let (level, name) = rest.split_once(' ').map_or((rest, None), |(l, n)| (l, Some(n)));
            let level: u8 =
                level.strip_prefix('>').and_then(|l| l.parse().ok()).ok_or(format!("`{read}`: write count >LEVEL"))?;
            let image = image_of(ran, name)?;
            Ok(vec![image.pixels().filter(|p| p.0[..3].iter().any(|&c| c > level)).count() as f64])
        }
        "differ" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let [levels, a, b] = words[..] else { return Err(format!("`{read}`: write differ LO..HI A B")) };
            let (lo, hi) = levels.split_once("..").ok_or(format!("`{read}`: write differ LO..HI A B"))?;
            let (lo, hi): (u8, u8) =
                (lo.parse().map_err(|_| read.to_string())?, hi.parse().map_err(|_| read.to_string())?);
            let (a, b) = (image_of(ran, Some(a))?, image_of(ran, Some(b))?);
            let apart =
                |p: &image::Rgba<u8>, q: &image::Rgba<u8>| (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap();
            Ok(vec![a.pixels().zip(b.pixels()).filter(|(p, q)| (lo..=hi).contains(&apart(p, q))).count() as f64])
        }
        "run" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let (line, colour, name) = match words[..] {
                [line, colour] => (line, colour, None),
                [line, colour, name] => (line, colour, Some(name)),
                _ => return Err(format!("`{read}`: write run x=X|y=Y R,G,B~LEVELS [IMAGE]")),
            };
            let image = image_of(ran, name)?;
            longest_run(&image, line, colour).ok_or(format!("`{read}`: write run x=X|y=Y R,G,B~LEVELS [IMAGE]"))
        }
        "nearest" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let usage = format!("`{read}`: write nearest x=X|y=Y R,G,B [last] [IMAGE]");
            let [line, colour, rest @ ..] = &words[..] else { return Err(usage) };
            let (last, name) = match rest {
                ["last", name @ ..] => (true, name.first().copied()),
                name => (false, name.first().copied()),
            };
            nearest_on_line(&image_of(ran, name)?, line, colour, last).ok_or(usage)
        }
        "box" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let usage = format!("`{read}`: write box R,G,B~LEVELS [IMAGE]");
            let [colour, name @ ..] = &words[..] else { return Err(usage) };
            unlike(&image_of(ran, name.first().copied())?, colour).ok_or(usage)
        }
        "file" => {
            let usage = format!("`{read}`: write file PATH /REGEX/");
            let (path, pattern) = rest.split_once(' ').ok_or(usage.clone())?;
            let pattern = pattern.trim().strip_prefix('/').and_then(|r| r.strip_suffix('/')).ok_or(usage)?;
            let folder = ran.map(|r| r.folder.as_path()).ok_or(format!("`{read}` needs a command"))?;
            let text = std::fs::read_to_string(folder.join(path)).map_err(|e| format!("{path}: {e}"))?;
            captured(&text, pattern)
        }
        "calc" => calculated(rest),
        _ => Err(format!(
            "`{read}`: no such reading (flip, out, file, pixel, max, count, differ, run, nearest, box, calc)"
        )),
    }
}

/// `R,G,B~LEVELS` as the colour and the levels each channel may differ by.
fn colour_within(colour: &str) -> Option<([u8; 3], u8)> {
    let (rgb, levels) = colour.split_once('~').unwrap_or((colour, "0"));
    let rgb: Vec<u8> = rgb.split(',').filter_map(|c| c.parse().ok()).collect();
    Some((rgb.try_into().ok()?, levels.parse().ok()?))
}

/// The pixels down the column `x=X` or along the row `y=Y`.
fn line_of<'a>(image: &'a image::RgbaImage, line: &str) -> Option<Vec<&'a image::Rgba<u8>>> {
    let (axis, at) = line.split_once('=')?;
    let at: u32 = at.parse().ok()?;
    match axis {
        "x" if at < image.width() => Some((0..image.height()).map(|y| image.get_pixel(at, y)).collect()),
        "y" if at < image.height() => Some((0..image.width()).map(|x| image.get_pixel(x, at)).collect()),
        _ => None,
    }
}

/// Where along the line (`x=X`: the row; `y=Y`: the column) the colour is nearest `R,G,B`, by
/// the sum of the channels' differences: the first of equally near pixels, or with `last` the
/// last (the edge of a band of that colour seen from its other side).
fn nearest_on_line(image: &image::RgbaImage, line: &str, colour: &str, last: bool) -> Option<Vec<f64>> {
    let (rgb, _) = colour_within(colour)?;
    let distance = |p: &image::Rgba<u8>| (0..3).map(|c| p.0[c].abs_diff(rgb[c]) as u32).sum::<u32>();
    let pixels = line_of(image, line)?;
    let nearest = pixels.iter().map(|p| distance(p)).min()?;
    let mut at = (0..pixels.len()).filter(|&i| distance(pixels[i]) == nearest);
    let at = if last { at.next_back() } else { at.next() }?;
    Some(vec![at as f64])
}

/// The box `x0, x1, y0, y1` (inclusive) of the pixels farther than LEVELS from `R,G,B~LEVELS`
/// in some channel: where something is drawn over a background of that colour.
fn unlike(image: &image::RgbaImage, colour: &str) -> Option<Vec<f64>> {
    let (rgb, levels) = colour_within(colour)?;
    let drawn = image.enumerate_pixels().filter(|(_, _, p)| (0..3).any(|c| p.0[c].abs_diff(rgb[c]) > levels));
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for (x, y, _) in drawn {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    (x0 <= x1).then(|| vec![x0 as f64, x1 as f64, y0 as f64, y1 as f64])
}

/// The longest run of pixels of `colour` (`R,G,B~LEVELS`: each channel within LEVELS) down the
/// column `x=X` or along the row `y=Y`: the size of what is drawn in that colour.
fn longest_run(image: &image::RgbaImage, line: &str, colour: &str) -> Option<Vec<f64>> {
    let (rgb, levels) = colour_within(colour)?;
    let (mut longest, mut current) = (0, 0);
    for p in line_of(image, line)? {
        let inside = (0..3).all(|c| p.0[c].abs_diff(rgb[c]) <= levels);
        current = if inside { current + 1 } else { 0 };
        longest = longest.max(current);
    }
    Some(vec![longest as f64])
}

/// Every number the first match of `pattern` captures (or, with no group, the match holds).
fn captured(printed: &str, pattern: &str) -> Result<Vec<f64>, String> {
    let regex = Regex::new(pattern).map_err(|e| format!("/{pattern}/: {e}"))?;
    let found = regex.captures(printed).ok_or(format!("/{pattern}/ is not in what it printed:\n{printed}"))?;
    let groups: Vec<&str> = match found.len() {
        1 => vec![found.get(0).unwrap().as_str()],
        _ => found.iter().skip(1).flatten().map(|m| m.as_str()).collect(),
    };
    Ok(groups.iter().flat_map(|g| numbers(g).into_iter().map(|(_, v)| v)).collect())
}

/// An arithmetic figure, worked as the text works it: `pi`, `deg` (π/180) and `srgb(x)` (the
/// byte, unrounded, that linear `x` encodes to) beside evalexpr's `math::…` functions. Every
/// integer is read as a real, so `1/2` is a half.
fn calculated(expression: &str) -> Result<Vec<f64>, String> {
    use evalexpr::{ContextWithMutableFunctions, ContextWithMutableVariables, Function, HashMapContext, Value};
    let literal = Regex::new(r"\d+(?:\.\d+)?").unwrap();
    let mut real = String::new();
    let mut last = 0;
    for m in literal.find_iter(expression) {
        real.push_str(&expression[last..m.end()]);
        let in_name = expression[..m.start()].chars().next_back().is_some_and(|c| c.is_alphanumeric() || c == '_');
        if !m.as_str().contains('.') && !in_name {
            real.push_str(".0");
        }
        last = m.end();
    }
    real.push_str(&expression[last..]);
    let mut context = HashMapContext::new();
    let pi = std::f64::consts::PI;
    context.set_value("pi".into(), Value::Float(pi)).unwrap();
    context.set_value("deg".into(), Value::Float(pi / 180.0)).unwrap();
    let srgb = Function::new(|x: &Value| {
        let x = x.as_number()?.clamp(0.0, 1.0);
        let encoded = if x <= 0.0031308 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
        Ok(Value::Float(255.0 * encoded))
    });
    context.set_function("srgb".into(), srgb).unwrap();
    let value = evalexpr::eval_with_context(&real, &context).map_err(|e| format!("calc {expression}: {e}"))?;
    let numbers = match value {
        Value::Tuple(values) => values.iter().map(|v| v.as_number()).collect::<Result<Vec<_>, _>>(),
        other => other.as_number().map(|v| vec![v]),
    };
    numbers.map_err(|e| format!("calc {expression}: {e}"))
}

/// The document's table: `tests/figures/NAME.toml` and any `NAME.PART.toml` beside it, or only
/// the parts whose file names start with `only` (`answers.4-6`).
fn table(name: &str, only: Option<&str>) -> Table {
    let mut table = Table { figure: Vec::new(), given: Vec::new() };
    let mut paths: Vec<PathBuf> = std::fs::read_dir(repository().join("tests/figures"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| {
            let stem = path.file_stem().unwrap().to_string_lossy().to_string();
            let ours = stem == name || stem.strip_prefix(name).is_some_and(|rest| rest.starts_with('.'));
            ours && path.extension().is_some_and(|e| e == "toml") && only.is_none_or(|only| stem.starts_with(only))
        })
        .collect();
    paths.sort();
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let part: Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        table.figure.extend(part.figure);
        table.given.extend(part.given);
    }
    table
}

fn document(name: &str) -> String {
    let path = repository().join("docs/course").join(format!("{name}.md"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Checks one figure; the error says where it is, what the program gives and how to see it.
fn check(
    figure: &Figure,
    name: &str,
    flat: &Flat,
    markdown: &str,
    folder: &Path,
    ran: &mut HashMap<String, Ran>,
) -> Result<(), String> {
    let doc = format!("docs/course/{name}.md");
    let place = locate(flat, &figure.text, &doc)?;
    let quoted = &markdown[place.clone()];
    let written = match &figure.value {
        Some(value) => {
            let flat_quote = flat_words(quoted);
            if !flat_quote.contains(value.as_str()) {
                return Err(format!("{doc}: \"{value}\" is not in \"{}\"", flat_words(&figure.text)));
            }
            value.clone()
        }
        None => {
            let first = numbers(quoted).into_iter().next().ok_or(format!("{doc}: no number in \"{}\"", figure.text))?;
            quoted[first.0].to_string()
        }
    };
    let expected = numbers(&written);
    for command in &figure.before {
        run(command, folder, ran)?;
    }
    let result = match &figure.run {
        Some(command) => run(command, folder, ran).map(Some)?,
        None => None,
    };
    let measured = reading(&figure.read, result)?;
    let under = if figure.read.contains("under the mask") { " under the mask" } else { "" };
    let reads_flip = figure.read == "flip" || !under.is_empty();
    let share = match result {
        Some(ran) if reads_flip && !rounds_as_the_course() => rounding_share(&ran.printed, under)?,
        _ => 0.0,
    };
    let how = figure.run.as_deref().map_or(figure.read.clone(), |c| format!("`{c}` ({})", figure.read));
    if measured.len() != expected.len() {
        return Err(format!("{doc}: \"{written}\" has {} numbers, {how} gives {measured:?}", expected.len()));
    }
    for ((range, printed), measured) in expected.iter().zip(&measured) {
        let tolerance = figure.tolerance.unwrap_or_else(|| last_digit(&written[range.clone()])) + share;
        if (printed - measured).abs() > tolerance * (1.0 + 1e-9) {
            return Err(format!(
                "{doc}: the figure {printed} in \"{}\" is not what {how} gives: {measured} (tolerance {tolerance})",
                flat_words(&figure.text)
            ));
        }
    }
    Ok(())
}

/// Checks every figure of document `name` in the parts of its table that `part` names (all where
/// none; `MIRADOR_FIGURES_PART` narrows it further, to check one part while writing it), and says
/// every disagreement at once.
fn check_document(name: &str, part: Option<&str>) {
    let markdown = document(name);
    let flat = flatten(&markdown);
    let asked = std::env::var("MIRADOR_FIGURES_PART").ok();
    if let (Some(asked), Some(part)) = (&asked, part)
        && !asked.starts_with(part)
    {
        return;
    }
    let table = table(name, asked.as_deref().or(part));
    let folder = std::env::temp_dir().join(format!("mirador-figures-{}-{}", std::process::id(), part.unwrap_or(name)));
    std::fs::create_dir_all(&folder).unwrap();
    let mut ran = HashMap::new();
    let mut errors: Vec<String> = table
        .figure
        .iter()
        .filter_map(|figure| check(figure, name, &flat, &markdown, &folder, &mut ran).err())
        .collect();
    let _ = std::fs::remove_dir_all(&folder);
    errors.extend(
        table.given.iter().filter_map(|given| locate(&flat, &given.text, &format!("docs/course/{name}.md")).err()),
    );
    eprintln!("{name}: {} figures checked by {} commands", table.figure.len() - errors.len(), ran.len());
    assert!(errors.is_empty(), "{} of {} figures disagree:\n{}", errors.len(), table.figure.len(), errors.join("\n\n"));
}

macro_rules! documents {
    ($($test:ident: $name:literal $(part $part:literal)?,)*) => {
        $(
            #[test]
            fn $test() {
                check_document($name, None $(.or(Some($part)))?);
            }
        )*
        /// Every document, once (the answers' parts are one document).
        const DOCUMENTS: &[&str] = &[
            "01-camera", "02-illumination", "03-mipmaps", "04-bump-mapping", "05-shadows", "06-transparency",
            "07-planar-mirrors", "08-environment-maps", "09-ray-tracing", "10-anti-aliasing", "11-volumes",
            "12-error-budget", "answers",
        ];
    };
}

documents! {
    chapter_1_the_camera: "01-camera",
    chapter_2_illumination: "02-illumination",
    chapter_3_mipmaps: "03-mipmaps",
    chapter_4_bump_mapping: "04-bump-mapping",
    chapter_5_shadows: "05-shadows",
    chapter_6_transparency: "06-transparency",
    chapter_7_planar_mirrors: "07-planar-mirrors",
    chapter_8_environment_maps: "08-environment-maps",
    chapter_9_ray_tracing: "09-ray-tracing",
    chapter_10_anti_aliasing: "10-anti-aliasing",
    chapter_11_volumes: "11-volumes",
    chapter_12_error_budget: "12-error-budget",
    the_answers_chapters_1_to_3: "answers" part "answers.1-3",
    the_answers_chapters_4_to_6: "answers" part "answers.4-6",
    the_answers_chapters_7_to_9: "answers" part "answers.7-9",
    the_answers_chapters_10_to_12: "answers" part "answers.10-12",
}

/// The byte ranges of `markdown` a reader sees as prose: not fenced blocks, headings, HTML
/// comments, link targets, nor inline code that is a command, a path or code.
fn prose(markdown: &str) -> Vec<std::ops::Range<usize>> {
    let mut seen = Vec::new();
    let mut fenced = false;
    let mut offset = 0;
    let code = Regex::new(r"`[^`]*`|\]\([^)]*\)|<!--.*?-->").unwrap();
    let not_read = Regex::new(r"mirador |--|\.(toml|png|rs|wgsl|md|sh)\b|::|/").unwrap();
    for line in markdown.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || line.starts_with('#') {
            continue;
        }
        let mut from = start;
        for m in code.find_iter(line) {
            let skip = !m.as_str().starts_with('`') || not_read.is_match(m.as_str());
            if skip {
                seen.push(from..start + m.start());
                from = start + m.end();
            }
        }
        seen.push(from..offset);
    }
    seen
}

/// The numbers a reader sees that need an account: every number with a decimal point, and every
/// integer of two digits or more.
fn figures_seen(markdown: &str) -> Vec<std::ops::Range<usize>> {
    prose(markdown)
        .into_iter()
        .flat_map(|range| {
            numbers(&markdown[range.clone()]).into_iter().map(move |(r, _)| r.start + range.start..r.end + range.start)
        })
        .filter(|r| {
            let written = &markdown[r.clone()];
            written.contains('.') || written.trim_start_matches(['-', '−']).len() >= 2
        })
        .collect()
}

/// The ranges of a document a table accounts for: each figure's value inside its words, and
/// every given text whole.
fn accounted(name: &str, markdown: &str, table: &Table) -> Vec<std::ops::Range<usize>> {
    let flat = flatten(markdown);
    let mut ranges = Vec::new();
    for figure in &table.figure {
        let Ok(place) = locate(&flat, &figure.text, name) else { continue };
        let quoted = &markdown[place.clone()];
        let inner = match &figure.value {
            Some(value) => {
                let written = flatten(quoted);
                written.text.find(value.as_str()).map(|at| written.origin[at]..end_of(&written, at, value))
            }
            None => numbers(quoted).into_iter().next().map(|(r, _)| r),
        };
        if let Some(inner) = inner {
            ranges.push(place.start + inner.start..place.start + inner.end);
        }
    }
    for given in &table.given {
        if let Ok(place) = locate(&flat, &given.text, name) {
            ranges.push(place);
        }
    }
    ranges
}

/// Every number a reader sees in the course's documents is checked or given.
#[test]
fn every_figure_is_checked_or_said_why() {
    let mut failures = Vec::new();
    for name in DOCUMENTS {
        let markdown = document(name);
        let table = table(name, None);
        let accounted = accounted(name, &markdown, &table);
        let open: Vec<String> = figures_seen(&markdown)
            .into_iter()
            .filter(|r| !accounted.iter().any(|a| a.start <= r.start && r.end <= a.end))
            .map(|r| {
                let line = markdown[..r.start].lines().count().max(1);
                let from = markdown.floor_char_boundary(r.start.saturating_sub(30));
                let context = &markdown[from..markdown.ceil_char_boundary((r.end + 20).min(markdown.len()))];
                format!("  {name}.md:{line}: {} in \"…{}…\"", &markdown[r.clone()], flat_words(context))
            })
            .collect();
        let mut whys: Vec<&str> = table.given.iter().map(|g| g.why.as_str()).collect();
        whys.sort();
        whys.dedup();
        eprintln!(
            "{name}: {} numbers seen, {} figures checked, given as {}; {} not yet accounted for",
            figures_seen(&markdown).len(),
            table.figure.len(),
            whys.join(", "),
            open.len()
        );
        if !open.is_empty() {
            failures.push(format!("{name}.md has numbers neither checked nor given:\n{}", open.join("\n")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
