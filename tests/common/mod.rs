//! Shared test harness: one headless device per test binary, scene rendering, and golden images
//! compared by FLIP.
//!
//! Golden images live in `tests/golden/NAME.png` and are compared by two statistics of the
//! per-pixel FLIP error (see [`Tolerance`]): the mean over the image, and the mean over its worst
//! 32×32 region, which catches a local change the whole-image mean dilutes. Every image
//! comparison here looks past differences of [`CPU_LEVELS`] (see `tests/README.md`). A comparison that
//! fails writes `tests/golden/NAME-actual.png` and `NAME-diff.png` (the FLIP error map; both
//! ignored by git) beside the golden. To bless new goldens, run the tests with `MIRADOR_BLESS=1`, then open every
//! image that changed and look at it before committing it (see README.md).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use mirador::gpu::Gpu;
use mirador::{RenderSettings, Scene};

/// Every scene under `assets/scenes/` and `assets/scenes/course/`, in order.
pub fn scene_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for folder in ["scenes", "scenes/course"] {
        let folder = asset(folder);
        let entries = std::fs::read_dir(&folder).unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        files.extend(
            entries.map(|e| e.expect("a folder entry").path()).filter(|p| p.extension().is_some_and(|x| x == "toml")),
        );
    }
    files.sort();
    files
}

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

/// An image of `tests/data/`.
pub fn data_image(relative: &str) -> image::RgbaImage {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(relative);
    image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba8()
}

pub fn load(relative: &str) -> Scene {
    Scene::load(&asset(relative)).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` with the rasterizer at its camera's size.
pub fn raster(scene: &Scene, settings: &RenderSettings) -> image::RgbaImage {
    mirador::raster::render_image(gpu(), scene, settings)
}

/// Per-pixel differences of up to this many levels (of 255, in every channel) are not counted
/// by any image comparison of the tests: the same build on another CPU generation rounds
/// differently, and a flat area near a rounding boundary moves by one level everywhere
/// (`tests/data/cross-cpu/`). Two levels: the one level measured, and one more of headroom.
pub const CPU_LEVELS: u8 = 2;

/// Mean FLIP error of `test` against `reference`, beyond [`CPU_LEVELS`].
pub fn flip(reference: &image::RgbaImage, test: &image::RgbaImage) -> f32 {
    difference(reference, test).flip_mean
}

/// How `test` differs from `reference`, beyond [`CPU_LEVELS`]; panics on images of two sizes.
pub fn difference(reference: &image::RgbaImage, test: &image::RgbaImage) -> mirador::compare::Difference {
    mirador::compare::difference_beyond(reference, test, CPU_LEVELS).unwrap_or_else(|e| panic!("{e}"))
}

/// What a render may differ from its golden by, in FLIP error (0: identical, 1: as different
/// as black and white).
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// The largest mean over the whole image: bounds a change spread over the image.
    pub flip_mean: f32,
    /// The largest mean over any `REGION`×`REGION` window: bounds a local change, which the
    /// whole-image mean dilutes (a wrong 40×40 patch is 0.7% of a 640×360 image).
    pub worst_region: f32,
}

/// The side, in pixels, of the windows [`GoldenError::worst_region`] averages over.
pub const REGION: u32 = mirador::compare::REGION;

/// How a render differs from its golden, in the statistics a [`Tolerance`] bounds.
#[derive(Clone, Copy, Debug)]
pub struct GoldenError {
    pub flip_mean: f32,
    pub worst_region: f32,
}

impl GoldenError {
    /// The statistics of per-pixel FLIP errors, rows from the top. A NaN error makes both NaN.
    pub fn from_flip(errors: &[f32], width: u32, height: u32) -> GoldenError {
        let figures = mirador::compare::Figures::of(errors, width, height, None);
        GoldenError { flip_mean: figures.mean, worst_region: figures.worst_region }
    }

    /// Compares two images (`golden` the reference).
    pub fn between(golden: &image::RgbaImage, actual: &image::RgbaImage) -> Result<GoldenError, String> {
        let difference = mirador::compare::difference_beyond(golden, actual, CPU_LEVELS).map_err(|e| e.to_string())?;
        Ok(GoldenError::from_flip(&difference.flip_errors, golden.width(), golden.height()))
    }

    /// What exceeds `tolerance`, one message each; empty when the render is within it. A NaN
    /// statistic exceeds every tolerance, though `NaN > t` is false.
    pub fn excesses(&self, tolerance: Tolerance) -> Vec<String> {
        let exceeds = |value: f32, limit: f32| value.is_nan() || value > limit;
        let mut excesses = Vec::new();
        if exceeds(self.flip_mean, tolerance.flip_mean) {
            excesses.push(format!("mean FLIP {:.5} > {}", self.flip_mean, tolerance.flip_mean));
        }
        if exceeds(self.worst_region, tolerance.worst_region) {
            excesses.push(format!(
                "mean FLIP of the worst {REGION}×{REGION} region {:.5} > {}",
                self.worst_region, tolerance.worst_region
            ));
        }
        excesses
    }
}

/// The directory of the golden images.
pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("golden")
}

/// Compares `actual` with `tests/golden/{name}.png` and fails beyond `tolerance` (see
/// [`check_golden`]). With `MIRADOR_BLESS` set, writes the golden instead.
pub fn assert_golden(name: &str, actual: &image::RgbaImage, tolerance: Tolerance) {
    let golden_path = golden_dir().join(format!("{name}.png"));
    if std::env::var_os("MIRADOR_BLESS").is_some() {
        mirador::output::write_png_atomically(actual, &golden_path).expect("writing the blessed golden");
        eprintln!("blessed {} — look at it before committing", golden_path.display());
        return;
    }
    match check_golden(&golden_dir(), name, actual, tolerance) {
        Ok(error) => eprintln!(
            "{name}: mean FLIP {:.5}, worst {REGION}×{REGION} region {:.5}",
            error.flip_mean, error.worst_region
        ),
        Err(message) => panic!("{message}"),
    }
}

/// Compares `actual` with `{dir}/{name}.png`. When it is beyond `tolerance`, or the golden is
/// missing or unreadable or of another size, writes `{name}-actual.png` (and `{name}-diff.png`,
/// the FLIP error map, when there is one) beside the golden and says why.
pub fn check_golden(
    dir: &Path,
    name: &str,
    actual: &image::RgbaImage,
    tolerance: Tolerance,
) -> Result<GoldenError, String> {
    let golden_path = dir.join(format!("{name}.png"));
    let actual_path = dir.join(format!("{name}-actual.png"));
    let diff_path = dir.join(format!("{name}-diff.png"));
    let keep_actual = || actual.save(&actual_path).expect("writing the actual image");
    let golden = match image::open(&golden_path) {
        Ok(image) => image.into_rgba8(),
        Err(e) => {
            keep_actual();
            return Err(format!(
                "no readable golden image {} ({e}); the render is in {}. Look at it, then bless with MIRADOR_BLESS=1",
                golden_path.display(),
                actual_path.display()
            ));
        }
    };
    let difference = match mirador::compare::difference_beyond(&golden, actual, CPU_LEVELS) {
        Ok(difference) => difference,
        Err(e) => {
            keep_actual();
            return Err(format!("{name}: {e}; the render is in {}", actual_path.display()));
        }
    };
    let error = GoldenError::from_flip(&difference.flip_errors, golden.width(), golden.height());
    let excesses = error.excesses(tolerance);
    if !excesses.is_empty() {
        keep_actual();
        difference.error_map.save(&diff_path).expect("writing the error map");
        return Err(format!(
            "{name}: {} (PSNR {:.2} dB); see {} and {}",
            excesses.join(", "),
            difference.psnr_db,
            actual_path.display(),
            diff_path.display()
        ));
    }
    let _ = std::fs::remove_file(&actual_path);
    let _ = std::fs::remove_file(&diff_path);
    Ok(error)
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

/// Every `.rs` file under `dir`, for the tests that read the source tree (its layers, its
/// functions' lengths).
pub fn rust_sources(dir: &Path) -> Vec<PathBuf> {
    sources(dir, "rs")
}

/// Every file under `dir` whose name ends in `.{extension}`.
pub fn sources(dir: &Path, extension: &str) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("reading a source folder") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == extension) {
                files.push(path);
            }
        }
    }
    files
}

/// An address's `%XX` escapes read back (the course site's links, tests/site.rs and
/// tests/web_page.rs).
pub fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let (mut out, mut i) = (Vec::new(), 0);
    while i < bytes.len() {
        match bytes[i] {
            b'%' if i + 3 <= bytes.len() => {
                out.push(u8::from_str_radix(&text[i + 1..i + 3], 16).expect("two hexadecimal digits after %"));
                i += 3;
            }
            byte => {
                out.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8(out).expect("UTF-8")
}
