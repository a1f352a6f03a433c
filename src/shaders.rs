//! WGSL composition, in one place: every pass's shader is the shared files of `shaders/common/`
//! followed by the pass's own file; the passes that draw the scene's surfaces get the surface
//! code ([`SURFACE`]) between the two. Shared code is never copied between shaders.

/// The shared WGSL, in dependency order.
pub const COMMON: &[(&str, &str)] = &[
    ("common/types.wgsl", include_str!("../shaders/common/types.wgsl")),
    ("common/lighting.wgsl", include_str!("../shaders/common/lighting.wgsl")),
    ("common/optics.wgsl", include_str!("../shaders/common/optics.wgsl")),
    ("common/bump.wgsl", include_str!("../shaders/common/bump.wgsl")),
    ("common/shadow.wgsl", include_str!("../shaders/common/shadow.wgsl")),
    ("common/environment.wgsl", include_str!("../shaders/common/environment.wgsl")),
];

/// The surface code every pass that draws the scene's surfaces shares, in its modules only, after
/// [`COMMON`]: the view group (group 2), the inspection's record, and the vertex stage and the
/// illumination model at a fragment with groups 0 and 1 (`shaders/common/surface.wgsl`).
pub const SURFACE: &[(&str, &str)] = &[
    ("common/view_group.wgsl", include_str!("../shaders/common/view_group.wgsl")),
    ("common/inspect.wgsl", include_str!("../shaders/common/inspect.wgsl")),
    ("common/surface.wgsl", include_str!("../shaders/common/surface.wgsl")),
];

/// The surface passes' own files: each composed after [`SURFACE`] into a module of its own, with
/// its private bindings (group 3) numbered from 0. The vertex stage is `@invariant`, so depth
/// written by one module is met exactly by another's `Equal` test (prepass and shading, depth
/// peeling).
pub const SCENE: &str = include_str!("../shaders/scene.wgsl");
pub const TRANSPARENCY: &str = include_str!("../shaders/transparency.wgsl");
pub const REFRACTION: &str = include_str!("../shaders/refraction.wgsl");
pub const VOLUME: &str = include_str!("../shaders/volume.wgsl");
pub const PRESENT: &str = include_str!("../shaders/present.wgsl");
pub const MIPMAP: &str = include_str!("../shaders/mipmap.wgsl");
pub const DEPTH_COPY: &str = include_str!("../shaders/depth_copy.wgsl");
pub const SHADOW: &str = include_str!("../shaders/shadow.wgsl");
pub const SHADOW_PROJECTED: &str = include_str!("../shaders/shadow_projected.wgsl");
pub const OVERLAYS: &str = include_str!("../shaders/overlays.wgsl");
pub const ENVIRONMENT: &str = include_str!("../shaders/environment.wgsl");
/// The viewer's: its 3D view's image stretched over the view while the camera moves.
pub const UPSCALE: &str = include_str!("../shaders/upscale.wgsl");

/// Every pass's whole source, by name, for tests that validate them all.
pub fn passes() -> Vec<(&'static str, String)> {
    let surface = [("scene", SCENE), ("transparency", TRANSPARENCY), ("refraction", REFRACTION), ("volume", VOLUME)];
    let others = [
        ("present", PRESENT),
        ("mipmap", MIPMAP),
        ("depth_copy", DEPTH_COPY),
        ("shadow", SHADOW),
        ("shadow_projected", SHADOW_PROJECTED),
        ("overlays", OVERLAYS),
        ("environment", ENVIRONMENT),
        ("upscale", UPSCALE),
    ];
    let surface = surface.into_iter().map(|(name, pass)| (name, compose_surface(pass)));
    surface.chain(others.into_iter().map(|(name, pass)| (name, compose(pass)))).collect()
}

/// The full source of a pass: the common files, then the pass's own.
pub fn compose(pass: &str) -> String {
    compose_after(COMMON.iter(), pass)
}

/// The full source of a surface pass: the common files, the surface code, then the pass's own.
pub fn compose_surface(pass: &str) -> String {
    compose_after(COMMON.iter().chain(SURFACE), pass)
}

fn compose_after<'a>(shared: impl Iterator<Item = &'a (&'a str, &'a str)>, pass: &str) -> String {
    let mut source = String::new();
    for (name, text) in shared {
        source.push_str("// ---- ");
        source.push_str(name);
        source.push('\n');
        source.push_str(text);
        source.push('\n');
    }
    source.push_str(pass);
    source
}

pub fn module(device: &wgpu::Device, label: &str, pass: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(compose(pass).into()),
    })
}

/// A surface pass's module ([`compose_surface`]).
pub fn surface_module(device: &wgpu::Device, label: &str, pass: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(compose_surface(pass).into()),
    })
}
