//! The labs (src/lab, docs/course/labs.md) as a student and a teacher meet them: every lab's
//! answer key scores full marks, its stub fails every known-answer test, each of its known
//! mistakes fails and is named by the test that caught it; a file that does not compile, has a
//! wrong signature or never returns ends in a clear message and a report, never a panic or a
//! hang. And the routes a lab takes instead of the GPU's fixed function draw what the fixed
//! function draws.

mod common;

use mirador::lab::{self, Lab};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mirador(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirador")).args(args).output().expect("running the mirador binary")
}

/// A fresh lab folder for `lab`, with the answer key when `solution`.
fn folder(lab: &str, case: &str, solution: bool) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-lab-{lab}-{case}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let dir_text = dir.display().to_string();
    let mut args = vec!["lab", "new", lab, &dir_text];
    if solution {
        args.push("--solution");
    }
    let output = mirador(&args);
    assert!(output.status.success(), "lab new: {}", String::from_utf8_lossy(&output.stderr));
    dir
}

/// What `lab check` wrote into `dir/results.json`.
fn results(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("results.json")).expect("lab check writes results.json");
    serde_json::from_str(&text).expect("results.json is JSON")
}

fn check(dir: &Path, extra: &[&str]) -> (Output, serde_json::Value) {
    let dir_text = dir.display().to_string();
    let mut args = vec!["lab", "check", &dir_text];
    args.extend(extra);
    let output = mirador(&args);
    let code = output.status.code();
    assert!(matches!(code, Some(0 | 1)), "lab check ended with {code:?}: {}", String::from_utf8_lossy(&output.stderr));
    let results = results(dir);
    (output, results)
}

fn tests_of(results: &serde_json::Value) -> &Vec<serde_json::Value> {
    results["tests"].as_array().expect("results.json lists its tests")
}

/// The answer key, the stub and each known mistake of `name`.
fn battery(name: &str) {
    let lab: Lab = lab::find(name).expect("a built-in lab");
    let known = lab.known_answers.len();

    let key = folder(name, "key", true);
    let (output, key_results) = check(&key, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "the answer key of {name} must pass:\n{stdout}");
    assert_eq!(key_results["score"], key_results["max_score"], "{stdout}");
    assert!(key.join("report.md").exists() && key.join("NOTES.md").exists());

    let stub = folder(name, "stub", false);
    let (output, stub_results) = check(&stub, &[]);
    assert!(!output.status.success(), "the stub of {name} must fail");
    for test in &tests_of(&stub_results)[..known] {
        assert_eq!(test["score"], 0.0, "the stub of {name} scores on {}", test["name"]);
    }

    for mistake in &lab.mistakes {
        let dir = folder(name, &mistake.name.replace(|c: char| !c.is_ascii_alphanumeric(), "-"), false);
        std::fs::write(dir.join(&lab.file), lab.mistaken(mistake)).expect("writing the mistaken file");
        let (output, results) = check(&dir, &[]);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(!output.status.success(), "{name}: the mistake `{}` passed every test:\n{stdout}", mistake.name);
        let named = tests_of(&results).iter().any(|t| t["mistake"] == mistake.name.as_str() && t["score"] == 0.0);
        assert!(named, "{name}: no failing test names the mistake `{}`:\n{stdout}", mistake.name);
        let _ = std::fs::remove_dir_all(&dir);
    }

    // Every other right answer the lab accepts scores full marks.
    for alternative in &lab.alternatives {
        let dir = folder(name, "alternative", false);
        std::fs::write(dir.join(&lab.file), lab.mistaken(alternative)).expect("writing the alternative");
        let (output, results) = check(&dir, &[]);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{name}: the right answer `{}` loses points:\n{stdout}", alternative.name);
        assert_eq!(results["score"], results["max_score"], "{stdout}");
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&key);
    let _ = std::fs::remove_dir_all(&stub);
}

#[test]
fn mipmaps_lab() {
    battery("mipmaps");
}

#[test]
fn bump_lab() {
    battery("bump");
}

#[test]
fn parallax_lab() {
    battery("parallax");
}

#[test]
fn shadow_map_lab() {
    battery("shadow-map");
}

#[test]
fn planar_mirrors_lab() {
    battery("planar-mirrors");
}

#[test]
fn transparency_lab() {
    battery("transparency");
}

#[test]
fn refraction_lab() {
    battery("refraction");
}

#[test]
fn environment_maps_lab() {
    battery("environment-maps");
}

#[test]
fn volumes_lab() {
    battery("volumes");
}

/// A broken student file, checked: the message names the place, a report is written, the score
/// falls short (to 0 when the file does not compile), and the command fails without a panic.
fn broken(case: &str, edit: impl Fn(&str) -> String, needles: &[&str], extra: &[&str]) -> String {
    let dir = folder("bump", case, true);
    let path = dir.join("bump.wgsl");
    let text = std::fs::read_to_string(&path).expect("the answer key");
    std::fs::write(&path, edit(&text)).expect("editing the student's file");
    let (output, results) = check(&dir, extra);
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(!output.status.success(), "{case}: a broken file must fail:\n{stdout}");
    for needle in needles {
        assert!(stdout.contains(needle), "{case}: the report should say `{needle}`:\n{stdout}");
    }
    assert!(results["score"].as_f64() < results["max_score"].as_f64(), "{case}: {stdout}");
    if stdout.contains("does not compile") {
        assert_eq!(results["score"], 0.0, "{case}: {stdout}");
    }
    assert!(dir.join("report.md").exists());
    let _ = std::fs::remove_dir_all(&dir);
    stdout
}

#[test]
fn a_syntax_error_is_given_at_the_students_line() {
    let line_of = |text: &str, needle: &str| text.lines().position(|l| l.contains(needle)).expect("the line") + 1;
    let key = lab::find("bump").unwrap().solution();
    let line = line_of(&key, "return k * vec2f(");
    let out = broken(
        "syntax",
        |t| t.replace("return k * vec2f(", "return k * vec2f(("),
        &[&format!("bump.wgsl:{line}:")],
        &[],
    );
    assert!(out.contains("return k * vec2f(("), "the line is shown:\n{out}");
    // A helper's brace left open runs into what the checker appends: said at the end of the
    // student's file, not in Mirador's.
    let open = "\nfn helper() -> f32 {\n    return 1.0;\n";
    let lines = format!("{key}{open}").lines().count();
    let out =
        broken("unclosed", |t| format!("{t}{open}"), &[&format!("bump.wgsl:{lines}:1: at the end of your file")], &[]);
    assert!(!out.contains("in Mirador's"), "{out}");
}

#[test]
fn a_type_error_is_given_at_the_students_line() {
    let key = lab::find("bump").unwrap().solution();
    let line = key.lines().position(|l| l.contains("let su = tu - dot(tu, n) * n;")).unwrap() + 1;
    let out =
        broken("type", |t| t.replace("let su = tu", "let su: vec2f = tu"), &[&format!("bump.wgsl:{line}:9:")], &[]);
    assert!(out.contains("`su` is expected to be `vec2<f32>`"), "{out}");
    // An error naga gives no place for is placed at the function it is in.
    let line = key.lines().position(|l| l.contains("fn perturbed_normal(")).unwrap() + 1;
    let out = broken(
        "unplaced",
        |t| t.replace("let len = length(m);", "let len = length(m) + vec2f(1.0);"),
        &[&format!("bump.wgsl:{line}:1: in `perturbed_normal`")],
        &[],
    );
    assert!(out.contains("Incompatible operands"), "{out}");
}

#[test]
fn a_wrong_signature_is_named_with_the_right_one() {
    broken(
        "signature",
        |t| {
            t.replace(
                "fn perturbed_normal(n: vec3f, tu: vec3f, tv: vec3f, du: f32, dv: f32)",
                "fn perturbed_normal(n: vec3f, tu: vec3f, tv: vec3f, d: vec2f)",
            )
        },
        &["`perturbed_normal` must keep its signature", "du: f32, dv: f32"],
        &[],
    );
    broken(
        "missing",
        |t| t.replace("fn perturbed_normal(", "fn perturbed_normal_mine("),
        &["`perturbed_normal` is missing"],
        &[],
    );
}

/// A loop whose condition never comes true. On a real GPU it would never return; lavapipe ends
/// every shader invocation's loops after about 65 536 iterations (measured: such a loop returns
/// x = 65535.7 from x = x + 1), so without the checker's guard it would score. The guard
/// (src/lab/isolate.rs) breaks the student's loops after 16 384 iterations on every device and
/// says so; the images of such a shader are not graded; the time limit is never reached.
#[test]
fn a_loop_that_never_ends_is_found_and_named_not_timed_out() {
    let start = std::time::Instant::now();
    let body = "        x = sin(x * 1.3 + cos(x));\n".repeat(100);
    let out = broken(
        "endless",
        |t| {
            t.replace(
                "    let su = tu - dot(tu, n) * n;",
                &format!("    var x = du;\n    loop {{\n{body}        if x > 5.0 {{ break; }}\n    }}\n    let su = tu - dot(tu, n) * n + vec3f(x * 1e-30);"),
            )
        },
        &[
            "your loops ran past 16384 iterations",
            "On a GPU a loop that does not end hangs it",
            "its images are not graded",
        ],
        &["--time-limit", "60"],
    );
    assert!(!out.contains("did not finish within"), "the guard, not the clock, stops it: {out}");
    // Only the central differences, which never call the loop, score.
    assert!(out.contains("lab bump: 1 / "), "{out}");
    assert!(start.elapsed().as_secs() < 60, "the check must stop the loop: {out}");
}

/// A loop that ends in every known-answer test (a 4×4 map) and runs away only in the image tests'
/// scene (a map of hundreds of texels): no flag is read out of an image, so the checker draws it
/// again with the slots' values NaN wherever the guard cut a loop off, and the two differ. Before,
/// the guard stopped the loop, the value came out right, and a shader that hangs a GPU scored
/// full marks.
#[test]
fn a_loop_that_runs_away_only_in_an_image_is_named() {
    let dir = folder("shadow-map", "endless-image", true);
    let path = dir.join("shadow_map.wgsl");
    let key = std::fs::read_to_string(&path).unwrap();
    let start = "    let centre = vec2i(floor(uv * f32(map_size)));\n";
    assert!(key.contains(start));
    let spin = "    var spin = 0u;\n    loop {\n        if spin > 3u && map_size < 64u { break; }\n        spin += 1u;\n    }\n";
    std::fs::write(&path, key.replace(start, &format!("{start}{spin}"))).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!output.status.success(), "{stdout}");
    let tests = tests_of(&results);
    let known = lab::find("shadow-map").unwrap().known_answers.len();
    assert!(tests[..known].iter().all(|t| t["score"] == t["max_score"]), "the known answers never spin: {stdout}");
    for test in &tests[known..] {
        assert_eq!(test["score"], 0.0, "{stdout}");
    }
    assert!(stdout.contains("your loops ran past 16384 iterations while drawing this image"), "{stdout}");
    assert!(stdout.contains("its images are not graded"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A student's helpers may have any name WGSL allows: `project` is one of Mirador's functions
/// (shaders/refraction.wgsl), `shade` another (shaders/common/surface.wgsl); before the
/// student's names were put apart both scored 0 for a correct file.
#[test]
fn a_helper_named_like_one_of_miradors_functions_scores_full_marks() {
    let dir = folder("bump", "helper", true);
    let path = dir.join("bump.wgsl");
    let text =
        std::fs::read_to_string(&path).unwrap().replace("let su = tu - dot(tu, n) * n;", "let su = project(tu, n);")
            + "\n// In n's plane.\nfn project(a: vec3f, n: vec3f) -> vec3f {\n    return a - dot(a, n) * n;\n}\n";
    std::fs::write(&path, text).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert_eq!(results["score"], results["max_score"], "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);

    let dir = folder("volumes", "helper", true);
    let path = dir.join("volumes.wgsl");
    let key = std::fs::read_to_string(&path).unwrap();
    assert!(key.contains("let seen = (1.0 - accumulated.a) * sample.a;"));
    let text = key.replace("let seen = (1.0 - accumulated.a) * sample.a;", "let seen = shade(accumulated, sample);")
        + "\nstruct Light { seen: f32 }\nfn shade(a: vec4f, s: vec4f) -> f32 {\n    let light = Light((1.0 - a.a) * s.a);\n    return light.seen;\n}\n";
    std::fs::write(&path, text).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert_eq!(results["score"], results["max_score"], "{stdout}");
    // And an error in a renamed helper is given in the student's own names, at the student's line
    // (naga places a wrong return type at the function's start).
    let text = std::fs::read_to_string(&path).unwrap().replace("return light.seen;", "return light.seen + vec2f(1.0);");
    let line = text.lines().position(|l| l.starts_with("fn shade(")).unwrap() + 1;
    std::fs::write(&path, text).unwrap();
    let (output, _) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains(&format!("volumes.wgsl:{line}:")), "{stdout}");
    assert!(!stdout.contains("student_"), "the message names the student's own names: {stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A result that is not a number is named as such, and the empty sample on an empty ray is a test
/// of its own: compositing by a division by α_out gives 0/0 there.
#[test]
fn a_nan_in_a_known_answer_is_named() {
    let dir = folder("volumes", "nan", true);
    let path = dir.join("volumes.wgsl");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "return vec4f(accumulated.rgb + seen * sample.rgb, accumulated.a + seen);",
        "let a = accumulated.a + seen;\n    return vec4f((accumulated.rgb + seen * sample.rgb) * (a / a), a);",
    );
    std::fs::write(&path, text).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let empty = tests_of(&results).iter().find(|t| t["name"].as_str().unwrap().contains("no 0/0")).unwrap();
    assert_eq!(empty["score"], 0.0, "{stdout}");
    assert!(empty["output"].as_str().unwrap().contains("NaN in components 1, 2, 3"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// NaN pixels in an image are named, and fail the test whatever the output transform shows them
/// as (another GPU shows them otherwise).
#[test]
fn nan_pixels_in_an_image_are_named() {
    let dir = folder("transparency", "nan-pixels", true);
    let path = dir.join("transparency.wgsl");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "return im + transmittance * behind;",
        "let zero = im.r - im.r;\n    return (im + transmittance * behind) * (zero / zero);",
    );
    std::fs::write(&path, text).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let images: Vec<_> = tests_of(&results).iter().filter(|t| t["name"].as_str().unwrap().contains("panes")).collect();
    assert!(!images.is_empty());
    for test in images {
        assert_eq!(test["score"], 0.0, "{stdout}");
        assert!(
            test["output"]
                .as_str()
                .unwrap()
                .contains("pixels are NaN or infinite before the output transform (0 of Mirador's)"),
            "{stdout}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The untouched stub is told it is the stub, never a known mistake's name; a mistake is named
/// only where it gives the student's values on every known-answer test.
#[test]
fn the_stub_is_told_it_is_the_stub_and_no_mistake_is_named_that_was_not_made() {
    let dir = folder("transparency", "stub-said", false);
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    for test in tests_of(&results) {
        assert!(test.get("mistake").is_none(), "{stdout}");
        assert!(
            test["output"].as_str().unwrap().contains("`transparent_blend` is still the stub's neutral body"),
            "{stdout}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);

    // An LOD from the texture's width alone agrees with "the LOD off by one" on one test only:
    // it is not told that mistake (it was, before every known answer had to agree).
    let dir = folder("mipmaps", "width-only", true);
    let path = dir.join("mipmaps.wgsl");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "return log2(max(length(duv_dx * size), length(duv_dy * size))) + bias;",
        "return log2(max(length(duv_dx * size.x), length(duv_dy * size.x))) + bias;",
    );
    std::fs::write(&path, text).unwrap();
    let (output, results) = check(&dir, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!output.status.success(), "{stdout}");
    assert!(tests_of(&results).iter().all(|t| t.get("mistake").is_none()), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// At the chapter's kt = 0.5, `1 − t` and a grey `t` draw the right panes: the lab's other image
/// tests vary the transmission (strong, coloured, over coloured backgrounds), so each loses more
/// than half the lab's points, and is named.
#[test]
fn a_blend_right_only_at_half_transmission_loses_half_the_points() {
    for (case, slip, mistake) in [
        ("one-minus-t", "return im + (1.0 - transmittance) * behind;", "what is behind filtered by 1 − kt·Mt"),
        ("grey-t", "return im + transmittance.r * behind;", "kt·Mt taken as grey"),
    ] {
        let dir = folder("transparency", case, true);
        let path = dir.join("transparency.wgsl");
        let text = std::fs::read_to_string(&path).unwrap().replace("return im + transmittance * behind;", slip);
        std::fs::write(&path, text).unwrap();
        let (output, results) = check(&dir, &[]);
        let stdout = String::from_utf8_lossy(&output.stdout);
        let (score, max) = (results["score"].as_f64().unwrap(), results["max_score"].as_f64().unwrap());
        assert!(score <= max / 2.0, "{case}: {score} / {max}\n{stdout}");
        assert!(tests_of(&results).iter().any(|t| t["mistake"] == mistake), "{case}: {stdout}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Grading as a teacher does: `--lab` names the lab, so the student's own lab.toml (which could
/// say another lab, or points of its own) is not read; `--points` must name tests that exist; a
/// hidden test the answer key fails (here a misspelt material) is the teacher's error: reported,
/// shown to nobody, and counted for nobody; hidden tests' details wait for publication.
#[test]
fn a_teachers_lab_points_and_hidden_tests_are_the_teachers() {
    let dir = folder("transparency", "teacher", true);
    let path = dir.join("transparency.wgsl");
    let text =
        std::fs::read_to_string(&path).unwrap().replace("return im + transmittance * behind;", "return im + behind;");
    std::fs::write(&path, text).unwrap();
    // The student sets the failing tests' points to 0 in their own lab.toml.
    let mut own = String::from("lab = \"transparency\"\n[points]\n");
    for test in &lab::find("transparency").unwrap().known_answers {
        own.push_str(&format!("\"{}\" = 0\n", test.name));
    }
    for test in &lab::find("transparency").unwrap().images {
        own.push_str(&format!("\"{}\" = 0\n", test.name));
    }
    std::fs::write(dir.join("lab.toml"), own).unwrap();
    let hidden = dir.join("hidden");
    std::fs::create_dir_all(&hidden).unwrap();
    std::fs::write(
        hidden.join("teacher.toml"),
        "[[image]]\nname = \"a misspelt material\"\nscene = \"course/transparency-order.toml\"\nset = [\"materials.red-light.kt=0.9\"]\nsize = [120, 68]\nagainst = \"reference\"\nmean = 0.002\nregion = 0.02\n\n[[known]]\nname = \"a hidden blend\"\ncall = \"vec4f(transparent_blend(vec3f(0.1), vec3f(0.5, 0.0, 1.0), vec3f(0.2)), 1.0)\"\nexpect = [0.2, 0.1, 0.3, 1.0]\npoints = 2\n",
    )
    .unwrap();
    let hidden_text = hidden.display().to_string();
    let (output, results) = check(&dir, &["--lab", "transparency", "--tests", &hidden_text]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let tests = tests_of(&results);
    let typo = tests.iter().find(|t| t["name"] == "a misspelt material").unwrap();
    assert_eq!((typo["max_score"].as_f64(), typo["visibility"].as_str()), (Some(0.0), Some("hidden")), "{stdout}");
    assert!(typo["output"].as_str().unwrap().contains("the lab's answer key fails this hidden test"), "{stdout}");
    assert!(stdout.contains("teacher: 1 hidden test(s) fail with the answer key"), "{stdout}");
    let blend = tests.iter().find(|t| t["name"] == "a hidden blend").unwrap();
    assert_eq!((blend["score"].as_f64(), blend["visibility"].as_str()), (Some(0.0), Some("after_published")));
    let first = &tests[0];
    assert_eq!((first["max_score"].as_f64(), first["visibility"].as_str()), (Some(1.0), Some("visible")));
    assert_eq!(results["max_score"].as_f64(), Some(18.0), "the lab's 16 and the hidden blend's 2: {stdout}");
    assert!(results["score"].as_f64().unwrap() < 9.0, "{stdout}");

    // Points for a test that does not exist are the teacher's error, said before any grading.
    let points = dir.join("points.toml");
    std::fs::write(&points, "\"the three panes agianst Mirador's\" = 4\n").unwrap();
    let output = mirador(&[
        "lab",
        "check",
        &dir.display().to_string(),
        "--lab",
        "transparency",
        "--points",
        &points.display().to_string(),
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("no test is named `the three panes agianst Mirador's`"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--results` in PrairieLearn's form: a file that does not compile is not gradable (no attempt
/// lost), a failed image test brings its pictures as data URLs under the grader's 1 MB, and a
/// submission without the lab's file still gets a result that says why.
#[test]
fn prairielearn_results_say_what_its_grader_reads() {
    let dir = folder("transparency", "prairielearn", true);
    let path = dir.join("transparency.wgsl");
    let results = dir.join("pl.json");
    let args = |dir: &Path| {
        vec![
            "lab".to_owned(),
            "check".to_owned(),
            dir.display().to_string(),
            "--lab".to_owned(),
            "transparency".to_owned(),
            "--format".to_owned(),
            "prairielearn".to_owned(),
            "--results".to_owned(),
            results.display().to_string(),
        ]
    };
    let run = |dir: &Path| {
        let args = args(dir);
        let output = Command::new(env!("CARGO_BIN_EXE_mirador")).args(&args).output().unwrap();
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&results).unwrap()).unwrap();
        (output, json)
    };
    let key = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        key.replace("return im + transmittance * behind;", "return im + (1.0 - transmittance) * behind;"),
    )
    .unwrap();
    let (_, json) = run(&dir);
    assert_eq!(json["gradable"], true);
    let score = json["score"].as_f64().unwrap();
    assert!(score > 0.0 && score < 0.5, "{json}");
    let images = json["images"].as_array().unwrap();
    assert!(!images.is_empty() && images[0]["url"].as_str().unwrap().starts_with("data:image/png;base64,"));
    assert!(serde_json::to_string(&json).unwrap().len() < 1_000_000);

    std::fs::write(&path, key.replace("return im + transmittance * behind;", "return im + transmittance * behind"))
        .unwrap();
    let (_, json) = run(&dir);
    assert_eq!((json["gradable"].as_bool(), json["score"].as_f64()), (Some(false), Some(0.0)), "{json}");
    assert!(json["message"].as_str().unwrap().contains("transparency.wgsl:"), "{json}");

    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let (output, json) = run(&empty);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(json["gradable"], false);
    assert!(json["message"].as_str().unwrap().contains("there is no `transparency.wgsl` in it"), "{json}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn points_come_from_the_folder_and_hidden_tests_run_after_the_labs_own() {
    let dir = folder("refraction", "points", true);
    let config = std::fs::read_to_string(dir.join("lab.toml")).unwrap();
    let config = config.replace(
        "\"fresnel: total internal reflection reflects everything\" = 1",
        "\"fresnel: total internal reflection reflects everything\" = 5",
    );
    std::fs::write(dir.join("lab.toml"), config).unwrap();
    let hidden = dir.join("hidden");
    std::fs::create_dir_all(&hidden).unwrap();
    std::fs::write(
        hidden.join("more.toml"),
        "[[known]]\nname = \"fresnel: water at normal incidence\"\ncall = \"vec4f(fresnel(1.0, 1.0 / 1.333))\"\nexpect = [0.0204, 0.0204, 0.0204, 0.0204]\ntolerance = 1e-3\npoints = 2\n",
    )
    .unwrap();
    let (output, results) = check(&dir, &["--tests", &hidden.display().to_string()]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stdout));
    let tests = tests_of(&results);
    let tir = tests.iter().find(|t| t["name"] == "fresnel: total internal reflection reflects everything").unwrap();
    assert_eq!(tir["max_score"], 5.0);
    let last = tests.last().unwrap();
    assert_eq!(
        (last["name"].as_str(), last["score"].as_f64()),
        (Some("fresnel: water at normal incidence"), Some(2.0))
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_student_file_is_never_overwritten() {
    let dir = folder("bump", "twice", false);
    let output = mirador(&["lab", "new", "bump", &dir.display().to_string()]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("already there"));
    let output = mirador(&["lab", "new", "no-such-lab", &dir.display().to_string()]);
    assert!(String::from_utf8_lossy(&output.stderr).contains("no lab named `no-such-lab`: the labs are mipmaps, bump"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The routes: texel loads filtered by hand draw what the sampler draws, and the shadow map
/// compared by hand what the comparison sampler finds, so a lab's reference is the technique
/// Mirador shows, not a look-alike.
#[test]
fn what_a_lab_routes_by_hand_draws_what_the_fixed_function_draws() {
    use mirador::lab::images;
    let gpu = common::gpu();
    let sorted = |sort: &str| vec![format!("transparency.sort=\"{sort}\"")];
    for (name, scene, set, bound) in [
        // Measured 0.0011, worst region 0.0048 (lavapipe, 240×136): the sampler's own filtering
        // precision. The route reads each level's size from level 0 (src/lab/isolate.rs); with
        // lavapipe's answer for textureDimensions(t, level) it was 0.0054 and 0.037, black
        // specks and all, which this bound fails.
        ("mipmaps", None, vec![], 0.004),
        ("shadow-map", None, vec!["shadows.filter=\"none\"".to_owned()], 0.01),
        ("planar-mirrors", None, vec!["mirrors.depth=1".to_owned()], 0.01),
        ("transparency", None, vec![], 0.00005),
        // Glass spheres whose near and far walls are drawn in one run of triangles, and in one
        // draw of an object's both faces: the blend by hand must still be applied fragment by
        // fragment. Applied draw by draw it is off by a mean of 0.00009 and 0.0012 (worst region
        // 0.0027 and 0.037); fragment by fragment it is the fixed function's image exactly.
        ("transparency", Some("transparency.toml"), sorted("triangle"), 0.00005),
        ("transparency", Some("transparency.toml"), sorted("unsorted"), 0.00005),
    ] {
        let lab = lab::find(name).unwrap();
        let scene = scene.map_or_else(|| lab.images[0].scene.clone(), str::to_owned);
        let test = lab::ImageTest { scene, set, ..lab.images[0].clone() };
        let scene = images::scene(&test, None).unwrap();
        let by_hand = images::raster(gpu, &scene, &lab::source::reference(&lab)).unwrap();
        let fixed = images::raster(gpu, &scene, &mirador::shaders::Wgsl::builtin()).unwrap();
        let (figures, _) = images::figures(&fixed, &by_hand);
        eprintln!(
            "{name} ({}): by hand against the fixed function: mean {:.5}, worst region {:.5}",
            test.scene, figures.mean, figures.worst_region
        );
        assert!(figures.mean <= bound && figures.worst_region <= 4.0 * bound, "{name}: {figures:?}");
        // No black speck the fixed function does not draw (an out-of-range texel reads 0).
        let black = |p: &image::Rgba<u8>| p[0] == 0 && p[1] == 0 && p[2] == 0;
        let specks = by_hand.pixels().zip(fixed.pixels()).filter(|(h, f)| black(h) && !black(f)).count();
        assert_eq!(specks, 0, "{name}: black pixels the fixed function does not draw");
        // And the route is taken: the stub's image differs.
        let stub = images::raster(gpu, &scene, &lab::source::student(&lab, &lab.stub())).unwrap();
        assert!(
            images::figures(&fixed, &stub).0.mean > 0.02,
            "{name}: the stub draws what Mirador draws: is the route taken?"
        );
    }
}

#[test]
fn diff_reports_the_mean_the_worst_region_and_the_masked_mean() {
    let dir = std::env::temp_dir().join(format!("mirador-lab-diff-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = image::RgbaImage::from_pixel(96, 64, image::Rgba([120, 120, 120, 255]));
    let mut b = a.clone();
    for y in 10..30 {
        for x in 60..90 {
            b.put_pixel(x, y, image::Rgba([250, 30, 30, 255]));
        }
    }
    let mask =
        image::RgbaImage::from_fn(
            96,
            64,
            |x, _| if x >= 48 { image::Rgba([255; 4]) } else { image::Rgba([0, 0, 0, 255]) },
        );
    for (image, name) in [(&a, "a.png"), (&b, "b.png"), (&mask, "mask.png")] {
        image.save(dir.join(name)).unwrap();
    }
    let path = |name: &str| dir.join(name).display().to_string();
    let output = mirador(&["diff", &path("a.png"), &path("b.png"), "--mask", &path("mask.png"), "--json", "-"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let figures: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let mean = figures["flip_mean"].as_f64().unwrap();
    let masked = figures["masked_flip_mean"].as_f64().unwrap();
    let worst = figures["worst_region"]["flip_mean"].as_f64().unwrap();
    // 600 changed pixels of 6144: the masked half holds them all, and the worst region is
    // mostly inside the patch.
    assert!(mean > 0.0 && (masked / mean - 2.0).abs() < 0.05, "mean {mean}, masked {masked}");
    assert!(worst > 5.0 * mean, "worst region {worst}, mean {mean}");
    assert!(figures["worst_region"]["x"].as_u64().unwrap() >= 58);
    let same = mirador(&["diff", &path("a.png"), &path("a.png"), "--json", "-"]);
    let same: serde_json::Value = serde_json::from_slice(&same.stdout).unwrap();
    assert_eq!(same["flip_mean"], 0.0);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The mutants of an answer key that no test can tell from it, each with why: a change at a
/// boundary the inputs never meet exactly, or on a value the inputs keep in range.
const EQUIVALENT_MUTANTS: &[(&str, &str)] = &[
    // The overflow guard's boundary: len is never exactly 3e38.
    ("bump", "if !(len > 0.0) || len >= 3.0e38 {"),
    // n' exactly perpendicular to n: the tilt would have to be infinite.
    ("bump", "return select(perturbed, -perturbed, dot(perturbed, n) <= 0.0);"),
    // The degenerate frame's boundary: a determinant is never exactly 1e-12.
    ("parallax", "if !(abs(det) >= 1e-12) {"),
    // α = 0 exactly gives u = 1, the same column as u = 0 (the map repeats).
    ("environment-maps", "if alpha <= 0.0 {"),
    // m is never negative, and m = 1e-12 exactly is never met.
    ("environment-maps", "if m <= 1e-12 {"),
    // The rim's bottom instead of its top: at −Z every point of the rim is right.
    ("environment-maps", "return vec2f(0.5, 1.0);"),
    // n is normalized: n.y stays in [−1, 1].
    ("environment-maps", "return vec2f(alpha / (2.0 * PI), acos(clamp(n.y, -2.0, 1.0)) / PI);"),
    ("environment-maps", "return vec2f(alpha / (2.0 * PI), acos(clamp(n.y, -1.0, 2.0)) / PI);"),
    // A point exactly in the light's plane (w = 0).
    ("shadow-map", "if clip.w < 0.0 {"),
    // The window is symmetric: centre − (x, y) visits the texels centre + (x, y) does.
    ("shadow-map", "let texel = clamp(centre - vec2i(x, y), vec2i(0), last);"),
    // Unit vectors: cos θ_i never exceeds 1.
    ("refraction", "let cos_i = clamp(dot(n, v), 0.0, 2.0);"),
    ("refraction", "let cos_i = clamp(cos_i_in, 0.0, 2.0);"),
    // Exactly at the critical angle (sin²θ_t = 1): a grazing ray, or none.
    ("refraction", "if sin2_t >= 1.0 {"),
    // Exactly at the critical angle both branches give 1 (r_s = r_p = 1).
    ("refraction", "if sin2_t > 1.0 {"),
];

/// Every one-operator or one-constant change of an answer key's code (comments and signatures
/// aside): `+ − * /` swapped, comparisons loosened or tightened, `min`/`max` and `floor`/`ceil`
/// swapped, the constants 0, ½, 1, 2 changed, a unary minus dropped. Each mutant is the key's
/// text with one change, and the line it changed.
fn mutants(key: &str) -> Vec<(String, String)> {
    const SWAPS: &[(&str, &str)] = &[
        (" + ", " - "),
        (" - ", " + "),
        (" * ", " / "),
        (" / ", " * "),
        (" < ", " <= "),
        (" <= ", " < "),
        (" > ", " >= "),
        (" >= ", " > "),
        ("min(", "max("),
        ("max(", "min("),
        ("floor(", "ceil("),
        ("2.0", "1.0"),
        ("1.0", "2.0"),
        ("0.5", "1.0"),
        ("0.0", "1.0"),
    ];
    let mut out = Vec::new();
    let mut offset = 0;
    for line in key.split_inclusive('\n') {
        let code = line.trim();
        if !(code.is_empty() || code.starts_with("//") || code.starts_with("fn ")) {
            let mut changes: Vec<(usize, usize, &str)> = Vec::new();
            for (from, to) in SWAPS {
                changes.extend(line.match_indices(from).map(|(at, _)| (at, from.len(), *to)));
            }
            let bytes = line.as_bytes();
            for (at, _) in line.match_indices('-') {
                let before = at.checked_sub(1).map(|i| bytes[i]);
                let after = bytes.get(at + 1).copied();
                if matches!(before, Some(b'(' | b',' | b' '))
                    && after.is_some_and(|c| c.is_ascii_alphanumeric() || c == b'(')
                {
                    changes.push((at, 1, ""));
                }
            }
            for (at, len, to) in changes {
                let mut text = key.to_owned();
                text.replace_range(offset + at..offset + at + len, to);
                let changed = text[offset..].lines().next().unwrap_or("").trim().to_owned();
                out.push((text, changed));
            }
        }
        offset += line.len();
    }
    out
}

/// Mutation testing of every lab: each mutant of the answer key must fail `lab check`, unless it
/// is one of the [`EQUIVALENT_MUTANTS`]. About 200 checks: run it when a lab or its tests change.
/// It writes the report of which tests kill which mutant to `MIRADOR_MUTATION_REPORT` (default
/// `target/mutation-report.md`): each mutant's line, and the tests it fails.
/// `MIRADOR_MUTATION_LABS=parallax,bump` sweeps those labs alone (a new lab's tests in minutes).
#[test]
#[ignore = "a sweep of about 15 minutes: cargo test --test labs -- --ignored every_mutant"]
fn every_mutant_of_every_answer_key_fails_its_checks() {
    let mut survivors = Vec::new();
    let mut equivalents_seen = Vec::new();
    let mut count = 0;
    let mut report = String::from("# Mutants of the labs' answer keys, and the tests that kill them\n\n");
    let only = std::env::var("MIRADOR_MUTATION_LABS").ok();
    let swept = |name: &str| only.as_deref().is_none_or(|names| names.split(',').any(|n| n.trim() == name));
    for lab in lab::catalog().into_iter().filter(|lab| swept(&lab.name)) {
        let dir = folder(&lab.name, "mutant", true);
        let file = dir.join(&lab.file);
        let key = std::fs::read_to_string(&file).expect("the answer key");
        let mut kills: std::collections::BTreeMap<String, usize> = Default::default();
        let mut lines = String::new();
        let mutants = mutants(&key);
        for (text, line) in &mutants {
            count += 1;
            std::fs::write(&file, text).expect("writing the mutant");
            let (output, results) = check(&dir, &[]);
            let equivalent = EQUIVALENT_MUTANTS.contains(&(lab.name.as_str(), line.as_str()));
            let killers: Vec<String> = tests_of(&results)
                .iter()
                .filter(|t| t["status"] == "failed")
                .map(|t| t["name"].as_str().unwrap_or("?").to_owned())
                .collect();
            let compiled = results["extra_data"]["compiled"] != false;
            for killer in killers.iter().filter(|_| compiled) {
                *kills.entry(killer.clone()).or_default() += 1;
            }
            let verdict = match (output.status.success(), equivalent, compiled) {
                (true, false, _) => {
                    survivors.push(format!("{}: {line}", lab.name));
                    "**survives**".to_owned()
                }
                (true, true, _) => {
                    equivalents_seen.push((lab.name.clone(), line.clone()));
                    "equivalent (listed)".to_owned()
                }
                (false, _, false) => "does not compile".to_owned(),
                (false, _, true) => format!("killed by {}", killers.join("; ")),
            };
            lines.push_str(&format!("| `{}` | {} |\n", line.replace('|', "\\|"), verdict.replace('|', "\\|")));
        }
        report.push_str(&format!(
            "## {} ({} mutants)\n\n| mutated line | verdict |\n|---|---|\n{lines}\n",
            lab.name,
            mutants.len()
        ));
        report.push_str("| test | mutants it kills |\n|---|---|\n");
        for test in lab.known_answers.iter().map(|t| &t.name).chain(lab.images.iter().map(|t| &t.name)) {
            report.push_str(&format!("| {} | {} |\n", test.replace('|', "\\|"), kills.get(test).copied().unwrap_or(0)));
        }
        report.push('\n');
        let _ = std::fs::remove_dir_all(&dir);
    }
    let path = std::env::var_os("MIRADOR_MUTATION_REPORT")
        .map_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target/mutation-report.md"), PathBuf::from);
    std::fs::write(&path, &report).expect("writing the mutation report");
    eprintln!(
        "{count} mutants, {} survived, {} equivalent; the report: {}",
        survivors.len(),
        equivalents_seen.len(),
        path.display()
    );
    assert!(survivors.is_empty(), "mutants that pass every test:\n{}", survivors.join("\n"));
    // And the list of equivalent ones is not stale: each is still made, and still passes.
    let stale: Vec<String> = EQUIVALENT_MUTANTS
        .iter()
        .filter(|(lab, _)| swept(lab))
        .filter(|(lab, line)| !equivalents_seen.iter().any(|(l, m)| l == lab && m == line))
        .map(|(lab, line)| format!("{lab}: {line}"))
        .collect();
    assert!(stale.is_empty(), "listed as equivalent but no longer made, or now caught:\n{}", stale.join("\n"));
}

/// Inspecting the student's pixels in the transparency lab reads the student's blend: where the
/// three panes overlap, drawn with a mistaken blend (`Im + I`: nothing filtered), the pixel's
/// terms add up to the radiance the student's blend drew, not to what Mirador's would have.
#[test]
fn explain_reads_the_students_blend() {
    use mirador::lab::images;
    let gpu = common::gpu();
    let lab = lab::find("transparency").unwrap();
    let mistake = lab.mistakes.iter().find(|m| m.name == "what is behind not filtered").expect("the mistake");
    let wgsl = lab::source::student(&lab, &lab.mistaken(mistake));
    let scene = images::scene(&lab.images[0], None).unwrap();
    // Each pane glows 0.5 in its colour: unfiltered, the overlap of all three is linear 0.5 grey.
    let image = images::raster(gpu, &scene, &wgsl).unwrap();
    let (x, y, _) = image
        .enumerate_pixels()
        .find(|(_, _, p)| p.0[..3].iter().all(|&c| c.abs_diff(188) <= 1))
        .expect("the three panes' overlap");
    let explanation = mirador::explain::Explainer::with_wgsl(gpu, &scene, &scene.settings, wgsl)
        .expect("an inspecting renderer")
        .explain(gpu, (x, y))
        .expect("the pixel explained");
    let raster = &explanation.raster;
    let sum: glam::Vec3 = raster.terms.iter().map(|t| t.radiance).sum();
    assert!(raster.radiance.min_element() > 0.45, "the student's blend drew {}", raster.radiance);
    assert!((sum - raster.radiance).abs().max_element() <= 2e-3, "terms {sum} against {}", raster.radiance);
}

/// The checks the viewer's lab panel runs, a step at a time as the page must (`Progress`), find
/// what `lab check` finds for the same file: the same tests pass, with the same scores and the
/// same mistakes named, for the answer key, the stub and a mistake. On the standard profile
/// (Vulkan) and on the WebGL2 one (GL), where the page runs without WebGPU: the known answers
/// are one-pixel draws, which WebGL2 can do.
#[test]
fn the_panels_checks_find_what_lab_check_finds() {
    use mirador::gpu::Gpu;
    use mirador::lab::checks::Progress;
    let lab = lab::find("planar-mirrors").expect("a built-in lab");
    let devices = [
        ("standard", Gpu::headless_on(wgpu::Backends::VULKAN).expect("a Vulkan device")),
        ("webgl2", Gpu::headless_webgl2_on(wgpu::Backends::GL).expect("a GL device")),
    ];
    let cases = [("key", lab.solution()), ("stub", lab.stub()), ("mistake", lab.mistaken(&lab.mistakes[0]))];
    for (case, text) in cases {
        let dir = folder(&lab.name, &format!("panel-{case}"), false);
        std::fs::write(dir.join(&lab.file), &text).expect("writing the student's file");
        let (_, cli) = check(&dir, &[]);
        for (profile, gpu) in &devices {
            let mut progress = Progress::start(gpu, &lab, &text);
            let mut polls = 0;
            while !progress.done() {
                if !progress.advance() {
                    gpu.wait();
                }
                polls += 1;
                assert!(polls < 100_000, "{case} on {profile}: the check never ends");
            }
            let report: serde_json::Value =
                serde_json::from_str(&mirador::lab::report::results_json(&progress.report())).expect("JSON");
            let (theirs, mine) = (tests_of(&cli), tests_of(&report));
            assert_eq!(mine.len(), theirs.len());
            for (index, (mine, theirs)) in mine.iter().zip(theirs).enumerate() {
                let what = format!(
                    "{case} on {profile}, {}:\n{}\nlab check: {}",
                    mine["name"], mine["output"], theirs["output"]
                );
                assert_eq!(mine["name"], theirs["name"], "{what}");
                assert_eq!(mine["score"], theirs["score"], "{what}");
                assert_eq!(mine["mistake"], theirs["mistake"], "{what}");
                let pictured = progress.pictures()[index].is_some();
                assert_eq!(pictured, index >= lab.known_answers.len(), "{what}: pictures for image tests only");
            }
            assert_eq!(report["score"], cli["score"], "{case} on {profile}");
            eprintln!("{case} on {profile}: {} / {} points, {polls} polls", report["score"], report["max_score"]);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Mutilated files, as a fuzzer makes them (a character of the code dropped, two swapped, one
/// repeated) from every lab's answer key: each check ends with a clear message and a whole results.json, never a
/// panic. (The libFuzzer target `lab_source`, fuzz/, does the same at scale on the file's checks.)
#[test]
fn a_mutilated_file_gets_a_clear_message_and_a_result_file() {
    for lab in lab::catalog() {
        let key = lab.solution();
        // The code's words and marks, comments aside.
        let code_start = key.find("\nfn ").expect("the key has a function") + 1;
        let tokens: Vec<(usize, usize)> = key[code_start..]
            .match_indices(|c: char| !c.is_whitespace())
            .map(|(at, _)| code_start + at)
            .filter(|&at| key[..at].rfind('\n').is_none_or(|line| !key[line..at].trim_start().starts_with("//")))
            .map(|at| (at, key[at..].chars().next().unwrap().len_utf8()))
            .collect();
        let pick = |k: usize| tokens[(k * 7919) % tokens.len()];
        let (a, b) = (pick(1), pick(2));
        let (first, second) = if a.0 < b.0 { (a, b) } else { (b, a) };
        let mutilated = [
            format!("{}{}", &key[..pick(0).0], &key[pick(0).0 + pick(0).1..]),
            format!(
                "{}{}{}{}{}",
                &key[..first.0],
                &key[second.0..second.0 + second.1],
                &key[first.0 + first.1..second.0],
                &key[first.0..first.0 + first.1],
                &key[second.0 + second.1..]
            ),
            format!("{}{}", &key[..pick(3).0 + pick(3).1], &key[pick(3).0..]),
        ];
        let dir = folder(&lab.name, "mutilated", false);
        for text in mutilated {
            std::fs::write(dir.join(&lab.file), &text).unwrap();
            let _ = std::fs::remove_file(dir.join("results.json"));
            let output = mirador(&["lab", "check", &dir.display().to_string()]);
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(matches!(output.status.code(), Some(0..=2)), "{}: {stderr}\n{text}", lab.name);
            assert!(!stderr.contains("panicked"), "{}: {stderr}", lab.name);
            let json = results(&dir);
            assert!(json["max_score"].as_f64().unwrap() > 0.0);
            let problems = json["extra_data"]["compiled"] == false;
            if problems {
                assert!(json["output"].as_str().unwrap().contains(&format!("{}:", lab.file)), "{json}");
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// A class of four checked (`lab check --lab`): the key, the stub, a known mistake and a file
/// that does not compile; then `lab summary` over it. Returns the class's folder and the page's.
fn class_summary(case: &str) -> (PathBuf, PathBuf, Lab) {
    let class = std::env::temp_dir().join(format!("mirador-lab-class-{case}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&class);
    let lab = lab::find("transparency").unwrap();
    let files = [
        ("ada", lab.solution()),
        ("bob", lab.stub()),
        ("cyd", lab.mistaken(&lab.mistakes[0])),
        ("dee", lab.solution().replace("return im", "retrun im")),
    ];
    for (name, text) in &files {
        let dir = class.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(&lab.file), text).unwrap();
        let output = mirador(&["lab", "check", &dir.display().to_string(), "--lab", "transparency"]);
        assert!(matches!(output.status.code(), Some(0 | 1)), "{}", String::from_utf8_lossy(&output.stderr));
    }
    let out = class.join("summary");
    let output = mirador(&["lab", "summary", &class.display().to_string(), "--out", &out.display().to_string()]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    (class, out, lab)
}

/// A class's results at a glance: the score histogram, each test's pass rate, the mistakes named,
/// the files that did not compile.
#[test]
fn a_class_summary_counts_scores_tests_mistakes_and_broken_files() {
    let (class, out, lab) = class_summary("markdown");
    let markdown = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(markdown.contains("4 submissions, mean score"), "{markdown}");
    let bar = |n: usize| "█".repeat(n);
    assert!(markdown.contains(&format!("| 0–10 % | 3 {} |", bar(40))), "{markdown}");
    assert!(markdown.contains(&format!("| 100 % | 1 {} |", bar(14))), "{markdown}");
    assert!(markdown.contains(&format!("- {}: 1 submission(s)", lab.mistakes[0].name)), "{markdown}");
    assert!(markdown.contains("- `transparency.wgsl:") && markdown.contains("1 submission(s): dee"), "{markdown}");
    let first = &lab.known_answers[0].name;
    assert!(markdown.contains(&format!("| {first} | 25 % |")), "{markdown}");
    let html = std::fs::read_to_string(out.join("summary.html")).unwrap();
    assert!(html.starts_with("<!doctype html>") && html.contains("id=\"histogram\""));
    let _ = std::fs::remove_dir_all(&class);
}

/// The summary page in a real browser: Chromium, headless, loads it from the disk and lays out
/// its tables (the histogram's eleven rows, a row per test), and a screenshot of it is taken
/// (`MIRADOR_SUMMARY_SCREENSHOT=FILE.png` keeps it).
#[test]
#[ignore = "needs Chromium (apt-get install chromium): cargo test --test labs -- --ignored summary_page"]
fn the_summary_page_opens_in_a_browser() {
    let (class, out, lab) = class_summary("browser");
    let page = format!("file://{}", out.join("summary.html").display());
    let profile = class.join("profile");
    let chromium = |extra: &[&str]| {
        Command::new("chromium")
            .args(["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"])
            .arg(format!("--user-data-dir={}", profile.display()))
            .args(extra)
            .arg(&page)
            .output()
            .expect("Chromium runs")
    };
    let dom = String::from_utf8_lossy(&chromium(&["--dump-dom"]).stdout).into_owned();
    assert_eq!(dom.matches("<span class=\"bar\"").count(), 11, "{dom}");
    let tests = lab.known_answers.len() + lab.images.len();
    let rows = dom[dom.find("id=\"tests\"").unwrap()..].split("</table>").next().unwrap().matches("<tr>").count();
    assert_eq!(rows, tests + 1, "a header and a row per test: {dom}");
    let shot = std::env::var_os("MIRADOR_SUMMARY_SCREENSHOT").map_or_else(|| class.join("summary.png"), PathBuf::from);
    let output = chromium(&["--window-size=1000,1400", &format!("--screenshot={}", shot.display())]);
    assert!(shot.is_file(), "{}", String::from_utf8_lossy(&output.stderr));
    let _ = std::fs::remove_dir_all(&class);
}
