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
/// Object-precision shadows: one channel per shadowed light.
pub const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The images of one view, recreated when their size changes.
pub struct FrameTargets {
    pub size: (u32, u32),
    pub hdr: GpuTexture,
    pub depth: GpuTexture,
    /// Object-precision shadows of the main view: one channel per shadowed light.
    pub shadow_mask: GpuTexture,
}

impl FrameTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> FrameTargets {
        FrameTargets {
            size,
            hdr: GpuTexture::target(device, "frame::hdr", size, HDR_FORMAT),
            depth: GpuTexture::target(device, "frame::depth", size, DEPTH_FORMAT),
            shadow_mask: GpuTexture::target(device, "frame::shadow_mask", size, MASK_FORMAT),
        }
    }
}

/// The size a frame is drawn at: the output's times the render scale, at least one pixel.
pub fn drawn_size(output: (u32, u32), render_scale: f32) -> (u32, u32) {
    let scaled = |n: u32| ((n as f32 * render_scale).round() as u32).clamp(1, n.max(1));
    (scaled(output.0), scaled(output.1))
}
