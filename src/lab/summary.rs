//! `mirador lab summary RESULTS…`: a class's `results.json` files (each written by `lab check`)
//! read together, and written as one page a teacher opens (`summary.html`, and the same as
//! `summary.md`): the score histogram, each test's pass rate and how well it separates strong
//! submissions from weak ones, the known mistakes matched most, the submissions that did not
//! compile, and the slowest checks.
//!
//! How well a test separates is its *discrimination*, as PrairieLearn's question statistics give
//! it: the correlation, over the submissions that compiled, between passing the test (1 or 0) and
//! the points scored on every other test (the rest score, so that a test is not correlated with
//! itself). Near 0: the test
//! does not tell strong from weak (everyone passes, or it is noise); negative: the strong fail it
//! more often than the weak, which usually means the test is wrong.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// One submission's results, as read back.
#[derive(Clone, Debug)]
pub struct Submission {
    /// The folder the results.json lies in (or the file itself, when that is all there is).
    pub name: String,
    pub score: f64,
    pub max_score: f64,
    pub seconds: f64,
    /// The file did not compile: no test ran.
    pub compile_error: Option<String>,
    /// Each test's name, whether it passed, its score, and the known mistake it named.
    pub tests: Vec<(String, bool, f64, Option<String>)>,
}

/// One test over the class.
#[derive(Clone, Debug, PartialEq)]
pub struct TestFigures {
    pub name: String,
    pub pass_rate: f64,
    /// `None` where it is undefined: everyone passed, everyone failed, or the rest scores are all
    /// the same.
    pub discrimination: Option<f64>,
}

/// The class's figures.
#[derive(Clone, Debug)]
pub struct Summary {
    pub submissions: Vec<Submission>,
    pub tests: Vec<TestFigures>,
    /// Each known mistake and how many submissions it was named in, most first.
    pub mistakes: Vec<(String, usize)>,
}

/// Reads every `results.json` under `paths` (files, or folders searched to any depth).
pub fn read(paths: &[PathBuf]) -> Result<Vec<Submission>, String> {
    let mut files = Vec::new();
    for path in paths {
        collect(path, &mut files)?;
    }
    files.sort();
    if files.is_empty() {
        return Err("no results.json in the paths given".to_owned());
    }
    files.iter().map(|file| submission(file)).collect()
}

fn collect(path: &Path, files: &mut Vec<PathBuf>) -> Result<(), String> {
    if path.is_file() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let entries = std::fs::read_dir(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for entry in entries.filter_map(Result::ok) {
        let child = entry.path();
        // Not through links: a link to a folder above would be followed for ever.
        if entry.file_type().is_ok_and(|t| t.is_dir()) {
            collect(&child, files)?;
        } else if child.file_name().is_some_and(|n| n == "results.json") {
            files.push(child);
        }
    }
    Ok(())
}

fn submission(file: &Path) -> Result<Submission, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: not a results.json: {e}", file.display()))?;
    let number = |key: &str| json[key].as_f64().ok_or_else(|| format!("{}: no `{key}`", file.display()));
    let name = file
        .parent()
        .and_then(|p| p.file_name())
        .map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned());
    let tests: Vec<(String, bool, f64, Option<String>)> = json["tests"]
        .as_array()
        .map(|tests| {
            tests
                .iter()
                // A teacher's test in error counts for nobody, and is not the class's.
                .filter(|t| t["visibility"] != "hidden")
                .map(|t| {
                    let passed = t["status"] == "passed" || t["score"].as_f64() == t["max_score"].as_f64();
                    let name = t["name"].as_str().unwrap_or("?").to_owned();
                    (name, passed, t["score"].as_f64().unwrap_or(0.0), t["mistake"].as_str().map(str::to_owned))
                })
                .collect()
        })
        .unwrap_or_default();
    let compiled = json["extra_data"]["compiled"].as_bool().unwrap_or(true);
    Ok(Submission {
        name,
        score: number("score")?,
        max_score: json["max_score"].as_f64().unwrap_or(0.0),
        seconds: json["execution_time"].as_f64().unwrap_or(0.0),
        compile_error: (!compiled).then(|| json["output"].as_str().unwrap_or("").to_owned()),
        tests,
    })
}

/// The class's figures from its submissions.
pub fn summarise(submissions: Vec<Submission>) -> Summary {
    let mut names: Vec<String> = Vec::new();
    for submission in &submissions {
        for (name, _, _, _) in &submission.tests {
            if !names.contains(name) {
                names.push(name.clone());
            }
        }
    }
    let tests = names
        .iter()
        .map(|name| {
            // Passing the test, and the points of every other test, per submission.
            let pairs = |s: &Submission| {
                let passed = s.tests.iter().find(|t| &t.0 == name)?.1;
                let others: f64 = s.tests.iter().filter(|t| &t.0 != name).map(|t| t.2).sum();
                Some((if passed { 1.0 } else { 0.0 }, others))
            };
            let all: Vec<(f64, f64)> = submissions.iter().filter_map(pairs).collect();
            let pass_rate = all.iter().map(|p| p.0).sum::<f64>() / all.len().max(1) as f64;
            // A file that did not compile ran no test: it says nothing of how a test separates.
            let compiled: Vec<(f64, f64)> =
                submissions.iter().filter(|s| s.compile_error.is_none()).filter_map(pairs).collect();
            TestFigures { name: name.clone(), pass_rate, discrimination: correlation(&compiled) }
        })
        .collect();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for submission in &submissions {
        let mut named: Vec<&String> = submission.tests.iter().filter_map(|t| t.3.as_ref()).collect();
        named.sort();
        named.dedup();
        for mistake in named {
            *counts.entry(mistake.clone()).or_default() += 1;
        }
    }
    let mut mistakes: Vec<(String, usize)> = counts.into_iter().collect();
    mistakes.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    Summary { submissions, tests, mistakes }
}

/// Pearson's correlation of the pairs; `None` where either side does not vary.
pub fn correlation(pairs: &[(f64, f64)]) -> Option<f64> {
    let n = pairs.len() as f64;
    if pairs.len() < 2 {
        return None;
    }
    let (mx, my) = (pairs.iter().map(|p| p.0).sum::<f64>() / n, pairs.iter().map(|p| p.1).sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// How many of the scores (as fractions of the maximum) fall in each tenth: `[0, 0.1)`, …,
/// `[0.9, 1)`, and a last bin for full marks.
pub fn histogram(submissions: &[Submission]) -> [usize; 11] {
    let mut bins = [0; 11];
    for s in submissions {
        let fraction = if s.max_score > 0.0 { (s.score / s.max_score).clamp(0.0, 1.0) } else { 0.0 };
        let bin = if fraction >= 1.0 { 10 } else { ((fraction * 10.0).floor() as usize).min(9) };
        bins[bin] += 1;
    }
    bins
}

fn bin_label(bin: usize) -> String {
    if bin == 10 { "100 %".to_owned() } else { format!("{}–{} %", bin * 10, bin * 10 + 10) }
}

fn percent(x: f64) -> String {
    format!("{:.0} %", 100.0 * x)
}

fn discrimination(d: Option<f64>) -> String {
    d.map_or_else(|| "—".to_owned(), |d| format!("{d:+.2}"))
}

fn mean_score(summary: &Summary) -> f64 {
    let fractions: Vec<f64> =
        summary.submissions.iter().map(|s| if s.max_score > 0.0 { s.score / s.max_score } else { 0.0 }).collect();
    fractions.iter().sum::<f64>() / fractions.len().max(1) as f64
}

/// The submissions that did not compile, grouped by their first error (most first).
fn broken(summary: &Summary) -> Vec<(String, Vec<&str>)> {
    let mut groups: Vec<(String, Vec<&str>)> = Vec::new();
    for s in summary.submissions.iter().filter(|s| s.compile_error.is_some()) {
        let first = s.compile_error.as_deref().unwrap_or("").lines().next().unwrap_or("").to_owned();
        match groups.iter_mut().find(|(error, _)| *error == first) {
            Some((_, names)) => names.push(&s.name),
            None => groups.push((first, vec![&s.name])),
        }
    }
    groups.sort_by_key(|group| std::cmp::Reverse(group.1.len()));
    groups
}

/// "3 submissions: a, b, c", the first five named.
fn names_of(names: &[&str]) -> String {
    let shown = names.iter().take(5).copied().collect::<Vec<_>>().join(", ");
    let more = if names.len() > 5 { format!(" and {} more", names.len() - 5) } else { String::new() };
    format!("{} submission(s): {shown}{more}", names.len())
}

fn slowest(summary: &Summary) -> Vec<&Submission> {
    let mut by_time: Vec<&Submission> = summary.submissions.iter().collect();
    by_time.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    by_time.truncate(5);
    by_time
}

/// The page as Markdown.
pub fn markdown(summary: &Summary) -> String {
    let mut out = format!(
        "# The class at a glance\n\n{} submissions, mean score {}.\n\n## Scores\n\n| score | submissions |\n|---|---|\n",
        summary.submissions.len(),
        percent(mean_score(summary))
    );
    let bins = histogram(&summary.submissions);
    let most = bins.iter().copied().max().unwrap_or(1).max(1);
    for (bin, count) in bins.iter().enumerate() {
        // Bars of at most 40 blocks; any submission at all shows one.
        let blocks = if *count == 0 { 0 } else { (count * 40).div_ceil(most) };
        let _ = writeln!(out, "| {} | {count} {} |", bin_label(bin), "█".repeat(blocks));
    }
    out.push_str("\n## Tests\n\nDiscrimination: the correlation between passing the test and the score on the other tests (near 0: it does not separate strong from weak; below 0: look at the test).\n\n| test | passed by | discrimination |\n|---|---|---|\n");
    for test in &summary.tests {
        let _ = writeln!(
            out,
            "| {} | {} | {} |",
            test.name.replace('|', "\\|"),
            percent(test.pass_rate),
            discrimination(test.discrimination)
        );
    }
    out.push_str("\n## Known mistakes\n\n");
    if summary.mistakes.is_empty() {
        out.push_str("None was named.\n");
    }
    for (mistake, count) in &summary.mistakes {
        let _ = writeln!(out, "- {mistake}: {count} submission(s)");
    }
    out.push_str("\n## Did not compile\n\n");
    let broken = broken(summary);
    if broken.is_empty() {
        out.push_str("Every submission compiled.\n");
    }
    for (error, names) in broken {
        let _ = writeln!(out, "- `{}`: {}", error.replace('`', "'"), names_of(&names));
    }
    out.push_str("\n## Slowest checks\n\n| submission | seconds |\n|---|---|\n");
    for s in slowest(summary) {
        let _ = writeln!(out, "| {} | {:.1} |", s.name, s.seconds);
    }
    out
}

/// Text made safe inside HTML (the course's site writes its links with it too).
pub(crate) fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The page as HTML: one file, no script, the histogram as bars.
pub fn html(summary: &Summary) -> String {
    let bins = histogram(&summary.submissions);
    let most = bins.iter().copied().max().unwrap_or(1).max(1);
    let mut out = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>The class at a glance</title>\n<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em}table{border-collapse:collapse}td,th{border-bottom:1px solid #ccc;padding:.25em .6em;text-align:left}.bar{background:#4a7bd0;height:1em;display:inline-block}.low{color:#b00}</style></head><body>\n",
    );
    let _ = writeln!(
        out,
        "<h1>The class at a glance</h1>\n<p id=\"count\">{} submissions, mean score {}.</p>",
        summary.submissions.len(),
        percent(mean_score(summary))
    );
    out.push_str("<h2>Scores</h2>\n<table id=\"histogram\"><tr><th>score</th><th>submissions</th></tr>\n");
    for (bin, count) in bins.iter().enumerate() {
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td><span class=\"bar\" style=\"width:{:.1}em\"></span> {count}</td></tr>",
            bin_label(bin),
            20.0 * *count as f64 / most as f64
        );
    }
    out.push_str("</table>\n<h2>Tests</h2>\n<p>Discrimination: the correlation between passing the test and the score on the other tests (near 0: it does not separate strong from weak; below 0: look at the test).</p>\n<table id=\"tests\"><tr><th>test</th><th>passed by</th><th>discrimination</th></tr>\n");
    for test in &summary.tests {
        let class = if test.discrimination.is_some_and(|d| d < 0.0) { " class=\"low\"" } else { "" };
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td>{}</td><td{class}>{}</td></tr>",
            escape(&test.name),
            percent(test.pass_rate),
            discrimination(test.discrimination)
        );
    }
    out.push_str("</table>\n<h2>Known mistakes</h2>\n<ul id=\"mistakes\">\n");
    if summary.mistakes.is_empty() {
        out.push_str("<li>None was named.</li>\n");
    }
    for (mistake, count) in &summary.mistakes {
        let _ = writeln!(out, "<li>{}: {count} submission(s)</li>", escape(mistake));
    }
    out.push_str("</ul>\n<h2>Did not compile</h2>\n<ul id=\"broken\">\n");
    let broken = broken(summary);
    if broken.is_empty() {
        out.push_str("<li>Every submission compiled.</li>\n");
    }
    for (error, names) in broken {
        let _ = writeln!(out, "<li><code>{}</code>: {}</li>", escape(&error), escape(&names_of(&names)));
    }
    out.push_str(
        "</ul>\n<h2>Slowest checks</h2>\n<table id=\"slowest\"><tr><th>submission</th><th>seconds</th></tr>\n",
    );
    for s in slowest(summary) {
        let _ = writeln!(out, "<tr><td>{}</td><td>{:.1}</td></tr>", escape(&s.name), s.seconds);
    }
    out.push_str("</table>\n</body></html>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn submission(name: &str, passed: &[bool]) -> Submission {
        Submission {
            name: name.to_owned(),
            score: passed.iter().filter(|p| **p).count() as f64,
            max_score: passed.len() as f64,
            seconds: 1.0,
            compile_error: None,
            tests: passed
                .iter()
                .enumerate()
                .map(|(i, p)| (format!("t{i}"), *p, if *p { 1.0 } else { 0.0 }, None))
                .collect(),
        }
    }

    #[test]
    fn a_test_the_strong_pass_and_the_weak_fail_discriminates() {
        // t0 follows the rest of the score; t1 everyone passes; t2 is passed by the weak only.
        let class = vec![
            submission("a", &[true, true, false, true, true]),
            submission("b", &[true, true, false, true, true]),
            submission("c", &[false, true, true, false, false]),
            submission("d", &[false, true, true, false, false]),
        ];
        let summary = summarise(class);
        let t = |name: &str| summary.tests.iter().find(|t| t.name == name).unwrap().clone();
        assert!(t("t0").discrimination.unwrap() > 0.5);
        assert_eq!(t("t1").discrimination, None);
        assert_eq!(t("t1").pass_rate, 1.0);
        assert!(t("t2").discrimination.unwrap() < -0.5);
        assert_eq!(histogram(&summary.submissions), [0, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0]);
    }
}
