//! Textures: render targets, sampled images, and layered textures ([`Layers`]).

use crate::shaders::Profile;

/// A texture with the default view of all its levels.
pub struct GpuTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl GpuTexture {
    /// A 2D texture to render into (and read back or sample from).
    pub fn target(device: &wgpu::Device, label: &str, size: (u32, u32), format: wgpu::TextureFormat) -> GpuTexture {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let target = Self::image(device, label, size, format, usage);
        if format.is_depth_stencil_format() {
            depth_texels_nearest(device, &target.texture);
        }
        target
    }

    /// An image that receives copies of a target (`COPY_DST`) for shaders to read: a frame's
    /// colour as it was before a pass draws over it. (Depth is copied by drawing,
    /// [`super::depth_copy`]: wgpu's GL backend cannot copy a depth texture.)
    pub fn copy_target(
        device: &wgpu::Device,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
    ) -> GpuTexture {
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
        Self::image(device, label, size, format, usage)
    }

    /// One 2D image of one level, with `usage`.
    fn image(
        device: &wgpu::Device,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> GpuTexture {
        let texture = Self::layered(device, label, (size, 1), format, usage);
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        GpuTexture { texture, view }
    }

    /// A 2D texture of one level and `layers` layers, with `usage`.
    fn layered(
        device: &wgpu::Device,
        label: &str,
        (size, layers): ((u32, u32), u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    }

    pub fn from_rgba8(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        (width, height): (u32, u32),
        rgba8: &[u8],
        format: wgpu::TextureFormat,
    ) -> GpuTexture {
        use wgpu::util::DeviceExt;
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            rgba8,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        GpuTexture { texture, view }
    }
}

/// What the layers of a 2D texture are, decided once, when it is made, for every backend.
///
/// WebGPU leaves that open until a view is made: any 2D texture with six layers may be viewed as
/// a cube, a 2D array or six 2D images. GL cannot: wgpu's GL backend picks the texture's GL
/// target at creation from its size alone (wgpu-hal's `get_info_from_desc`): a square texture
/// whose layer count is a multiple of 6 becomes a `CUBE_MAP` (six layers) or a
/// `CUBE_MAP_ARRAY`, any other with one layer a `TEXTURE_2D`, with more a `TEXTURE_2D_ARRAY`.
/// A shader can then sample it only through a view of that one kind, of all its layers (a view
/// of layer k alone cannot be bound for sampling at all; drawing into one layer is fine).
/// Anything else reads black, with an error in the log. So every layered texture is made by
/// [`Layers::texture`], which pads the layer count until GL's rule gives the kind asked for,
/// and sampled through the view it returns.
///
/// On a device of the WebGL2 profile ([`Profile`]), which has no cube-map arrays, cubes are
/// made as a 2D array instead: cube k's face f is layer 6k + f, with one padding layer at the
/// end so that GL does not make a cube array of it, and the WGSL picks the face
/// (`shaders/profile/webgl2.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layers {
    /// One image: `D2` views.
    Single,
    /// `n` images of one size, sampled through a `D2Array` view.
    Array(u32),
    /// One cube: six square faces, sampled through a `Cube` view.
    Cube,
    /// `n` cubes, sampled through a `CubeArray` view, or a `D2Array` view of `6n + 1` layers on
    /// the WebGL2 profile.
    Cubes(u32),
}

impl Layers {
    /// How many layers a texture of these layers and of `width × height` texels is made with.
    /// An array gets at least two layers (one would make a `TEXTURE_2D`), and one more when
    /// square and a multiple of 6 (six shadow-map layers of one point light would make a cube);
    /// a cube array at least two cubes (one would make a `CUBE_MAP`). The padding layers are
    /// never drawn into nor read.
    pub fn count(self, (width, height): (u32, u32), profile: Profile) -> u32 {
        match self {
            Layers::Single => 1,
            Layers::Array(n) => {
                let n = n.max(2);
                if width == height && n.is_multiple_of(6) { n + 1 } else { n }
            }
            Layers::Cube => 6,
            Layers::Cubes(n) if profile == Profile::WebGl2 => 6 * n.max(1) + 1,
            Layers::Cubes(n) => 6 * n.max(2),
        }
    }

    /// The view dimension the texture is sampled through.
    pub fn view_dimension(self, profile: Profile) -> wgpu::TextureViewDimension {
        let declared = match self {
            Layers::Single => wgpu::TextureViewDimension::D2,
            Layers::Array(_) => wgpu::TextureViewDimension::D2Array,
            Layers::Cube => wgpu::TextureViewDimension::Cube,
            Layers::Cubes(_) => wgpu::TextureViewDimension::CubeArray,
        };
        profile.view_dimension(declared)
    }

    /// What a 2D texture's layers are, read back from its size by GL's rule: what a texture made
    /// by [`Layers::texture`] was made as (a padded count reads as the padded number).
    /// On the WebGL2 profile, a square texture of `6n + 1` layers reads as `n` cubes, as
    /// [`Layers::count`] makes them. A square array can have that count too (one point light's
    /// six shadow layers are padded to seven): only the mip generator reads kinds back, and it is
    /// given images and cubes, never arrays. Both are sampled through a 2D-array view there.
    pub fn of(texture: &wgpu::Texture, profile: Profile) -> Layers {
        Layers::by_gl_rule(texture.depth_or_array_layers(), texture.width() == texture.height(), profile)
    }

    /// wgpu-hal's `get_info_from_desc`: the kind GL makes of `count` layers, square or not.
    fn by_gl_rule(count: u32, square: bool, profile: Profile) -> Layers {
        match count {
            1 => Layers::Single,
            6 if square => Layers::Cube,
            n if square && n.is_multiple_of(6) => Layers::Cubes(n / 6),
            n if square && profile == Profile::WebGl2 && n > 6 && n % 6 == 1 => Layers::Cubes(n / 6),
            n => Layers::Array(n),
        }
    }

    /// A 2D texture of these layers, made from `descriptor` with its layer count set by
    /// [`Layers::count`], and the view of all its layers and levels to sample it through.
    /// Panics (a programmer error) on a cube that is not square or a texture that is not 2D.
    pub fn texture(self, device: &wgpu::Device, descriptor: &wgpu::TextureDescriptor) -> GpuTexture {
        let (width, height) = (descriptor.size.width, descriptor.size.height);
        assert!(descriptor.dimension == wgpu::TextureDimension::D2, "layers are those of a 2D texture");
        assert!(width == height || !matches!(self, Layers::Cube | Layers::Cubes(_)), "a cube's faces are square");
        let profile = Profile::of(device);
        let size = wgpu::Extent3d { depth_or_array_layers: self.count((width, height), profile), ..descriptor.size };
        let texture = device.create_texture(&wgpu::TextureDescriptor { size, ..descriptor.clone() });
        debug_assert_eq!(
            Layers::of(&texture, profile).view_dimension(profile),
            self.view_dimension(profile),
            "GL's rule reads it back"
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: descriptor.label,
            dimension: Some(self.view_dimension(profile)),
            ..Default::default()
        });
        GpuTexture { texture, view }
    }
}

/// On wgpu's GL backend, a depth image is set to filter NEAREST, so that shaders can read it with
/// `textureLoad` (as unfilterable floats, [`super::layout::depth_texels`]). OpenGL ES, and so
/// WebGL2, counts a depth texture that filters linearly without a comparison as incomplete, and
/// reads zeros from it: the volume ended every ray at the near plane and drew nothing in the
/// page's WebGL2 (desktop GL, llvmpipe's, reads it anyway). wgpu sets NEAREST for the colour
/// formats that cannot filter, not for depth. A comparison sampler's own filter still applies.
#[cfg_attr(all(target_arch = "wasm32", not(feature = "webgl2")), allow(unused_variables))]
fn depth_texels_nearest(device: &wgpu::Device, texture: &wgpu::Texture) {
    #[cfg(any(
        windows,
        target_os = "linux",
        target_os = "android",
        target_os = "freebsd",
        all(target_arch = "wasm32", feature = "webgl2")
    ))]
    {
        use glow::HasContext;
        use wgpu::hal::api::Gles;
        // SAFETY: the context is wgpu's own, locked (and made current) for the call; the texture
        // is bound, given two parameters wgpu never sets for it, and unbound, before wgpu records
        // anything with it (wgpu binds each texture it draws with at each draw).
        unsafe {
            let (Some(hal_device), Some(hal_texture)) = (device.as_hal::<Gles>(), texture.as_hal::<Gles>()) else {
                return;
            };
            if let wgpu::hal::gles::TextureInner::Texture { raw, target } = hal_texture.inner {
                let gl = hal_device.context().lock();
                gl.bind_texture(target, Some(raw));
                gl.tex_parameter_i32(target, glow::TEXTURE_MIN_FILTER, glow::NEAREST as i32);
                gl.tex_parameter_i32(target, glow::TEXTURE_MAG_FILTER, glow::NEAREST as i32);
                gl.bind_texture(target, None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Layers, Profile};

    /// Every kind keeps its kind under GL's rule, however many it holds; on the WebGL2 profile,
    /// GL makes a 2D array of the cubes, and they read back as cubes.
    #[test]
    fn padded_counts_read_back_as_the_kind_asked_for() {
        let kind = |layers: Layers| std::mem::discriminant(&layers);
        for n in 1..=25 {
            for (layers, size) in
                [(Layers::Array(n), (64, 64)), (Layers::Array(n), (64, 32)), (Layers::Cubes(n), (8, 8))]
            {
                let count = layers.count(size, Profile::Standard);
                let held = if matches!(layers, Layers::Cubes(_)) { 6 * n } else { n };
                assert!(count >= held, "{layers:?}: {count} layers");
                let read = Layers::by_gl_rule(count, size.0 == size.1, Profile::Standard);
                assert_eq!(kind(read), kind(layers), "{layers:?} of {size:?}: {count} layers");
            }
            let count = Layers::Cubes(n).count((8, 8), Profile::WebGl2);
            assert!(count >= 6 * n && !count.is_multiple_of(6), "a 2D array to GL: {count} layers");
            assert_eq!(Layers::by_gl_rule(count, true, Profile::WebGl2), Layers::Cubes(n));
        }
        assert_eq!(Layers::Array(6).count((512, 512), Profile::Standard), 7, "one point light's six layers");
        assert_eq!(Layers::Array(1).count((512, 512), Profile::Standard), 2);
        assert_eq!(Layers::Cubes(1).count((16, 16), Profile::Standard), 12);
        assert_eq!(Layers::Cubes(1).count((16, 16), Profile::WebGl2), 7);
        assert_eq!(Layers::Cube.count((16, 16), Profile::Standard), 6);
    }
}
