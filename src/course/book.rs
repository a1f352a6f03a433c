//! The course's mdBook preprocessor (`mirador book`, run by mdBook as web/site.sh builds the
//! site): mdBook hands over the book as JSON, each chapter's Markdown is rewritten, the book goes
//! back as JSON. What it rewrites, and why:
//! - Under every shell block, an "open in the browser" link per command, made by the CLI's own
//!   parser from the command as the shell would run it ([`super::commands`]), so a link cannot
//!   drift from its command; commands the page cannot run are said to need the command line.
//! - The formulas, fenced as `math` (LaTeX, which the forge's file view typesets too), become
//!   elements that the site's KaTeX typesets (web/site/math.js).
//! - A chapter with labs ends with them, opened in the page.
//! - Links out of the course: to another page of the book, as on the forge; to a built-in scene,
//!   the page with that scene open; to any other file of the repository, the repository's page
//!   for it (`source`) or, without one, a copy of the file in the site (`source/PATH.txt`); to
//!   the answers, in a student's site, nowhere (the link's text is kept).

use std::path::{Component, Path, PathBuf};

use anyhow::{Context as _, bail};
use serde_json::Value;

use super::{Linked, PageLink, commands};
use crate::lab::summary::escape;

/// The teachers' answers: a page of the book only when web/site.sh is given `--answers`.
const ANSWERS: &str = "docs/course/answers.md";

/// What the preprocessor knows besides the book.
pub struct Options<'a> {
    /// The repository's root, where the files a chapter links are.
    pub repository: PathBuf,
    /// The address under which the repository's files are shown (`https://…/blob/COMMIT`), if
    /// any; without one, linked files are copied into the site.
    pub source: Option<String>,
    /// The page's address for a command's words after `mirador`, or why it has none; an error
    /// for a command Mirador refuses (the course has a mistake).
    pub link_of: &'a dyn Fn(&[String]) -> anyhow::Result<Linked>,
}

/// The book after the rewriting, and the repository's files to copy into the site's `source/`
/// (empty with a `source` address).
pub struct Rewritten {
    pub book: Value,
    pub copies: Vec<String>,
}

impl Rewritten {
    /// Copies the linked files into `book_src/source/` ([`copy_name`]), and writes an
    /// `index.html` listing each folder's copies.
    pub fn write_copies(&self, repository: &Path, book_src: &Path) -> anyhow::Result<()> {
        let mut folders: std::collections::BTreeMap<&str, Vec<&str>> = Default::default();
        for path in &self.copies {
            let to = book_src.join("source").join(copy_name(path));
            std::fs::create_dir_all(to.parent().unwrap_or(book_src))?;
            std::fs::copy(repository.join(path), &to).with_context(|| format!("copying {path} into the site"))?;
            let (folder, name) = path.rsplit_once('/').unwrap_or(("", path));
            folders.entry(folder).or_default().push(name);
        }
        for (folder, names) in folders {
            let items: String = names
                .iter()
                .map(|n| format!("<li><a href=\"{}\">{}</a></li>\n", escape(&copy_name(n)), escape(n)))
                .collect();
            let page = format!(
                "<!doctype html>\n<meta charset=\"utf-8\">\n<title>{0}</title>\n<h1>{0}/</h1>\n<ul>\n{items}</ul>\n",
                escape(folder)
            );
            std::fs::write(book_src.join("source").join(folder).join("index.html"), page)?;
        }
        Ok(())
    }
}

/// Rewrites the book mdBook hands over (`[context, book]` as JSON).
pub fn preprocess(input: &str, options: &Options) -> anyhow::Result<Rewritten> {
    let input: Value = serde_json::from_str(input).context("mdBook's input is not JSON")?;
    let Some(mut book) = input.get(1).cloned() else { bail!("mdBook's input is not [context, book]") };
    let mut chapters = Vec::new();
    visit(&mut book, &mut |chapter| {
        if let Some(path) = chapter.get("source_path").and_then(Value::as_str) {
            chapters.push(path.to_owned());
        }
    });
    let mut copies = Vec::new();
    let mut failure = None;
    visit(&mut book, &mut |chapter| {
        let Some(path) = chapter.get("source_path").and_then(Value::as_str).map(str::to_owned) else { return };
        let Some(content) = chapter.get_mut("content") else { return };
        let page = Page { staged: Path::new(&path), chapters: &chapters, options };
        match page.rewrite(content.as_str().unwrap_or_default(), &mut copies) {
            Ok(text) => *content = Value::String(text),
            Err(e) => failure = Some(e.context(path.clone())),
        }
    });
    if let Some(e) = failure {
        return Err(e);
    }
    copies.sort();
    copies.dedup();
    Ok(Rewritten { book, copies })
}

/// Calls `f` on every chapter of the book, nested ones too (mdBook 0.5's `items`, 0.4's
/// `sections`).
fn visit(value: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    match value {
        Value::Object(map) => {
            if let Some(chapter) = map.get_mut("Chapter") {
                f(chapter);
            }
            for item in map.values_mut() {
                visit(item, f);
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|item| visit(item, f)),
        _ => {}
    }
}

/// Where a repository file is staged in the book: the course's files at its root, the other
/// documents of `docs/` under `reference/`.
fn staged_path(repository_path: &str) -> String {
    match repository_path.strip_prefix("docs/course/") {
        Some(rest) => rest.to_owned(),
        None => format!("reference/{}", repository_path.trim_start_matches("docs/")),
    }
}

/// The inverse of [`staged_path`].
fn repository_path(staged: &Path) -> PathBuf {
    match staged.strip_prefix("reference") {
        Ok(rest) => Path::new("docs").join(rest),
        Err(_) => Path::new("docs/course").join(staged),
    }
}

/// One chapter being rewritten.
struct Page<'a> {
    /// Its path in the book (`01-camera.md`, `reference/scene-format.md`).
    staged: &'a Path,
    /// Every chapter's path in the book.
    chapters: &'a [String],
    options: &'a Options<'a>,
}

impl Page<'_> {
    /// The chapter's number, for a chapter of the course (`07-planar-mirrors.md`).
    fn chapter(&self) -> Option<u32> {
        let name = self.staged.to_str()?;
        name.split_once('-').and_then(|(n, _)| n.parse().ok()).filter(|_| !name.contains('/'))
    }

    /// `../` as many times as the chapter is deep in the book: the way back to the site's root.
    fn up(&self) -> String {
        "../".repeat(self.staged.components().count() - 1)
    }

    fn rewrite(&self, markdown: &str, copies: &mut Vec<String>) -> anyhow::Result<String> {
        // The chapters (`NN-….md`) get their commands' links; the introduction, the labs' guide
        // and the reference pages print commands in their general forms (`SCENE.toml`, `[--set …]`).
        let printed = if self.chapter().is_some() { commands(markdown) } else { Vec::new() };
        let mut out = String::with_capacity(markdown.len() * 2);
        let mut math: Option<String> = None;
        let mut fenced = false;
        for (i, line) in markdown.lines().enumerate() {
            let fence = line.trim_start().starts_with("```");
            if let Some(body) = &mut math {
                if fence {
                    out.push_str(&format!("<div class=\"math-display\">{}</div>\n", escape(body.trim_end())));
                    math = None;
                } else {
                    body.push_str(line);
                    body.push('\n');
                }
                continue;
            }
            if fence && !fenced && line.trim() == "```math" {
                math = Some(String::new());
                continue;
            }
            if fence {
                fenced = !fenced;
            }
            if fenced || fence {
                out.push_str(line);
            } else {
                out.push_str(&self.links(line, copies)?);
            }
            out.push('\n');
            let here: Vec<&Vec<String>> = printed.iter().filter(|p| p.block_end == i).map(|p| &p.words).collect();
            if fence && !here.is_empty() {
                out.push_str(&self.live(&here).with_context(|| format!("the shell block ending on line {}", i + 1))?);
            }
        }
        if math.is_some() {
            bail!("a ```math block is not closed");
        }
        out.push_str(&self.labs());
        Ok(out)
    }

    /// The paragraph under a shell block: a link per command the page can show, and what needs
    /// the command line.
    fn live(&self, commands: &[&Vec<String>]) -> anyhow::Result<String> {
        let mut links = Vec::new();
        let mut cli = Vec::new();
        for words in commands {
            let Some(args) = mirador_arguments(words) else { continue };
            let args = match args {
                Ok(args) => args,
                Err(why) => {
                    cli.push(format!("<code>{}</code> ({why})", escape(&words.join(" "))));
                    continue;
                }
            };
            match (self.options.link_of)(&args)? {
                Linked::Page(link) => {
                    let then = link.then.as_ref().map(|t| format!(", then {}", escape(t))).unwrap_or_default();
                    links.push(format!(
                        "<a href=\"{}mirador/{}\">{}</a>{then}",
                        self.up(),
                        escape(&link.query()),
                        escape(&label(&args))
                    ));
                }
                Linked::CommandLine(why) => {
                    cli.push(format!("<code>{}</code> ({})", escape(&args.join(" ")), escape(&why)))
                }
            }
        }
        let mut out = String::new();
        if !links.is_empty() {
            out.push_str(&format!("\n<p class=\"mirador-live\">Open in the browser: {}</p>\n\n", links.join(" · ")));
        }
        if !cli.is_empty() {
            out.push_str(&format!("\n<p class=\"mirador-cli\">Needs the command line: {}</p>\n\n", cli.join("; ")));
        }
        Ok(out)
    }

    /// The chapter's labs in the page, for a chapter `NN-….md`: a paragraph after its own "Lab"
    /// section, which says how to do them from the command line.
    fn labs(&self) -> String {
        let Some(number) = self.chapter() else { return String::new() };
        let labs: Vec<_> = crate::lab::catalog().into_iter().filter(|lab| lab.chapter == number).collect();
        if labs.is_empty() {
            return String::new();
        }
        let links: Vec<String> =
            labs.iter().map(|lab| format!("[{0}]({1}mirador/?lab={0})", lab.name, self.up())).collect();
        format!(
            "\nIn the browser, with nothing installed: {} (your file is an editor beside the view, drawn as you \
             type; the panel's Check button runs the lab's tests and gives its `results.json`). A class graded \
             with hidden tests uses `mirador lab new` and `mirador lab check`, as above.\n",
            links.join(", ")
        )
    }

    /// The line with every Markdown link target `](…)` sent where it works on the site.
    fn links(&self, line: &str, copies: &mut Vec<String>) -> anyhow::Result<String> {
        let mut out = String::with_capacity(line.len());
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let (before, after) = rest.split_at(at + 2);
            out.push_str(before);
            let Some(end) = after.find(')') else {
                rest = after;
                break;
            };
            match self.target(&after[..end], copies)? {
                Some(target) => {
                    out.push_str(&target);
                    rest = &after[end..];
                }
                None => {
                    // The link dropped, its text kept: `[text](…)` → `text`.
                    out.truncate(out.len() - 2);
                    if let Some(open) = out.rfind('[') {
                        out.remove(open);
                    }
                    rest = &after[end + 1..];
                }
            }
        }
        out.push_str(rest);
        Ok(out)
    }

    /// Where one link goes on the site; `None`: nowhere, the link's text kept.
    fn target(&self, href: &str, copies: &mut Vec<String>) -> anyhow::Result<Option<String>> {
        if href.contains("://") || href.starts_with('#') || href.starts_with("mailto:") || href.is_empty() {
            return Ok(Some(href.to_owned()));
        }
        let (path, fragment) = href.split_once('#').map_or((href, ""), |(p, f)| (p, f));
        let fragment = if fragment.is_empty() { String::new() } else { format!("#{fragment}") };
        let origin = repository_path(self.staged);
        let Some(linked) = normalize(&origin.parent().unwrap_or(Path::new("")).join(path)) else {
            bail!("the link {href} leaves the repository");
        };
        let linked = linked.to_string_lossy().replace('\\', "/");
        let staged = staged_path(&linked);
        let folder = self.options.repository.join(&linked).is_dir();
        if self.chapters.contains(&staged)
            || (!linked.ends_with(".md") && !folder && linked.starts_with("docs/course/"))
        {
            // mdBook writes the book's README.md as index.html.
            let staged = if staged == "README.md" { "index.html".to_owned() } else { staged };
            return Ok(Some(format!("{}{staged}{fragment}", self.up())));
        }
        // Without the forge: no answers (left out of a student's site), and no folder of the
        // course's own (its files are in the site already, with no listing to show them).
        if self.options.source.is_none() && (linked == ANSWERS || (folder && linked.starts_with("docs/course/"))) {
            return Ok(None);
        }
        if linked.starts_with("assets/scenes/")
            && let Ok(scene) = PageLink::builtin_scene(Path::new(&linked))
        {
            let link = PageLink { scene: Some(scene), ..PageLink::default() };
            return Ok(Some(format!("{}mirador/{}", self.up(), link.query())));
        }
        if !self.options.repository.join(&linked).exists() {
            bail!("the link {href} names {linked}, which the repository does not have");
        }
        if let Some(source) = &self.options.source {
            return Ok(Some(format!("{}/{linked}{fragment}", source.trim_end_matches('/'))));
        }
        if folder {
            // A folder: its files copied, and a page that lists them.
            for entry in
                std::fs::read_dir(self.options.repository.join(&linked)).with_context(|| format!("reading {linked}"))?
            {
                let entry = entry?;
                if entry.file_type()?.is_file() {
                    copies.push(format!("{}/{}", linked.trim_end_matches('/'), entry.file_name().to_string_lossy()));
                }
            }
            return Ok(Some(format!("{}source/{}/index.html", self.up(), linked.trim_end_matches('/'))));
        }
        let copy = copy_name(&linked);
        copies.push(linked);
        Ok(Some(format!("{}source/{copy}", self.up())))
    }
}

/// The arguments after `mirador` of a command a chapter prints (`cargo run --release -- ARGS`,
/// `cargo run --release`, `mirador ARGS`); `Err` for a teaching example, which only the command
/// line runs; `None` for a command that is not Mirador's (`bash`, `cargo build`).
fn mirador_arguments(words: &[String]) -> Option<Result<Vec<String>, String>> {
    let words: Vec<&str> = words.iter().map(String::as_str).collect();
    match words.as_slice() {
        ["mirador", args @ ..] => Some(Ok(args.iter().map(|s| s.to_string()).collect())),
        ["cargo", "run", rest @ ..] => {
            let (options, args) = match rest.iter().position(|w| *w == "--") {
                Some(at) => (&rest[..at], &rest[at + 1..]),
                None => (rest, &[][..]),
            };
            if options.contains(&"--example") {
                return Some(Err("a teaching example: a program of its own".into()));
            }
            Some(Ok(args.iter().map(|s| s.to_string()).collect()))
        }
        _ => None,
    }
}

/// A link's words: the image the command writes, else its settings, else what it does.
fn label(args: &[String]) -> String {
    if let Some(at) = args.iter().position(|a| a == "-o" || a == "--output")
        && let Some(name) = args.get(at + 1)
    {
        return name.clone();
    }
    let sets: Vec<&str> = args.windows(2).filter(|w| w[0] == "--set").map(|w| w[1].as_str()).collect();
    let verb = args.first().map_or("view", String::as_str);
    match sets.is_empty() {
        true => verb.to_owned(),
        false => format!("{verb} {}", sets.join(" ")),
    }
}

/// The name of a repository file's copy in the site's `source/`: `PATH.txt` (a browser shows a
/// text file; it would download a `.rs`), and `.markdown.txt` for `.md`, since mdBook turns any
/// link with `.md` in it into one to a page of the book.
fn copy_name(path: &str) -> String {
    match path.strip_suffix(".md") {
        Some(stem) => format!("{stem}.markdown.txt"),
        None => format!("{path}.txt"),
    }
}

/// `a/b/../c` → `a/c`; `None` if it climbs above its start.
fn normalize(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn link_of(args: &[String]) -> anyhow::Result<Linked> {
        match args.first().map(String::as_str) {
            Some("render") if args.iter().any(|a| a.contains("no_such")) => anyhow::bail!("no setting no_such"),
            Some("render") => Ok(Linked::Page(PageLink {
                scene: Some(args[1].trim_start_matches("assets/scenes/").into()),
                set: args.windows(2).filter(|w| w[0] == "--set").map(|w| w[1].clone()).collect(),
                view: Some("raster"),
                ..PageLink::default()
            })),
            _ => Ok(Linked::CommandLine("not in the page".into())),
        }
    }

    fn book(path: &str, content: &str) -> String {
        let chapter = |path: &str, content: &str| serde_json::json!({"Chapter": {"name": "x", "content": content, "source_path": path, "sub_items": []}});
        let others =
            ["01-camera.md", "05-shadows.md", "reference/scene-format.md", "README.md"].map(|p| chapter(p, ""));
        serde_json::json!([{}, {"items": [chapter(path, content), others[0], others[1], others[2], others[3]]}])
            .to_string()
    }

    fn rewritten(path: &str, content: &str, source: Option<&str>) -> anyhow::Result<(String, Vec<String>)> {
        let options = Options {
            repository: PathBuf::from(env!("CARGO_MANIFEST_DIR")),
            source: source.map(str::to_owned),
            link_of: &link_of,
        };
        let out = preprocess(&book(path, content), &options)?;
        let text = out.book["items"][0]["Chapter"]["content"].as_str().unwrap().to_owned();
        Ok((text, out.copies))
    }

    #[test]
    fn every_command_gets_its_link_or_says_it_needs_the_command_line() {
        let chapter = "# 5\n```sh\nfor s in 1 2; do\n  cargo run --release -- render assets/scenes/course/mirror-pair.toml -o d$s.png --set mirrors.depth=$s\ndone\n\
                       cargo run --release --example shadows\ncargo run --release -- diff a.png b.png\nbash x.sh\n```\nafter\n";
        let (text, _) = rewritten("05-shadows.md", chapter, None).unwrap();
        assert!(text.contains(
            "Open in the browser: <a href=\"mirador/?scene=course/mirror-pair.toml&amp;set=mirrors.depth%3D1&amp;view=raster\">d1.png</a> · "
        ));
        assert!(text.contains(">d2.png</a></p>"));
        assert!(text.contains(
            "Needs the command line: <code>cargo run --release --example shadows</code> (a teaching example"
        ));
        assert!(text.contains("<code>diff a.png b.png</code> (not in the page)"));
        assert!(!text.contains("bash x.sh</code>"), "not Mirador's: no note");
        assert!(
            text.contains("In the browser, with nothing installed: [shadow-map](mirador/?lab=shadow-map) (your file")
        );
    }

    #[test]
    fn a_command_mirador_refuses_fails_the_book_naming_its_block() {
        let chapter = "# 5\n\n```sh\ncargo run --release -- render assets/scenes/showcase.toml --set no_such=1\n```\n";
        let error = rewritten("05-shadows.md", chapter, None).unwrap_err();
        assert_eq!(format!("{error:#}"), "05-shadows.md: the shell block ending on line 5: no setting no_such");
    }

    #[test]
    fn math_blocks_become_elements_for_katex_with_their_text_escaped() {
        let (text, _) = rewritten("02-x.md", "a\n```math\nx < y \\\\\n\\text{a&b}\n```\nb\n", None).unwrap();
        assert!(text.contains("<div class=\"math-display\">x &lt; y \\\\\n\\text{a&amp;b}</div>\nb"), "{text}");
    }

    #[test]
    fn links_leaving_the_course_go_where_they_work_on_the_site() {
        let line = "[a](05-shadows.md#x) [b](../../assets/scenes/course/mirror-pair.toml) [c](../../src/lib.rs) [see the answers](answers.md) [the images](images/) \
                    [d](../scene-format.md#camera) [e](images/mipmaps.png) [f](https://x.org/a)";
        let (text, copies) = rewritten("01-camera.md", line, None).unwrap();
        assert_eq!(
            text.trim_end(),
            "[a](05-shadows.md#x) [b](mirador/?scene=course/mirror-pair.toml) [c](source/src/lib.rs.txt) see the answers the images \
             [d](reference/scene-format.md#camera) [e](images/mipmaps.png) [f](https://x.org/a)"
        );
        assert_eq!(copies, ["src/lib.rs"]);
        let (text, copies) = rewritten(
            "reference/architecture.md",
            "[c](../src/lib.rs#L3) [g](course/01-camera.md) [h](course/answers.md) [i](course/README.md#x)",
            Some("https://f/blob/abc"),
        )
        .unwrap();
        assert_eq!(
            text.trim_end(),
            "[c](https://f/blob/abc/src/lib.rs#L3) [g](../01-camera.md) [h](https://f/blob/abc/docs/course/answers.md) [i](../index.html#x)"
        );
        assert!(copies.is_empty());
        assert!(
            rewritten("01-camera.md", "[x](../../no/such/file.rs)", None)
                .unwrap_err()
                .root_cause()
                .to_string()
                .contains("does not have")
        );
    }
}
