//! The tests run, one after another, in the process that `lab check` starts for them
//! (`mirador lab run`): each finished test is one JSON line on standard output, so the checker
//! knows how far the run got if a test never returns and must be stopped.

use super::checks::{Checked, Checker, Test};
use super::{ImageTest, KnownAnswer, Lab};
use crate::gpu::Gpu;
use crate::gpu::readback::block_on;
use serde::Deserialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A file of hidden tests: known-answer and image tests in a lab's own format.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TestFile {
    #[serde(default)]
    known: Vec<KnownAnswer>,
    #[serde(default)]
    image: Vec<ImageTest>,
}

/// The lab's tests, then those of every `*.toml` file in `hidden` (a teacher's folder), in name
/// order.
pub fn tests(lab: &Lab, hidden: Option<&Path>) -> Result<Vec<Test>, String> {
    let mut tests = Test::of(lab);
    let Some(folder) = hidden else {
        return Ok(tests);
    };
    for path in hidden_files(folder)? {
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file: TestFile = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        tests.extend(file.known.into_iter().map(|t| Test::Known(t, Some(folder.to_path_buf()))));
        tests.extend(file.image.into_iter().map(|t| Test::Image(t, Some(folder.to_path_buf()))));
    }
    Ok(tests)
}

/// The `*.toml` files of a teacher's folder of hidden tests, in name order.
pub fn hidden_files(folder: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map_err(|e| format!("{}: cannot read the hidden tests' folder: {e}", folder.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    Ok(files)
}

/// Runs `tests[from..]` with the student's file `text`, writing each finding as a line to
/// standard output and, unless `pictures` is false, each image test's pictures into
/// `folder/report/`.
pub fn run(lab: &Lab, text: &str, tests: &[Test], from: usize, folder: &Path, pictures: bool) -> Result<(), String> {
    let gpu = Gpu::headless().map_err(|e| e.to_string())?;
    if let Some(reason) = lab.refusal(gpu.profile()) {
        return Err(format!(
            "{}: a device of the WebGL2 profile cannot run lab {}: {reason}",
            gpu.describe(),
            lab.name
        ));
    }
    let checker = Checker::new(gpu, lab, text);
    let mut out = std::io::stdout().lock();
    for (index, test) in tests.iter().enumerate().skip(from) {
        let Checked { mut finding, pictures: drawn } = block_on(&checker.gpu.device, checker.run(test, index));
        finding.images = drawn.filter(|_| pictures).and_then(|drawn| save(folder, test.name(), &drawn));
        let line = serde_json::to_string(&finding).expect("a finding serialises");
        writeln!(out, "{line}").and_then(|_| out.flush()).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Writes a test's three pictures into `folder/report/`; `None` when they cannot be written.
fn save(folder: &Path, name: &str, pictures: &[image::RgbaImage; 3]) -> Option<[String; 3]> {
    let slug: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
    let dir = folder.join("report");
    std::fs::create_dir_all(&dir).ok()?;
    let mut names = Vec::new();
    for (picture, kind) in pictures.iter().zip(["correct", "yours", "difference"]) {
        let file = format!("report/{slug}-{kind}.png");
        crate::output::write_png_atomically(picture, &folder.join(&file)).ok()?;
        names.push(file);
    }
    names.try_into().ok()
}
