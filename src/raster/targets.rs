//! The images a view draws into, and their formats. The main view's targets belong to the caller
//! (a window's frame, a screenshot); mirrored views' and cube faces' belong to the passes that
//! show them (`super::mirror`, `super::environment`). Every view draws into its own, so the
//! phases of one view never read what another is writing.

use crate::gpu::texture::GpuTexture;

/// Linear radiance, before the output transform.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The format of offscreen screenshots.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The images of one view, recreated when their size changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    /// What the view's phases make for its own shading (read through its view group).
    pub images: ViewImages,
}

impl FrameTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        FrameTargets {
            size,
            hdr: GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT),
            depth: GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT),
            images: ViewImages::new(device, size),
        }
    }
}

/// An image a view's phases make for its own shading, kept in the view's targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewImage {
    /// Object-precision shadows: one channel per shadowed light, 1 where the light is hidden
    /// (`super::shadow::projected`, drawn after the view's depth prepass).
    ProjectedMask,
}

impl ViewImage {
    /// Every view image, in the order the targets keep them.
    pub const ALL: [ViewImage; 1] = [ViewImage::ProjectedMask];

    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            ViewImage::ProjectedMask => wgpu::TextureFormat::Rgba8Unorm,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            ViewImage::ProjectedMask => "view_group::projected_mask",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Every view image of one view's targets, at the targets' size.
pub struct ViewImages {
    images: Vec<GpuTexture>,
}

impl ViewImages {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> ViewImages {
        let images = ViewImage::ALL.iter().map(|i| GpuTexture::target(device, i.label(), size, i.format())).collect();
        ViewImages { images }
    }

    pub fn get(&self, image: ViewImage) -> &GpuTexture {
        &self.images[image.index()]
    }
}

/// The size a frame is drawn at: the output's times the render scale, at least one pixel.
pub fn drawn_size(output: (u32, u32), render_scale: f32) -> (u32, u32) {
    let scaled = |n: u32| ((n as f32 * render_scale).round() as u32).clamp(1, n.max(1));
    (scaled(output.0), scaled(output.1))
}
