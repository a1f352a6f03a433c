//! What a check writes: the terminal's summary, `results.json` in Gradescope's format (each test
//! with its `name`, `score`, `max_score` and `output`), and `report.md`, a page with each image
//! test's Correct / Yours / Difference pictures and score.

use super::Lab;
use super::source::Problem;
#[cfg(not(target_arch = "wasm32"))]
use crate::output::write_atomically;
use std::fmt::Write;
#[cfg(not(target_arch = "wasm32"))]
use std::path::Path;

/// One test's result, as Gradescope reads it (`name`, `score`, `max_score`, `output`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TestResult {
    pub name: String,
    pub score: f32,
    pub max_score: f32,
    pub output: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mistake: Option<String>,
    /// `passed` or `failed`, as Gradescope colours a test.
    pub status: &'static str,
    /// `visible`, or for a teacher's hidden test `after_published`: Gradescope shows its name,
    /// score and output only once the grades are published.
    pub visibility: &'static str,
    #[serde(skip)]
    pub passed: bool,
    #[serde(skip)]
    pub images: Option<[String; 3]>,
}

/// What a check found.
pub struct Report {
    pub lab: Lab,
    pub problems: Vec<Problem>,
    pub results: Vec<TestResult>,
    pub seconds: f64,
}

impl TestResult {
    /// Whether it counts: not a teacher's test in error ([`super::checks::Test::teachers_error`],
    /// the one result never shown), which neither passes nor fails a student.
    pub fn counted(&self) -> bool {
        self.visibility != "hidden"
    }
}

impl Report {
    pub fn score(&self) -> f32 {
        self.results.iter().map(|r| r.score).sum()
    }

    pub fn max_score(&self) -> f32 {
        self.results.iter().map(|r| r.max_score).sum()
    }

    pub fn passed(&self) -> bool {
        self.problems.is_empty() && self.results.iter().filter(|r| r.counted()).all(|r| r.passed)
    }

    /// The tests a teacher must mend: hidden tests the answer key fails.
    pub fn teachers_errors(&self) -> impl Iterator<Item = &TestResult> {
        self.results.iter().filter(|r| !r.counted())
    }
}

/// The terminal's summary.
pub fn text(report: &Report) -> String {
    let mut out = String::new();
    for problem in &report.problems {
        let _ = writeln!(out, "{}", problem.display(&report.lab.file));
    }
    for result in &report.results {
        let mark = match (result.counted(), result.passed) {
            (false, _) => "SKIP",
            (true, true) => "pass",
            (true, false) => "FAIL",
        };
        let _ = writeln!(out, "{mark}  {:>4} / {:<4} {}", points(result.score), points(result.max_score), result.name);
        if !result.passed || !result.counted() {
            for line in result.output.lines() {
                let _ = writeln!(out, "            {line}");
            }
        }
    }
    let _ = writeln!(
        out,
        "\nlab {}: {} / {} points, {} of {} tests passed, in {:.1} s",
        report.lab.name,
        points(report.score()),
        points(report.max_score()),
        report.results.iter().filter(|r| r.passed).count(),
        report.results.iter().filter(|r| r.counted()).count(),
        report.seconds
    );
    let errors: Vec<&str> = report.teachers_errors().map(|r| r.name.as_str()).collect();
    if !errors.is_empty() {
        let _ = writeln!(
            out,
            "teacher: {} hidden test(s) fail with the answer key and were not graded: {}",
            errors.len(),
            errors.join("; ")
        );
    }
    out
}

/// A score as the reports write it: `3`, `2.5`.
pub fn points(value: f32) -> String {
    if value.fract() == 0.0 { format!("{value:.0}") } else { format!("{value:.1}") }
}

/// `results.json`'s text: the report in Gradescope's format.
pub fn results_json(report: &Report) -> String {
    let problems: Vec<String> = report.problems.iter().map(|p| p.display(&report.lab.file)).collect();
    let json = serde_json::json!({
        "score": report.score(),
        "max_score": report.max_score(),
        "execution_time": report.seconds,
        "output": if problems.is_empty() { format!("lab {}", report.lab.name) } else { problems.join("\n") },
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "extra_data": { "lab": report.lab.name, "compiled": report.problems.is_empty() },
        "tests": report.results,
    });
    serde_json::to_string_pretty(&json).expect("a report serialises")
}

/// The grading services' formats of `results.json` ([`super::autograder`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Gradescope's (and the one `lab check` always writes in the lab's folder).
    #[default]
    Gradescope,
    /// PrairieLearn's external grader's.
    Prairielearn,
}

/// The pictures a PrairieLearn result may carry, in bytes of data URL: its grader takes up to
/// 1 MB of results in all.
#[cfg(not(target_arch = "wasm32"))]
const PICTURES_BUDGET: usize = 700_000;

/// `results.json` for PrairieLearn's external grader: `gradable` (false when the file does not
/// compile, so that the student loses no attempt), `score` from 0 to 1, each test's points, and
/// the failed image tests' pictures (yours, the difference) as data URLs read from `folder`,
/// while they fit [`PICTURES_BUDGET`]. A hidden test's output is not shown.
#[cfg(not(target_arch = "wasm32"))]
pub fn prairielearn_json(report: &Report, folder: &Path) -> String {
    use base64::Engine;
    let problems: Vec<String> = report.problems.iter().map(|p| p.display(&report.lab.file)).collect();
    let counted: Vec<&TestResult> = report.results.iter().filter(|r| r.counted()).collect();
    let tests: Vec<serde_json::Value> = counted
        .iter()
        .map(|r| {
            let hidden = r.visibility != "visible";
            serde_json::json!({
                "name": r.name,
                "points": r.score,
                "max_points": r.max_score,
                "output": if hidden { "(a hidden test: its details are not shown)".to_owned() } else { r.output.clone() },
            })
        })
        .collect();
    let mut images = Vec::new();
    let mut spent = 0;
    for result in counted.iter().filter(|r| !r.passed && r.visibility == "visible") {
        let Some([_, yours, difference]) = &result.images else { continue };
        for (file, what) in [(yours, "yours"), (difference, "difference")] {
            let Ok(bytes) = std::fs::read(folder.join(file)) else { continue };
            let url = format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes));
            if spent + url.len() > PICTURES_BUDGET {
                continue;
            }
            spent += url.len();
            images.push(serde_json::json!({ "label": format!("{}: {what}", result.name), "url": url }));
        }
    }
    let max = report.max_score();
    let json = serde_json::json!({
        "gradable": report.problems.is_empty(),
        "score": if max > 0.0 { report.score() / max } else { 0.0 },
        "message": if problems.is_empty() {
            format!("lab {}: {} / {} points", report.lab.name, points(report.score()), points(max))
        } else {
            format!("{} does not compile, so no test ran and this attempt does not count:\n{}", report.lab.file, problems.join("\n"))
        },
        "tests": tests,
        "images": images,
    });
    serde_json::to_string_pretty(&json).expect("a report serialises")
}

/// A result file for a submission that could not be checked at all (`why`: no file, a folder
/// that cannot be read), in `format`: a score of 0 that says why; for PrairieLearn, not
/// gradable, so no attempt is lost.
pub fn failure_json(format: Format, why: &str) -> String {
    let json = match format {
        Format::Gradescope => serde_json::json!({ "score": 0.0, "output": why, "tests": [] }),
        Format::Prairielearn => serde_json::json!({ "gradable": false, "score": 0.0, "message": why }),
    };
    serde_json::to_string_pretty(&json).expect("a message serialises")
}

/// Writes `results.json` and `report.md` (with the pictures the run left in `report/`) into
/// `dir`.
#[cfg(not(target_arch = "wasm32"))]
pub fn write(report: &Report, dir: &Path) -> Result<(), String> {
    let json = results_json(report);
    let path = dir.join("results.json");
    write_atomically(json.as_bytes(), &path).map_err(|e| format!("{}: {e}", path.display()))?;
    let path = dir.join("report.md");
    write_atomically(markdown(report).as_bytes(), &path).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(not(target_arch = "wasm32"))]
fn markdown(report: &Report) -> String {
    let lab = &report.lab;
    let mut out = format!(
        "# Lab `{}`: {}\n\n**{} / {} points**, {} of {} tests passed ({:.1} s).\n\n",
        lab.name,
        lab.title,
        points(report.score()),
        points(report.max_score()),
        report.results.iter().filter(|r| r.passed).count(),
        report.results.iter().filter(|r| r.counted()).count(),
        report.seconds
    );
    if !report.problems.is_empty() {
        out.push_str("## Your file does not compile\n\n```text\n");
        for problem in &report.problems {
            out.push_str(&problem.display(&lab.file));
            out.push('\n');
        }
        out.push_str("```\n\n");
    }
    out.push_str("| Test | Score | What it found |\n|---|---|---|\n");
    for result in report.results.iter().filter(|r| r.counted()) {
        let found = result.output.replace('|', "\\|").replace('\n', "<br>");
        let _ =
            writeln!(out, "| {} | {} / {} | {} |", result.name, points(result.score), points(result.max_score), found);
    }
    let pictured: Vec<_> = report.results.iter().filter_map(|r| r.images.as_ref().map(|i| (r, i))).collect();
    if !pictured.is_empty() {
        out.push_str("\n## Images\n\n| Test | Correct | Yours | Difference (FLIP) | Score |\n|---|---|---|---|---|\n");
        for (result, [correct, yours, difference]) in pictured {
            let _ = writeln!(
                out,
                "| {} | ![correct]({correct}) | ![yours]({yours}) | ![difference]({difference}) | {} / {} |",
                result.name,
                points(result.score),
                points(result.max_score)
            );
        }
    }
    out
}
