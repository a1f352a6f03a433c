//! Mip generation for a 4096² RGBA8 texture, three ways, in the same run:
//!
//! - the GPU ([`MipmapGenerator`], one render pass per level, linear averaging through the sRGB
//!   view), timed from submission until the queue is idle;
//! - the `image` crate, level by level with `imageops::resize` and the triangle filter (the
//!   usual CPU way; it filters the stored, sRGB-encoded values, so it is a workload reference,
//!   not the same answer);
//! - Mirador's own CPU [`MipChain::build`] (decode to linear f32, exact box filter, rayon).
//!
//! `cargo bench --bench textures`; prints the median of a few runs and the ratios.

use std::time::{Duration, Instant};

use image::imageops::{FilterType, resize};
use mirador::gpu::Gpu;
use mirador::gpu::mipmap::{MIPMAP_USAGE, MipmapGenerator, mip_level_count};
use mirador::raster::scene_gpu::texture_format;
use mirador::scene::{ColorSpace, Texture};
use mirador::texture::MipChain;

const SIZE: u32 = 4096;
const RUNS: usize = 3;

fn median(mut samples: Vec<Duration>) -> Duration {
    samples.sort();
    samples[samples.len() / 2]
}

fn time(runs: usize, mut f: impl FnMut()) -> Duration {
    median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed()
            })
            .collect(),
    )
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A smooth gradient with hash noise: mip levels with structure and detail.
fn pattern(size: u32) -> Vec<u8> {
    let mut state = 0x9e37_79b9u32;
    let mut bytes = Vec::with_capacity((4 * size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            bytes.extend_from_slice(&[(255 * (x + y) / (2 * size)) as u8, state as u8, (state >> 8) as u8, 255]);
        }
    }
    bytes
}

fn main() {
    let bytes = pattern(SIZE);
    let levels = mip_level_count(SIZE, SIZE);
    println!("mip chain of a {SIZE}×{SIZE} RGBA8 sRGB texture ({levels} levels), median of {RUNS} runs");

    let gpu_time = match Gpu::headless() {
        Ok(gpu) => {
            let device = &gpu.device;
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("bench::texture"),
                size: wgpu::Extent3d { width: SIZE, height: SIZE, depth_or_array_layers: 1 },
                mip_level_count: levels,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: texture_format(ColorSpace::Srgb),
                usage: MIPMAP_USAGE,
                view_formats: &[],
            });
            gpu.queue.write_texture(
                texture.as_image_copy(),
                &bytes,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * SIZE), rows_per_image: Some(SIZE) },
                texture.size(),
            );
            gpu.wait();
            let generator = MipmapGenerator::new(device);
            let generate = || {
                let mut encoder =
                    device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("bench::encoder") });
                generator.record(device, &mut encoder, &texture);
                gpu.queue.submit([encoder.finish()]);
                gpu.wait();
            };
            // The first run builds the pipeline; it is not counted.
            generate();
            let t = time(RUNS, generate);
            println!("  GPU MipmapGenerator ({}): {:10.1} ms", gpu.describe(), ms(t));
            Some(t)
        }
        Err(e) => {
            println!("  GPU: skipped ({e})");
            None
        }
    };

    let base = image::RgbaImage::from_raw(SIZE, SIZE, bytes.clone()).expect("the pattern has SIZE² texels");
    let image_time = time(RUNS, || {
        let mut level = base.clone();
        while level.width() > 1 || level.height() > 1 {
            level = resize(&level, (level.width() / 2).max(1), (level.height() / 2).max(1), FilterType::Triangle);
        }
        std::hint::black_box(&level);
    });
    println!("  image::imageops::resize, triangle, level by level: {:10.1} ms", ms(image_time));

    let texture =
        Texture { path: "bench".into(), width: SIZE, height: SIZE, rgba8: bytes, color_space: ColorSpace::Srgb };
    let chain_time = time(RUNS, || {
        std::hint::black_box(MipChain::build(&texture));
    });
    println!(
        "  mirador MipChain::build (linear f32, {} threads): {:10.1} ms",
        rayon::current_num_threads(),
        ms(chain_time)
    );

    if let Some(gpu_time) = gpu_time {
        println!("  image crate / GPU: {:.2}×", image_time.as_secs_f64() / gpu_time.as_secs_f64());
        println!("  MipChain::build / GPU: {:.2}×", chain_time.as_secs_f64() / gpu_time.as_secs_f64());
    }
}
