//! Mip chains on the GPU (docs/course/03-mipmaps.md).
//!
//! Mipmapping stores a texture at every power-of-two reduction, level `i + 1` the box average of
//! level `i`, `M_{i+1}[j, k] = ¼ (M_i[2j, 2k] + M_i[2j+1, 2k] + M_i[2j, 2k+1] + M_i[2j+1, 2k+1])`,
//! so that a distant surface reads a texel that already averages everything its pixel covers
//! instead of one texel picked at random (aliasing).
//!
//! [`MipmapGenerator`] fills levels `1..` of a texture from its level 0 with one render pass per
//! level: a fullscreen triangle into a view of level `i + 1` whose fragments `textureLoad` their
//! footprint from level `i` (`shaders/mipmap.wgsl`). Render passes rather than compute:
//! `Rgba8UnormSrgb` cannot be a storage texture, and through views of the texture's own format
//! an sRGB texture is decoded to linear when read and encoded when written, so the averages are
//! taken on linear values on every backend (Vulkan and GL alike).
//!
//! Each pass also writes its level, unrounded, to a transient `Rgba16Float` scratch chain, and
//! the next level is computed from that rather than from the 8-bit level: computing level
//! `i + 1` from the rounded level `i` would add up to half a step of rounding per level (a
//! smooth gradient rounds the same way everywhere, so the errors do not average out; on lavapipe
//! that reached 2/255 by level 3). The scratch costs 8 bytes per texel of levels `1..` (a third
//! of level 0's texel count) until the work is done.
//!
//! Non-power-of-two sizes follow the CPU chain's rule (`src/texture/mipmap.rs`): level sizes
//! `max(1, ⌊size/2⌋)`, as wgpu gives them, and on an odd axis of `n = 2h + 1` texels each output
//! texel averages three texels with weights `(h−j)/n, h/n, (j+1)/n`, the exact coverage of its
//! footprint, so the mean is kept. The GPU chain is rounded to 8 bits at every level; the CPU
//! chain stays in f32; tests/mipmaps.rs checks they agree within 1/255 on every level.
//!
//! Cubes and cube arrays get a chain per face. Level 1 cannot read a face's level 0 as a 2D view
//! of that layer: GL samples a cube only through a view of the whole cube ([`Layers`]), and
//! `textureLoad` has no cube form. So each face is first drawn into a transient 2D image of the
//! scratch's format, texel for texel (a nearest lookup at each texel's centre direction), and
//! level 1 reads that image; Mirador's cubes are half floats, the scratch's own format, so the
//! copy is exact and the chain is the one a 2D view of the layer would give.
//!
//! Limits: one pass per level (no single-pass downsampler); only 2D textures and cubes (not 2D
//! arrays) whose format can be rendered to and read as float; meant for 8-bit textures and half
//! floats (a 32-bit float texture's levels would pass through the 16-bit scratch and lose
//! precision).

use std::collections::HashMap;
use std::sync::Mutex;

use super::texture::{GpuTexture, Layers};
use crate::gpu::layout;
use crate::shaders;
use crate::texture::mipmap::Filter;

/// How many levels a full chain of a `width × height` texture has, `⌊log2 max(w, h)⌋ + 1`: the
/// `mip_level_count` to create it with.
pub fn mip_level_count(width: u32, height: u32) -> u32 {
    crate::texture::mipmap::mip_level_count(width, height)
}

/// The usages a texture needs for [`MipmapGenerator::record`] (plus `COPY_DST` to upload level 0
/// and `COPY_SRC` to read levels back).
pub const MIPMAP_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::TEXTURE_BINDING
    .union(wgpu::TextureUsages::RENDER_ATTACHMENT)
    .union(wgpu::TextureUsages::COPY_DST)
    .union(wgpu::TextureUsages::COPY_SRC);

/// The format of the unrounded chain the levels are computed from: renderable and readable on
/// every backend, with 11 significant bits (an error under 1/16 of an 8-bit step per level).
const SCRATCH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Builds mip chains on the GPU. Made once per device; render pipelines are made on first use of
/// each texture format and kept.
pub struct MipmapGenerator {
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: Mutex<HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>>,
    /// Copying one face of a cube, and of a cube array, into a 2D image.
    face_of_cube: FaceCopy,
    face_of_cubes: FaceCopy,
    /// Nearest, clamped: each face texel read at its centre is that texel.
    face_sampler: wgpu::Sampler,
}

/// The pass that draws one face of a cube (or of a cube array) into a 2D image for level 1 to
/// read (`fs_mipmap_face_*` in `shaders/mipmap.wgsl`).
struct FaceCopy {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// The binding the cube is read through.
    binding: u32,
}

impl FaceCopy {
    fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        dimension: wgpu::TextureViewDimension,
        (binding, fragment): (u32, &str),
    ) -> FaceCopy {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mipmap::face_layout"),
            entries: &[
                layout::sampler(1, wgpu::SamplerBindingType::NonFiltering),
                layout::texture(
                    binding,
                    wgpu::TextureSampleType::Float { filterable: false },
                    shaders::Profile::of(device).view_dimension(dimension),
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mipmap::face_pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = layout::fullscreen_pipeline(
            device,
            "mipmap::face_pipeline",
            &pipeline_layout,
            module,
            ("vs_mipmap_face", fragment),
            &[Some(SCRATCH_FORMAT.into())],
        );
        FaceCopy { layout, pipeline, binding }
    }
}

impl MipmapGenerator {
    pub fn new(device: &wgpu::Device) -> MipmapGenerator {
        let module = shaders::module(device, "mipmap::shader", shaders::MIPMAP);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mipmap::bind_group_layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    // textureLoad only: no filtering needed, so any float format works.
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mipmap::layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        MipmapGenerator {
            face_of_cube: FaceCopy::new(device, &module, wgpu::TextureViewDimension::Cube, (2, "fs_mipmap_face_cube")),
            face_of_cubes: FaceCopy::new(
                device,
                &module,
                wgpu::TextureViewDimension::CubeArray,
                (3, "fs_mipmap_face_cubes"),
            ),
            face_sampler: device
                .create_sampler(&wgpu::SamplerDescriptor { label: Some("mipmap::face_sampler"), ..Default::default() }),
            module,
            layout,
            pipeline_layout,
            pipelines: Mutex::new(HashMap::new()),
        }
    }

    fn pipeline(&self, device: &wgpu::Device, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
        let mut pipelines = self.pipelines.lock().expect("no thread panicked while holding the pipeline cache");
        pipelines
            .entry(format)
            .or_insert_with(|| {
                layout::fullscreen_pipeline(
                    device,
                    "mipmap::pipeline",
                    &self.pipeline_layout,
                    &self.module,
                    ("vs_mipmap", "fs_mipmap"),
                    &[Some(SCRATCH_FORMAT.into()), Some(format.into())],
                )
            })
            .clone()
    }

    /// Records into `encoder` the passes that fill levels `1..` of `texture` from level 0, each
    /// level from the unrounded level above (kept in a scratch chain made for this call and
    /// released with the command buffer), for every array layer (a cube's six faces each get
    /// their own chain). Submit the encoder to run them; nothing else is needed before sampling
    /// the texture in a later submission (or later in the same encoder).
    ///
    /// Panics (a programmer error) unless `texture` is a 2D image, a cube or a cube array
    /// ([`Layers`]), single-sample, and has `TEXTURE_BINDING | RENDER_ATTACHMENT` usage with a
    /// renderable float format.
    pub fn record(&self, device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) {
        self.record_layers(device, encoder, texture, 0..texture.depth_or_array_layers());
    }

    /// [`MipmapGenerator::record`] for the array layers `layers` alone.
    pub fn record_layers(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        layers: std::ops::Range<u32>,
    ) {
        let levels = texture.mip_level_count();
        if levels <= 1 || layers.is_empty() {
            return;
        }
        let profile = shaders::Profile::of(device);
        let face_copy = self.face_copy(texture, profile);
        let pipeline = self.pipeline(device, texture.format());
        let scratch = scratch_chain(device, texture);
        let face = face_copy.map(|copy| self.face_source(device, texture, copy, profile));
        encoder.push_debug_group("mipmap");
        for layer in layers {
            if let Some(face) = &face {
                draw(encoder, "mipmap::face_pass", (face.pipeline, &face.group), &[&face.image], layer);
            }
            for level in 1..levels {
                let source = match &face {
                    _ if level > 1 => level_view(&scratch, level - 2, 0),
                    Some(face) => face.image.clone(),
                    None => level_view(texture, 0, layer),
                };
                let targets = [level_view(&scratch, level - 1, 0), level_view(texture, level, layer)];
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("mipmap::bind_group"),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&source),
                    }],
                });
                draw(encoder, "mipmap::pass", (&pipeline, &group), &[&targets[0], &targets[1]], 0);
            }
        }
        encoder.pop_debug_group();
    }

    /// The face copy a cube or cube array's levels start from (`None` for a 2D image), once
    /// `texture` is known to be one the generator handles.
    fn face_copy(&self, texture: &wgpu::Texture, profile: shaders::Profile) -> Option<&FaceCopy> {
        assert!(
            texture.dimension() == wgpu::TextureDimension::D2 && texture.sample_count() == 1,
            "mipmaps are generated for single-sample 2D textures"
        );
        assert!(
            texture.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT),
            "a texture needs TEXTURE_BINDING | RENDER_ATTACHMENT usage to have its mipmaps generated"
        );
        match Layers::of(texture, profile) {
            Layers::Single => None,
            Layers::Cube => Some(&self.face_of_cube),
            Layers::Cubes(_) => Some(&self.face_of_cubes),
            Layers::Array(_) => panic!("mipmaps are generated for 2D images and cubes, not for 2D arrays"),
        }
    }

    /// A cube's level 0, one face at a time, as the 2D image level 1 reads; and the group that
    /// reads the whole cube (its level 0) to draw it.
    fn face_source<'a>(
        &self,
        device: &wgpu::Device,
        texture: &wgpu::Texture,
        copy: &'a FaceCopy,
        profile: shaders::Profile,
    ) -> FaceSource<'a> {
        let image = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("mipmap::face"),
            size: wgpu::Extent3d { depth_or_array_layers: 1, ..texture.size() },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SCRATCH_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let cube = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("mipmap::face_source"),
            dimension: Some(Layers::of(texture, profile).view_dimension(profile)),
            base_mip_level: 0,
            mip_level_count: Some(1),
            ..Default::default()
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mipmap::face_group"),
            layout: &copy.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&self.face_sampler) },
                wgpu::BindGroupEntry { binding: copy.binding, resource: wgpu::BindingResource::TextureView(&cube) },
            ],
        });
        FaceSource { pipeline: &copy.pipeline, group, image: level_view(&image, 0, 0) }
    }
}

/// One face of a cube drawn into a 2D image for level 1 to read: the face copy's pipeline, the
/// group that reads the cube, and the image.
struct FaceSource<'a> {
    pipeline: &'a wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    image: wgpu::TextureView,
}

/// The chain `texture`'s levels are computed from before rounding: its level i holds the
/// texture's level i + 1; the layers take turns in it.
fn scratch_chain(device: &wgpu::Device, texture: &wgpu::Texture) -> wgpu::Texture {
    let level1 =
        wgpu::Extent3d { depth_or_array_layers: 1, ..texture.size().mip_level_size(1, wgpu::TextureDimension::D2) };
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("mipmap::scratch"),
        size: level1,
        mip_level_count: texture.mip_level_count() - 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SCRATCH_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    })
}

/// The view of one level of one layer, as a 2D image in the texture's format.
fn level_view(texture: &wgpu::Texture, level: u32, layer: u32) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some("mipmap::level_view"),
        format: Some(texture.format()),
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_mip_level: level,
        mip_level_count: Some(1),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

/// One fullscreen triangle of `pipeline` with `group` into `targets`, as instance `instance`.
/// Every texel is drawn, so the targets' old contents are not loaded.
fn draw(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    (pipeline, group): (&wgpu::RenderPipeline, &wgpu::BindGroup),
    targets: &[&wgpu::TextureView],
    instance: u32,
) {
    let attachments: Vec<_> = targets
        .iter()
        .map(|view| Some(layout::color_attachment(view, wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT))))
        .collect();
    let mut pass = encoder.begin_render_pass(&layout::pass(label, &attachments, None));
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.draw(0..3, instance..instance + 1);
}

/// Fills levels `1..` of `texture` from its level 0 and submits the work (without waiting). A
/// one-off: it builds a [`MipmapGenerator`] each call; a renderer keeps one and calls
/// [`MipmapGenerator::record`].
pub fn generate_mipmaps(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) {
    let generator = MipmapGenerator::new(device);
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mipmap::encoder") });
    generator.record(device, &mut encoder, texture);
    queue.submit([encoder.finish()]);
}

/// Uploads an RGBA8 image of `width × height` texels as a texture of `format` with a full mip
/// chain (usage [`MIPMAP_USAGE`]), writes level 0 and submits the generation of the other levels.
/// The view covers every level. A short pixel buffer (a malformed file) is padded with
/// transparent black rather than rejected by wgpu's validation.
pub fn upload_with_mipmaps(
    (device, queue): (&wgpu::Device, &wgpu::Queue),
    generator: &MipmapGenerator,
    label: &str,
    ((width, height), rgba8): ((u32, u32), &[u8]),
    format: wgpu::TextureFormat,
) -> GpuTexture {
    let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: mip_level_count(width, height),
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: MIPMAP_USAGE,
        view_formats: &[],
    });
    let row = 4 * width as usize;
    let expected = row * height as usize;
    let mut padded;
    let data = if rgba8.len() >= expected {
        &rgba8[..expected]
    } else {
        padded = rgba8.to_vec();
        padded.resize(expected, 0);
        &padded[..]
    };
    queue.write_texture(
        texture.as_image_copy(),
        data,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row as u32), rows_per_image: Some(height) },
        size,
    );
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mipmap::encoder") });
    generator.record(device, &mut encoder, &texture);
    queue.submit([encoder.finish()]);
    let view = texture.create_view(&wgpu::TextureViewDescriptor { label: Some("mipmap::view"), ..Default::default() });
    GpuTexture { texture, view }
}

/// The sampler that makes the GPU read a mipmapped texture as [`crate::texture::MipChain::sample`]
/// does with `filter`: repeat wrapping; level 0 only (`lod_max_clamp = 0`) for nearest and
/// bilinear; linear within a level and nearest or linear between levels for nearest-mip and
/// trilinear. `max_anisotropy > 1` turns on anisotropic filtering for trilinear only (wgpu
/// requires every filter to be linear for it, and ignores it where the device lacks it);
/// the level-colour view is computed in the shader and samples nothing, so it gets trilinear.
pub fn sampler_descriptor(filter: Filter, max_anisotropy: u16) -> wgpu::SamplerDescriptor<'static> {
    use wgpu::{FilterMode, MipmapFilterMode};
    let (label, texel, mip, max_lod) = match filter {
        Filter::Nearest => ("mipmap::sampler_nearest", FilterMode::Nearest, MipmapFilterMode::Nearest, 0.0),
        Filter::Bilinear => ("mipmap::sampler_bilinear", FilterMode::Linear, MipmapFilterMode::Nearest, 0.0),
        Filter::NearestMip => ("mipmap::sampler_nearest_mip", FilterMode::Linear, MipmapFilterMode::Nearest, 32.0),
        Filter::Trilinear | Filter::LevelColour => {
            ("mipmap::sampler_trilinear", FilterMode::Linear, MipmapFilterMode::Linear, 32.0)
        }
    };
    let anisotropy = if filter == Filter::Trilinear { max_anisotropy.clamp(1, 16) } else { 1 };
    wgpu::SamplerDescriptor {
        label: Some(label),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: texel,
        min_filter: texel,
        mipmap_filter: mip,
        lod_min_clamp: 0.0,
        lod_max_clamp: max_lod,
        compare: None,
        anisotropy_clamp: anisotropy,
        border_color: None,
    }
}

/// Copies mip level `level` of a 2D texture with 4 bytes per texel (RGBA8, sRGB or not: the
/// stored bytes) into a tightly packed `Vec<u8>`, rows from the top. The texture needs
/// `COPY_SRC` usage. ([`super::readback::read_texels`] reads level 0 only.)
pub fn read_level_rgba8(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture, level: u32) -> Vec<u8> {
    let size = texture.size().mip_level_size(level, texture.dimension());
    let row = 4 * size.width;
    let padded_row = super::readback::padded_row(u64::from(row)) as u32;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mipmap::readback_buffer"),
        size: u64::from(padded_row) * u64::from(size.height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mipmap::readback_encoder") });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: level,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row),
                rows_per_image: Some(size.height),
            },
        },
        wgpu::Extent3d { depth_or_array_layers: 1, ..size },
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |result| result.expect("mapping the mip readback buffer"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the mip readback copy");
    let mapped = slice.get_mapped_range().expect("the buffer was mapped for reading above");
    let mut packed = Vec::with_capacity((row * size.height) as usize);
    for padded in mapped.chunks_exact(padded_row as usize) {
        packed.extend_from_slice(&padded[..row as usize]);
    }
    drop(mapped);
    buffer.unmap();
    packed
}
