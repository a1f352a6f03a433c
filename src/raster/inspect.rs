//! Inspecting one pixel of the rasterizer's frame: the values its shaders computed there, read
//! back from the GPU (`shaders/common/inspect.wgsl`), not computed again on the CPU.
//!
//! An inspecting renderer (`Renderer::inspecting`) binds a storage buffer in the lighting group
//! (binding 11). While a pixel is inspected, the main view's pipelines are the `INSPECT` variants
//! whose `*_inspect` entry points append, for every fragment that lands on the pixel, a record
//! of what it computed: its kind (opaque, mirror, transparent, background, isosurface, volume),
//! depth, material and object, the terms of the illumination model, each light's visibility with
//! its shadow-map lookup (layer, texel, stored and receiver depth, lit fraction), the texture's
//! level and footprint, bump mapping's slopes, the reflections. Records come in the order the
//! fragments were drawn. Fragment shaders that write to storage run before the depth test (late
//! depth), so records of fragments the depth test then rejected are there too; [`RasterPixel`]
//! says which were blended (`crate::explain` reads them); the frame keeps what it decided before
//! it drew (`crate::raster::frame::FrameFacts`).
//!
//! Other views (mirrored cameras, cube faces) draw with the plain variants, and frames that
//! inspect nothing never compile the `INSPECT` variants: normal frames pay nothing.

pub use crate::shaders::constants::{
    INSPECT_BACKGROUND, INSPECT_ISOSURFACE, INSPECT_MIRROR, INSPECT_OPAQUE, INSPECT_REFRACTION, INSPECT_TRANSPARENT,
    INSPECT_VOLUME, MAX_INSPECTED,
};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

use super::uniforms::MAX_LIGHTS;
use crate::gpu::Gpu;

/// What the depth test and the blend do with a kind of record: how it takes part in the pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// A surface the z-buffer keeps when it is the nearest (`Less`).
    Surface,
    /// The world, drawn where no surface is.
    Background,
    /// Blended over the surface in draw order where nearer than it (one per layer when peeled),
    /// letting `kt·Mt` (or `1 − α`) of what is behind through.
    Transparent,
    /// Composited over what is behind wherever it was drawn, letting `1 − α` through.
    Composited,
}

/// A kind of record, declared by the pass whose `*_inspect` entry point writes it: its code
/// (`INSPECT_*`), the name `mirador explain` gives it, how it takes part in the pixel, and the
/// terms of its own light paths beyond the illumination model (each named as the course writes
/// it). The frame lists every pass's kinds (`crate::raster::frame::record_kinds`); the explainer
/// replays the depth test and the blend from `part` alone.
#[derive(Clone, Copy, Debug)]
pub struct RecordKind {
    pub code: u32,
    pub name: &'static str,
    pub part: Part,
    pub terms: fn(&GpuInspectFragment) -> Vec<(&'static str, Vec3)>,
}

/// No terms beyond the illumination model's (and the environment's, which every surface may add).
pub fn no_terms(_: &GpuInspectFragment) -> Vec<(&'static str, Vec3)> {
    Vec::new()
}

/// `InspectLight` of `shaders/common/inspect.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuInspectLight {
    pub ambient: Vec3,
    pub layer: i32,
    pub diffuse: Vec3,
    pub lit: f32,
    pub specular: Vec3,
    pub stored_depth: f32,
    pub visibility: Vec3,
    pub receiver_depth: f32,
    pub texel: Vec2,
    pub _pad0: f32,
    pub _pad1: f32,
}

/// `InspectFragment` of `shaders/common/inspect.wgsl`: what one fragment at the pixel computed.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuInspectFragment {
    pub kind: u32,
    pub material: u32,
    pub object: u32,
    pub depth: f32,
    pub world: Vec3,
    pub lod: f32,
    pub normal: Vec3,
    pub alpha: f32,
    pub geometric: Vec3,
    pub samples: f32,
    pub uv: Vec2,
    pub footprint: Vec2,
    pub colour: Vec3,
    pub bump_k: f32,
    pub bump: Vec2,
    pub bump_delta: Vec2,
    pub emission: Vec3,
    pub env_layer: i32,
    pub global_ambient: Vec3,
    pub fresnel: f32,
    pub environment: Vec3,
    pub _pad1: f32,
    pub env_direction: Vec3,
    pub _pad2: f32,
    pub mirror: Vec3,
    pub _pad3: f32,
    pub radiance: Vec3,
    pub _pad4: f32,
    pub refraction_exit: Vec3,
    pub refraction_found: f32,
    pub refracted_direction: Vec3,
    pub fresnel_exit: f32,
    pub refracted: Vec3,
    pub refraction_source: f32,
    /// The transparency lab's blend by hand: `b`, what the pixel behind is multiplied by.
    pub blend_factor: Vec3,
    pub _pad5: f32,
    pub lights: [GpuInspectLight; MAX_LIGHTS],
}

/// The head of `Inspection` in `shaders/common/inspect.wgsl`; the records follow it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuInspectionHead {
    pub pixel: [u32; 2],
    pub count: u32,
    pub _pad: u32,
}

const HEAD: u64 = std::mem::size_of::<GpuInspectionHead>() as u64;
const RECORD: u64 = std::mem::size_of::<GpuInspectFragment>() as u64;
const SIZE: u64 = HEAD + MAX_INSPECTED as u64 * RECORD;

/// What the rasterizer computed at one pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterPixel {
    pub pixel: (u32, u32),
    /// The frame's linear radiance there (the HDR target, half floats), before the output
    /// transform: what `render --exr` writes.
    pub radiance: Vec3,
    /// Every fragment that landed on the pixel in the main view, in the order drawn (more than
    /// [`MAX_INSPECTED`] are dropped; `dropped` counts them).
    pub fragments: Vec<GpuInspectFragment>,
    pub dropped: u32,
}

/// The inspection buffer, bound in the lighting group of an inspecting renderer.
pub struct Inspector {
    pub buffer: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// The pixel inspected by the next frames.
    pub pixel: Option<(u32, u32)>,
}

impl Inspector {
    pub fn new(device: &wgpu::Device) -> Inspector {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("inspect::buffer"),
            size: SIZE,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("inspect::readback"),
            size: SIZE,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Inspector { buffer, readback, pixel: None }
    }

    /// Clears the records before a frame that inspects `pixel`.
    pub fn begin(&self, queue: &wgpu::Queue, (x, y): (u32, u32)) {
        let head = GpuInspectionHead { pixel: [x, y], count: 0, _pad: 0 };
        queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(&head));
    }

    /// The records of the last frame, and the radiance of `hdr` (the frame's HDR target) at the
    /// pixel. Waits for the GPU.
    pub fn read(&self, gpu: &Gpu, hdr: &wgpu::Texture) -> Option<RasterPixel> {
        let pixel = self.pixel?;
        let texel = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("inspect::texel"),
            size: 8,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("inspect::read") });
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &self.readback, 0, SIZE);
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: hdr,
                mip_level: 0,
                origin: wgpu::Origin3d { x: pixel.0, y: pixel.1, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &texel,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: None, rows_per_image: None },
            },
            wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
        );
        gpu.queue.submit([encoder.finish()]);
        self.readback.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping the inspection records"));
        texel.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping the inspected texel"));
        gpu.wait();
        let (head, fragments) = {
            let bytes = self.readback.slice(..).get_mapped_range().ok()?;
            let head: GpuInspectionHead = bytemuck::pod_read_unaligned(&bytes[..HEAD as usize]);
            let count = (head.count as usize).min(MAX_INSPECTED);
            let fragments = (0..count)
                .map(|i| {
                    let start = (HEAD + i as u64 * RECORD) as usize;
                    bytemuck::pod_read_unaligned(&bytes[start..start + RECORD as usize])
                })
                .collect();
            (head, fragments)
        };
        self.readback.unmap();
        let radiance = {
            let bytes = texel.slice(..).get_mapped_range().ok()?;
            let half = |i: usize| half::f16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]).to_f32();
            Vec3::new(half(0), half(1), half(2))
        };
        texel.unmap();
        let dropped = head.count.saturating_sub(MAX_INSPECTED as u32);
        Some(RasterPixel { pixel, radiance, fragments, dropped })
    }
}
