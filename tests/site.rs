//! The course as a site (web/site.sh), checked without mdBook or a browser: the book's
//! preprocessor, `mirador book`, run over every page as mdBook runs it. Every Mirador command a
//! chapter prints gets its link into the page or says that it needs the command line; every link
//! names a scene built into the page, with settings that scene takes, in a view the page has; the
//! links out of the course go where the site has them; the answers stay out unless asked for.
//! web/site-test.sh does the rest in a browser (web/README.md, "The course as a site").

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::{Value, json};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The pages of the book as web/site.sh stages them: (path in the book, path in the repository).
fn pages(answers: bool) -> Vec<(String, PathBuf)> {
    let mut names: Vec<String> = std::fs::read_dir(root().join("docs/course"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md") && (answers || n != "answers.md"))
        .collect();
    names.sort();
    let mut pages: Vec<(String, PathBuf)> =
        names.into_iter().map(|n| (n.clone(), root().join("docs/course").join(n))).collect();
    for doc in ["scene-format", "architecture", "performance"] {
        pages.push((format!("reference/{doc}.md"), root().join(format!("docs/{doc}.md"))));
    }
    pages
}

/// The book after `mirador book`, page by page, and the folder it copied files into.
fn preprocessed(answers: bool, name: &str) -> (Vec<(String, String)>, PathBuf) {
    let book_root = std::env::temp_dir().join(format!("mirador-site-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&book_root);
    std::fs::create_dir_all(&book_root).unwrap();
    let items: Vec<Value> = pages(answers)
        .iter()
        .map(|(path, file)| {
            let content = std::fs::read_to_string(file).unwrap();
            json!({"Chapter": {"name": path, "content": content, "source_path": path, "path": path, "sub_items": []}})
        })
        .collect();
    let context = json!({"root": book_root, "renderer": "html", "mdbook_version": "0.5.4",
        "config": {"book": {"src": "src"}, "preprocessor": {"mirador": {"repository": root()}}}});
    let input = json!([context, {"items": items}]).to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_mirador"))
        .arg("book")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write as _;
    child.stdin.take().unwrap().write_all(input.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "mirador book failed: {}", String::from_utf8_lossy(&out.stderr));
    let book: Value = serde_json::from_slice(&out.stdout).expect("mirador book writes the book as JSON");
    let chapters = book["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|item| {
            let chapter = &item["Chapter"];
            (chapter["source_path"].as_str().unwrap().to_owned(), chapter["content"].as_str().unwrap().to_owned())
        })
        .collect();
    (chapters, book_root)
}

/// Every `href="…"` of the HTML the preprocessor wrote, with `&amp;` read back.
fn hrefs(text: &str) -> Vec<String> {
    text.split("href=\"").skip(1).map(|rest| rest[..rest.find('"').unwrap()].replace("&amp;", "&")).collect()
}

/// The query's pairs, decoded.
fn pairs(query: &str) -> Vec<(String, String)> {
    query
        .split('&')
        .map(|pair| {
            pair.split_once('=')
                .map_or((pair.to_owned(), String::new()), |(k, v)| (k.to_owned(), common::percent_decoded(v)))
        })
        .collect()
}

/// What the page does with a link's address (web/index.html), done here: the scene loaded with
/// the scene values among the settings, then the render settings set, one by one.
fn open_as_the_page_would(query: &str) -> Result<(), String> {
    use mirador::scene::file::overrides;
    let pairs = pairs(query);
    let mut scene = None;
    let mut sets = Vec::new();
    for (key, value) in &pairs {
        match key.as_str() {
            "scene" => scene = Some(value.clone()),
            "set" => sets.push(value.clone()),
            "view" if ["raster", "traced", "split", "difference"].contains(&value.as_str()) => {}
            "budget" | "lab" => {}
            other => return Err(format!("the page reads no `{other}={value}`")),
        }
    }
    let Some(scene) = scene else { return Ok(()) };
    let path = format!("assets/scenes/{scene}");
    if !mirador::files::BUILTIN.contains(&path.as_str()) {
        return Err(format!("{path} is not built into the page"));
    }
    let (scene_values, settings): (Vec<String>, Vec<String>) =
        sets.into_iter().partition(|s| overrides::is_scene_override(s));
    let mut loaded = overrides::load(&root().join(&path), &scene_values).map_err(|e| format!("{e:#}"))?;
    for assignment in &settings {
        loaded.settings.set(assignment).map_err(|e| format!("{assignment}: {e:#}"))?;
    }
    Ok(())
}

#[test]
fn every_command_of_the_course_opens_in_the_page_or_says_it_needs_the_command_line() {
    let (chapters, book_root) = preprocessed(false, "commands");
    let mut links = 0;
    for (path, text) in &chapters {
        let original =
            std::fs::read_to_string(pages(false).iter().find(|(p, _)| p == path).unwrap().1.clone()).unwrap();
        let mirador_commands = mirador::course::commands(&original)
            .iter()
            .filter(|p| {
                p.words.first().is_some_and(|w| w == "mirador") || p.words.starts_with(&["cargo".into(), "run".into()])
            })
            .count();
        let live: usize = text
            .lines()
            .filter(|l| l.starts_with("<p class=\"mirador-live\">"))
            .map(|l| l.matches("<a href=").count())
            .sum();
        let cli: usize = text
            .lines()
            .filter(|l| l.starts_with("<p class=\"mirador-cli\">"))
            .map(|l| l.matches("<code>").count())
            .sum();
        if !path.starts_with(|c: char| c.is_ascii_digit()) {
            assert_eq!(live + cli, 0, "{path}: the commands outside the chapters are general forms: no links");
            continue;
        }
        assert_eq!(live + cli, mirador_commands, "{path}: {mirador_commands} commands, {live} links and {cli} notes");
        // Only what the page truly cannot do needs the command line.
        for note in text
            .lines()
            .filter(|l| l.starts_with("<p class=\"mirador-cli\">"))
            .flat_map(|l| l.split("</code> (").skip(1))
        {
            let why = &note[..note.find(')').unwrap_or(note.len())];
            assert!(
                ["a teaching example", "is not built into the page", "the page has no such command"]
                    .iter()
                    .any(|w| why.contains(w)),
                "{path}: a command needs the command line for no reason the page has: {why}"
            );
        }
        for href in hrefs(text).into_iter().filter(|h| h.contains("mirador/?")) {
            let query = href.split_once('?').unwrap().1;
            open_as_the_page_would(query).unwrap_or_else(|e| panic!("{path}: {href}: {e}"));
            links += 1;
        }
        for target in hrefs(text)
            .into_iter()
            .chain(markdown_targets(text))
            .filter(|h| h.starts_with("source/") || h.starts_with("../source/"))
        {
            let copy = book_root.join("src").join(target.trim_start_matches("../"));
            assert!(copy.exists(), "{path}: {target} was not copied into the site");
        }
    }
    assert!(links > 60, "{links} links into the page");
    let _ = std::fs::remove_dir_all(book_root);
}

/// Every file under a folder.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() { files.extend(walk(&path)) } else { files.push(path) }
    }
    files
}

/// Every Markdown link target `](…)` of a text.
fn markdown_targets(text: &str) -> Vec<String> {
    text.split("](").skip(1).filter_map(|rest| rest.find(')').map(|end| rest[..end].to_owned())).collect()
}

#[test]
fn a_link_is_its_command_as_the_page_reads_it() {
    let (chapters, book_root) = preprocessed(false, "known");
    let chapter = |name: &str| chapters.iter().find(|(p, _)| p == name).unwrap().1.clone();
    // Chapter 7's loop: its variable in both the setting and the trace option, which becomes the
    // setting it sets.
    assert!(chapter("07-planar-mirrors.md").contains(
        "<a href=\"mirador/?scene=course/mirror-pair.toml&amp;set=mirrors.depth%3D2&amp;set=trace.max_depth%3D2&amp;view=split\">depth2.png</a>"
    ));
    // Chapter 10: `--aa regular --spp 16` as the two settings they set; the budget of chapter 12.
    assert!(chapter("10-anti-aliasing.md").contains(
        "set=trace.anti_aliasing%3D%22regular%22&amp;set=trace.samples%3D4&amp;view=traced\">aa-regular.png</a>"
    ));
    assert!(chapter("12-error-budget.md").contains("?scene=course/shadows-bias.toml&amp;budget\">budget</a>"));
    // A teaching example, and a scene the student writes first, need the command line.
    assert!(
        chapter("09-ray-tracing.md")
            .contains("<code>cargo run --release --example sphereflake -- 2</code> (a teaching example")
    );
    assert!(chapter("09-ray-tracing.md").contains("sphereflake-2.toml is not built into the page"));
    // Each chapter with labs opens them in the page.
    assert!(chapter("04-bump-mapping.md").contains("[bump](mirador/?lab=bump), [parallax](mirador/?lab=parallax) ("));
    // A scene linked in the prose opens in the page; a page of docs/ is a page of the book.
    assert!(chapter("01-camera.md").contains("](mirador/?scene=course/camera-perspective.toml)"));
    assert!(chapter("01-camera.md").contains("](reference/scene-format.md#camera)"));
    assert!(
        chapter("reference/architecture.md").contains("](../01-camera.md")
            || !chapter("reference/architecture.md").contains("course/01-camera.md")
    );
    let _ = std::fs::remove_dir_all(book_root);
}

#[test]
fn the_answers_are_in_the_site_only_when_asked_for() {
    let (chapters, book_root) = preprocessed(false, "students");
    for (path, text) in &chapters {
        assert!(!markdown_targets(text).iter().any(|t| t.contains("answers")), "{path} links the answers");
    }
    // Nor is a copy of them made (`source/`, as the site copies a linked file).
    let copies = book_root.join("src/source");
    let answers_copied = copies.exists()
        && walk(&copies).iter().any(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("answers")));
    assert!(!answers_copied, "the answers were copied into a student's site");
    let _ = std::fs::remove_dir_all(book_root);
    let (chapters, book_root) = preprocessed(true, "teachers");
    let readme = &chapters.iter().find(|(p, _)| p == "README.md").unwrap().1;
    assert!(markdown_targets(readme).contains(&"answers.md".to_owned()), "the teachers' site links its answers");
    let _ = std::fs::remove_dir_all(book_root);
}

#[test]
fn mirador_link_prints_a_commands_address_or_why_it_has_none() {
    let link = |args: &[&str]| {
        let out =
            Command::new(env!("CARGO_BIN_EXE_mirador")).arg("link").args(args).current_dir(root()).output().unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).trim().to_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // No scene: the showcase, as the command draws it.
    assert_eq!(link(&["render", "-o", "x.png"]).1, "?scene=showcase.toml&view=raster");
    assert_eq!(
        link(&[
            "--page",
            "https://a.b/mirador/",
            "compare",
            "assets/scenes/course/mirror-pair.toml",
            "-o",
            "s.png",
            "--max-depth",
            "2"
        ])
        .1,
        "https://a.b/mirador/?scene=course/mirror-pair.toml&set=trace.max_depth%3D2&view=split"
    );
    let (ok, _, error) = link(&["diff", "a.png", "b.png"]);
    assert!(!ok && error.contains("the page cannot show this: the page has no such command"), "{error}");
    let (ok, _, error) =
        link(&["render", "assets/scenes/showcase.toml", "-o", "x.png", "--set", "shadows.enabld=false"]);
    assert!(!ok && error.contains("no such setting"), "a setting Mirador refuses is an error: {error}");
}
