//! Shared test harness: one headless device per test binary, scene rendering, and golden images
//! compared by FLIP.
//!
//! Golden images live in `tests/golden/NAME.png`. A comparison that fails writes
//! `tests/golden/NAME-actual.png` and `NAME-diff.png` (the FLIP error map; both ignored by git)
//! beside the golden. To bless new goldens, run the tests with `MIRADOR_BLESS=1`, then open every
//! image that changed and look at it before committing it (see README.md).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use mirador::gpu::Gpu;
use mirador::{RenderSettings, Scene};

/// The device every test in this binary shares (device creation dominates small renders).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| {
        Gpu::headless().unwrap_or_else(|e| panic!("image tests need a graphics adapter (see README.md): {e}"))
    })
}

pub fn asset(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(relative)
}

pub fn load(relative: &str) -> Scene {
    Scene::load(&asset(relative)).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` with the rasterizer at its camera's size.
pub fn raster(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    mirador::raster::render_image(gpu(), scene, settings)
}

/// Compares `actual` with `tests/golden/{name}.png` by mean FLIP error and fails above
/// `max_flip_mean`, leaving the actual image and the error map beside the golden.
pub fn assert_golden(name: &str, actual: &image::RgbaImage, max_flip_mean: f32) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("golden");
    let golden_path = dir.join(format!("{name}.png"));
    let actual_path = dir.join(format!("{name}-actual.png"));
    let diff_path = dir.join(format!("{name}-diff.png"));
    if std::env::var_os("MIRADOR_BLESS").is_some() {
        mirador::output::write_png_atomically(actual, &golden_path).expect("writing the blessed golden");
        eprintln!("blessed {} — look at it before committing", golden_path.display());
        return;
    }
    let golden = match image::open(&golden_path) {
        Ok(image) => image.into_rgba8(),
        Err(e) => {
            actual.save(&actual_path).expect("writing the actual image");
            panic!(
                "no golden image {} ({e}); the render is in {}. Look at it, then bless with MIRADOR_BLESS=1",
                golden_path.display(),
                actual_path.display()
            );
        }
    };
    let difference = mirador::compare::difference(&golden, actual).unwrap_or_else(|e| panic!("{name}: {e}"));
    if difference.flip_mean > max_flip_mean {
        actual.save(&actual_path).expect("writing the actual image");
        difference.error_map.save(&diff_path).expect("writing the error map");
        panic!(
            "{name}: mean FLIP {:.5} > {max_flip_mean} (PSNR {:.2} dB); see {} and {}",
            difference.flip_mean,
            difference.psnr_db,
            actual_path.display(),
            diff_path.display()
        );
    }
    let _ = std::fs::remove_file(&actual_path);
    let _ = std::fs::remove_file(&diff_path);
}

/// Where a compute probe finds its data in bind group 0.
pub struct ProbeBindings<'a> {
    /// The storage buffer of input records.
    pub input: u32,
    /// The storage buffer the probe writes one `O` per input record into.
    pub output: u32,
    /// Anything else the probe reads (textures, samplers).
    pub extra: &'a [wgpu::BindGroupEntry<'a>],
}

/// Runs the compute entry point `entry` of the WGSL `source` once per input record (one
/// invocation per workgroup, `inputs.len()` workgroups) and returns its outputs: how a WGSL
/// function is tested against its Rust twin on the same inputs.
pub fn run_probe<I: bytemuck::Pod, O: bytemuck::Pod>(
    label: &str,
    source: &str,
    entry: &str,
    inputs: &[I],
    bindings: ProbeBindings,
) -> Vec<O> {
    use wgpu::util::DeviceExt;
    let gpu = gpu();
    let device = &gpu.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (std::mem::size_of::<O>() * inputs.len()) as u64;
    let buffer = |usage| {
        device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
    };
    let output = buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let staging = buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ);
    let mut entries = vec![
        wgpu::BindGroupEntry { binding: bindings.input, resource: input.as_entire_binding() },
        wgpu::BindGroupEntry { binding: bindings.output, resource: output.as_entire_binding() },
    ];
    entries.extend(bindings.extra.iter().cloned());
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(inputs.len() as u32, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping the probe's results"));
    gpu.wait();
    let view = staging.slice(..).get_mapped_range().expect("mapped above");
    bytemuck::cast_slice(&view).to_vec()
}
