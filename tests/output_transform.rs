//! The output transform runs twice: in `shaders/present.wgsl` for the rasterizer and in
//! `src/output.rs` for the ray tracer. Both must give the same bytes for the same radiance, or
//! `compare` would measure the transforms instead of the renderers.

mod common;

use glam::Vec3;
use mirador::gpu::{readback, texture::GpuTexture};
use mirador::output::OutputTransform;
use mirador::raster::context::FrameEncoder;
use mirador::raster::present::PresentPass;
use mirador::raster::{HDR_FORMAT, OUTPUT_FORMAT};
use mirador::settings::ToneMap;
use wgpu::util::DeviceExt;

/// IEEE half-precision bits of a non-negative value in the normal range (truncating).
fn f16_bits(x: f32) -> u16 {
    if x == 0.0 {
        return 0;
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    assert!((1..31).contains(&exponent), "{x} is outside half precision's normal range");
    ((exponent as u16) << 10) | ((bits >> 13) & 0x3ff) as u16
}

fn f16_value(bits: u16) -> f32 {
    if bits == 0 {
        return 0.0;
    }
    let exponent = i32::from(bits >> 10) - 15;
    (1.0 + f32::from(bits & 0x3ff) / 1024.0) * 2f32.powi(exponent)
}

#[test]
fn gpu_present_pass_matches_the_rust_transform() {
    let gpu = common::gpu();
    let (width, height) = (256u32, 5u32);
    // Rows: a ramp over [0, 1.25] in each channel at once, then per channel, then tiny values,
    // then highlights up to 32 (the tone curves' shoulders), grey and saturated.
    let radiance: Vec<Vec3> = (0..height)
        .flat_map(|row| {
            (0..width).map(move |i| {
                let t = i as f32 / 255.0 * 1.25;
                match row {
                    0 => Vec3::splat(t),
                    1 => Vec3::new(t, t * 0.5, t * 0.25),
                    2 => Vec3::splat(1e-4 + t * 0.01),
                    3 => Vec3::splat(2f32.powf(t * 4.0) - 1.0),
                    _ => Vec3::new(2f32.powf(t * 4.0), 0.3, 0.05 * t),
                }
            })
        })
        .collect();
    let half: Vec<u16> = radiance.iter().flat_map(|c| [c.x, c.y, c.z, 1.0].map(f16_bits)).collect();
    let exact: Vec<Vec3> =
        half.chunks_exact(4).map(|h| Vec3::new(f16_value(h[0]), f16_value(h[1]), f16_value(h[2]))).collect();
    let hdr = gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("output_transform::hdr"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HDR_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&half),
    );
    let hdr_view = hdr.create_view(&Default::default());
    let output = GpuTexture::target(&gpu.device, "output_transform::output", (width, height), OUTPUT_FORMAT);
    let mut present = PresentPass::new(&gpu.device, OUTPUT_FORMAT);
    let curves = [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::Aces, ToneMap::PbrNeutral];
    for (exposure, tone_map) in [1.0, 2.0].into_iter().flat_map(|e| curves.map(|c| (e, c))) {
        let transform = OutputTransform { exposure, tone_map };
        let mut frame = FrameEncoder::new(gpu, false);
        present.record(gpu, &mut frame, &hdr_view, &output.view, transform);
        frame.finish();
        let bytes = readback::read_rgba8(&gpu.device, &gpu.queue, &output.texture).expect("reading the output back");
        let cpu = mirador::output::encode_image(width, height, &exact, transform);
        let worst = bytes.iter().zip(cpu.as_raw()).map(|(&g, &c)| g.abs_diff(c)).max().unwrap();
        assert!(worst <= 1, "{transform:?}: GPU and CPU output transforms differ by up to {worst}/255");
    }
}
