//! `mirador lab check DIR`: the student's file validated, then the tests run in a child process
//! under a time limit each, scored from the points a teacher can edit, and reported.

use super::checks::Finding;
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
    /// A teacher's folder of hidden tests.
    pub hidden: Option<PathBuf>,
    /// A points file in place of the folder's own `[points]`.
    pub points: Option<PathBuf>,
    /// How long one test may take.
    pub time_limit: Duration,
}

/// Checks the lab in `options.dir` and writes its reports there.
pub fn check(options: &Options) -> Result<Report, String> {
    let start = Instant::now();
    let folder = LabFolder::read(&options.dir)?;
    let lab = find(&folder.lab).map_err(|e| format!("{}: {e}", options.dir.join("lab.toml").display()))?;
    let points = match &options.points {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            toml::from_str::<BTreeMap<String, f32>>(&text).map_err(|e| format!("{}: {e}", path.display()))?
        }
        None => folder.points,
    };
    let path = options.dir.join(&lab.file);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let tests = tests(&lab, options.hidden.as_deref())?;
    let problems = source::problems(&lab, &text);
    let findings = if problems.is_empty() {
        run_in_child(options, tests.len())
    } else {
        let why = format!("not run: {} does not compile (see the first problem above)", lab.file);
        (0..tests.len()).map(|index| Finding::unfinished(index, &why)).collect()
    };
    let results = tests.iter().zip(findings).map(|(test, finding)| test.result(finding, &points)).collect();
    let report = Report { lab, problems, results, seconds: start.elapsed().as_secs_f64() };
    super::report::write(&report, &options.dir)?;
    Ok(report)
}

/// Runs the tests in `mirador lab run` children: a test that takes longer than the limit stops
/// its child (a software GPU cannot be interrupted) and the tests after it are not run; a child
/// that dies is restarted after the test it died on.
fn run_in_child(options: &Options, count: usize) -> Vec<Finding> {
    let mut findings: Vec<Finding> = Vec::new();
    while findings.len() < count {
        let from = findings.len();
        let exe = match std::env::current_exe() {
            Ok(exe) => exe,
            Err(e) => return fill(findings, count, &format!("not run: {e}")),
        };
        let mut command = Command::new(exe);
        command.args(["lab", "run"]).arg(&options.dir).args(["--from", &from.to_string()]);
        if let Some(hidden) = &options.hidden {
            command.arg("--tests").arg(hidden);
        }
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
