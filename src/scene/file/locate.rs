//! Where a file a scene names is read from. First beside the scene file, as the scene format
//! says. Then, for a scene copied out of Mirador's tree (a student's copy of a course scene,
//! `cp assets/scenes/course/shadows-methods.toml ~/lab/`), in Mirador's own tree: the same path
//! with its leading `..` steps dropped, under `assets/` and under the tree's root
//! (`../../textures/checker.png` → `assets/textures/checker.png`,
//! `../../../tests/data/obj/teapot.obj` → `tests/data/obj/teapot.obj`). A file found nowhere is
//! reported with every place looked.

use std::cell::RefCell;
use std::path::{Component, Path, PathBuf};

thread_local! {
    /// The files found while [`recording`] runs on this thread: as the scene names each, and
    /// where it was read from.
    static FOUND: RefCell<Option<Vec<(String, PathBuf)>>> = const { RefCell::new(None) };
}

/// Runs `work` (a scene's loading) and returns what it returned with every file [`locate`]
/// found for it, as the scene names it and where it lies: what a copy of the scene must carry
/// (`super::super::copy`).
pub fn recording<T>(work: impl FnOnce() -> T) -> (T, Vec<(String, PathBuf)>) {
    FOUND.with(|found| *found.borrow_mut() = Some(Vec::new()));
    let value = work();
    let files = FOUND.with(|found| found.borrow_mut().take()).unwrap_or_default();
    (value, files)
}

/// The root of the tree this binary was built from (in the browser, the page's built-in files).
fn mirador_root() -> &'static Path {
    Path::new(if cfg!(target_arch = "wasm32") { "" } else { env!("CARGO_MANIFEST_DIR") })
}

/// Where `relative`, named by a scene in `dir`, is read from; and, when it is in none of the
/// places looked, all of them (the first is then the one returned, so the reader's own error
/// names the file beside the scene).
pub fn locate(dir: &Path, relative: &str) -> (PathBuf, Vec<PathBuf>) {
    let beside = dir.join(relative);
    let given = Path::new(relative);
    let mut candidates = vec![beside.clone()];
    if given.is_relative() {
        let rest: PathBuf =
            given.components().skip_while(|c| matches!(c, Component::ParentDir | Component::CurDir)).collect();
        if !rest.as_os_str().is_empty() {
            candidates.push(mirador_root().join("assets").join(&rest));
            candidates.push(mirador_root().join(&rest));
        }
    }
    match candidates.iter().find(|c| crate::files::check_regular(c).is_ok()) {
        Some(found) => {
            FOUND.with(|files| {
                if let Some(files) = files.borrow_mut().as_mut() {
                    files.push((relative.to_owned(), found.clone()));
                }
            });
            (found.clone(), Vec::new())
        }
        None => (beside, candidates),
    }
}

/// `message`, with the places looked when there were more than one.
pub fn with_places(message: String, looked: &[PathBuf]) -> String {
    if looked.len() < 2 {
        return message;
    }
    let places: Vec<String> = looked.iter().map(|p| p.display().to_string()).collect();
    format!("{message} (looked beside the scene and in Mirador's own files: {})", places.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_copied_course_scene_finds_its_files_in_mirador_s_tree() {
        let elsewhere = std::env::temp_dir().join("a-student-folder");
        let (found, looked) = locate(&elsewhere, "../../textures/checker.png");
        assert!(looked.is_empty(), "{looked:?}");
        assert_eq!(found, mirador_root().join("assets/textures/checker.png"));
        let (found, _) = locate(&elsewhere, "../../../tests/data/obj/teapot.obj");
        assert_eq!(found, mirador_root().join("tests/data/obj/teapot.obj"));
        // Beside the scene comes first.
        let here = mirador_root().join("assets/scenes/course");
        assert_eq!(locate(&here, "../../textures/checker.png").0, here.join("../../textures/checker.png"));
        // Nowhere: every place looked, the first beside the scene.
        let (first, looked) = locate(&elsewhere, "../textures/nothing.png");
        assert_eq!(first, elsewhere.join("../textures/nothing.png"));
        assert_eq!(looked.len(), 3);
        assert!(with_places("x".into(), &looked).contains("assets/textures/nothing.png"));
    }
}
