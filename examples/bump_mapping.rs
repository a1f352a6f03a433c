//! Bump mapping from a height field, side by side (docs/course/04-bump-mapping.md).
//!
//! The geometry stays flat; only the normal used for shading changes. A grey-level texture
//! gives a height f_h(u, v). Its slopes come from finite differences,
//! du = k·(f_h(u+Δ, v) − f_h(u−Δ, v))/2Δ and dv alike, with Δ one texel and k a user scale.
//! The surface's tangents t_u = ∂p/∂u and t_v = ∂p/∂v are tilted by them, t'_u = t_u + du·n and
//! t'_v = t_v + dv·n, and the perturbed normal is n' = normalize(t'_u × t'_v), turned to n's
//! side. Light then falls on each cobble as if it stood out of the surface. The silhouette
//! stays smooth and no bump casts a shadow: that is where bump mapping shows it is a trick.
//!
//! Run with `cargo run --release --example bump_mapping [OUT.png]`; writes `bump_mapping.png`.

use std::path::PathBuf;

use anyhow::Context;
use mirador::compare::sheet::{Panel, sheet};
use mirador::gpu::Gpu;
use mirador::raster::Headless;
use mirador::settings::BumpView;
use mirador::{RenderSettings, Scene};

const EXPLANATION: &str = "\
flat: bump mapping off | height field: the grey-level f_h(u, v) shown as the surface's colour |
bumped with k × 0.5, × 1, × 2 | the perturbed normals as colours (0.5 + 0.5·n') | ray traced,
with the same finite differences on the tracer's analytic tangents.";

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("bump_mapping.png"), PathBuf::from);
    println!("{EXPLANATION}");
    let scene = Scene::load(&mirador::scene::builtin_path("bumps.toml"))?;
    let gpu = Gpu::headless()?;
    let mut headless = Headless::new(&gpu, &scene);
    let base = scene.settings.clone();
    let with = |change: &dyn Fn(&mut RenderSettings)| {
        let mut settings = base.clone();
        change(&mut settings);
        settings
    };
    let mut panels = vec![Panel::new("flat", headless.render(&gpu, &scene, &with(&|s| s.bump.enabled = false)))];

    // The height field itself: the same scene with each height map as the colour texture.
    let mut heights = scene.clone();
    for material in &mut heights.materials {
        if let Some(map) = material.height_map {
            (material.texture, material.color, material.ks) = (Some(map), glam::Vec3::ONE, 0.0);
        }
    }
    let flat_heights = with(&|s| s.bump.enabled = false);
    panels.push(Panel::new("height field f_h", mirador::raster::render_image(&gpu, &heights, &flat_heights)));

    for scale in [0.5, 1.0, 2.0] {
        panels.push(Panel::new(
            format!("bumped, k × {scale}"),
            headless.render(&gpu, &scene, &with(&|s| s.bump.scale = scale)),
        ));
    }
    panels.push(Panel::new("normals", headless.render(&gpu, &scene, &with(&|s| s.bump.view = BumpView::Normals))));
    panels.push(Panel::new("ray traced", mirador::trace::render_image(&scene, &base)));
    mirador::output::write_png_atomically(&sheet(&panels), &out)
        .with_context(|| format!("writing {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
