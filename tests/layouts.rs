//! Every `#[repr(C)]` GPU struct has the size naga computes for its WGSL twin, so padding is
//! checked here instead of being kept in step by hand in two places.

use mirador::raster::uniforms::{GpuFrame, GpuLight, GpuMaterial, GpuObject, GpuPresent};
use mirador::shaders;

/// The byte size of each named struct in a WGSL source, as naga lays it out.
fn struct_sizes(source: &str) -> Vec<(String, u32)> {
    let module = naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    module
        .types
        .iter()
        .filter_map(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { span, .. } => Some((ty.name.clone()?, *span)),
            _ => None,
        })
        .collect()
}

fn wgsl_size(sizes: &[(String, u32)], name: &str) -> usize {
    sizes.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no struct {name} in the WGSL")).1 as usize
}

#[test]
fn gpu_structs_match_their_wgsl_twins() {
    let scene = struct_sizes(&shaders::compose(shaders::OPAQUE));
    let checks = [
        ("Light", std::mem::size_of::<GpuLight>()),
        ("Frame", std::mem::size_of::<GpuFrame>()),
        ("Material", std::mem::size_of::<GpuMaterial>()),
        ("Object", std::mem::size_of::<GpuObject>()),
    ];
    for (name, rust) in checks {
        assert_eq!(wgsl_size(&scene, name), rust, "WGSL {name} vs its Rust twin");
    }
    let present = struct_sizes(&shaders::compose(shaders::PRESENT));
    assert_eq!(wgsl_size(&present, "Present"), std::mem::size_of::<GpuPresent>());
}

#[test]
fn every_pass_shader_validates() {
    for (name, pass) in [("opaque", shaders::OPAQUE), ("present", shaders::PRESENT)] {
        let source = shaders::compose(pass);
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}
