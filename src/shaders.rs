//! WGSL composition, in one place: every pass's shader is the shared files of `shaders/common/`
//! followed by the pass's own file. Shared code is never copied between shaders.

/// The shared WGSL, in dependency order.
pub const COMMON: &[(&str, &str)] = &[
    ("common/types.wgsl", include_str!("../shaders/common/types.wgsl")),
    ("common/lighting.wgsl", include_str!("../shaders/common/lighting.wgsl")),
    ("common/optics.wgsl", include_str!("../shaders/common/optics.wgsl")),
    ("common/bump.wgsl", include_str!("../shaders/common/bump.wgsl")),
    ("common/shadow.wgsl", include_str!("../shaders/common/shadow.wgsl")),
    ("common/environment.wgsl", include_str!("../shaders/common/environment.wgsl")),
];

/// The scene pass and the transparent surfaces' entry points: one module, so that every variant
/// computes exactly the same vertex positions (depth peeling tests `Equal` against them). The
/// volumes' ray marching joins them to share the illumination model and the shadow lookups.
/// The view group's declarations (group 2, what a view's shading reads) come first.
pub const SCENE: &str = concat!(
    include_str!("../shaders/view_group.wgsl"),
    "\n// ---- scene.wgsl\n",
    include_str!("../shaders/scene.wgsl"),
    "\n// ---- transparency.wgsl\n",
    include_str!("../shaders/transparency.wgsl"),
    "\n// ---- refraction.wgsl\n",
    include_str!("../shaders/refraction.wgsl"),
    "\n// ---- volume.wgsl\n",
    include_str!("../shaders/volume.wgsl"),
    "\n// ---- inspect.wgsl\n",
    include_str!("../shaders/inspect.wgsl")
);
pub const PRESENT: &str = include_str!("../shaders/present.wgsl");
pub const MIPMAP: &str = include_str!("../shaders/mipmap.wgsl");
pub const DEPTH_COPY: &str = include_str!("../shaders/depth_copy.wgsl");
pub const SHADOW: &str = include_str!("../shaders/shadow.wgsl");
pub const SHADOW_PROJECTED: &str = include_str!("../shaders/shadow_projected.wgsl");
pub const OVERLAYS: &str = include_str!("../shaders/overlays.wgsl");
pub const ENVIRONMENT: &str = include_str!("../shaders/environment.wgsl");
/// The viewer's: its 3D view's image stretched over the view while the camera moves.
pub const UPSCALE: &str = include_str!("../shaders/upscale.wgsl");

/// Every pass's own file, by name, for tests that validate them all.
pub const PASSES: &[(&str, &str)] = &[
    ("scene", SCENE),
    ("present", PRESENT),
    ("mipmap", MIPMAP),
    ("depth_copy", DEPTH_COPY),
    ("shadow", SHADOW),
    ("shadow_projected", SHADOW_PROJECTED),
    ("overlays", OVERLAYS),
    ("environment", ENVIRONMENT),
    ("upscale", UPSCALE),
];

/// The full source of a pass: the common files, then the pass's own.
pub fn compose(pass: &str) -> String {
    let mut source = String::new();
    for (name, text) in COMMON {
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
