//! `mirador lab autograder NAME DIR --for SERVICE`: what the services that grade classes need to
//! run a lab's check on every submission, written into one folder. Mirador runs on their
//! engines, with their formats; it does not bring a runner of its own.
//!
//! - **Gradescope**: `setup.sh` (its Ubuntu 22.04 image: Mesa's lavapipe, and the Mirador binary
//!   beside the script put on `PATH`) and `run_autograder`, which grades
//!   `/autograder/submission` with the teacher's lab, points and hidden tests from
//!   `/autograder/source/lab/` (never from the student's files) and writes
//!   `/autograder/results/results.json`, with each test's `status` and `visibility`.
//! - **PrairieLearn**: its external grader's entry point `run.sh` and a `Dockerfile` for the
//!   image: the submission in `/grade/student`, the results in `/grade/results/results.json`
//!   (`gradable`, `score` from 0 to 1, each test's points, the image tests' pictures as data
//!   URLs under the grader's 1 MB).
//! - **GitHub Classroom**: `.github/workflows/classroom.yml`, one check then one
//!   `autograding-command-grader` step per test (`mirador lab passed`), and the
//!   `autograding-grading-reporter` that adds up their points. A student's repository holds its
//!   tests: nothing there is hidden.
//!
//! Each folder also holds `lab/points.toml` (every test's points, the lab's by default) and
//! `lab/hidden/` (the teacher's hidden tests), and a README saying how to upload it.

use super::Lab;
use super::checks::Test;
use crate::output::write_atomically;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The services a folder can be written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Service {
    Gradescope,
    Prairielearn,
    Classroom,
}

/// What `lab autograder` is given.
pub struct Options {
    pub dir: PathBuf,
    pub service: Service,
    /// The teacher's hidden tests (`*.toml`, the lab's own format), copied in.
    pub hidden: Option<PathBuf>,
    /// The teacher's points (`"test name" = points`); the lab's own otherwise.
    pub points: Option<PathBuf>,
    /// The Mirador binary to put in the folder (Gradescope and PrairieLearn): this one, unless
    /// another is named (one built on the service's Ubuntu, where this one's C library is newer).
    pub binary: PathBuf,
    /// The most seconds one test may take.
    pub time_limit: f64,
}

/// Writes the folder; returns the files written.
pub fn write(lab: &Lab, options: &Options) -> Result<Vec<PathBuf>, String> {
    let dir = &options.dir;
    let tests = super::run::tests(lab, options.hidden.as_deref())?;
    let points = points(lab, &tests, options.points.as_deref())?;
    let mut written = Vec::new();
    let mut file = |path: PathBuf, text: &[u8], executable: bool| -> Result<(), String> {
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        }
        write_atomically(text, &path).map_err(|e| format!("{}: {e}", path.display()))?;
        if executable {
            executable_bit(&path)?;
        }
        written.push(path);
        Ok(())
    };
    let lab_dir = match options.service {
        Service::Classroom => dir.join(".mirador"),
        Service::Gradescope | Service::Prairielearn => dir.join("lab"),
    };
    file(lab_dir.join("points.toml"), points_file(lab, &tests, &points).as_bytes(), false)?;
    // A folder git keeps even when it holds no test (a repository drops empty folders, and the
    // scripts name it).
    file(lab_dir.join("hidden/README.md"), HIDDEN_README.as_bytes(), false)?;
    if let Some(hidden) = &options.hidden {
        // Every file of the folder, not only its tests: a hidden image test names its own scene
        // (and the scene its textures) by a path relative to the folder.
        for path in files_under(hidden)? {
            let text = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let relative = path.strip_prefix(hidden).expect("a file listed under the folder");
            file(lab_dir.join("hidden").join(relative), &text, false)?;
        }
    }
    if options.service == Service::Classroom
        && let Some((name, value)) = points.iter().find(|(_, v)| v.fract() != 0.0)
    {
        return Err(format!("`{name}` = {value}: GitHub Classroom's grader takes whole points"));
    }
    let check = CheckLine { lab: &lab.name, time_limit: options.time_limit };
    match options.service {
        Service::Gradescope => {
            file(dir.join("setup.sh"), gradescope_setup().as_bytes(), true)?;
            file(dir.join("run_autograder"), gradescope_run(lab, &check).as_bytes(), true)?;
            file(dir.join("README.md"), gradescope_readme(lab).as_bytes(), false)?;
            copy_binary(&options.binary, &dir.join("mirador"))?;
            written.push(dir.join("mirador"));
        }
        Service::Prairielearn => {
            file(dir.join("run.sh"), prairielearn_run(lab, &check).as_bytes(), true)?;
            file(dir.join("Dockerfile"), prairielearn_dockerfile().as_bytes(), false)?;
            file(dir.join("README.md"), prairielearn_readme(lab).as_bytes(), false)?;
            copy_binary(&options.binary, &dir.join("mirador"))?;
            written.push(dir.join("mirador"));
        }
        Service::Classroom => {
            let workflow = classroom_workflow(lab, &tests, &points, &check);
            file(dir.join(".github/workflows/classroom.yml"), workflow.as_bytes(), false)?;
            file(dir.join(".mirador/README.md"), classroom_readme(lab).as_bytes(), false)?;
        }
    }
    Ok(written)
}

/// Every file under `folder`, its subfolders' too, in order of their paths (links are followed).
fn files_under(folder: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files = Vec::new();
    let mut folders = vec![folder.to_path_buf()];
    while let Some(next) = folders.pop() {
        let entries = std::fs::read_dir(&next).map_err(|e| format!("{}: {e}", next.display()))?;
        for entry in entries {
            let path = entry.map_err(|e| format!("{}: {e}", next.display()))?.path();
            if path.is_dir() {
                folders.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

const HIDDEN_README: &str = "# Hidden tests\n\nThe teacher's hidden tests: `*.toml` files in the lab's own format \
(docs/course/labs.md, \"Points and hidden tests\"), run after the lab's own. This file keeps the \
folder in a repository when it holds none.\n";

/// Every test's points: the teacher's file, checked against the tests, over the lab's own.
fn points(lab: &Lab, tests: &[Test], file: Option<&Path>) -> Result<BTreeMap<String, f32>, String> {
    let mut points: BTreeMap<String, f32> = tests.iter().map(|t| (t.name().to_owned(), t.points())).collect();
    if let Some(path) = file {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let theirs: BTreeMap<String, f32> = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        super::check::teachers_points(&theirs, tests).map_err(|e| format!("{}: {e}", path.display()))?;
        points.extend(theirs);
    }
    let _ = lab;
    Ok(points)
}

fn points_file(lab: &Lab, tests: &[Test], points: &BTreeMap<String, f32>) -> String {
    let mut text = format!(
        "# Lab `{}`: each test's points, which `mirador lab check --points` reads (the student's\n# own lab.toml is never read when grading).\n",
        lab.name
    );
    for test in tests {
        let value = points.get(test.name()).copied().unwrap_or(test.points());
        let _ = writeln!(text, "\"{}\" = {value}", test.name().replace('\\', "\\\\").replace('"', "\\\""));
    }
    text
}

fn copy_binary(from: &Path, to: &Path) -> Result<(), String> {
    let bytes = std::fs::read(from).map_err(|e| format!("{}: cannot read the Mirador binary: {e}", from.display()))?;
    write_atomically(&bytes, to).map_err(|e| format!("{}: {e}", to.display()))?;
    executable_bit(to)
}

#[cfg(unix)]
fn executable_bit(path: &Path) -> Result<(), String> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(not(unix))]
fn executable_bit(_: &Path) -> Result<(), String> {
    Ok(())
}

/// The `lab check` arguments every service's script shares.
struct CheckLine<'a> {
    lab: &'a str,
    time_limit: f64,
}

impl CheckLine<'_> {
    /// `lab check` of `submission`, with the folder `lab` (points and hidden tests), writing the
    /// results for `format`.
    fn command(&self, submission: &str, lab: &str, format: &str, results: &str) -> String {
        format!(
            "\"$MIRADOR\" lab check \"{submission}\" --lab {} --points \"{lab}/points.toml\" --tests \"{lab}/hidden\" --time-limit {} --format {format} --results \"{results}\"",
            self.lab, self.time_limit
        )
    }
}

fn gradescope_setup() -> String {
    "#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image (Ubuntu 22.04).
# Written by `mirador lab autograder`.
set -euo pipefail
apt-get update
DEBIAN_FRONTEND=noninteractive apt-get install -y mesa-vulkan-drivers libvulkan1
install -m 755 /autograder/source/mirador /usr/local/bin/mirador
# Fails here, when the image is built, rather than on the first submission: a binary built
# against a newer C library than Ubuntu 22.04's does not start (see README.md).
mirador --version
"
    .to_owned()
}

/// What a service runs for each submission: the submission copied from `ROOT/SUBMISSION` (so the
/// check's reports never write into it), the check, and a result written whatever happens.
/// `head` is the script's first comment; `root` names the variable a test sets in place of the
/// service's folder, and `fallback` is the result of a check that crashed (a `printf` format
/// whose `%s` is the exit status).
struct Runner<'a> {
    head: String,
    root: (&'a str, &'a str),
    submission: &'a str,
    lab_folder: &'a str,
    format: &'a str,
    fallback: &'a str,
}

impl Runner<'_> {
    fn script(&self, check: &CheckLine) -> String {
        let (variable, default) = self.root;
        let results = "$root/results/results.json";
        format!(
            "#!/usr/bin/env bash
{head}
set -uo pipefail
root=\"${{{variable}:-{default}}}\"
MIRADOR=\"${{MIRADOR:-mirador}}\"
work=\"$(mktemp -d)\"
cp -R \"$root/{submission}/.\" \"$work/\"
mkdir -p \"$root/results\"
{command}
status=$?
# 0: every test passed, 1: some failed, 2: not checked (why is in the results); each wrote the
# results. Only a crash leaves none.
if [ ! -s \"{results}\" ]; then
    printf '{fallback}\\n' \"$status\" > \"{results}\"
fi
",
            head = self.head.trim_end(),
            submission = self.submission,
            command = check.command("$work", &format!("$root/{}", self.lab_folder), self.format, results),
            fallback = self.fallback,
        )
    }
}

fn gradescope_run(lab: &Lab, check: &CheckLine) -> String {
    Runner {
        head: format!(
            "# Gradescope runs this for each submission. Written by `mirador lab autograder` for lab `{}`.
# The lab, its points and its hidden tests come from this folder (source/lab/), never from the
# student's files; the student's {} is found anywhere in the submission.
# AUTOGRADER_ROOT and MIRADOR stand in for /autograder and the installed binary in a test.",
            lab.name, lab.file
        ),
        root: ("AUTOGRADER_ROOT", "/autograder"),
        submission: "submission",
        lab_folder: "source/lab",
        format: "gradescope",
        fallback: "{\"score\": 0, \"output\": \"The autograder could not grade this submission (mirador exited with %s). Please tell your instructor.\", \"tests\": []}",
    }
    .script(check)
}

fn gradescope_readme(lab: &Lab) -> String {
    format!(
        "# Lab `{name}` on Gradescope

Written by `mirador lab autograder {name} DIR --for gradescope`. In Gradescope, make a
*Programming Assignment*, choose *Zip file upload* with the base image *Ubuntu 22.04*, and
upload a zip of this folder's files (not of the folder):

```sh
cd DIR && zip -r ../{name}-autograder.zip .
```

- `setup.sh` installs Mesa's lavapipe (Vulkan on the CPU: no GPU needed) and `mirador`.
- `run_autograder` grades `/autograder/submission`: the student uploads `{file}` (alone, or
  anywhere in a zip or a repository). The lab, the points (`lab/points.toml`) and the hidden
  tests (`lab/hidden/*.toml`) are this folder's; a student's `lab.toml` is not read.
- The results: each test's score, `status`, and `visibility` (your hidden tests'
  `after_published`: their names and outputs show once you publish the grades). A hidden test
  that the answer key itself fails is reported to you and counts for nobody.

The `mirador` binary here is the one that wrote the folder. It must start on Ubuntu 22.04,
whose C library is glibc 2.35 (`objdump -T mirador | grep GLIBC_` lists what it asks for);
`setup.sh` fails when Gradescope builds the image if it does not. Then build one on Ubuntu 22.04
(for example in `docker run ubuntu:22.04`) and pass it with `--binary`.

Gradescope's default limits (one CPU, 768 MB of memory, 10 minutes) hold every lab with a wide
margin: docs/performance.md, \"Grading a class\", has the figures.
",
        name = lab.name,
        file = lab.file
    )
}

fn prairielearn_run(lab: &Lab, check: &CheckLine) -> String {
    Runner {
        head: format!(
            "# PrairieLearn's external grader runs this in the image the Dockerfile builds. Written by
# `mirador lab autograder` for lab `{}`: the student's {} from /grade/student, the lab's
# points and hidden tests from /grade/tests/lab (the question's tests/ folder), the results in
# /grade/results/results.json. GRADE_ROOT and MIRADOR stand in for /grade and the binary in a test.",
            lab.name, lab.file
        ),
        root: ("GRADE_ROOT", "/grade"),
        submission: "student",
        lab_folder: "tests/lab",
        format: "prairielearn",
        fallback: "{\"gradable\": false, \"score\": 0, \"message\": \"The autograder could not grade this submission (mirador exited with %s).\"}",
    }
    .script(check)
}

fn prairielearn_dockerfile() -> String {
    "# The image PrairieLearn's external grader runs (written by `mirador lab autograder`):
# Ubuntu 22.04, Mesa's lavapipe and the mirador binary beside this file.
FROM ubuntu:22.04
RUN apt-get update \\
 && DEBIAN_FRONTEND=noninteractive apt-get install -y mesa-vulkan-drivers libvulkan1 \\
 && rm -rf /var/lib/apt/lists/*
COPY mirador /usr/local/bin/mirador
RUN mirador --version
"
    .to_owned()
}

fn prairielearn_readme(lab: &Lab) -> String {
    format!(
        "# Lab `{name}` on PrairieLearn

Written by `mirador lab autograder {name} DIR --for prairielearn`.

1. Build the grader's image from this folder and push it where your PrairieLearn reads images:
   `docker build -t YOUR/mirador-grader DIR`.
2. In the question's folder: copy `run.sh` and `lab/` into `tests/` (so that `/grade/tests/run.sh`
   and `/grade/tests/lab/` exist), give the student a file editor or upload for `{file}`
   (`pl-file-editor` or `pl-file-upload`), and set in `info.json`:

```json
\"gradingMethod\": \"External\",
\"externalGradingOptions\": {{
    \"enabled\": true,
    \"image\": \"YOUR/mirador-grader\",
    \"entrypoint\": \"/grade/tests/run.sh\",
    \"timeout\": 300
}}
```

The results give `score` from 0 to 1, each test's points and output, and the image tests'
pictures (yours and the difference, as data URLs, kept under the grader's 1 MB). A file that does
not compile is `gradable: false` with the compiler's message: the student loses no attempt.
Hidden tests' outputs are left out of what the student sees; a hidden test that the answer key
fails counts for nobody.
",
        name = lab.name,
        file = lab.file
    )
}

fn classroom_workflow(lab: &Lab, tests: &[Test], points: &BTreeMap<String, f32>, check: &CheckLine) -> String {
    let mut out = format!(
        "# GitHub Classroom's autograding for lab `{name}`, written by `mirador lab autograder`.
# One check writes results.json; each test is then one command-grader step worth its points.
# Put a mirador binary built for Ubuntu at .mirador/mirador (or change the install step).
name: Autograding Tests
on: [push, repository_dispatch]
permissions:
  checks: write
  actions: read
  contents: read
jobs:
  run-autograding-tests:
    runs-on: ubuntu-22.04
    if: github.actor != 'github-classroom[bot]'
    steps:
      - name: Checkout code
        uses: actions/checkout@v4
      - name: Install lavapipe and mirador
        run: |
          sudo apt-get update
          sudo DEBIAN_FRONTEND=noninteractive apt-get install -y mesa-vulkan-drivers libvulkan1
          sudo install -m 755 .mirador/mirador /usr/local/bin/mirador
      - name: Check the lab
        run: MIRADOR=mirador; {command} || true
",
        name = lab.name,
        command = check.command(".", ".mirador", "gradescope", "results.json"),
    );
    let mut ids = Vec::new();
    for (index, test) in tests.iter().enumerate() {
        // GitHub Classroom's grader counts whole points (checked in `write`).
        let id = format!("test-{}", index + 1);
        let value = points.get(test.name()).copied().unwrap_or(test.points());
        let _ = write!(
            out,
            "      - name: {quoted}
        id: {id}
        uses: classroom-resources/autograding-command-grader@v1
        with:
          test-name: {quoted}
          command: mirador lab passed results.json {index}
          timeout: 1
          max-score: {max}
",
            quoted = yaml_string(test.name()),
            max = value as u32,
        );
        ids.push(id);
    }
    let _ = write!(
        out,
        "      - name: Autograding Reporter\n        uses: classroom-resources/autograding-grading-reporter@v1\n        env:\n"
    );
    for id in &ids {
        let _ = writeln!(out, "          {}_RESULTS: \"${{{{steps.{id}.outputs.result}}}}\"", id.to_uppercase());
    }
    let _ = write!(out, "        with:\n          runners: {}\n", ids.join(","));
    out
}

fn classroom_readme(lab: &Lab) -> String {
    format!(
        "# Lab `{name}` on GitHub Classroom

Written by `mirador lab autograder {name} DIR --for classroom` into the assignment's template
repository (with `mirador lab new {name} DIR` for the student's files). Add a mirador binary
built on Ubuntu 22.04 as `.mirador/mirador`, and commit. `.github/workflows/classroom.yml` runs
the check on every push, then one step per test worth its points (`mirador lab passed`): the
Classroom's grade is their sum.

Everything in a student's repository is the student's to read: tests in `.mirador/hidden/` are
not hidden here. Grade with hidden tests on Gradescope or PrairieLearn, or run
`mirador lab check --tests` on the collected repositories yourself.
",
        name = lab.name
    )
}

/// `text` as a double-quoted YAML scalar.
fn yaml_string(text: &str) -> String {
    format!("\"{}\"", text.replace('\\', "\\\\").replace('"', "\\\""))
}
