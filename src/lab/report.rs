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

impl Report {
    pub fn score(&self) -> f32 {
        self.results.iter().map(|r| r.score).sum()
    }

    pub fn max_score(&self) -> f32 {
        self.results.iter().map(|r| r.max_score).sum()
    }

    pub fn passed(&self) -> bool {
        self.problems.is_empty() && self.results.iter().all(|r| r.passed)
    }
}

/// The terminal's summary.
pub fn text(report: &Report) -> String {
    let mut out = String::new();
    for problem in &report.problems {
        let _ = writeln!(out, "{}", problem.display(&report.lab.file));
    }
    for result in &report.results {
        let mark = if result.passed { "pass" } else { "FAIL" };
        let _ = writeln!(out, "{mark}  {:>4} / {:<4} {}", points(result.score), points(result.max_score), result.name);
        if !result.passed {
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
        report.results.len(),
        report.seconds
    );
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
        "tests": report.results,
    });
    serde_json::to_string_pretty(&json).expect("a report serialises")
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
        report.results.len(),
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
    for result in &report.results {
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
