//! The course (`docs/course/`) and the references into it stay true:
//!
//! - every relative link and image in the documentation (`docs/**/*.md`, `README.md`,
//!   `tests/README.md`) names a file that exists, and an anchor that one of its headings makes
//!   (GitHub's rule: the heading's text in lower case, spaces to `-`, other punctuation dropped,
//!   `-1`, `-2`, … after repeats);
//! - every `docs/course/<file>.md` or `docs/course/<file>.md#anchor` written in `src/` or
//!   `shaders/` names a chapter and a heading that exist;
//! - the code cites the course, not the team's working notes (`TECHNIQUES.md`);
//! - every scene of the exercises (`assets/scenes/course/`) loads, is used by a chapter, and every
//!   scene a chapter names exists;
//! - every image of the course is linked from a chapter and made by `docs/course/images.sh`;
//! - every function, type or constant a document names by a link to its file
//!   (``[`bump_normal`](../../src/texture/bump.rs)``) is declared in that file;
//! - every formula of a chapter (a ```` ```math ```` block of `docs/course/NN-name.md`) names the
//!   code that computes it: the paragraph before it or the text after it links a function of
//!   `src/` or `shaders/` that the linked file declares, or says that no function computes it.
//!
//! Nothing here needs a GPU.

use std::collections::{BTreeSet, HashMap};
use std::fs;
use std::path::{Component, Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` (recursively) whose name ends with one of `extensions`, sorted.
fn files_under(dir: &Path, extensions: &[&str]) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(dir) = pending.pop() {
        let Ok(entries) = fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                pending.push(path);
            } else if extensions.iter().any(|e| path.to_string_lossy().ends_with(e)) {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `path` relative to the repository, for messages.
fn shown(path: &Path) -> String {
    path.strip_prefix(root()).unwrap_or(path).display().to_string()
}

/// The documentation the link check reads.
fn documentation() -> Vec<PathBuf> {
    let mut files = files_under(&root().join("docs"), &[".md"]);
    files.push(root().join("README.md"));
    files.push(root().join("tests").join("README.md"));
    files
}

/// Whether a line opens or closes a fenced code block (``` or ~~~, possibly indented in a list).
fn is_fence(line: &str) -> bool {
    let t = line.trim_start();
    t.starts_with("```") || t.starts_with("~~~")
}

/// The lines of a Markdown file that are not inside fenced code blocks, with their numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut inside = false;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if is_fence(line) {
            inside = !inside;
        } else if !inside {
            lines.push((i + 1, line));
        }
    }
    lines
}

/// `line` with its code spans blanked out (a run of n backticks up to the next run of n).
fn without_code_spans(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let run = chars[i..].iter().take_while(|&&c| c == '`').count();
        let mut j = i + run;
        let mut closed = None;
        while j < chars.len() {
            if chars[j] == '`' {
                let other = chars[j..].iter().take_while(|&&c| c == '`').count();
                if other == run {
                    closed = Some(j + other);
                    break;
                }
                j += other;
            } else {
                j += 1;
            }
        }
        match closed {
            Some(end) => {
                out.push(' ');
                i = end;
            }
            None => {
                out.extend(&chars[i..i + run]);
                i += run;
            }
        }
    }
    out
}

/// The targets of the links and images on one line of prose: `[text](target "title")`,
/// `![alt](target)`, reference definitions `[name]: target`, and HTML `href="…"` / `src="…"`.
fn link_targets(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut targets = Vec::new();
    let trimmed = line.trim_start();
    if trimmed.starts_with('[')
        && let Some(close) = trimmed.find("]:")
        && !trimmed[1..close].contains(['[', ']'])
        && let Some(target) = trimmed[close + 2..].split_whitespace().next()
    {
        targets.push(target.trim_matches(['<', '>']).to_string());
    }
    let mut rest = line.as_str();
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let mut depth = 0;
        let mut end = after.len();
        for (k, c) in after.char_indices() {
            match c {
                '(' => depth += 1,
                ')' if depth == 0 => {
                    end = k;
                    break;
                }
                ')' => depth -= 1,
                _ => {}
            }
        }
        let inside = after[..end].trim();
        let target = if let Some(stripped) = inside.strip_prefix('<') {
            stripped.split('>').next().unwrap_or("").to_string()
        } else {
            inside.split_whitespace().next().unwrap_or("").to_string()
        };
        if !target.is_empty() {
            targets.push(target);
        }
        rest = &after[end.min(after.len())..];
    }
    for attribute in ["href=\"", "src=\""] {
        let mut rest = line.as_str();
        while let Some(at) = rest.find(attribute) {
            let after = &rest[at + attribute.len()..];
            let end = after.find('"').unwrap_or(after.len());
            targets.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    targets
}

fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:") || target.starts_with("data:")
}

fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && bytes[i + 1].is_ascii_hexdigit()
            && bytes[i + 2].is_ascii_hexdigit()
            && let Ok(b) = u8::from_str_radix(&text[i + 1..i + 3], 16)
        {
            out.push(b);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A heading's text as GitHub renders it for its anchor: code spans keep their text, links keep
/// their text, emphasis marks go.
fn heading_text(raw: &str) -> String {
    let mut text = String::new();
    let mut rest = raw;
    // Links: keep the bracketed text.
    while let Some(open) = rest.find('[') {
        text.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find("](") {
            Some(close) if after[close + 2..].contains(')') => {
                text.push_str(&after[..close]);
                let tail = &after[close + 2..];
                rest = &tail[tail.find(')').map_or(tail.len(), |k| k + 1)..];
            }
            _ => {
                text.push('[');
                rest = after;
            }
        }
    }
    text.push_str(rest);
    text.replace(['`', '*'], "")
}

/// GitHub's anchor for a heading text: lower case; letters, digits, `_`, `-` and spaces kept;
/// spaces become `-`.
fn slug(text: &str) -> String {
    text.trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors a Markdown file's headings make (ATX `#` and setext headings), with GitHub's
/// `-1`, `-2` suffixes on repeats, and any HTML `id="…"` / `name="…"` anchors.
fn anchors_of(text: &str) -> BTreeSet<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut anchors = BTreeSet::new();
    let mut add = |base: String, anchors: &mut BTreeSet<String>| {
        let count = seen.entry(base.clone()).or_insert(0);
        let anchor = if *count == 0 { base.clone() } else { format!("{base}-{count}") };
        *count += 1;
        anchors.insert(anchor);
    };
    let lines = prose_lines(text);
    for (index, &(number, line)) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let hashes = trimmed.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line.len() - trimmed.len() < 4 {
            let after = &trimmed[hashes..];
            if after.is_empty() || after.starts_with(' ') || after.starts_with('\t') {
                let content = after.trim().trim_end_matches('#').trim();
                add(slug(&heading_text(content)), &mut anchors);
                continue;
            }
        }
        // A setext heading: a line of prose directly above a line of `=` or `-` only.
        if let Some(&(next_number, next)) = lines.get(index + 1) {
            let under = next.trim();
            let is_underline = !under.is_empty()
                && (under.chars().all(|c| c == '=') || under.chars().all(|c| c == '-'))
                && next_number == number + 1;
            let is_paragraph = !trimmed.is_empty()
                && !trimmed.starts_with(['-', '*', '>', '|'])
                && !trimmed.starts_with(|c: char| c.is_ascii_digit());
            if is_underline && is_paragraph {
                add(slug(&heading_text(trimmed)), &mut anchors);
            }
        }
        for attribute in ["id=\"", "name=\""] {
            let mut rest = line;
            while let Some(at) = rest.find(attribute) {
                let after = &rest[at + attribute.len()..];
                let end = after.find('"').unwrap_or(after.len());
                anchors.insert(after[..end].to_string());
                rest = &after[end..];
            }
        }
    }
    anchors
}

/// `path` with `.` and `..` folded away (without touching the file system).
fn normalized(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// Why `target`, written in `from`, does not resolve; `None` when it does.
fn broken(from: &Path, target: &str, anchors: &mut HashMap<PathBuf, BTreeSet<String>>) -> Option<String> {
    let target = percent_decoded(target);
    let (path, anchor) = match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target.as_str(), None),
    };
    let file = if path.is_empty() {
        from.to_path_buf()
    } else if let Some(absolute) = path.strip_prefix('/') {
        root().join(absolute)
    } else {
        normalized(&from.parent().expect("a file has a folder").join(path))
    };
    if !file.starts_with(root()) {
        return Some(format!("{} lies outside the repository", file.display()));
    }
    if !file.exists() {
        return Some(format!("{} does not exist", shown(&file)));
    }
    let anchor = anchor?;
    if file.extension().is_none_or(|e| e != "md") {
        return Some(format!(
            "#{anchor} points into {}: link the file, not a place in it (line numbers go stale)",
            shown(&file)
        ));
    }
    let known = anchors.entry(file.clone()).or_insert_with(|| anchors_of(&read(&file)));
    if known.contains(anchor) {
        None
    } else {
        let near: Vec<&String> =
            known.iter().filter(|a| a.contains(anchor) || anchor.contains(a.as_str())).take(5).collect();
        Some(format!("{} has no heading with the anchor #{anchor} (close ones: {near:?})", shown(&file)))
    }
}

#[test]
fn every_relative_link_in_the_documentation_resolves() {
    let mut anchors = HashMap::new();
    let mut problems = Vec::new();
    let mut checked = 0;
    for doc in documentation() {
        let text = read(&doc);
        for (number, line) in prose_lines(&text) {
            for target in link_targets(line) {
                if is_external(&target) {
                    continue;
                }
                checked += 1;
                if let Some(why) = broken(&doc, &target, &mut anchors) {
                    problems.push(format!("{}:{number}: ({target}) {why}", shown(&doc)));
                }
            }
        }
    }
    assert!(checked > 50, "the check found only {checked} links: is the parser still reading the documentation?");
    assert!(problems.is_empty(), "{} broken links:\n{}", problems.len(), problems.join("\n"));
}

/// The `docs/course/…` references in a text: the path (trimmed of sentence punctuation) and the
/// anchor, if any, with the line they are on.
fn course_references(text: &str) -> Vec<(usize, String, Option<String>)> {
    const MARK: &str = "docs/course/";
    let mut found = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let mut rest = line;
        while let Some(at) = rest.find(MARK) {
            let after = &rest[at..];
            let path_len = after
                .char_indices()
                .find(|&(_, c)| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-' | '/')))
                .map_or(after.len(), |(k, _)| k);
            let path = after[..path_len].trim_end_matches(['.', '/', '-']);
            let mut anchor = None;
            let tail = &after[path.len()..];
            if let Some(hash) = tail.strip_prefix('#') {
                let len = hash
                    .char_indices()
                    .find(|&(_, c)| !(c.is_alphanumeric() || matches!(c, '_' | '-')))
                    .map_or(hash.len(), |(k, _)| k);
                anchor = Some(hash[..len].to_string());
            }
            found.push((number + 1, path.to_string(), anchor));
            rest = &after[MARK.len()..];
        }
    }
    found
}

#[test]
fn the_codes_references_to_the_course_resolve() {
    let mut anchors = HashMap::new();
    let mut problems = Vec::new();
    for dir in ["src", "shaders", "examples", "benches", "tests", "assets"] {
        for file in files_under(&root().join(dir), &[".rs", ".wgsl", ".toml"]) {
            // This file's messages name the pattern (docs/course/NN-name.md) rather than a chapter.
            if file.ends_with("tests/course.rs") {
                continue;
            }
            for (number, path, anchor) in course_references(&read(&file)) {
                if path == "docs/course" {
                    continue;
                }
                let target = match &anchor {
                    Some(a) => format!("{path}#{a}"),
                    None => path.clone(),
                };
                if let Some(why) = broken(&root().join("README.md"), &target, &mut anchors) {
                    problems.push(format!("{}:{number}: {target}: {why}", shown(&file)));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{} references into the course do not resolve:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn the_code_cites_the_course_not_techniques_md() {
    let mut mentions = Vec::new();
    for dir in ["src", "shaders", "examples", "benches", "tests", "assets"] {
        for file in files_under(&root().join(dir), &[".rs", ".wgsl", ".toml"]) {
            for (number, line) in read(&file).lines().enumerate() {
                // This test's own text names the file it looks for.
                if line.contains("TECHNIQUES.md") && !file.ends_with("tests/course.rs") {
                    mentions.push(format!("{}:{}: {}", shown(&file), number + 1, line.trim()));
                }
            }
        }
    }
    assert!(
        mentions.is_empty(),
        "{} places in the code still cite TECHNIQUES.md, the team's working notes; cite the course's \
         chapter instead (docs/course/NN-name.md#anchor, see docs/course/README.md):\n{}",
        mentions.len(),
        mentions.join("\n")
    );
}

fn course_scenes() -> Vec<PathBuf> {
    files_under(&root().join("assets").join("scenes").join("course"), &[".toml"])
}

fn course_chapters() -> Vec<PathBuf> {
    files_under(&root().join("docs").join("course"), &[".md"])
}

#[test]
fn every_exercise_scene_loads() {
    let scenes = course_scenes();
    assert!(scenes.len() >= 11, "one scene or more per chapter, found {}", scenes.len());
    let failures: Vec<String> = scenes
        .iter()
        .filter_map(|path| mirador::Scene::load(path).err().map(|e| format!("{}: {e}", shown(path))))
        .collect();
    assert!(failures.is_empty(), "exercise scenes that do not load:\n{}", failures.join("\n"));
}

/// The `assets/scenes/…toml` paths a text names (in commands, code spans or links).
fn scene_mentions(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("scenes/") {
        let start = rest[..at].rfind(|c: char| c.is_whitespace() || matches!(c, '`' | '(' | '"')).map_or(0, |k| k + 1);
        let after = &rest[at..];
        let len = after
            .char_indices()
            .find(|&(_, c)| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-' | '/')))
            .map_or(after.len(), |(k, _)| k);
        let mention = format!("{}{}", &rest[start..at], &after[..len]);
        if mention.ends_with(".toml") {
            found.push(mention);
        }
        rest = &after[len.max(1)..];
    }
    found
}

#[test]
fn every_scene_a_chapter_names_exists_and_every_exercise_scene_is_used() {
    let mut named = BTreeSet::new();
    let mut problems = Vec::new();
    for chapter in course_chapters() {
        for mention in scene_mentions(&read(&chapter)) {
            // Commands run from the repository's root; links are relative to the chapter.
            let from_root = root().join(mention.trim_start_matches("./"));
            let from_chapter = normalized(&chapter.parent().expect("a folder").join(&mention));
            let file = if from_root.exists() { from_root } else { from_chapter };
            if file.exists() {
                named.insert(normalized(&file));
            } else {
                problems.push(format!("{}: names {mention}, which does not exist", shown(&chapter)));
            }
        }
    }
    for scene in course_scenes() {
        if !named.contains(&normalized(&scene)) {
            problems.push(format!("{} is used by no chapter", shown(&scene)));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn every_course_image_is_linked_and_made_by_the_script() {
    let images = files_under(&root().join("docs").join("course").join("images"), &[".png"]);
    assert!(!images.is_empty(), "the course has images");
    let script = read(&root().join("docs").join("course").join("images.sh"));
    let chapters: String = course_chapters().iter().map(|c| read(c)).collect();
    let mut problems = Vec::new();
    for image in &images {
        let name = image.file_name().expect("a name").to_string_lossy().to_string();
        if !script.contains(&name) {
            problems.push(format!("{name}: not made by docs/course/images.sh"));
        }
        if !chapters.contains(&format!("images/{name}")) {
            problems.push(format!("{name}: linked from no chapter"));
        }
    }
    let total: u64 = images.iter().map(|i| fs::metadata(i).map_or(0, |m| m.len())).sum();
    assert!(total < 6 << 20, "the course's images take {} KiB; keep them to a few MiB", total >> 10);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_link_parser_reads_what_github_reads() {
    assert_eq!(link_targets("see [a](x.md#b) and ![i](images/p.png \"t\")"), ["x.md#b", "images/p.png"]);
    assert_eq!(link_targets("`[not](a link)` but [this](y.md)"), ["y.md"]);
    assert_eq!(link_targets("[ref]: ../z.md#c"), ["../z.md#c"]);
    assert_eq!(slug(&heading_text("`[camera]`")), "camera");
    assert_eq!(slug(&heading_text("5. Cast shadows: maps & polygons")), "5-cast-shadows-maps--polygons");
    assert_eq!(slug(&heading_text("The `trace.max_depth` [setting](x.md)")), "the-tracemax_depth-setting");
    assert_eq!(slug("Latitude–longitude (α = a·u)"), "latitudelongitude-α--au");
    let anchors = anchors_of("# A\n## Tests\n```\n# not a heading\n```\n## Tests\nSetext\n---\n");
    assert_eq!(anchors, ["a", "setext", "tests", "tests-1"].map(String::from).into_iter().collect());
    assert_eq!(
        course_references("see docs/course/05-shadows.md#acne-and-peter-panning. And docs/course/01-camera.md."),
        [
            (1, "docs/course/05-shadows.md".to_string(), Some("acne-and-peter-panning".to_string())),
            (1, "docs/course/01-camera.md".to_string(), None)
        ]
    );
}

/// The names a text links to source files by, ``[`NAME`](PATH)`` with NAME an identifier or a
/// path of them (`Type::method`) and PATH a `.rs` or `.wgsl` file: (line, name, target).
fn named_declarations(text: &str) -> Vec<(usize, String, String)> {
    let mut found = Vec::new();
    for (number, line) in prose_lines(text) {
        let mut rest = line;
        while let Some(start) = rest.find("[`") {
            rest = &rest[start + 2..];
            let Some(end) = rest.find("`](") else { break };
            let name = rest[..end].trim_end_matches("()").to_owned();
            let after = &rest[end + 3..];
            let Some(close) = after.find(')') else { break };
            let target = after[..close].split('#').next().unwrap_or("").to_owned();
            let identifier = !name.is_empty()
                && name.split("::").all(|part| {
                    part.chars().next().is_some_and(|c| c.is_alphabetic() || c == '_')
                        && part.chars().all(|c| c.is_alphanumeric() || c == '_')
                });
            if identifier && (target.ends_with(".rs") || target.ends_with(".wgsl")) {
                found.push((number, name, target));
            }
            rest = &after[close..];
        }
    }
    found
}

/// Whether `source` declares `name`'s last part (a function, type, trait, constant, macro or
/// module item) and, for `Type::item`, mentions `Type`.
fn declares(source: &str, name: &str) -> bool {
    let parts: Vec<&str> = name.split("::").collect();
    let last = parts[parts.len() - 1];
    let keywords =
        ["fn", "struct", "enum", "trait", "type", "const", "static", "mod", "macro_rules!", "var", "override", "alias"];
    let declared = source.lines().any(|line| {
        let words: Vec<&str> =
            line.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '!')).filter(|w| !w.is_empty()).collect();
        words.windows(2).any(|w| keywords.contains(&w[0]) && w[1] == last)
    });
    declared && parts[..parts.len() - 1].iter().all(|part| source.contains(part))
}

#[test]
fn every_declaration_a_document_links_to_its_file_is_there() {
    let mut problems = Vec::new();
    let mut checked = 0;
    for document in documentation() {
        for (line, name, target) in named_declarations(&read(&document)) {
            let file = normalized(&document.parent().expect("a folder").join(&target));
            checked += 1;
            match fs::read_to_string(&file) {
                Ok(source) if declares(&source, &name) => {}
                Ok(_) => problems.push(format!("{}:{line}: `{name}` is not declared in {target}", shown(&document))),
                Err(_) => problems.push(format!("{}:{line}: {target} does not exist", shown(&document))),
            }
        }
    }
    assert!(checked >= 15, "{checked} names checked");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // The check can fail: a name its file does not declare, and a method of a type it never names.
    let source = "pub struct MipChain;\nimpl MipChain {\n    pub fn sample(&self) {}\n}\n";
    assert!(declares(source, "MipChain::sample") && declares(source, "MipChain"));
    assert!(!declares(source, "MipChain::sampled") && !declares(source, "Other::sample"));
    let text = "see [`bump_normal`](../../src/texture/bump.rs) and [`a link`](x.rs)";
    assert_eq!(named_declarations(text), [(1, "bump_normal".to_owned(), "../../src/texture/bump.rs".to_owned())]);
}

/// Whether a line of prose is an ATX heading (`#` to `######`, then a space or nothing).
fn is_heading(line: &str) -> bool {
    let trimmed = line.trim_start();
    let hashes = trimmed.chars().take_while(|&c| c == '#').count();
    let after = &trimmed[hashes.min(trimmed.len())..];
    (1..=6).contains(&hashes) && line.len() - trimmed.len() < 4 && (after.is_empty() || after.starts_with([' ', '\t']))
}

/// The ```` ```math ```` blocks of a Markdown text, each as (the line of its opening fence, the
/// lines around it that must say what computes it): from the paragraph just before the block to
/// the line before the next heading or the next math block. Lines are numbered from 1.
fn formula_contexts(text: &str) -> Vec<(usize, std::ops::RangeInclusive<usize>)> {
    let lines: Vec<&str> = text.lines().collect();
    // Whether each line is a heading outside a fence, and the math blocks as (open, close) indices.
    let mut heading = vec![false; lines.len()];
    let mut math_opens = vec![false; lines.len()];
    let mut blocks = Vec::new();
    let mut open: Option<(usize, bool)> = None;
    for (i, line) in lines.iter().enumerate() {
        if is_fence(line) {
            match open {
                None => {
                    let math = line.trim_start().trim_start_matches(['`', '~']).trim() == "math";
                    math_opens[i] = math;
                    open = Some((i, math));
                }
                Some((start, math)) => {
                    if math {
                        blocks.push((start, i));
                    }
                    open = None;
                }
            }
        } else if open.is_none() {
            heading[i] = is_heading(line);
        }
    }
    blocks
        .into_iter()
        .map(|(start, close)| {
            // The paragraph before: back over blank lines, then over the lines of prose above them.
            let mut first = start;
            let mut k = start;
            while k > 0 && lines[k - 1].trim().is_empty() {
                k -= 1;
            }
            while k > 0 && !lines[k - 1].trim().is_empty() && !heading[k - 1] && !is_fence(lines[k - 1]) {
                k -= 1;
                first = k;
            }
            let last = (close + 1..lines.len()).find(|&j| heading[j] || math_opens[j]).unwrap_or(lines.len()) - 1;
            (start + 1, first + 1..=last + 1)
        })
        .collect()
}

/// The formulas of `document` (a chapter at that path, text `text`) whose surroundings link no
/// function of `src/` or `shaders/` that the linked file declares, and do not say that no
/// function computes them: one message each, naming the chapter and the block's line. Also the
/// number of formulas read.
fn formulas_without_code(document: &Path, text: &str) -> (Vec<String>, usize) {
    let named = named_declarations(text);
    let code = [root().join("src"), root().join("shaders")];
    let contexts = formula_contexts(text);
    let lines: Vec<&str> = text.lines().collect();
    let problems = contexts
        .iter()
        .filter(|(_, around)| {
            let prose = lines[around.start() - 1..*around.end()].join("\n");
            if prose.contains("no function computes it") {
                return false;
            }
            !named.iter().any(|(line, name, target)| {
                let file = normalized(&document.parent().expect("a folder").join(target));
                around.contains(line)
                    && code.iter().any(|dir| file.starts_with(dir))
                    && fs::read_to_string(&file).is_ok_and(|source| declares(&source, name))
            })
        })
        .map(|(line, _)| {
            format!(
                "{}:{line}: this formula names no function that computes it: link one in the paragraph before it \
                 or the text after it, as [`name`](../../src/…/file.rs) or (../../shaders/…/file.wgsl), or say \
                 that no function computes it",
                shown(document)
            )
        })
        .collect();
    (problems, contexts.len())
}

#[test]
fn every_formula_names_the_code_that_computes_it() {
    let mut problems = Vec::new();
    let mut formulas = 0;
    for chapter in course_chapters() {
        let name = chapter.file_name().expect("a name").to_string_lossy().to_string();
        // The numbered chapters: docs/course/NN-name.md.
        if !(name.len() > 3 && name.as_bytes()[..2].iter().all(u8::is_ascii_digit) && name.as_bytes()[2] == b'-') {
            continue;
        }
        let (found, count) = formulas_without_code(&chapter, &read(&chapter));
        problems.extend(found);
        formulas += count;
    }
    assert!(
        formulas >= 30,
        "the check found only {formulas} ```math blocks in the chapters: is it still reading them?"
    );
    assert!(problems.is_empty(), "{} formulas name no code:\n{}", problems.len(), problems.join("\n"));

    // The check can fail, and reads what it should: the paragraph before a formula and the text
    // after it, up to a heading (not a `#` line in a code block) or the next formula.
    let chapter = root().join("docs").join("course").join("00-example.md");
    let text = [
        "# A",                                                        // 1
        "",                                                           // 2
        "Snell's law, by [`refract`](../../src/scene/optics.rs):",    // 3: before block 1
        "",                                                           // 4
        "```math",                                                    // 5: block 1, passes
        "x",                                                          // 6
        "```",                                                        // 7
        "",                                                           // 8
        "```math",                                                    // 9: block 2, passes by what follows
        "y",                                                          // 10
        "```",                                                        // 11
        "",                                                           // 12
        "```text",                                                    // 13
        "# not a heading",                                            // 14
        "```",                                                        // 15
        "",                                                           // 16
        "Computed by [`fresnel`](../../shaders/common/optics.wgsl).", // 17
        "## B",                                                       // 18
        "",                                                           // 19
        "By [`refracted`](../../src/scene/optics.rs).",               // 20: not declared there
        "",                                                           // 21
        "```math",                                                    // 22: block 3, fails
        "z",                                                          // 23
        "```",                                                        // 24
        "",                                                           // 25
        "By [`read`](../../tests/course.rs), which is not the code.", // 26
        "",                                                           // 27
        "```math",                                                    // 28: block 4, fails
        "w",                                                          // 29
        "```",                                                        // 30
        "",                                                           // 31
        "## C",                                                       // 32
        "",                                                           // 33
        "Too late: [`refract`](../../src/scene/optics.rs).",          // 34
        "",                                                           // 35
        "```math",                                                    // 36: block 5, passes
        "v",                                                          // 37
        "```",                                                        // 38
        "## D",                                                       // 39
        "",                                                           // 40
        "```math",                                                    // 41: block 6, passes
        "u",                                                          // 42
        "```",                                                        // 43
        "",                                                           // 44
        "A definition; no function computes it alone.",               // 45
    ]
    .join("\n");
    let (found, count) = formulas_without_code(&chapter, &text);
    assert_eq!(count, 6);
    let lines: Vec<&str> = found.iter().map(|f| f.split(": ").next().unwrap_or("")).collect();
    assert_eq!(lines, ["docs/course/00-example.md:22", "docs/course/00-example.md:28"], "{found:?}");
    let contexts = formula_contexts(&text);
    assert_eq!(contexts[0], (5, 3..=8));
    assert_eq!(contexts[1], (9, 9..=17));
    assert_eq!(contexts[3], (28, 26..=31));
    assert_eq!(contexts[5], (41, 41..=45));
}
