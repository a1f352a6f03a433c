//! The GPU's part of adaptive displacement: per displaced object its patches, its height field
//! and the vertex and index buffers the compute shader writes, which every pass then draws as the
//! object's mesh (`SceneGeometry::set_displaced`).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::patches::bounded_levels;
use super::{Levels, MAX_TRIANGLES, MAX_VERTICES, Patches};
use crate::gpu::Gpu;
use crate::gpu::uniform::UniformBuffer;
use crate::raster::geometry::{GpuMesh, SceneGeometry};
use crate::raster::uniforms::Vertex;
use crate::scene::{ProceduralHeight, Scene};
use crate::settings::{RenderSettings, Tessellation};
use crate::shaders;
use crate::texture::mipmap::MipLevel;

/// The most texels of a height map the compute shader reads (64 MB of floats); a larger map's
/// object keeps the uniform mesh, said once.
const MAX_HEIGHT_TEXELS: u64 = 16 << 20;

/// The largest displacement `k` (world units per unit of height) tessellated on the GPU: beyond
/// it the cross products of the normals' fan overflow f32.
const MAX_K: f32 = 1e12;

/// Threads per workgroup (`@workgroup_size` in `shaders/tessellation.wgsl`).
const WORKGROUP: u32 = 64;

/// `Params` of `shaders/tessellation.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct GpuParams {
    k: f32,
    kind: u32,
    amplitude: f32,
    patch_count: u32,
    frequency: [f32; 2],
    _pad: [f32; 2],
    map_size: [u32; 2],
    noise_seed: u32,
    noise_cells: u32,
    noise_octaves: u32,
    vertex_count: u32,
    triangle_count: u32,
    row: u32,
}

/// What the last frame's tessellation made, for `--stats` and the viewer.
#[derive(Clone, Debug, PartialEq)]
pub struct TessellationReport {
    pub objects: usize,
    pub triangles: u64,
    pub vertices: u64,
    /// The longest edge on screen the levels were chosen for, in pixels, and the one asked
    /// (`bump.edge_pixels`): they differ where the bound on triangles forced longer edges.
    pub edge_pixels: f32,
    pub asked: f32,
    /// The finest split of any triangle.
    pub finest: u32,
    /// The frame made its triangles again (the view or the settings changed).
    pub made: bool,
}

impl TessellationReport {
    /// A line for `--stats` and the viewer.
    pub fn summary(&self) -> String {
        let mut line = format!(
            "adaptive displacement: {} objects, {} triangles, {} vertices, finest split {}, edges under {:.1} px",
            self.objects, self.triangles, self.vertices, self.finest, self.edge_pixels
        );
        if self.edge_pixels > self.asked {
            line.push_str(&format!(
                " (asked {:.1} px: the bound of {MAX_TRIANGLES} triangles and {MAX_VERTICES} vertices forced longer edges)",
                self.asked
            ));
        }
        line
    }
}

/// One displaced object on the GPU.
struct Object {
    patches: Patches,
    /// What the shader's `params` holds, and the buffer it is written to.
    params: GpuParams,
    uniform: UniformBuffer<GpuParams>,
    patch_buffer: wgpu::Buffer,
    /// The centre of the box around the moved corners.
    centre: Vec3,
    /// The height map's red channel as 32-bit floats (1×1 for a procedural field).
    heights: wgpu::TextureView,
    /// The levels buffer and the output buffers, with what they hold room for (patches,
    /// vertices, triangles); grown, never shrunk.
    buffers: Option<(wgpu::Buffer, wgpu::Buffer, wgpu::Buffer, [u32; 3])>,
    levels: Levels,
    group: Option<wgpu::BindGroup>,
}

/// Adaptive displacement's compute pass and the scene's displaced objects.
#[derive(Default)]
pub struct TessellationPass {
    /// Made when a scene first has something to tessellate: a scene without displacement
    /// compiles no compute shader.
    pipelines: Option<Pipelines>,
    objects: Vec<Object>,
    /// The last frame's report.
    pub report: Option<TessellationReport>,
}

/// The pass's group layout and its two entry points.
struct Pipelines {
    layout: wgpu::BindGroupLayout,
    vertices: wgpu::ComputePipeline,
    indices: wgpu::ComputePipeline,
}

impl Pipelines {
    fn new(device: &wgpu::Device) -> Pipelines {
        let storage = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tessellation::layout"),
            entries: &[
                crate::gpu::layout::uniform(0, wgpu::ShaderStages::COMPUTE),
                storage(1, true),
                storage(2, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                storage(4, false),
                storage(5, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tessellation::pipeline_layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = shaders::module(device, "tessellation::shader", shaders::TESSELLATION);
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&format!("tessellation::{entry}")),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Pipelines { vertices: pipeline("cs_vertices"), indices: pipeline("cs_indices"), layout }
    }
}

impl TessellationPass {
    /// Takes `scene`'s displaced objects in place of the last scene's.
    pub fn load(&mut self, gpu: &Gpu, scene: &Scene) {
        self.objects = (0..scene.displaced.len()).filter_map(|i| Object::new(gpu, scene, i)).collect();
        self.report = None;
        if !self.objects.is_empty() && self.pipelines.is_none() {
            self.pipelines = Some(Pipelines::new(&gpu.device));
        }
    }

    /// Tessellates the displaced objects for `scene`'s camera when `settings` ask for adaptive
    /// tessellation and the levels changed, recording the compute pass on `encoder`, and gives
    /// `geometry` the meshes to draw in place of the uniform ones (none otherwise). The hybrid's
    /// relief swap (`hybrid.relief`) draws the uniform mesh: the very triangles the tracer traces.
    pub fn prepare(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        scene: &Scene,
        settings: &RenderSettings,
        geometry: &mut SceneGeometry,
    ) -> Option<&TessellationReport> {
        let bump = &settings.bump;
        let adaptive = bump.tessellation == Tessellation::Adaptive && !settings.hybrid.relief;
        let wanted = bump.enabled && adaptive && !self.objects.is_empty();
        if !wanted {
            geometry.set_displaced(Vec::new());
            self.report = None;
            return None;
        }
        for object in &mut self.objects {
            object.follow(&gpu.device, scene);
        }
        let patches: Vec<&Patches> = self.objects.iter().map(|o| &o.patches).collect();
        let (levels, edge_pixels) = bounded_levels(&patches, &scene.camera, bump);
        let triangles: u64 = levels.iter().map(|l| l.triangles).sum();
        let vertices: u64 = levels.iter().map(|l| l.vertices).sum();
        if triangles > MAX_TRIANGLES || vertices > MAX_VERTICES {
            if self.report.is_some() || geometry.has_displaced() {
                log::warn!(
                    "adaptive displacement: the meshes have too many triangles even unsplit; drawing the uniform mesh"
                );
            }
            geometry.set_displaced(Vec::new());
            self.report = None;
            return None;
        }
        let finest = levels.iter().flat_map(|l| l.patches.iter().map(|p| p[3])).max().unwrap_or(1);
        let made = self.objects.iter().zip(&levels).any(|(o, l)| o.levels != *l) || !geometry.has_displaced();
        if made {
            self.record(gpu, encoder, levels);
            geometry.set_displaced(self.objects.iter().map(|o| (o.patches.object, o.mesh())).collect());
        }
        let asked = bump.edge_pixels;
        self.report = Some(TessellationReport {
            objects: self.objects.len(),
            triangles,
            vertices,
            edge_pixels,
            asked,
            finest,
            made,
        });
        self.report.as_ref()
    }

    /// Writes each object's levels and records its two dispatches.
    fn record(&mut self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, levels: Vec<Levels>) {
        let Some(pipelines) = &self.pipelines else { return };
        for (object, levels) in self.objects.iter_mut().zip(levels) {
            object.upload(gpu, &pipelines.layout, levels);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tessellation::pass"),
            timestamp_writes: None,
        });
        for object in &self.objects {
            let Some(group) = &object.group else { continue };
            pass.set_bind_group(0, group, &[]);
            let row = object.params.row / WORKGROUP;
            let counts =
                [(&pipelines.vertices, object.params.vertex_count), (&pipelines.indices, object.params.triangle_count)];
            for (pipeline, count) in counts {
                pass.set_pipeline(pipeline);
                let groups = count.div_ceil(WORKGROUP);
                pass.dispatch_workgroups(row, groups.div_ceil(row), 1);
            }
        }
    }

    /// The CPU's twin of the last tessellation of each object (for the teaching view): its
    /// object and its triangles.
    pub fn cpu_meshes(&self, scene: &Scene) -> Vec<(usize, crate::scene::Mesh)> {
        self.objects
            .iter()
            .filter_map(|o| {
                let material = scene.materials.get(o.patches.material)?;
                let mesh = crate::texture::displacement::with_field(scene, material, |field| {
                    o.patches.tessellate(&o.levels, field)
                })?;
                Some((o.patches.object, mesh))
            })
            .collect()
    }

    /// Reads back the vertices and indices the GPU made for each object (tests).
    pub fn read_back(&self, gpu: &Gpu) -> Vec<(Vec<Vertex>, Vec<u32>)> {
        self.objects
            .iter()
            .map(|o| {
                let Some((_, vertices, indices, _)) = &o.buffers else { return (Vec::new(), Vec::new()) };
                let v = read_buffer(gpu, vertices, o.levels.vertices * 48);
                let i = read_buffer(gpu, indices, o.levels.triangles * 12);
                (bytemuck::pod_collect_to_vec(&v), bytemuck::pod_collect_to_vec(&i))
            })
            .collect()
    }
}

impl Object {
    /// Surface `index` of `scene`, with its height field as the compute shader reads it; `None`
    /// where it cannot be tessellated (said).
    fn new(gpu: &Gpu, scene: &Scene, index: usize) -> Option<Object> {
        let device = &gpu.device;
        let patches = Patches::new(scene, index)?;
        if patches.patches.is_empty() {
            return None;
        }
        let name = &scene.objects[patches.object].name;
        // A displacement so large that the surface leaves f32's range (or its normals' products
        // would): the uniform mesh, which leaves such points unmoved, is drawn instead.
        if !(patches.k.abs() <= MAX_K)
            || patches.patches.iter().any(|p| p.moved.iter().flatten().any(|x| !x.is_finite()))
        {
            log::warn!(
                "`{name}`: a displacement of {} is too large to tessellate on the GPU; it keeps the uniform mesh",
                patches.k
            );
            return None;
        }
        let material = &scene.materials[patches.material];
        let mut params = GpuParams { k: patches.k, ..GpuParams::default() };
        let (heights, size): (Vec<f32>, [u32; 2]) = match material.height_field {
            Some(ProceduralHeight::Sine { frequency, amplitude }) => {
                (params.kind, params.amplitude, params.frequency) = (1, amplitude, frequency.to_array());
                (vec![0.0], [1, 1])
            }
            Some(ProceduralHeight::Noise { seed, cells, octaves, amplitude }) => {
                (params.kind, params.amplitude) = (2, amplitude);
                (params.noise_seed, params.noise_cells, params.noise_octaves) = (seed, cells, octaves);
                (vec![0.0], [1, 1])
            }
            None => {
                let texture = material.height_map.and_then(|id| scene.textures.get(id.0))?;
                let largest = device.limits().max_texture_dimension_2d;
                let texels = u64::from(texture.width) * u64::from(texture.height);
                if texels > MAX_HEIGHT_TEXELS || texture.width.max(texture.height) > largest {
                    log::warn!(
                        "{}: a height map of {}×{} is too large to tessellate on the GPU; `{name}` keeps the uniform mesh",
                        texture.path.display(),
                        texture.width,
                        texture.height,
                    );
                    return None;
                }
                let level = MipLevel::from_texture(texture);
                params.map_size = [level.width, level.height];
                (level.texels.iter().map(|t| t.x).collect(), params.map_size)
            }
        };
        let heights = device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("tessellation::heights"),
                size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&heights),
        );
        Some(Object {
            patch_buffer: patch_buffer(device, &patches),
            heights: heights.create_view(&wgpu::TextureViewDescriptor::default()),
            centre: centre(&patches),
            patches,
            uniform: UniformBuffer::new(device, "tessellation::params", &params),
            params,
            buffers: None,
            levels: Levels::default(),
            group: None,
        })
    }

    /// Places the patches again if the object moved since they were made.
    fn follow(&mut self, device: &wgpu::Device, scene: &Scene) {
        let Some(object) = scene.objects.get(self.patches.object) else { return };
        if object.world_from_local == self.patches.world_from_local {
            return;
        }
        let index = scene.displaced.iter().position(|s| s.object == self.patches.object);
        if let Some(moved) = index.and_then(|i| Patches::new(scene, i)) {
            self.patch_buffer = patch_buffer(device, &moved);
            self.centre = centre(&moved);
            self.patches = moved;
            self.levels = Levels::default();
            self.group = None;
        }
    }

    /// Writes `levels` and the parameters, growing the buffers (and making the group again)
    /// where they lack room or the patches were placed again. The totals are within the bound,
    /// so they fit in 32 bits.
    fn upload(&mut self, gpu: &Gpu, layout: &wgpu::BindGroupLayout, levels: Levels) {
        let device = &gpu.device;
        let (vertex_count, triangle_count) = (levels.vertices as u32, levels.triangles as u32);
        let need = [levels.patches.len() as u32, vertex_count, triangle_count];
        let fits = self.buffers.as_ref().is_some_and(|(.., room)| room.iter().zip(need).all(|(&r, n)| r >= n));
        if !fits {
            // Room for a little more than asked, so a moving camera does not grow them every frame.
            let room = need.map(|n| n + n / 4 + 1);
            let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: usage | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                })
            };
            let level_buffer = buffer("tessellation::levels", u64::from(room[0]) * 32, wgpu::BufferUsages::COPY_DST);
            let vertices = buffer("tessellation::vertices", u64::from(room[1]) * 48, wgpu::BufferUsages::VERTEX);
            let indices = buffer("tessellation::indices", u64::from(room[2]) * 12, wgpu::BufferUsages::INDEX);
            self.buffers = Some((level_buffer, vertices, indices, room));
            self.group = None;
        }
        let (level_buffer, vertices, indices, _) = self.buffers.as_ref().expect("made above");
        let count = vertex_count.max(triangle_count).div_ceil(WORKGROUP);
        self.params.patch_count = levels.patches.len() as u32;
        self.params.vertex_count = vertex_count;
        self.params.triangle_count = triangle_count;
        self.params.row = count.clamp(1, 65_535) * WORKGROUP;
        gpu.queue.write_buffer(level_buffer, 0, bytemuck::cast_slice(&levels.patches));
        self.uniform.write(&gpu.queue, &self.params);
        if self.group.is_none() {
            let buffers = [(1, &self.patch_buffer), (2, level_buffer), (4, vertices), (5, indices)];
            let mut entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding: *binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            entries.push(wgpu::BindGroupEntry { binding: 0, resource: self.uniform.binding() });
            entries
                .push(wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&self.heights) });
            self.group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("tessellation::group"),
                layout,
                entries: &entries,
            }));
        }
        self.levels = levels;
    }

    /// The object's mesh as the GPU made it, in world coordinates.
    fn mesh(&self) -> GpuMesh {
        let (_, vertices, indices, _) = self.buffers.as_ref().expect("uploaded before it is drawn");
        GpuMesh {
            vertices: vertices.clone(),
            indices: indices.clone(),
            index_count: self.params.triangle_count * 3,
            centre: self.centre,
        }
    }
}

/// The storage buffer of `patches`.
fn patch_buffer(device: &wgpu::Device, patches: &Patches) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("tessellation::patches"),
        contents: bytemuck::cast_slice(&patches.patches),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// The centre of the box around the patches' moved corners (the transparency pass sorts by it).
fn centre(patches: &Patches) -> Vec3 {
    let corners = patches.patches.iter().flat_map(|p| p.moved).map(|p| Vec3::from_slice(&p[..3]));
    let (low, high) = corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(p), h.max(p)));
    (low + high) / 2.0
}

/// The first `size` bytes of `buffer`, copied to one the CPU can map.
fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer, size: u64) -> Vec<u8> {
    if size == 0 {
        return Vec::new();
    }
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("tessellation::readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping the tessellation's readback"));
    gpu.wait();
    staging.slice(..).get_mapped_range().map(|b| b.to_vec()).unwrap_or_default()
}
