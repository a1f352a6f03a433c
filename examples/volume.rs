//! Direct volume rendering, step by step (docs/course/11-volumes.md).
//!
//! A volume is a scalar field sampled on a grid of voxels. To see it, a ray is cast through each
//! pixel and cut into `k` equally spaced samples between where it enters and leaves the grid's
//! box. Each sample is
//! 1. **reconstructed** from the voxels around it: the nearest voxel's value (the voxels show as
//!    blocks) or trilinear interpolation of the eight around it;
//! 2. **classified** by a transfer function into a colour `C_v` and an opacity `α_v` (given per
//!    voxel of thickness, so corrected to `1 − (1 − α_v)^ℓ` for a sample standing for `ℓ`
//!    voxels);
//! 3. **shaded** with the voxel illumination `C = C_amb + C_luz·k_dif·(n·L)`, `n` the normalized
//!    gradient of the field, estimated by forward or central differences;
//! 4. **composited** front to back, `C_out = C_in + (1 − α_in)·α_v·C`,
//!    `α_out = α_in + (1 − α_in)·α_v`, and the ray stops early once `α_out` is nearly 1.
//!
//! An **isosurface** is the other way to look at the same samples: the first place where the
//! field crosses one value, found between two samples and refined by bisection, shaded like any
//! surface. The ray tracer and the rasterizer's ray-marching pass take the same samples per pixel.
//!
//! Run with `cargo run --release --example volume [OUT.png]`; writes `volume.png` by default.

use std::path::{Path, PathBuf};

use anyhow::Context;
use image::RgbaImage;
use mirador::compare::sheet::{Panel, rows, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::{VolumeGradient, VolumeMode, VolumeReconstruction, VolumeView};
use mirador::trace::whitted::RayCounts;
use mirador::trace::{RenderControl, Tracer};
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
Direct volume rendering, one step of the pipeline per panel (ray traced unless marked raster).
Row 1, reconstruction and gradients: Marschner-Lobb's test field on its standard 41^3 grid, seen
close up as its isosurface f = 0.5. Nearest reconstruction shows the voxels as blocks (and their
gradients as noise); trilinear interpolation gives the smooth rings; forward differences shift
the normals by half a voxel and streak the shading that central differences keep smooth (FLIP
map of the two).
Row 2, classification and shading: a CT-like head phantom (64^3, Hounsfield-like units) through a
transfer function that leaves air clear, makes soft tissue faint pink, the two lesions red and
bone a faint white; the ventricles (0 HU) stay clear. No shading shows the classified colours
composited front to back; gradient shading adds C_amb + C_luz*k_dif*(n.L); the rasterizer marches
the same samples (FLIP map of raster against traced); the isosurface at 500 HU is only the skull.
The thin red layer on the skull is partial volume: its blurred edge passes through the lesions'
values, and classification cannot tell them apart.
Row 3, the step: at 2 voxels the thin skull is undersampled (rings), but opacity correction keeps
the overall opacity; without correction the opacity grows with the number of samples: step 0.25
is too opaque and step 2 too clear.
Row 4, early termination: with opaque bone a ray stops at the skull. Samples per pixel as heat
(black none, white 512): without termination every ray marches the whole box, with it the rays
that meet bone stop there. Empty air still costs samples: nothing skips it.";

/// Marschner and Lobb's field as its isosurface, seen from close enough that a voxel spans about
/// ten pixels.
const MARSCHNER_LOBB: &str = r#"
[camera]
eye = [0.55, 1.1, 1.25]
center = [0.05, 0.25, 0.1]
fovy = 40
width = 320
height = 240

[world]
ambient = [0.2, 0.2, 0.22]
background = [0.05, 0.05, 0.07]

[materials.ivory]
color = [0.85, 0.8, 0.7]
ks = 0.3
shininess = 30

[[lights]]
name = "key"
type = "directional"
direction = [-0.5, -1.0, -0.4]
intensity = 0.9

[[volumes]]
name = "marschner-lobb"
field = { type = "marschner_lobb", resolution = 41 }
range = [0, 1]
mode = "isosurface"
iso = 0.5
material = "ivory"
rotate = [-90, 0, 0]
"#;

/// The phantom, its transfer function left as `TRANSFER`.
const PHANTOM: &str = r#"
[camera]
eye = [0.8, 0.45, 2.45]
center = [0.0, 0.0, 0.0]
fovy = 38
width = 320
height = 240

[world]
ambient = [0.25, 0.25, 0.28]
background = [0.05, 0.05, 0.07]

[materials.bone]
color = [0.9, 0.86, 0.78]
ks = 0.2
shininess = 20

[[lights]]
name = "key"
type = "directional"
direction = [0.5, -0.7, -0.5]
intensity = 0.9

[[volumes]]
name = "phantom"
field = { type = "phantom", resolution = 64 }
range = [-1000, 1000]
iso = 500
material = "bone"
transfer = TRANSFER
"#;

/// Soft tissue faint, lesions red, bone a faint white: every tissue seen through the others.
const TRANSLUCENT: &str = "[
  { value = -1000, colour = [0, 0, 0], alpha = 0 },
  { value = -100, colour = [0.8, 0.55, 0.45], alpha = 0 },
  { value = 40, colour = [0.8, 0.55, 0.45], alpha = 0.02 },
  { value = 150, colour = [0.8, 0.55, 0.45], alpha = 0 },
  { value = 330, colour = [0.95, 0.15, 0.08], alpha = 0 },
  { value = 400, colour = [0.95, 0.15, 0.08], alpha = 0.5 },
  { value = 470, colour = [0.95, 0.15, 0.08], alpha = 0 },
  { value = 700, colour = [0.95, 0.92, 0.85], alpha = 0 },
  { value = 1000, colour = [0.95, 0.92, 0.85], alpha = 0.12 },
]";

/// The same soft tissue, and bone opaque from 500 HU.
const OPAQUE_BONE: &str = "[
  { value = -1000, colour = [0, 0, 0], alpha = 0 },
  { value = -100, colour = [0.8, 0.55, 0.45], alpha = 0 },
  { value = 40, colour = [0.8, 0.55, 0.45], alpha = 0.02 },
  { value = 150, colour = [0.8, 0.55, 0.45], alpha = 0 },
  { value = 300, colour = [0.95, 0.92, 0.85], alpha = 0 },
  { value = 500, colour = [0.95, 0.92, 0.85], alpha = 1 },
  { value = 1000, colour = [0.95, 0.92, 0.85], alpha = 1 },
]";

fn parse(text: &str, name: &str) -> anyhow::Result<Scene> {
    Ok(mirador::scene::file::parse(text, Path::new(name))?)
}

/// Traces `scene` and prints the volume samples it took and those early termination saved.
fn trace(label: &str, scene: &Scene, settings: &RenderSettings) -> (RgbaImage, RayCounts) {
    let tracer = Tracer::new(scene, settings);
    let (radiance, stats) = tracer.render(&RenderControl::default()).expect("nothing cancels this render");
    let counts = stats.rays;
    let planned = counts.volume_samples + counts.volume_samples_saved;
    if planned == 0 {
        println!("{label:>28}: an isosurface (its search's samples are not counted)");
    } else {
        println!(
            "{label:>28}: {:>9} samples taken, {:>9} saved by early termination ({:.1} %)",
            counts.volume_samples,
            counts.volume_samples_saved,
            100.0 * counts.volume_samples_saved as f64 / planned as f64
        );
    }
    (radiance.to_rgba8(mirador::output::OutputTransform::of(settings)), counts)
}

fn traced(label: &str, scene: &Scene, settings: &RenderSettings) -> Panel {
    Panel::new(label, trace(label, scene, settings).0)
}

fn flip(label: &str, reference: &RgbaImage, test: &RgbaImage) -> anyhow::Result<Panel> {
    let difference = mirador::compare::difference(reference, test)?;
    Ok(Panel::new(format!("{label} ({:.3})", difference.flip_mean), difference.error_map))
}

fn millions(n: u64) -> String {
    format!("{:.1} M", n as f64 / 1e6)
}

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("volume.png"), PathBuf::from);
    println!("{EXPLANATION}\n");
    let gpu = Gpu::headless()?;
    let with = |base: &RenderSettings, change: &dyn Fn(&mut RenderSettings)| {
        let mut settings = base.clone();
        change(&mut settings);
        settings
    };

    // Row 1: reconstruction and gradients.
    let ml = parse(MARSCHNER_LOBB, "marschner_lobb.toml")?;
    let base = ml.settings.clone();
    let nearest = with(&base, &|s| s.volume.reconstruction = VolumeReconstruction::Nearest);
    let forward = with(&base, &|s| s.volume.gradient = VolumeGradient::Forward);
    let (central_image, _) = trace("trilinear, central", &ml, &base);
    let (forward_image, _) = trace("trilinear, forward", &ml, &forward);
    let first = vec![
        traced("nearest", &ml, &nearest),
        Panel::new("trilinear, central", central_image.clone()),
        Panel::new("forward differences", forward_image.clone()),
        flip("FLIP forward/central", &central_image, &forward_image)?,
    ];

    // Row 2: classification, shading, both renderers, the isosurface.
    let phantom = parse(&PHANTOM.replace("TRANSFER", TRANSLUCENT), "phantom.toml")?;
    // A quarter voxel: at the default half voxel the thin skull already rings.
    let base = with(&phantom.settings, &|s| s.volume.step = 0.25);
    let mut headless = Headless::new(&gpu, &phantom);
    let (shaded, _) = trace("gradient shading", &phantom, &base);
    let rasterized = headless.render(&gpu, &phantom, &base);
    let isosurface = with(&base, &|s| s.volume.mode = VolumeMode::Isosurface);
    let second = vec![
        traced("classified, no shading", &phantom, &with(&base, &|s| s.volume.gradient = VolumeGradient::Off)),
        Panel::new("gradient shading", shaded.clone()),
        Panel::new("gradient shading, raster", rasterized.clone()),
        flip("FLIP raster/traced", &shaded, &rasterized)?,
        traced("isosurface 500 HU", &phantom, &isosurface),
    ];

    // Row 3: the step, with and without opacity correction.
    let step = |step: f32, correction: bool| {
        with(&base, &|s| (s.volume.step, s.volume.opacity_correction) = (step, correction))
    };
    let third = vec![
        Panel::new("step 0.25, corrected", shaded),
        traced("step 2, corrected", &phantom, &step(2.0, true)),
        traced("step 0.25, uncorrected", &phantom, &step(0.25, false)),
        traced("step 2, uncorrected", &phantom, &step(2.0, false)),
    ];

    // Row 4: early termination, as samples per pixel.
    let bone = parse(&PHANTOM.replace("TRANSFER", OPAQUE_BONE), "phantom_bone.toml")?;
    let samples = |termination: bool| {
        with(&base, &|s| (s.volume.view, s.volume.early_termination) = (VolumeView::Samples, termination))
    };
    let (all, all_counts) = trace("samples, no termination", &bone, &samples(false));
    let (stopped, stopped_counts) = trace("samples, termination", &bone, &samples(true));
    let saved = 1.0 - stopped_counts.volume_samples as f64 / all_counts.volume_samples as f64;
    let fourth = vec![
        traced("opaque bone", &bone, &base),
        Panel::new(format!("no termination: {}", millions(all_counts.volume_samples)), all),
        Panel::new(
            format!("termination: {} (-{:.0} %)", millions(stopped_counts.volume_samples), 100.0 * saved),
            stopped,
        ),
        Panel::new("termination, raster", Headless::new(&gpu, &bone).render(&gpu, &bone, &samples(true))),
    ];

    let image = rows(&[sheet(&first), sheet(&second), sheet(&third), sheet(&fourth)]);
    mirador::output::write_png_atomically(&image, &out).with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
