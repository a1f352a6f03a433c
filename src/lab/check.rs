//! `mirador lab check DIR`: the student's file validated, then the tests run in a child process
//! under a time limit each, scored from the points a teacher can edit, and reported.

use super::checks::{Finding, Test};
use super::find;
use super::report::Report;
use super::run::tests;
use super::source;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A lab's folder's `lab.toml`: which lab it is, and the points of its tests.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabFolder {
    pub lab: String,
    /// Points by test name; a test not named keeps the lab's own.
    #[serde(default)]
    pub points: BTreeMap<String, f32>,
}

impl LabFolder {
    pub fn read(dir: &Path) -> Result<LabFolder, String> {
        let path = dir.join("lab.toml");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("{}: {e} (a lab's folder is made by `mirador lab new LAB DIR`)", path.display()))?;
        toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// How `lab check` runs.
pub struct Options {
    pub dir: PathBuf,
    /// The lab to grade, as a teacher names it: the folder's `lab.toml`, which is the student's to
    /// edit, is then not read at all (neither which lab it is nor its points).
    pub lab: Option<String>,
    /// A teacher's folder of hidden tests.
    pub hidden: Option<PathBuf>,
    /// A points file in place of the folder's own `[points]`.
    pub points: Option<PathBuf>,
    /// How long one test may take.
    pub time_limit: Duration,
    /// Where to write the results too, and in which service's format.
    pub results: Option<(PathBuf, super::report::Format)>,
}

/// Whose functions a run of the tests uses.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Whose {
    Student,
    /// The lab's answer key: a teacher's hidden tests are run with it first.
    Key,
}

/// Checks the lab in `options.dir` and writes its reports there.
pub fn check(options: &Options) -> Result<Report, String> {
    let start = Instant::now();
    let (lab, folder_points) = match &options.lab {
        Some(name) => (find(name)?, BTreeMap::new()),
        None => {
            let folder = LabFolder::read(&options.dir)?;
            let lab = find(&folder.lab).map_err(|e| format!("{}: {e}", options.dir.join("lab.toml").display()))?;
            (lab, folder.points)
        }
    };
    let tests = tests(&lab, options.hidden.as_deref())?;
    let points = match &options.points {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let points =
                toml::from_str::<BTreeMap<String, f32>>(&text).map_err(|e| format!("{}: {e}", path.display()))?;
            teachers_points(&points, &tests).map_err(|e| format!("{}: {e}", path.display()))?;
            points
        }
        None => folder_points,
    };
    let path = submitted(&options.dir, &lab.file)?;
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    // A teacher's hidden test that the answer key fails is the teacher's error: it is reported,
    // and counts for nobody.
    let own = Test::of(&lab).len();
    let teachers_errors: BTreeMap<usize, String> = if tests.len() > own {
        run_in_child(options, &lab, Whose::Key, own, tests.len(), &path)
            .into_iter()
            .skip(own)
            // A test the key did not run to its end is no verdict on the test: it is graded.
            .filter(|finding| !finding.passed && !finding.unfinished)
            .map(|finding| (finding.index, finding.output))
            .collect()
    } else {
        BTreeMap::new()
    };
    let problems = source::problems(&lab, &text);
    let findings = if problems.is_empty() {
        run_in_child(options, &lab, Whose::Student, 0, tests.len(), &path)
    } else {
        let why = format!("not run: {} does not compile (see the first problem above)", lab.file);
        (0..tests.len()).map(|index| Finding::unfinished(index, &why)).collect()
    };
    let results = tests
        .iter()
        .zip(findings)
        .enumerate()
        .map(|(index, (test, finding))| match teachers_errors.get(&index) {
            Some(why) => test.teachers_error(why),
            None => test.result(finding, &points),
        })
        .collect();
    let report = Report { lab, problems, results, seconds: start.elapsed().as_secs_f64() };
    super::report::write(&report, &options.dir)?;
    if let Some((path, format)) = &options.results {
        let json = match format {
            super::report::Format::Gradescope => super::report::results_json(&report),
            super::report::Format::Prairielearn => super::report::prairielearn_json(&report, &options.dir),
        };
        crate::output::write_atomically(json.as_bytes(), path).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(report)
}

/// The student's file `name` in `dir`, or, in a submission that is a zip or a repository, the one
/// file of that name nearest the top (up to four folders down).
fn submitted(dir: &Path, name: &str) -> Result<PathBuf, String> {
    let mut level = vec![dir.to_path_buf()];
    for _ in 0..5 {
        let mut found: Vec<PathBuf> =
            level.iter().map(|folder| folder.join(name)).filter(|path| path.is_file()).collect();
        found.sort();
        if let Some(path) = found.into_iter().next() {
            return Ok(path);
        }
        let mut next = Vec::new();
        for folder in &level {
            let Ok(entries) = std::fs::read_dir(folder) else { continue };
            let mut folders: Vec<PathBuf> = entries
                .filter_map(|entry| entry.ok())
                .filter(|entry| entry.file_type().is_ok_and(|t| t.is_dir()))
                .map(|entry| entry.path())
                .filter(|path| !path.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')))
                .collect();
            folders.sort();
            next.extend(folders);
        }
        level = next;
    }
    Err(format!("{}: there is no `{name}` in it (the lab's file, which the student writes)", dir.display()))
}

/// A teacher's points file names only tests there are, with points a grade can add up.
pub fn teachers_points(points: &BTreeMap<String, f32>, tests: &[Test]) -> Result<(), String> {
    for (name, value) in points {
        if !tests.iter().any(|test| test.name() == name) {
            let names: Vec<&str> = tests.iter().map(Test::name).collect();
            return Err(format!("no test is named `{name}`; the tests are: {}", names.join("; ")));
        }
        if !value.is_finite() || *value < 0.0 {
            return Err(format!("`{name}` = {value}: points are a number from 0 up"));
        }
    }
    Ok(())
}

/// Runs the tests in `mirador lab run` children: a test that takes longer than the limit stops
/// its child (a software GPU cannot be interrupted) and the tests after it are not run; a child
/// that dies is restarted after the test it died on.
fn run_in_child(
    options: &Options,
    lab: &super::Lab,
    whose: Whose,
    from: usize,
    count: usize,
    file: &Path,
) -> Vec<Finding> {
    let mut findings: Vec<Finding> = (0..from).map(|index| Finding::unfinished(index, "not run")).collect();
    while findings.len() < count {
        let from = findings.len();
        let exe = match std::env::current_exe() {
            Ok(exe) => exe,
            Err(e) => return fill(findings, count, &format!("not run: {e}")),
        };
        let mut command = Command::new(exe);
        command.args(["lab", "run"]).arg(&options.dir).args(["--from", &from.to_string(), "--lab", &lab.name]);
        if let Some(hidden) = &options.hidden {
            command.arg("--tests").arg(hidden);
        }
        match whose {
            Whose::Key => command.arg("--key"),
            Whose::Student => command.arg("--file").arg(file),
        };
        let mut child = match command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn() {
            Ok(child) => child,
            Err(e) => return fill(findings, count, &format!("not run: cannot start the checker: {e}")),
        };
        let (sender, lines) = mpsc::channel();
        let stdout = child.stdout.take().expect("piped above");
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if sender.send(line).is_err() {
                    break;
                }
            }
        });
        loop {
            match lines.recv_timeout(options.time_limit) {
                Ok(line) => match serde_json::from_str::<Finding>(&line) {
                    Ok(finding) => findings.push(finding),
                    Err(_) => continue,
                },
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    let _ = child.kill();
                    let _ = child.wait();
                    let limit = options.time_limit.as_secs_f64();
                    let index = findings.len();
                    findings.push(Finding::unfinished(
                        index,
                        &format!("did not finish within {limit} s: a loop that never ends?"),
                    ));
                    return fill(findings, count, &format!("not run: an earlier test did not finish within {limit} s"));
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    let output = child.wait_with_output();
                    if findings.len() < count {
                        let stderr =
                            output.map(|o| String::from_utf8_lossy(&o.stderr).into_owned()).unwrap_or_default();
                        let tail: Vec<&str> = stderr.lines().rev().take(3).collect();
                        let tail: Vec<&str> = tail.into_iter().rev().collect();
                        let index = findings.len();
                        findings.push(Finding::unfinished(
                            index,
                            &format!("the checker stopped during this test: {}", tail.join(" / ")),
                        ));
                    }
                    break;
                }
            }
        }
    }
    findings
}

fn fill(mut findings: Vec<Finding>, count: usize, why: &str) -> Vec<Finding> {
    while findings.len() < count {
        let index = findings.len();
        findings.push(Finding::unfinished(index, why));
    }
    findings
}
