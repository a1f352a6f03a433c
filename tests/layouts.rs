//! Twins that cannot drift: every `#[repr(C)]` GPU struct has the size and the field offsets naga
//! computes for its WGSL twin, every code shared by Rust and WGSL (light kinds, terms, filter
//! modes, shadow methods, view modes, height sources, array limits) is written once, in Rust, and
//! composed into the WGSL (no WGSL file declares its own), and every pipeline constant the scene
//! pass sets is an `override` of its shader. So padding and codes are checked here instead of
//! being kept in step by hand in two places.

mod common;

use std::mem::{offset_of, size_of};

use mirador::raster::keys::{FrameKey, MaterialKey, shadow_filter_code};
use mirador::raster::shadow::views::MAX_LAYERS;
use mirador::raster::shadow::{GpuShadowLayer, GpuShadows};
use mirador::raster::uniforms::{
    self, GpuEnvironment, GpuFrame, GpuInstance, GpuLight, GpuMaterial, GpuPresent, GpuView,
};
use mirador::shaders;

fn parse(source: &str) -> naga::Module {
    naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)))
}

/// A struct's name, size, and its members' (name, offset).
type StructLayout = (String, u32, Vec<(String, u32)>);

/// Each named struct's layout, as naga computes it.
fn structs(module: &naga::Module) -> Vec<StructLayout> {
    module
        .types
        .iter()
        .filter_map(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { span, members } => Some((
                ty.name.clone()?,
                *span,
                members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(),
            )),
            _ => None,
        })
        .collect()
}

/// Every surface pass's module, parsed.
fn surface_modules() -> Vec<naga::Module> {
    SURFACE_PASSES.iter().map(|(_, pass)| parse(&shaders::compose_surface(pass))).collect()
}

/// The value of a named `const` of scalar type, in the first of `modules` that has it.
fn constant(modules: &[naga::Module], name: &str) -> f64 {
    let (module, c) = modules
        .iter()
        .find_map(|m| m.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).map(|(_, c)| (m, c)))
        .unwrap_or_else(|| panic!("no const {name} in the WGSL"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => f64::from(v),
        naga::Expression::Literal(naga::Literal::I32(v)) => f64::from(v),
        naga::Expression::Literal(naga::Literal::F32(v)) => f64::from(v),
        ref other => panic!("const {name} is not a scalar literal: {other:?}"),
    }
}

/// Compares a WGSL struct with its Rust twin: the size, and the offset of every field that is not
/// padding (the Rust twin's fields are listed with their offsets by `fields!`).
fn check_struct(all: &[StructLayout], name: &str, size: usize, rust: &[(&str, usize)]) {
    let (_, span, members) =
        all.iter().find(|(n, _, _)| n == name).unwrap_or_else(|| panic!("no struct {name} in the WGSL"));
    assert_eq!(*span as usize, size, "size of WGSL {name} vs its Rust twin");
    let wgsl: Vec<(&str, usize)> =
        members.iter().filter(|(m, _)| !m.starts_with("_pad")).map(|(m, o)| (m.as_str(), *o as usize)).collect();
    let rust: Vec<(&str, usize)> = rust.iter().copied().filter(|(m, _)| !m.starts_with("_pad")).collect();
    assert_eq!(wgsl, rust, "fields and offsets of WGSL {name} vs its Rust twin");
}

/// `(field name, offset)` for each listed field of a Rust struct.
macro_rules! fields {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        [$((stringify!($field), offset_of!($ty, $field))),*]
    };
}

#[test]
fn gpu_structs_match_their_wgsl_twins_field_by_field() {
    let scene = structs(&parse(&shaders::compose_surface(shaders::SCENE)));
    check_struct(
        &scene,
        "Light",
        size_of::<GpuLight>(),
        &fields!(GpuLight {
            position,
            kind,
            direction,
            attenuation,
            radiance,
            cos_inner,
            cos_outer,
            shadow_layer,
            shadow_slot
        }),
    );
    check_struct(
        &scene,
        "Frame",
        size_of::<GpuFrame>(),
        &fields!(GpuFrame { ambient, light_count, terms, lod_bias, bump_scale, bump_delta_texels, traced, lights }),
    );
    check_struct(
        &scene,
        "View",
        size_of::<GpuView>(),
        &fields!(GpuView {
            clip_from_world,
            world_from_clip,
            eye,
            orthographic,
            view_axis,
            mirrored,
            clip_plane,
            clip_from_reflected
        }),
    );
    check_struct(
        &scene,
        "Material",
        size_of::<GpuMaterial>(),
        &fields!(GpuMaterial {
            color,
            ka,
            kd,
            ks,
            shininess,
            transparent,
            specular_color,
            bump_scale,
            emission,
            normal_scale,
            transmission,
            height_amplitude,
            height_frequency,
            noise_seed,
            noise_cells,
            noise_octaves,
            alpha,
            alpha_cutoff,
            alpha_mode,
            reflectance,
            index,
            ior,
        }),
    );
    check_struct(
        &scene,
        "ShadowLayer",
        size_of::<GpuShadowLayer>(),
        &fields!(GpuShadowLayer { clip_from_world, texel_size, perspective }),
    );
    check_struct(
        &scene,
        "Environment",
        size_of::<GpuEnvironment>(),
        &fields!(GpuEnvironment {
            sphere_from_world,
            world_from_map,
            zenith,
            source,
            horizon,
            intensity,
            ground,
            sun_cos_outer,
            sun_direction,
            sun_cos_inner,
            sun_color,
            background,
            proxy_min,
            parallax,
            proxy_max,
            cube_centres,
        }),
    );
    check_struct(&scene, "Shadows", size_of::<GpuShadows>(), &fields!(GpuShadows { layers, map_size, normal_offset }));
    let present = structs(&parse(&shaders::compose(shaders::PRESENT)));
    check_struct(&present, "Present", size_of::<GpuPresent>(), &fields!(GpuPresent { exposure, tone_map, scale }));
}

#[test]
fn instance_attributes_match_the_wgsl_locations() {
    let module = parse(&shaders::compose_surface(shaders::SCENE));
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("Instance"))
        .expect("an Instance struct in the WGSL");
    let naga::TypeInner::Struct { members, .. } = &ty.inner else { panic!("Instance is a struct") };
    let wgsl: Vec<u32> = members
        .iter()
        .map(|m| match m.binding {
            Some(naga::Binding::Location { location, .. }) => location,
            ref other => panic!("Instance member without a location: {other:?}"),
        })
        .collect();
    let rust: Vec<u32> = GpuInstance::ATTRIBUTES.iter().map(|a| a.shader_location).collect();
    assert_eq!(wgsl, rust);
    let offsets: Vec<u64> = GpuInstance::ATTRIBUTES.iter().map(|a| a.offset).collect();
    assert_eq!(
        offsets,
        [0, 16, 32, 48, 64, 76, 88, 100, 104],
        "the matrix columns, the normal matrix's, the environment layer, then the object"
    );
    use mirador::raster::volume::GpuVolume;
    let volume = structs(&parse(&shaders::compose_surface(shaders::VOLUME)));
    check_struct(
        &volume,
        "Volume",
        size_of::<GpuVolume>(),
        &fields!(GpuVolume {
            world_from_local,
            local_from_world,
            normal_from_local,
            half_extent,
            voxel_length,
            spacing,
            step,
            dims,
            iso,
            termination,
            opacity_correction,
            view,
            samples_white
        }),
    );
    assert_eq!(size_of::<GpuInstance>(), 108);
}

/// Every constant the WGSL shares with the Rust is written once, in Rust
/// (`src/shaders/constants.rs`, and the approximations table's bits and layers), and composed
/// ahead of every module: no WGSL file declares one of those names itself, so no second spelling
/// can drift; every composed module parses with them (`every_pass_shader_validates`).
#[test]
fn shared_constants_are_written_once_in_rust() {
    let prelude = shaders::constants::prelude();
    let names: Vec<&str> = prelude
        .lines()
        .filter_map(|line| line.strip_prefix("const "))
        .map(|rest| rest.split([':', ' ']).next().unwrap())
        .collect();
    assert!(names.len() >= 75, "{} constants in the prelude", names.len());
    let files: Vec<(String, String)> =
        common::sources(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders")), "wgsl")
            .into_iter()
            .map(|path| (path.display().to_string(), std::fs::read_to_string(&path).expect("a WGSL file")))
            .collect();
    let declares = |text: &str, name: &str| text.lines().any(|l| l.trim_start().starts_with(&format!("const {name}:")));
    for (path, text) in &files {
        for name in &names {
            assert!(!declares(text, name), "{path} declares {name}, which src/shaders/constants.rs writes");
        }
    }
    // The check can fail: a file with its own copy is found.
    assert!(declares("fn f() {}\nconst MAX_LIGHTS: u32 = 16u;\n", "MAX_LIGHTS"));
    // Each value is the Rust's: the prelude of a few, as naga reads them.
    let module = surface_modules();
    assert_eq!(constant(&module, "MAX_LIGHTS"), uniforms::MAX_LIGHTS as f64);
    assert_eq!(constant(&module, "MAX_SHADOW_LAYERS"), MAX_LAYERS as f64);
    assert_eq!(constant(&module, "ENV_LAYER_NONE"), f64::from(uniforms::ENV_LAYER_NONE));
    for filter in [mirador::settings::ShadowFilter::None, mirador::settings::ShadowFilter::Poisson] {
        let code = f64::from(shadow_filter_code(filter));
        assert!(prelude.contains(&format!(
            "const SHADOW_FILTER_{}: u32 = {code}u;",
            if code == 0.0 { "NONE" } else { "POISSON" }
        )));
    }
    for term in mirador::settings::Traced::ALL {
        let name = term.row().name.to_uppercase();
        assert_eq!(constant(&module, &format!("TRACED_{name}")), f64::from(term.bit()));
        assert_eq!(constant(&module, &format!("TRACED_{name}_LAYER")), f64::from(term.layer()));
    }
    let present = parse(&shaders::compose(shaders::PRESENT));
    let code = mirador::raster::present::tone_map_code(mirador::settings::ToneMap::Aces);
    assert_eq!(constant(std::slice::from_ref(&present), "TONE_MAP_ACES"), f64::from(code));
}

/// The surface passes' own files, by name.
const SURFACE_PASSES: [(&str, &str); 4] = [
    ("scene", shaders::SCENE),
    ("transparency", shaders::TRANSPARENCY),
    ("refraction", shaders::REFRACTION),
    ("volume", shaders::VOLUME),
];

#[test]
fn every_pipeline_constant_is_an_override_of_its_pass_module() {
    let shared = [FrameKey::NAMES, MaterialKey::NAMES].concat();
    for (name, pass) in SURFACE_PASSES {
        let module = parse(&shaders::compose_surface(pass));
        let overrides: Vec<String> = module.overrides.iter().filter_map(|(_, o)| o.name.clone()).collect();
        let own: &[&str] = match name {
            "volume" => mirador::raster::volume::VolumeKey::NAMES,
            "refraction" => mirador::raster::refraction::RefractionKey::NAMES,
            _ => &[],
        };
        let names: Vec<&str> = shared.iter().chain(own).copied().collect();
        for key in &names {
            assert!(overrides.iter().any(|o| o == key), "{key} is set by a pipeline key but is no override of {name}");
        }
        assert_eq!(overrides.len(), names.len(), "{name} has overrides no key sets: {overrides:?}");
    }
}

#[test]
fn every_pass_shader_validates() {
    for (name, source) in shaders::passes() {
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}

/// The sampled textures each entry point of each pass reads (the shaders' global uses, through
/// every call), against the downlevel limit of 16 a stage that WebGL2 and small GPUs give
/// (`wgpu::Limits::downlevel_webgl2_defaults`). The fullest entry point and its count, for
/// docs/architecture.md's count of the view group's free bindings.
fn sampled_textures_per_entry_point() -> Vec<(String, usize)> {
    shaders::passes().iter().flat_map(|(name, source)| sampled_textures(name, source)).collect()
}

/// The sampled textures each entry point of the module `source` reads.
fn sampled_textures(name: &str, source: &str) -> Vec<(String, usize)> {
    let mut counts = Vec::new();
    {
        let module = parse(source);
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        for (index, entry) in module.entry_points.iter().enumerate() {
            let uses = info.get_entry_point(index);
            let textures = module
                .global_variables
                .iter()
                .filter(|(handle, var)| {
                    matches!(module.types[var.ty].inner, naga::TypeInner::Image { .. }) && !uses[*handle].is_empty()
                })
                .count();
            counts.push((format!("{name}::{}", entry.name), textures));
        }
    }
    counts
}

#[test]
fn no_entry_point_reads_more_sampled_textures_than_the_downlevel_limit() {
    let limit = wgpu::Limits::downlevel_webgl2_defaults().max_sampled_textures_per_shader_stage as usize;
    assert_eq!(limit, 16);
    let counts = sampled_textures_per_entry_point();
    let (fullest, most) = counts.iter().max_by_key(|(_, n)| *n).expect("entry points").clone();
    eprintln!("the fullest entry point: {fullest}, {most} sampled textures of {limit}");
    for (entry, count) in &counts {
        assert!(*count <= limit, "{entry} reads {count} sampled textures, over the downlevel limit of {limit}");
    }
    // The counter can tell: seventeen textures read by one entry point, one more declared unread.
    let declared: String = (0..18).map(|i| format!("@group(0) @binding({i}) var t{i}: texture_2d<f32>;\n")).collect();
    let reads: String = (0..17).map(|i| format!(" + textureLoad(t{i}, vec2i(0), 0)")).collect();
    let made_up = format!("{declared}@fragment fn fs() -> @location(0) vec4f {{ return vec4f(0.0){reads}; }}\n");
    assert_eq!(sampled_textures("made-up", &made_up), [("made-up::fs".to_owned(), 17)]);
    // The count is of what is read: the scene pass's shading reads the shadow maps, the
    // environment's and the view's images, and the material's.
    let shading = counts.iter().find(|(entry, _)| entry == "scene::fs_scene").map(|(_, n)| *n);
    assert!(shading.is_some_and(|n| n >= 10), "scene::fs_scene: {shading:?} of {counts:?}");
}

#[test]
fn each_surface_pass_numbers_its_own_bindings_from_zero_in_its_own_file() {
    for (_, shared) in shaders::SURFACE {
        assert!(!shared.contains("@group(3)"), "the surface code declares no pass's private binding");
    }
    for (name, pass) in SURFACE_PASSES {
        let module = parse(&shaders::compose_surface(pass));
        let mut bindings: Vec<u32> = module
            .global_variables
            .iter()
            .filter_map(|(_, var)| var.binding.as_ref().filter(|b| b.group == 3).map(|b| b.binding))
            .collect();
        bindings.sort_unstable();
        let expected: Vec<u32> = (0..bindings.len() as u32).collect();
        assert_eq!(bindings, expected, "{name}'s group 3, numbered from 0 without gaps");
    }
}

/// What a WGSL resource variable must be to take a binding of type `ty`, and `None` if it is.
fn binding_mismatch(module: &naga::Module, var: &naga::GlobalVariable, ty: &wgpu::BindingType) -> Option<String> {
    use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, TypeInner};
    let inner = &module.types[var.ty].inner;
    let fits = match (ty, inner) {
        (wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, .. }, _) => {
            var.space == AddressSpace::Uniform
        }
        (wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, .. }, _) => {
            matches!(var.space, AddressSpace::Storage { access } if access.contains(naga::StorageAccess::STORE) != *read_only)
        }
        (wgpu::BindingType::Sampler(kind), TypeInner::Sampler { comparison }) => {
            *comparison == (*kind == wgpu::SamplerBindingType::Comparison)
        }
        (wgpu::BindingType::Texture { sample_type, view_dimension, .. }, TypeInner::Image { dim, arrayed, class }) => {
            use wgpu::TextureViewDimension as D;
            let dimension = match view_dimension {
                D::D1 => (ImageDimension::D1, false),
                D::D2 => (ImageDimension::D2, false),
                D::D2Array => (ImageDimension::D2, true),
                D::Cube => (ImageDimension::Cube, false),
                D::CubeArray => (ImageDimension::Cube, true),
                D::D3 => (ImageDimension::D3, false),
            };
            let class_fits = matches!(
                (sample_type, class),
                (wgpu::TextureSampleType::Depth, ImageClass::Depth { .. })
                    | (wgpu::TextureSampleType::Float { .. }, ImageClass::Sampled { kind: ScalarKind::Float, .. })
            );
            dimension == (*dim, *arrayed) && class_fits
        }
        _ => false,
    };
    (!fits).then(|| format!("{inner:?} in {:?}, the table says {ty:?}", var.space))
}

/// Every difference between the view group's table and the group-2 variables of `source`, a
/// whole module's source.
fn view_group_differences(source: &str) -> Vec<String> {
    use mirador::raster::view_group::VIEW_GROUP;
    let module = parse(source);
    let mut differences = Vec::new();
    let mut declared = Vec::new();
    for (_, var) in module.global_variables.iter() {
        let Some(binding) = var.binding.as_ref().filter(|b| b.group == 2) else { continue };
        let name = var.name.clone().unwrap_or_default();
        declared.push(binding.binding);
        match VIEW_GROUP.iter().find(|b| b.binding == binding.binding) {
            None => differences.push(format!("WGSL {name} (binding {}) is not in VIEW_GROUP", binding.binding)),
            Some(row) if row.name != name => {
                differences.push(format!("binding {}: WGSL names it {name}, VIEW_GROUP {}", row.binding, row.name))
            }
            Some(row) => {
                if let Some(mismatch) = binding_mismatch(&module, var, &row.ty) {
                    differences.push(format!("{name}: {mismatch}"));
                }
            }
        }
    }
    for row in VIEW_GROUP.iter().filter(|row| !declared.contains(&row.binding)) {
        differences.push(format!("VIEW_GROUP's {} (binding {}) is not declared in the WGSL", row.name, row.binding));
    }
    differences
}

#[test]
fn the_view_group_table_is_the_wgsl_binding_by_binding() {
    for (name, pass) in SURFACE_PASSES {
        let differences = view_group_differences(&shaders::compose_surface(pass));
        assert!(differences.is_empty(), "{name}: the view group's table against its WGSL:\n{}", differences.join("\n"));
    }
    let scene = shaders::compose_surface(shaders::SCENE);
    // The check can fail: a view image renamed, retyped, or left out of the table.
    let renamed = scene
        .replace("var drawn_images:", "var shadow_mask:")
        .replace("textureLoad(drawn_images", "textureLoad(shadow_mask");
    let found = view_group_differences(&renamed);
    assert!(found.iter().any(|d| d.contains("WGSL names it shadow_mask")), "{found:?}");
    let retyped = parse("@group(2) @binding(4) var drawn_images: texture_2d<f32>;");
    let (_, var) = retyped.global_variables.iter().next().unwrap();
    let row = |binding: u32| mirador::raster::view_group::VIEW_GROUP.iter().find(|row| row.binding == binding).unwrap();
    assert!(binding_mismatch(&retyped, var, &row(4).ty).is_some(), "a 2D image where the table has a 2D array");
    assert!(binding_mismatch(&retyped, var, &row(9).ty).is_none(), "the sphere map's row is a 2D image");
    let extra = format!("{scene}\n@group(2) @binding(20) var stray: texture_2d<f32>;");
    assert!(view_group_differences(&extra).iter().any(|d| d.contains("stray")));
    // Every view array has its row, and so every view image its binding.
    for array in mirador::raster::targets::ViewArray::ALL {
        let resource = mirador::raster::view_group::Resource::View(array);
        assert!(mirador::raster::view_group::VIEW_GROUP.iter().any(|row| row.resource == resource), "{array:?}");
    }
}

/// Every kind of inspection record the WGSL writes (`INSPECT_*` of shaders/common/inspect.wgsl)
/// is declared by exactly one pass (its `RECORDS`), with a name of its own: the explainer knows
/// the kinds only through those declarations.
#[test]
fn every_inspection_record_kind_is_declared_once_by_its_pass() {
    let modules = surface_modules();
    let mut wgsl: Vec<(String, u32)> = modules[0]
        .constants
        .iter()
        .filter_map(|(_, c)| c.name.clone())
        .filter(|name| name.starts_with("INSPECT_"))
        .map(|name| {
            let code = constant(&modules, &name) as u32;
            (name, code)
        })
        .collect();
    wgsl.sort_by_key(|(_, code)| *code);
    let kinds: Vec<_> = mirador::raster::frame::record_kinds().collect();
    for (name, code) in &wgsl {
        let declared = kinds.iter().filter(|k| k.code == *code).count();
        assert_eq!(declared, 1, "{name} = {code} is declared by {declared} passes");
    }
    assert_eq!(kinds.len(), wgsl.len(), "a pass declares a kind the WGSL does not write");
    let mut names: Vec<&str> = kinds.iter().map(|k| k.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), kinds.len(), "each kind has a name of its own");
}
