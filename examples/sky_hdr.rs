//! The project's own environment map: the default procedural [`Sky`] (docs/course/07-planar-mirrors.md) baked
//! into a 512 × 256 latitude–longitude Radiance HDR, `assets/environments/sky.hdr`.
//!
//! Each texel holds the sky's radiance towards its centre (`latlong_direction`, the image centre
//! looking along −Z, +Y up), in linear light: the sun's texels are about 20, far above 1, which
//! is why the file is HDR and not PNG. At 0.7° a texel the 1.5° sun is a few texels wide.
//!
//! Run with `cargo run --example sky_hdr [OUT.hdr]`.

use std::path::PathBuf;

use anyhow::Context;
use mirador::scene::{EnvImage, Sky};

fn main() -> anyhow::Result<()> {
    let out = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets").join("environments").join("sky.hdr")
    });
    let sky = Sky::default();
    let image = EnvImage::latlong_from(512, 256, |d| sky.radiance(d));
    let pixels: Vec<image::Rgb<f32>> = image.texels.iter().map(|t| image::Rgb(t.to_array())).collect();
    let file = std::fs::File::create(&out).with_context(|| format!("cannot create {}", out.display()))?;
    image::codecs::hdr::HdrEncoder::new(std::io::BufWriter::new(file))
        .encode(&pixels, image.width as usize, image.height as usize)
        .with_context(|| format!("cannot write {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
