//! `mirador lab new LAB DIR`: the folder a student works in.

use super::Lab;
use super::check::LabFolder;
use crate::output::write_atomically;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Writes the lab's folder: `lab.toml` (which lab, and each test's points for a teacher to
/// edit), the student's file (the stub, or with `solution` the answer key), `TASK.md`, the public
/// test scenes under `scenes/`, and with `solution` the teacher's `NOTES.md`. Refuses to write
/// over a student's file that is already there. Returns the files written.
pub fn create(lab: &Lab, dir: &Path, solution: bool) -> Result<Vec<PathBuf>, String> {
    let file = dir.join(&lab.file);
    if file.exists() {
        return Err(format!(
            "{}: already there; a lab's folder is made once (move it away to start again)",
            file.display()
        ));
    }
    std::fs::create_dir_all(dir.join("scenes")).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut written = Vec::new();
    let mut write = |path: PathBuf, text: &str| -> Result<(), String> {
        write_atomically(text.as_bytes(), &path).map_err(|e| format!("{}: {e}", path.display()))?;
        written.push(path);
        Ok(())
    };
    write(dir.join("lab.toml"), &folder_file(lab))?;
    write(file, &if solution { lab.solution() } else { lab.stub() })?;
    write(dir.join("TASK.md"), &task(lab))?;
    if solution {
        write(
            dir.join("NOTES.md"),
            &format!(
                "# Lab `{}`: notes for the teacher\n{}\n## Known mistakes\n\n{}",
                lab.name,
                lab.notes,
                mistakes(lab)
            ),
        )?;
    }
    for scene in &lab.scenes {
        let source = crate::scene::builtin_path(scene);
        let text = std::fs::read_to_string(&source).map_err(|e| format!("{}: {e}", source.display()))?;
        let name = Path::new(scene).file_name().expect("a scene path names a file");
        write(dir.join("scenes").join(name), &text)?;
    }
    Ok(written)
}

fn folder_file(lab: &Lab) -> String {
    let mut text = format!(
        "# Lab `{}` (mirador lab check reads this file).\nlab = \"{}\"\n\n# Each test's points: a teacher may change them.\n[points]\n",
        lab.name, lab.name
    );
    let names =
        lab.known_answers.iter().map(|t| (&t.name, t.points)).chain(lab.images.iter().map(|t| (&t.name, t.points)));
    for (name, points) in names {
        let _ = writeln!(text, "{} = {points}", toml_key(name));
    }
    // Checked when written: a test's name must survive the trip through TOML.
    debug_assert!(toml::from_str::<LabFolder>(&text).is_ok());
    text
}

fn toml_key(name: &str) -> String {
    format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""))
}

fn task(lab: &Lab) -> String {
    let chapter = crate::lab::chapter_file(lab.chapter).unwrap_or_default();
    format!(
        "# Lab `{}`: {}\n\nChapter {} of the course{}.\n{}\n## Files\n\n- `{}`: yours. Keep each function's signature; add helpers if you like, named as you like (the checker keeps your names apart from Mirador's).\n- `scenes/`: the scenes the image tests draw, to render and look at: `mirador render scenes/NAME.toml -o look.png`.\n- `lab.toml`: which lab this is, and the points of its tests.\n\n`mirador lab check .` validates your file, runs the tests, and writes `results.json` and `report.md`.\n",
        lab.name,
        lab.title,
        lab.chapter,
        if chapter.is_empty() { String::new() } else { format!(" (docs/course/{chapter})") },
        lab.task,
        lab.file
    )
}

fn mistakes(lab: &Lab) -> String {
    lab.mistakes.iter().map(|m| format!("- **{}**: {}\n", m.name, m.sentence)).collect()
}
