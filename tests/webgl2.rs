//! The WebGL2 profile (issue 36): every pass Mirador draws with compiles to what WebGL2 runs.
//!
//! WebGL2 is OpenGL ES 3.0, whose shading language (GLSL ES 3.00) has no cube-map arrays, no
//! `textureGather`, no storage buffers and no compute shaders. wgpu's GL backend in the page
//! writes each entry point as GLSL ES 3.00 with naga's GLSL writer; this test does the same for
//! every pass composed for the WebGL2 profile (`shaders/profile/webgl2.wgsl`), and checks that
//! the standard profile's text would not compile there (its cube arrays), so the test can fail.
//!
//! Entry points a WebGL2 device never draws with are left out by rule, not by name: those that
//! write the inspection's storage buffer (`explain`, which the WebGL2 profile refuses with its
//! reason). The images this profile draws are compared with Vulkan's in `tests/gl_backend.rs`.

use mirador::shaders::{Profile, Wgsl};

/// Built-in functions GLSL ES 3.10 added, which naga's writer emits for ES 3.00 all the same
/// (it checks types and qualifiers against the version, not every function).
const LATER_BUILTINS: &[&str] = &[
    "textureGather",
    "textureGatherOffset",
    "textureQueryLevels",
    "findMSB",
    "findLSB",
    "bitCount",
    "bitfieldExtract",
    "bitfieldInsert",
    "bitfieldReverse",
    "imageLoad",
    "imageStore",
];

/// Each entry point of each pass of `wgsl` composed for `profile`, written as WebGL2's GLSL: the entry
/// points written, and the failures with their reasons.
fn write_as_webgl2(wgsl: &Wgsl, profile: Profile) -> (Vec<String>, Vec<String>) {
    let (mut written, mut failed) = (Vec::new(), Vec::new());
    for (pass, source) in wgsl.for_profile(profile).passes() {
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{pass}: {}", e.emit_to_string(&source)));
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{pass}: {e:?}"));
        for (index, entry) in module.entry_points.iter().enumerate() {
            let uses_storage = module.global_variables.iter().any(|(handle, var)| {
                matches!(var.space, naga::AddressSpace::Storage { .. })
                    && !info.get_entry_point(index)[handle].is_empty()
            });
            if uses_storage {
                continue;
            }
            let name = format!("{pass}::{}", entry.name);
            match glsl_es_300(&module, &info, entry) {
                Ok(glsl) => match LATER_BUILTINS.iter().find(|f| glsl.contains(&format!("{f}("))) {
                    Some(builtin) => failed.push(format!("{name}: {builtin}, which GLSL ES 3.00 lacks")),
                    None => written.push(name),
                },
                Err(e) => failed.push(format!("{name}: {e}")),
            }
        }
    }
    (written, failed)
}

fn glsl_es_300(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    entry: &naga::EntryPoint,
) -> Result<String, String> {
    let constants = naga::back::PipelineConstants::default();
    let (module, info) =
        naga::back::pipeline_constants::process_overrides(module, info, Some((entry.stage, &entry.name)), &constants)
            .map_err(|e| e.to_string())?;
    let options = naga::back::glsl::Options {
        version: naga::back::glsl::Version::Embedded { version: 300, is_webgl: true },
        ..Default::default()
    };
    let pipeline = naga::back::glsl::PipelineOptions {
        shader_stage: entry.stage,
        entry_point: entry.name.clone(),
        multiview: None,
    };
    let mut glsl = String::new();
    let mut writer = naga::back::glsl::Writer::new(
        &mut glsl,
        &module,
        &info,
        &options,
        &pipeline,
        naga::proc::BoundsCheckPolicies::default(),
    )
    .map_err(|e| e.to_string())?;
    writer.write().map_err(|e| e.to_string())?;
    Ok(glsl)
}

#[test]
fn every_pass_is_written_as_webgl2_glsl_on_the_webgl2_profile() {
    let (written, failed) = write_as_webgl2(&Wgsl::builtin(), Profile::WebGl2);
    assert!(failed.is_empty(), "entry points WebGL2 cannot compile:\n{}", failed.join("\n"));
    // Every pass has entry points a WebGL2 device draws with.
    for pass in ["scene", "transparency", "refraction", "volume", "mipmap", "environment", "shadow", "present"] {
        assert!(written.iter().any(|w| w.starts_with(&format!("{pass}::"))), "{pass}: nothing written: {written:?}");
    }
}

#[test]
fn the_standard_profile_is_not_webgl2_glsl() {
    let (_, failed) = write_as_webgl2(&Wgsl::builtin(), Profile::Standard);
    // The cube arrays (every surface pass reads the dynamic cubes), and the shadow filters' gather.
    assert!(failed.iter().any(|f| f.starts_with("scene::")), "{failed:?}");
    assert!(failed.iter().any(|f| f.starts_with("mipmap::")), "{failed:?}");
}

/// Every lab's routes compile for WebGL2, or the lab says why not (`webgl2` in its lab.toml), and
/// only then: the page offers a lab on WebGL2 exactly when it runs there.
#[test]
fn every_lab_runs_on_webgl2_or_says_why_not() {
    for lab in mirador::lab::catalog() {
        let (_, failures) = write_as_webgl2(&mirador::lab::source::reference(&lab), Profile::WebGl2);
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
