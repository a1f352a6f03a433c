//! The tests run, one after another, in the process that `lab check` starts for them
//! (`mirador lab run`): each finished test is one JSON line on standard output, so the checker
//! knows how far the run got if a test never returns and must be stopped.

use super::harness::Harness;
use super::images::{self, Outcome};
use super::{Against, ImageTest, KnownAnswer, Lab, Mistake, source};
use crate::gpu::Gpu;
use crate::shaders::Wgsl;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A test of a lab: the lab's own, or a teacher's hidden one (from `folder`).
#[derive(Clone, Debug)]
pub enum Test {
    Known(KnownAnswer),
    Image(ImageTest, Option<PathBuf>),
}

impl Test {
    pub fn name(&self) -> &str {
        match self {
            Test::Known(test) => &test.name,
            Test::Image(test, _) => &test.name,
        }
    }

    pub fn points(&self) -> f32 {
        match self {
            Test::Known(test) => test.points,
            Test::Image(test, _) => test.points,
        }
    }
}

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
    let mut tests: Vec<Test> = lab.known_answers.iter().cloned().map(Test::Known).collect();
    tests.extend(lab.images.iter().cloned().map(|t| Test::Image(t, None)));
    let Some(folder) = hidden else {
        return Ok(tests);
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map_err(|e| format!("{}: cannot read the hidden tests' folder: {e}", folder.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    for path in files {
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file: TestFile = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        tests.extend(file.known.into_iter().map(Test::Known));
        tests.extend(file.image.into_iter().map(|t| Test::Image(t, Some(folder.to_path_buf()))));
    }
    Ok(tests)
}

/// What one test found, as the run reports it to the checker.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Finding {
    pub index: usize,
    pub passed: bool,
    pub output: String,
    /// The known mistake the student's result matches, and what to tell them.
    pub mistake: Option<(String, String)>,
    /// Correct, yours, difference: the image test's PNGs, relative to the lab's folder.
    pub images: Option<[String; 3]>,
}

/// Runs `tests[from..]` with the student's file `text`, writing each finding as a line to
/// standard output and each image test's pictures into `folder/report/`.
pub fn run(lab: &Lab, text: &str, tests: &[Test], from: usize, folder: &Path) -> Result<(), String> {
    let gpu = Gpu::headless().map_err(|e| e.to_string())?;
    if gpu.profile() == crate::gpu::Profile::WebGl2 {
        return Err(format!(
            "{}: a device of the WebGL2 profile has no compute shaders and no storage buffers, which the \
             known-answer tests run in (unset MIRADOR_LIMITS, or use Vulkan)",
            gpu.describe()
        ));
    }
    let harness = Harness::new(&gpu);
    let student = source::student(lab, text);
    let reference = source::reference(lab);
    let mistakes: Vec<(&Mistake, Wgsl)> =
        lab.mistakes.iter().map(|m| (m, source::student(lab, &lab.mistaken(m)))).collect();
    let mut out = std::io::stdout().lock();
    for (index, test) in tests.iter().enumerate().skip(from) {
        let finding = match test {
            Test::Known(known) => known_answer(&gpu, &harness, known, &student, &mistakes, index),
            Test::Image(image, hidden) => {
                image_test(&gpu, image, hidden.as_deref(), (&student, &reference), &mistakes, folder, index)
            }
        };
        let line = serde_json::to_string(&finding).expect("a finding serialises");
        writeln!(out, "{line}").and_then(|_| out.flush()).map_err(|e| e.to_string())?;
    }
    Ok(())
}

fn known_answer(
    gpu: &Gpu,
    harness: &Harness,
    test: &KnownAnswer,
    student: &Wgsl,
    mistakes: &[(&Mistake, Wgsl)],
    index: usize,
) -> Finding {
    let value = match harness.call(gpu, student, &test.call) {
        Ok(value) => value,
        Err(error) => return Finding { index, passed: false, output: error, mistake: None, images: None },
    };
    let (passed, wanted) = judge_value(test, value);
    let shown = |v: [f32; 4]| format!("({}, {}, {}, {})", v[0], v[1], v[2], v[3]);
    let output = format!("{} = {}; {wanted}", test.call, shown(value));
    let mut mistake = None;
    if !passed {
        // The mistake whose own value is this one (and is wrong).
        let tolerance = test.tolerance.max(1e-5);
        mistake = mistakes.iter().find_map(|(m, wgsl)| {
            let theirs = harness.call(gpu, wgsl, &test.call).ok()?;
            let same = theirs.iter().zip(value).all(|(a, b)| (a - b).abs() <= tolerance || (a.is_nan() && b.is_nan()));
            (same && !judge_value(test, theirs).0).then(|| (m.name.clone(), m.sentence.clone()))
        });
    }
    Finding { index, passed, output, mistake, images: None }
}

/// Whether `value` is right, and what was wanted.
fn judge_value(test: &KnownAnswer, value: [f32; 4]) -> (bool, String) {
    if let Some(expect) = test.expect {
        let ok = value.iter().zip(expect).all(|(v, e)| (v - e).abs() <= test.tolerance);
        return (
            ok,
            format!("expected ({}, {}, {}, {}) ± {}", expect[0], expect[1], expect[2], expect[3], test.tolerance),
        );
    }
    let min = test.min.unwrap_or([f32::NEG_INFINITY; 4]);
    let max = test.max.unwrap_or([f32::INFINITY; 4]);
    let ok = (0..4).all(|i| value[i] >= min[i] && value[i] <= max[i]);
    (ok, format!("expected each component within [{:?}, {:?}]", min, max))
}

fn image_test(
    gpu: &Gpu,
    test: &ImageTest,
    hidden: Option<&Path>,
    (student, reference): (&Wgsl, &Wgsl),
    mistakes: &[(&Mistake, Wgsl)],
    folder: &Path,
    index: usize,
) -> Finding {
    let fail = |output: String| Finding { index, passed: false, output, mistake: None, images: None };
    let scene = match images::scene(test, hidden) {
        Ok(scene) => scene,
        Err(error) => return fail(format!("the test's scene: {error}")),
    };
    let yours = match images::raster(gpu, &scene, student) {
        Ok(image) => image,
        Err(error) => return fail(format!("drawing with your functions: {error}")),
    };
    let mirador = match images::raster(gpu, &scene, reference) {
        Ok(image) => image,
        Err(error) => return fail(format!("drawing with Mirador's functions: {error}")),
    };
    let (correct, outcome) = match test.against {
        Against::Reference => (mirador.clone(), images::judge(test, &mirador, &yours, None)),
        Against::Tracer => {
            let traced = images::traced(&scene);
            let outcome = images::judge(test, &traced, &yours, Some(&mirador));
            (traced, outcome)
        }
    };
    let Outcome { passed, error_map, output, .. } = outcome;
    let mistake = if passed {
        None
    } else {
        mistakes.iter().find_map(|(m, wgsl)| {
            let theirs = images::raster(gpu, &scene, wgsl).ok()?;
            let (same, _) = images::figures(&theirs, &yours);
            (same.mean <= 0.002 && same.worst_region <= 0.02).then(|| (m.name.clone(), m.sentence.clone()))
        })
    };
    let images = save(folder, &test.name, [&correct, &yours, &error_map]);
    Finding { index, passed, output, mistake, images }
}

/// Writes a test's three pictures into `folder/report/`; `None` when they cannot be written.
fn save(folder: &Path, name: &str, pictures: [&image::RgbaImage; 3]) -> Option<[String; 3]> {
    let slug: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
    let dir = folder.join("report");
    std::fs::create_dir_all(&dir).ok()?;
    let mut names = Vec::new();
    for (picture, kind) in pictures.into_iter().zip(["correct", "yours", "difference"]) {
        let file = format!("report/{slug}-{kind}.png");
        crate::output::write_png_atomically(picture, &folder.join(&file)).ok()?;
        names.push(file);
    }
    names.try_into().ok()
}
