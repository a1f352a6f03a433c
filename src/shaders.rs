//! WGSL composition, in one place: every pass's shader is the device's profile
//! (`shaders/profile/`, [`Profile`]) and the shared files of `shaders/common/`, followed by the
//! pass's own file; the passes that draw the scene's surfaces get the surface code ([`SURFACE`])
//! between the two. Shared code is never copied between shaders. Ahead of them all comes the
//! constants' prelude ([`constants::prelude`]): every constant the WGSL shares with the Rust code,
//! written from the Rust.

pub mod constants;

/// What the device's shaders may use. Mirador's WGSL calls a few functions for what a small
/// device lacks, and each profile's file defines them (`shaders/profile/`): the same passes,
/// the same bindings, compiled for either.
///
/// A device's profile is fixed when it is made (`gpu::Gpu::with_adapter`): `WebGl2` where the
/// adapter has no cube-map arrays (WebGL2, OpenGL ES 3.0), or where `MIRADOR_LIMITS=webgl2`
/// asks for it (to try those paths natively, on wgpu's GL backend). Such a device is made with
/// wgpu's WebGL2 limits, which allow no storage buffers, and that is how [`Profile::of`] reads
/// it back from the device alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Profile {
    /// WebGPU, Vulkan, desktop GL and OpenGL ES 3.2: cube-map arrays and `textureGather`.
    #[default]
    Standard,
    /// WebGL2 and OpenGL ES 3.0: no cube-map arrays (each cube is six layers of a 2D array), no
    /// `textureGather`, no storage buffers (so no `explain` and no lab checks), no compute.
    WebGl2,
}

impl Profile {
    /// The profile `device` was made for: [`Profile::WebGl2`] when it has no storage buffers.
    pub fn of(device: &wgpu::Device) -> Profile {
        if device.limits().max_storage_buffers_per_shader_stage == 0 { Profile::WebGl2 } else { Profile::Standard }
    }

    /// The file that defines the profile's functions.
    pub fn wgsl(self) -> (&'static str, &'static str) {
        match self {
            Profile::Standard => ("profile/standard.wgsl", include_str!("../shaders/profile/standard.wgsl")),
            Profile::WebGl2 => ("profile/webgl2.wgsl", include_str!("../shaders/profile/webgl2.wgsl")),
        }
    }

    /// The view dimension a binding declared as `dimension` has on this profile: a cube array is
    /// a 2D array on WebGL2 (the WGSL's `CubeArray`).
    pub fn view_dimension(self, dimension: wgpu::TextureViewDimension) -> wgpu::TextureViewDimension {
        match (self, dimension) {
            (Profile::WebGl2, wgpu::TextureViewDimension::CubeArray) => wgpu::TextureViewDimension::D2Array,
            (_, dimension) => dimension,
        }
    }
}

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
/// Displacement tessellated adaptively, in compute shaders (src/raster/tessellation).
pub const TESSELLATION: &str = include_str!("../shaders/tessellation.wgsl");

/// Every pass's whole source, by name, for tests that validate them all.
pub fn passes() -> Vec<(&'static str, String)> {
    Wgsl::builtin().passes()
}

/// The full source of a pass: the common files, then the pass's own.
pub fn compose(pass: &str) -> String {
    Wgsl::builtin().compose(pass)
}

/// The full source of a surface pass: the common files, the surface code, then the pass's own.
pub fn compose_surface(pass: &str) -> String {
    Wgsl::builtin().compose_surface(pass)
}

pub fn module(device: &wgpu::Device, label: &str, pass: &str) -> wgpu::ShaderModule {
    Wgsl::builtin().module(device, label, pass)
}

/// The WGSL the passes compile: Mirador's own, or Mirador's with some of its module-scope
/// declarations put in other hands. That is the lab's seam (src/lab): a student's file defines
/// the functions of a technique's heart, each pass compiles them in place of Mirador's, and
/// nothing is rebuilt. WGSL declarations may come in any order, so the replacements are appended
/// after the pass's own file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Wgsl {
    /// The names of Mirador's declarations (functions, constants) left out.
    replaced: Vec<String>,
    /// What is compiled in their place, appended to every module.
    code: String,
    /// The device profile the text is composed for; [`Wgsl::module`] takes the device's own.
    profile: Profile,
    /// A WGSL expression, true when the appended code's loops were cut off in this invocation
    /// (the lab's loop guard, src/lab/isolate.rs).
    tripped: Option<String>,
}

impl Wgsl {
    /// Mirador's own WGSL.
    pub fn builtin() -> Wgsl {
        Wgsl::default()
    }

    /// Mirador's WGSL with the declarations named `replaced` left out and `code` appended.
    pub fn replacing(replaced: Vec<String>, code: String) -> Wgsl {
        Wgsl { replaced, code, profile: Profile::Standard, tripped: None }
    }

    /// The same WGSL, its appended code's loops guarded: `tripped` is a WGSL expression that is
    /// true where the guard cut them off.
    pub fn with_tripped(self, tripped: String) -> Wgsl {
        Wgsl { tripped: Some(tripped), ..self }
    }

    /// The expression that says the appended code's loops were cut off, where they are guarded.
    pub fn tripped(&self) -> Option<&str> {
        self.tripped.as_deref()
    }

    /// The same WGSL composed for a device of `profile`.
    pub fn for_profile(&self, profile: Profile) -> Wgsl {
        Wgsl { profile, ..self.clone() }
    }

    /// Whether this is Mirador's own WGSL.
    pub fn is_builtin(&self) -> bool {
        self.replaced.is_empty() && self.code.is_empty()
    }

    /// Whether a lab routes the technique behind the constant `name` through its slots
    /// (`const NAME = true;` in place of Mirador's `false`), where a pass must draw differently
    /// for it (the transparency lab's blend).
    pub fn routes(&self, name: &str) -> bool {
        self.replaced.iter().any(|n| n == name) && self.code.contains(&format!("const {name} = true;"))
    }

    /// What is appended to every module, at the end of the composed text.
    pub fn code(&self) -> &str {
        &self.code
    }

    /// Every pass's whole source, by name.
    pub fn passes(&self) -> Vec<(&'static str, String)> {
        let surface =
            [("scene", SCENE), ("transparency", TRANSPARENCY), ("refraction", REFRACTION), ("volume", VOLUME)];
        let others = [
            ("present", PRESENT),
            ("mipmap", MIPMAP),
            ("depth_copy", DEPTH_COPY),
            ("shadow", SHADOW),
            ("shadow_projected", SHADOW_PROJECTED),
            ("overlays", OVERLAYS),
            ("environment", ENVIRONMENT),
            ("upscale", UPSCALE),
            ("tessellation", TESSELLATION),
        ];
        let surface = surface.into_iter().map(|(name, pass)| (name, self.compose_surface(pass)));
        surface.chain(others.into_iter().map(|(name, pass)| (name, self.compose(pass)))).collect()
    }

    /// The full source of a pass: the common files, then the pass's own.
    pub fn compose(&self, pass: &str) -> String {
        self.compose_after(COMMON.iter(), pass)
    }

    /// The full source of a surface pass: the common files, the surface code, then the pass's own.
    pub fn compose_surface(&self, pass: &str) -> String {
        self.compose_after(COMMON.iter().chain(SURFACE), pass)
    }

    /// The common files alone, then the replacements: what a lab's known-answer tests run
    /// their function calls in (`extra` is the test's entry point).
    pub fn compose_common(&self, extra: &str) -> String {
        self.compose_after(COMMON.iter(), extra)
    }

    fn compose_after<'a>(&self, shared: impl Iterator<Item = &'a (&'a str, &'a str)>, pass: &str) -> String {
        let mut source = String::new();
        let (profile, profile_text) = self.profile.wgsl();
        let first = [("constants (src/shaders/constants.rs)", constants::prelude()), (profile, profile_text)];
        for (name, text) in first.into_iter().chain(shared.map(|&(name, text)| (name, text))) {
            source.push_str("// ---- ");
            source.push_str(name);
            source.push('\n');
            source.push_str(&self.without_replaced(text));
            source.push('\n');
        }
        source.push_str(&self.without_replaced(pass));
        if !self.code.is_empty() {
            source.push_str("\n// ---- replaced\n");
            source.push_str(&self.code);
        }
        source
    }

    fn without_replaced(&self, text: &str) -> String {
        let mut text = text.to_owned();
        for name in &self.replaced {
            while let Some(range) = declaration(&text, name) {
                text.replace_range(range, "");
            }
        }
        text
    }

    /// A pass's module ([`Self::compose`]), for `device`'s profile.
    pub fn module(&self, device: &wgpu::Device, label: &str, pass: &str) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(self.for_profile(Profile::of(device)).compose(pass).into()),
        })
    }

    /// A surface pass's module ([`Self::compose_surface`]), for `device`'s profile.
    pub fn surface_module(&self, device: &wgpu::Device, label: &str, pass: &str) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(self.for_profile(Profile::of(device)).compose_surface(pass).into()),
        })
    }
}

/// Where the module-scope declaration `name` lies in `text`: a function from its `fn` line to its
/// closing brace's line, or a constant from its line to its `;`, each with its line end. The
/// declaration must begin its line, as every one of Mirador's does.
pub fn declaration(text: &str, name: &str) -> Option<std::ops::Range<usize>> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let Some(rest) = line.strip_prefix("fn ").or_else(|| line.strip_prefix("const ")) else {
            continue;
        };
        let Some(after) = rest.strip_prefix(name) else {
            continue;
        };
        if after.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let end =
            if line.starts_with("fn ") { function_end(text, start)? } else { start + text[start..].find(';')? + 1 };
        let end = text[end..].find('\n').map_or(text.len(), |n| end + n + 1);
        return Some(start..end);
    }
    None
}

/// The byte after the brace that closes the body of the function starting at `start`.
fn function_end(text: &str, start: usize) -> Option<usize> {
    let open = start + text[start..].find('{')?;
    let mut depth = 0usize;
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i + 1);
                }
            }
            _ => {}
        }
    }
    None
}
