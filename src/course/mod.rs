//! The course as a site (web/site.sh): what a chapter prints, made into what a browser opens.
//!
//! - [`commands`]: the command lines of a chapter's shell blocks, as the shell would run them
//!   (continued lines joined, each `for` loop's body once per value, quotes and `$variables`
//!   resolved), so that a link can be made from exactly what the student would type.
//! - [`PageLink`]: the page's address for one command: its scene, its settings, its view
//!   (`mirador link` prints it; the CLI's own parser makes it, `src/main.rs`).
//! - [`book`]: the mdBook preprocessor that puts those links under every command, typesets the
//!   formulas, opens each chapter's labs, and sends links that leave the course where they work
//!   on the site.

pub mod book;
mod shell;

pub use shell::{Printed, commands};

/// What the page makes of a command: its address, or why only the command line runs it.
#[derive(Clone, Debug, PartialEq)]
pub enum Linked {
    Page(PageLink),
    /// Why the page cannot show it (a teaching example, a scene the student writes first).
    CommandLine(String),
}

/// Where a command of the course is shown in the page: `index.html?scene=…&set=…&view=…`, the
/// steps the page runs when it opens (web/index.html reads them).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PageLink {
    /// A built-in scene, by its name under `assets/scenes/` (`course/mirror-pair.toml`); `None`:
    /// the showcase.
    pub scene: Option<String>,
    /// Settings and scene values, `KEY=VALUE` as `--set` takes them, applied in order.
    pub set: Vec<String>,
    /// `raster`, `traced`, `split` or `difference`; `None`: the page's own (raster).
    pub view: Option<&'static str>,
    /// Measure the error budget once the scene is drawn (the panel's button).
    pub budget: bool,
    /// What to do in the page that the address cannot say (`inspect the pixel 320,180: I, then a
    /// click`).
    pub then: Option<String>,
}

impl PageLink {
    /// The address's query, from `?`: each value percent-encoded.
    pub fn query(&self) -> String {
        let mut pairs: Vec<(&str, &str)> = Vec::new();
        if let Some(scene) = &self.scene {
            pairs.push(("scene", scene));
        }
        pairs.extend(self.set.iter().map(|s| ("set", s.as_str())));
        if let Some(view) = self.view {
            pairs.push(("view", view));
        }
        if self.budget {
            pairs.push(("budget", ""));
        }
        let text: Vec<String> = pairs
            .iter()
            .map(|(key, value)| match value.is_empty() {
                true => key.to_string(),
                false => format!("{key}={}", percent_encode(value)),
            })
            .collect();
        format!("?{}", text.join("&"))
    }

    /// The scene's name under `assets/scenes/` when `path` is a scene built into the page
    /// ([`crate::files::BUILTIN`]); else why a student must open it from the command line.
    pub fn builtin_scene(path: &std::path::Path) -> Result<String, String> {
        let text = path.to_string_lossy().replace('\\', "/");
        let name = text.trim_start_matches("./").trim_start_matches("assets/scenes/");
        let full = format!("assets/scenes/{name}");
        match crate::files::BUILTIN.contains(&full.as_str()) {
            true => Ok(name.to_owned()),
            false => Err(format!("{text} is not built into the page (open your own files with its file picker)")),
        }
    }
}

/// Percent-encodes everything but the characters an address's query keeps as they are, so that
/// `=`, `&`, `"`, `[`, spaces and commas in a setting's value survive the trip.
fn percent_encode(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for byte in text.bytes() {
        match byte {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b'/' => out.push(byte as char),
            _ => out.push_str(&format!("%{byte:02X}")),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_keeps_every_character_of_a_value() {
        let link = PageLink {
            scene: Some("course/mirror-pair.toml".into()),
            set: vec!["mirrors.depth=2".into(), "camera.eye=[6.0, 3.4, 14.0]".into(), r#"a.b="c&d""#.into()],
            view: Some("split"),
            budget: true,
            then: None,
        };
        assert_eq!(
            link.query(),
            "?scene=course/mirror-pair.toml&set=mirrors.depth%3D2&set=camera.eye%3D%5B6.0%2C%203.4%2C%2014.0%5D\
             &set=a.b%3D%22c%26d%22&view=split&budget"
        );
    }

    #[test]
    fn only_scenes_built_into_the_page_are_linked() {
        assert_eq!(
            PageLink::builtin_scene("assets/scenes/course/mirror-pair.toml".as_ref()),
            Ok("course/mirror-pair.toml".into())
        );
        assert!(PageLink::builtin_scene("sphereflake-3.toml".as_ref()).unwrap_err().contains("file picker"));
    }
}
