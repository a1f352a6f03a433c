//! Known-answer tests: one call of a student's function on tiny inputs, run in a fragment shader
//! with the shared WGSL (and the student's functions in place of Mirador's), its value written
//! bit for bit into a 2×1 `Rgba32Uint` target (beside it, whether the loop guard cut the
//! student's loops off: [`ENTRY`]) and read back. A fragment shader rather than a
//! compute one: WebGL2 has none, and the page's lab runs its checks there too. Inputs a texture
//! function needs are two tiny textures made here, whose every texel is known (the values a
//! test expects are worked out by hand from these):
//!
//! - `lab_texture`: `texture_2d<f32>`, 4×4 with a full chain of 3 levels. Level 0 holds
//!   (x, y, (x + y) mod 2, 1) at texel (x, y); level 1 holds (10 + x, 10 + y, 0.5, 1); level 2
//!   holds (20, 20, 0.5, 1). Levels far apart make a wrong level, weight or texel show at once.
//! - `lab_depth`: `texture_depth_2d_array`, 4×4, one layer, depth (x + 4y + 1)/20 at texel
//!   (x, y): 0.05 in the top-left corner to 0.8 in the bottom-right.

use crate::gpu::readback::Pending;
use crate::gpu::{Gpu, layout};
use crate::shaders::Wgsl;
use wgpu::util::DeviceExt;

/// The harness's bindings, declared before the entry points.
pub const BINDINGS: &str = "
@group(0) @binding(0) var lab_texture: texture_2d<f32>;
@group(0) @binding(1) var lab_depth: texture_depth_2d_array;
";

/// The known-answer test's entry points, `{call}` and `{tripped}` filled in: pixel 0 gets the
/// value's bits, pixel 1 whether the loop guard cut the student's loops off while computing it
/// (each pixel computes the call, the same way). Chosen by integer arithmetic, not by a branch:
/// lavapipe wrote the sign bit of pixel 0's first component into pixel 1 when each returned
/// from its own branch (measured: a value of −1 gave pixel 1 0x80000000).
pub const ENTRY: &str = "
@vertex
fn lab_vertex(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    return vec4f(f32(i / 2u) * 4.0 - 1.0, f32(i % 2u) * 4.0 - 1.0, 0.0, 1.0);
}

@fragment
fn lab_main(@builtin(position) lab_pixel: vec4f) -> @location(0) vec4u {
    let lab_value: vec4f = {call};
    let lab_first = u32(lab_pixel.x < 1.0);
    return bitcast<vec4u>(lab_value) * lab_first + vec4u(u32({tripped}), 0u, 0u, 0u) * (1u - lab_first);
}
";

/// What a known-answer call gave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Call {
    pub value: [f32; 4],
    /// The student's loops ran past the guard's bound ([`super::isolate::ITERATIONS`]).
    pub tripped: bool,
}

const SIDE: u32 = 4;

/// The format of the target a call's value is written to: four `u32`, the value's bits, which no
/// blending or conversion can touch (and which WebGL2 can render to, as it cannot to floats
/// without an extension).
const TARGET: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// The harness's textures and layout, made once for every call.
pub struct Harness {
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    target: wgpu::Texture,
}

impl Harness {
    pub fn new(gpu: &Gpu) -> Harness {
        let device = &gpu.device;
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lab::harness"),
            entries: &[
                layout::texture(
                    0,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
                layout::texture(1, wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
            ],
        });
        let texture = colour_texture(gpu);
        let depth = depth_texture(gpu);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lab::harness"),
            layout: &group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&texture.create_view(&Default::default())),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&depth.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2Array),
                        ..Default::default()
                    })),
                },
            ],
        });
        let target = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("lab::harness::target"),
            size: wgpu::Extent3d { width: 2, height: 1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: TARGET,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        Harness { layout: group_layout, group, target }
    }

    /// The module that computes `call` (a `vec4f` expression) in the shared WGSL as `wgsl`
    /// composes it, for `wgsl`'s profile: `lab_main` writes the value's bits at pixel 0, and at
    /// pixel 1 whether the student's loops were cut off ([`Wgsl::tripped`]).
    pub fn module(wgsl: &Wgsl, call: &str) -> String {
        let tripped = wgsl.tripped().unwrap_or("false");
        let entry = ENTRY.replace("{call}", call).replace("{tripped}", tripped);
        wgsl.compose_common(&format!("{BINDINGS}{entry}"))
    }

    /// The value of `call` (a `vec4f` expression) in a module of the shared WGSL as `wgsl`
    /// composes it; a GPU error is the error's text.
    pub async fn call(&self, gpu: &Gpu, wgsl: &Wgsl, call: &str) -> Result<Call, String> {
        // Composed for the device's profile, as the passes are: WebGL2 has no cube arrays.
        let source = Harness::module(&wgsl.for_profile(gpu.profile()), call);
        if let Err(error) = naga::front::wgsl::parse_str(&source) {
            return Err(format!("the test's call `{call}` does not compile: {}", error.message()));
        }
        let readback = gpu.checked_later(|| self.draw(gpu, source)).await.map_err(|e| e.to_string())?;
        let bytes = readback.map_err(|e| e.to_string())?.texels(&gpu.device).await.map_err(|e| e.to_string())?;
        let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
        let value = [0, 4, 8, 12].map(|i| f32::from_bits(word(i)));
        Ok(Call { value, tripped: word(16) == 1 })
    }

    /// Draws the one pixel of `source`'s `lab_main` and starts reading it back.
    fn draw(&self, gpu: &Gpu, source: String) -> Result<Pending, crate::gpu::readback::ReadbackError> {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("lab::call"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lab::call"),
            bind_group_layouts: &[Some(&self.layout)],
            immediate_size: 0,
        });
        let targets = [Some(TARGET.into())];
        let pipeline = layout::fullscreen_pipeline(
            device,
            "lab::call",
            &pipeline_layout,
            &module,
            ("lab_vertex", "lab_main"),
            &targets,
        );
        let view = self.target.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let attachments = [Some(layout::color_attachment(&view, wgpu::LoadOp::Clear(wgpu::Color::BLACK)))];
            let mut pass = encoder.begin_render_pass(&layout::pass("lab::call", &attachments, None));
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
        Pending::start(device, &gpu.queue, &self.target, 16)
    }
}

/// `lab_texture`: see the module's header.
fn colour_texture(gpu: &Gpu) -> wgpu::Texture {
    let texel = |level: u32, x: u32, y: u32| -> [f32; 4] {
        match level {
            0 => [x as f32, y as f32, ((x + y) % 2) as f32, 1.0],
            1 => [10.0 + x as f32, 10.0 + y as f32, 0.5, 1.0],
            _ => [20.0, 20.0, 0.5, 1.0],
        }
    };
    let mut data = Vec::new();
    for level in 0..3 {
        let side = SIDE >> level;
        for y in 0..side {
            for x in 0..side {
                data.extend(texel(level, x, y));
            }
        }
    }
    gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("lab_texture"),
            size: wgpu::Extent3d { width: SIDE, height: SIDE, depth_or_array_layers: 1 },
            mip_level_count: 3,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::MipMajor,
        bytemuck::cast_slice(&data),
    )
}

/// `lab_depth`, drawn (a depth texture cannot be written from a buffer): a full-screen triangle
/// whose fragments write their texel's depth.
fn depth_texture(gpu: &Gpu) -> wgpu::Texture {
    let device = &gpu.device;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("lab_depth"),
        size: wgpu::Extent3d { width: SIDE, height: SIDE, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let source = "
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    return vec4f(f32(i / 2u) * 4.0 - 1.0, f32(i % 2u) * 4.0 - 1.0, 0.0, 1.0);
}
@fragment fn fs(@builtin(position) p: vec4f) -> @builtin(frag_depth) f32 {
    return (floor(p.x) + 4.0 * floor(p.y) + 1.0) / 20.0;
}";
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("lab_depth"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("lab_depth"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    });
    let view = texture.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lab_depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([encoder.finish()]);
    texture
}
