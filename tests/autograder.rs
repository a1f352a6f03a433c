//! `mirador lab autograder` (src/lab/autograder.rs) as the grading services run it.
//!
//! Gradescope's contract end to end, for every lab: the folder written, a submission laid out as
//! Gradescope lays it (`/autograder/submission`, here a temporary root, the student's file
//! inside a folder of a zip), `run_autograder` run under Gradescope's default limits (one CPU,
//! 768 MB of memory, 10 minutes), and `/autograder/results/results.json` read back: the answer
//! key scores full marks, with its peak memory under a third of the limit. The peak is that of
//! every child this test binary waited for; the other tests here start only small ones.

use std::path::PathBuf;
use std::process::Command;

fn mirador(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_mirador")).args(args).output().expect("running the mirador binary")
}

fn temporary(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-autograder-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Gradescope's default memory limit.
const GRADESCOPE_MEMORY_MB: f64 = 768.0;

/// The largest resident set of any child this process has waited for (and of theirs), in MB.
#[cfg(target_os = "linux")]
fn children_peak_mb() -> f64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes the struct it is given, which lives for the call.
    let result = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    assert_eq!(result, 0);
    usage.ru_maxrss as f64 / 1024.0
}

#[test]
#[cfg(target_os = "linux")]
fn every_lab_grades_on_gradescopes_contract_within_its_limits() {
    let root = temporary("gradescope");
    let labs: Vec<String> = mirador::lab::catalog().into_iter().map(|lab| lab.name).collect();
    let mut figures = Vec::new();
    for name in &labs {
        let lab = mirador::lab::find(name).unwrap();
        let autograder = root.join(name);
        let source = autograder.join("source");
        let hidden = root.join(format!("{name}-hidden"));
        std::fs::create_dir_all(&hidden).unwrap();
        let output = mirador(&[
            "lab",
            "autograder",
            name,
            &source.display().to_string(),
            "--for",
            "gradescope",
            "--tests",
            &hidden.display().to_string(),
        ]);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        for file in ["setup.sh", "run_autograder", "README.md", "mirador", "lab/points.toml"] {
            assert!(source.join(file).is_file(), "{name}: {file} is written");
        }
        // The submission: the student's folder, zipped with its folder, and a lab.toml of theirs
        // that claims points it has no right to.
        let student = autograder.join("submission").join("my-lab");
        let output = mirador(&["lab", "new", name, &student.display().to_string(), "--solution"]);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        std::fs::write(student.join("lab.toml"), "lab = \"bump\"\n").unwrap();

        let start = std::time::Instant::now();
        let mut command = Command::new("taskset");
        command
            .args(["-c", "0", "bash"])
            .arg(source.join("run_autograder"))
            .env("AUTOGRADER_ROOT", &autograder)
            .env("MIRADOR", env!("CARGO_BIN_EXE_mirador"));
        let output = command.output().expect("taskset and bash run the autograder");
        let seconds = start.elapsed().as_secs_f64();
        let results = autograder.join("results/results.json");
        let text = std::fs::read_to_string(&results)
            .unwrap_or_else(|e| panic!("{name}: no results.json ({e}): {}", String::from_utf8_lossy(&output.stderr)));
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(json["score"], json["max_score"], "{name}: the answer key scores full marks:\n{text}");
        assert!(json["max_score"].as_f64().unwrap() > 0.0);
        let tests = json["tests"].as_array().unwrap();
        assert_eq!(tests.len(), lab.known_answers.len() + lab.images.len(), "{name}: the lab's tests, not lab.toml's");
        assert!(tests.iter().all(|t| t["status"] == "passed" && t["visibility"] == "visible"), "{text}");
        figures.push((name.clone(), seconds));
        let _ = std::fs::remove_dir_all(&autograder);
    }
    let peak = children_peak_mb();
    eprintln!("Gradescope's contract, one CPU: peak resident memory {peak:.0} MB; seconds per lab: {figures:?}");
    assert!(
        peak * 3.0 <= GRADESCOPE_MEMORY_MB,
        "a check must fit Gradescope's 768 MB three times over: its peak was {peak:.0} MB"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A submission the autograder cannot grade (no lab file) still gets Gradescope a results.json
/// that says why, with a score of 0.
#[test]
fn a_submission_without_the_file_gets_a_result_that_says_why() {
    let autograder = temporary("nothing");
    let source = autograder.join("source");
    let output = mirador(&["lab", "autograder", "bump", &source.display().to_string(), "--for", "gradescope"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    std::fs::create_dir_all(autograder.join("submission")).unwrap();
    std::fs::write(autograder.join("submission/notes.txt"), "no shader here").unwrap();
    let output = Command::new("bash")
        .arg(source.join("run_autograder"))
        .env("AUTOGRADER_ROOT", &autograder)
        .env("MIRADOR", env!("CARGO_BIN_EXE_mirador"))
        .output()
        .unwrap();
    let text = std::fs::read_to_string(autograder.join("results/results.json"))
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&output.stderr)));
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["score"], 0.0);
    assert!(json["output"].as_str().unwrap().contains("there is no `bump.wgsl` in it"), "{text}");
    let _ = std::fs::remove_dir_all(&autograder);
}

/// PrairieLearn's folder: its entry point and image, and the lab's points beside them.
#[test]
fn prairielearns_folder_has_its_entry_point_and_image() {
    let dir = temporary("prairielearn");
    let output = mirador(&["lab", "autograder", "volumes", &dir.display().to_string(), "--for", "prairielearn"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let run = std::fs::read_to_string(dir.join("run.sh")).unwrap();
    assert!(run.contains("--format prairielearn") && run.contains("/grade/results/results.json"), "{run}");
    assert!(run.contains("--lab volumes"));
    let docker = std::fs::read_to_string(dir.join("Dockerfile")).unwrap();
    assert!(docker.contains("FROM ubuntu:22.04") && docker.contains("mesa-vulkan-drivers"));
    assert!(dir.join("lab/points.toml").is_file() && dir.join("mirador").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// GitHub Classroom's workflow: one command-grader step per test worth the test's points (a
/// teacher's points file over the lab's), the reporter adding them up, and `lab passed` exiting
/// 0 exactly for a passed test.
#[test]
fn classrooms_workflow_has_one_step_per_test_worth_its_points() {
    let dir = temporary("classroom");
    let points = dir.join("points.toml");
    std::fs::write(&points, "\"the three panes against Mirador's\" = 5\n").unwrap();
    let output = mirador(&[
        "lab",
        "autograder",
        "transparency",
        &dir.display().to_string(),
        "--for",
        "classroom",
        "--points",
        &points.display().to_string(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let workflow = std::fs::read_to_string(dir.join(".github/workflows/classroom.yml")).unwrap();
    let lab = mirador::lab::find("transparency").unwrap();
    let count = lab.known_answers.len() + lab.images.len();
    assert_eq!(workflow.matches("uses: classroom-resources/autograding-command-grader@v1").count(), count);
    assert!(workflow.contains("uses: classroom-resources/autograding-grading-reporter@v1"));
    let runners: Vec<String> = (1..=count).map(|i| format!("test-{i}")).collect();
    assert!(workflow.contains(&format!("runners: {}", runners.join(","))), "{workflow}");
    assert!(workflow.contains("TEST-1_RESULTS: \"${{steps.test-1.outputs.result}}\""), "{workflow}");
    let five = workflow.find("test-name: \"the three panes against Mirador's\"").expect("the test's step");
    assert!(workflow[five..].lines().nth(3).unwrap().contains("max-score: 5"), "{workflow}");

    let results = dir.join("results.json");
    std::fs::write(
        &results,
        r#"{"tests": [{"name": "a", "status": "passed", "max_score": 1, "output": ""}, {"name": "b", "status": "failed", "max_score": 1, "output": "no"}, {"name": "a teacher's error", "status": "failed", "max_score": 0, "output": "not graded"}]}"#,
    )
    .unwrap();
    let passed = |index: &str| mirador(&["lab", "passed", &results.display().to_string(), index]).status.code();
    // A test worth nothing (a teacher's test in error) costs nobody a point.
    assert_eq!((passed("0"), passed("1"), passed("2"), passed("3")), (Some(0), Some(1), Some(0), Some(2)));
    // The hidden tests' folder survives a repository, which keeps no empty folder.
    assert!(dir.join(".mirador/hidden/README.md").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A hidden image test names its own scene by a path under the hidden folder: the grading
/// folder gets every file of it, subfolders too, so the grader finds the scene (before, only the
/// tests' `*.toml` files were copied, and such a test was skipped as the teacher's error).
#[test]
fn the_hidden_tests_scenes_go_with_them() {
    let root = temporary("hidden-scenes");
    let hidden = root.join("hidden");
    std::fs::create_dir_all(hidden.join("scenes")).unwrap();
    let scene = std::fs::read_to_string(mirador::scene::builtin_path("course/shadows-bias.toml")).unwrap();
    std::fs::write(hidden.join("scenes/my-scene.toml"), &scene).unwrap();
    std::fs::write(
        hidden.join("more.toml"),
        "[[image]]\nname = \"my scene\"\nscene = \"scenes/my-scene.toml\"\nsize = [64, 36]\nagainst = \"reference\"\nmean = 0.01\nregion = 0.05\npoints = 1\n",
    )
    .unwrap();
    let source = root.join("source");
    let output = mirador(&[
        "lab",
        "autograder",
        "shadow-map",
        &source.display().to_string(),
        "--for",
        "prairielearn",
        "--tests",
        &hidden.display().to_string(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert!(source.join("lab/hidden/more.toml").is_file(), "the hidden test is copied");
    let copied = std::fs::read_to_string(source.join("lab/hidden/scenes/my-scene.toml")).expect("its scene is copied");
    assert_eq!(copied, scene);
    let _ = std::fs::remove_dir_all(&root);
}
