//! The WebGL2 profile (issue 36): every pass Mirador draws with compiles to what WebGL2 runs.
//!
//! WebGL2 is OpenGL ES 3.0, whose shading language (GLSL ES 3.00) has no cube-map arrays, no
//! `textureGather`, no `textureNumLevels`, no storage buffers and no compute shaders. wgpu's GL
//! backend in the page writes each entry point as GLSL ES 3.00 with naga's GLSL writer;
//! `mirador::lab::source::webgl2_written` does the same for every pass composed for a profile,
//! and these tests run it on the WebGL2 profile (`shaders/profile/webgl2.wgsl`), on the standard
//! profile (whose cube arrays must fail, so the check can), and on every lab. The page's lab
//! uses the same function to check a student's file on a WebGL2 device.
//!
//! Entry points a WebGL2 device never draws with are left out by rule, not by name: those that
//! write the inspection's storage buffer (`explain`, which the WebGL2 profile refuses with its
//! reason). The images this profile draws are compared with Vulkan's in `tests/gl_backend.rs`.

use mirador::lab::source::{webgl2_failures, webgl2_written};
use mirador::shaders::{Profile, Wgsl};

#[test]
fn every_pass_is_written_as_webgl2_glsl_on_the_webgl2_profile() {
    let (written, failed) = webgl2_written(&Wgsl::builtin(), Profile::WebGl2);
    assert!(failed.is_empty(), "entry points WebGL2 cannot compile:\n{}", failed.join("\n"));
    // Every pass has entry points a WebGL2 device draws with.
    for pass in ["scene", "transparency", "refraction", "volume", "mipmap", "environment", "shadow", "present", "lab"] {
        assert!(written.iter().any(|w| w.starts_with(&format!("{pass}::"))), "{pass}: nothing written: {written:?}");
    }
}

#[test]
fn the_standard_profile_is_not_webgl2_glsl() {
    let (_, failed) = webgl2_written(&Wgsl::builtin(), Profile::Standard);
    // The cube arrays (every surface pass reads the dynamic cubes, the mip chain copies them, and
    // the shared code the known-answer harness composes declares them).
    for pass in ["scene", "mipmap", "lab"] {
        assert!(failed.iter().any(|f| f.starts_with(pass) && f.contains("CubeArray")), "{pass}: {failed:?}");
    }
}

/// Every lab's routes compile for WebGL2, or the lab says why not (`webgl2` in its lab.toml), and
/// only then: the page offers a lab on WebGL2 exactly when it runs there.
#[test]
fn every_lab_runs_on_webgl2_or_says_why_not() {
    for lab in mirador::lab::catalog() {
        let failures = webgl2_failures(&mirador::lab::source::reference(&lab));
        eprintln!("{}: {} entry points WebGL2 cannot compile {:?}", lab.name, failures.len(), failures.first());
        match &lab.webgl2 {
            Some(reason) => {
                assert!(!failures.is_empty(), "{} says it cannot run on WebGL2 ({reason}), yet compiles", lab.name)
            }
            None => {
                assert!(failures.is_empty(), "{} cannot run on WebGL2 and does not say why: {failures:?}", lab.name)
            }
        }
    }
}

/// A student's file that WGSL accepts but WebGL2 cannot compile is a problem on a WebGL2 device
/// (the page without WebGPU), placed in the function that causes it, and none on the standard one.
#[test]
fn a_student_function_webgl2_lacks_is_a_problem_there() {
    let lab = mirador::lab::find("mipmaps").expect("a built-in lab");
    let solution = lab.solution();
    let lacking = solution.replacen("let last = ", "let last = f32(textureNumLevels(t) - 1u) + 0.0 * ", 1);
    assert_ne!(lacking, solution, "the solution clamps to its last level");
    assert!(mirador::lab::source::problems_on(&lab, &solution, Profile::WebGl2).is_empty());
    assert!(mirador::lab::source::problems_on(&lab, &lacking, Profile::Standard).is_empty());
    let problems = mirador::lab::source::problems_on(&lab, &lacking, Profile::WebGl2);
    let problem = problems.first().expect("WebGL2 has no textureNumLevels").display(&lab.file);
    eprintln!("{problem}");
    assert!(problem.contains("WebGL2") && problem.contains("trilinear_sample"), "{problem}");
}
