//! Mip chains (docs/course/03-mipmaps.md): the CPU chain against the box formula worked by hand, the
//! non-power-of-two rule, the GPU chain against the CPU chain on every level, and the filters
//! (CPU known answers, and the GPU sampler against the CPU sampler).

mod common;

use glam::{Vec2, Vec4};
use mirador::gpu::mipmap::{MipmapGenerator, mip_level_count, read_level_rgba8, sampler_descriptor};
use mirador::output::srgb_decode;
use mirador::raster::scene_gpu::texture_format;
use mirador::scene::{ColorSpace, Texture};
use mirador::texture::mipmap::{Filter, LEVEL_PALETTE, MipChain, MipLevel, level_colour};

/// Uploads `image` with its mip chain, in the format the rasterizer gives its colour space.
fn upload(
    gpu: &mirador::gpu::Gpu,
    generator: &MipmapGenerator,
    label: &str,
    image: &Texture,
) -> mirador::gpu::texture::GpuTexture {
    let pixels = ((image.width, image.height), image.rgba8.as_slice());
    mirador::gpu::mipmap::upload_with_mipmaps(
        (&gpu.device, &gpu.queue),
        generator,
        label,
        pixels,
        texture_format(image.color_space),
    )
}

fn texture(width: u32, height: u32, rgba8: Vec<u8>, color_space: ColorSpace) -> Texture {
    assert_eq!(rgba8.len(), (4 * width * height) as usize);
    Texture { path: "test".into(), width, height, rgba8, color_space }
}

/// A level from one value per texel, put in every channel.
fn grey_level(width: u32, height: u32, values: &[f32]) -> MipLevel {
    assert_eq!(values.len(), (width * height) as usize);
    MipLevel { width, height, texels: values.iter().map(|&v| Vec4::splat(v)).collect() }
}

fn reds(level: &MipLevel) -> Vec<f32> {
    level.texels.iter().map(|t| t.x).collect()
}

/// Reproducible bytes: a smooth gradient plus hash noise, so levels have both structure and detail.
fn test_pattern(width: u32, height: u32, seed: u32) -> Vec<u8> {
    let mut state = seed.wrapping_mul(0x9e37_79b9) | 1;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    let mut bytes = Vec::with_capacity((4 * width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let gradient = (255 * (x + y) / (width + height).max(1)) as u8;
            let n = noise();
            bytes.extend_from_slice(&[gradient, n as u8, (n >> 8) as u8 | 0x80, (n >> 16) as u8]);
        }
    }
    bytes
}

#[test]
fn power_of_two_chain_is_the_box_formula_exactly() {
    // 4×4 → 2×2 → 1×1, by hand:
    //  0  1  2  3
    //  4  5  6  7    →   2.5  4.5   →   7.5
    //  8  9 10 11       10.5 12.5
    // 12 13 14 15
    let chain = MipChain::from_level0(grey_level(4, 4, &(0..16).map(|v| v as f32).collect::<Vec<_>>()));
    assert_eq!(chain.levels.len(), 3);
    assert_eq!(reds(&chain.levels[1]), vec![2.5, 4.5, 10.5, 12.5]);
    assert_eq!(reds(&chain.levels[2]), vec![7.5]);

    // From 8-bit linear texels: M₁[j,k] = (M₀[2j,2k] + M₀[2j+1,2k] + M₀[2j,2k+1] + M₀[2j+1,2k+1])/4
    // with M₀ = byte/255, bit for bit.
    let bytes = test_pattern(4, 4, 3);
    let chain = MipChain::build(&texture(4, 4, bytes.clone(), ColorSpace::Linear));
    let m0 = |i: usize, j: usize, c: usize| bytes[4 * (4 * j + i) + c] as f32 / 255.0;
    for k in 0..2 {
        for j in 0..2 {
            for c in 0..4 {
                let expected = (m0(2 * j, 2 * k, c)
                    + m0(2 * j + 1, 2 * k, c)
                    + m0(2 * j, 2 * k + 1, c)
                    + m0(2 * j + 1, 2 * k + 1, c))
                    / 4.0;
                assert_eq!(chain.levels[1].texels[2 * k + j][c], expected, "texel ({j}, {k}) channel {c}");
            }
        }
    }
    let l1 = &chain.levels[1].texels;
    assert_eq!(chain.levels[2].texels[0], (l1[0] + l1[1] + l1[2] + l1[3]) / 4.0);
}

#[test]
fn srgb_textures_are_averaged_in_linear() {
    // Black and white sRGB texels in a checker: the light they give averages to linear 0.5
    // (encoded 188). Averaging the encoded bytes would give 127.5, i.e. linear 0.21.
    let (b, w) = ([0, 0, 0, 255], [255, 255, 255, 255]);
    let rgba8 = [b, w, w, b].concat();
    let chain = MipChain::build(&texture(2, 2, rgba8, ColorSpace::Srgb));
    let (black, white) = (srgb_decode(0.0), srgb_decode(1.0));
    let expected = (black + white + white + black) / 4.0;
    let got = chain.levels[1].texels[0];
    assert_eq!(got.x, expected);
    assert!((got.x - 0.5).abs() < 1e-6, "{got}");
    assert!((got.x - srgb_decode(0.5)).abs() > 0.2, "averaged the encoded values: {got}");
    assert_eq!(got.w, 1.0, "alpha is linear");
    assert_eq!(chain.levels[1].to_rgba8(ColorSpace::Srgb), vec![188, 188, 188, 255]);

    // A 4×4 sRGB texture by the formula on decoded values.
    let bytes = test_pattern(4, 4, 5);
    let chain = MipChain::build(&texture(4, 4, bytes.clone(), ColorSpace::Srgb));
    let m0 = |i: usize, j: usize, c: usize| {
        let stored = bytes[4 * (4 * j + i) + c] as f32 / 255.0;
        if c == 3 { stored } else { srgb_decode(stored) }
    };
    for k in 0..2 {
        for j in 0..2 {
            for c in 0..4 {
                let expected = (m0(2 * j, 2 * k, c)
                    + m0(2 * j + 1, 2 * k, c)
                    + m0(2 * j, 2 * k + 1, c)
                    + m0(2 * j + 1, 2 * k + 1, c))
                    / 4.0;
                assert_eq!(chain.levels[1].texels[2 * k + j][c], expected, "texel ({j}, {k}) channel {c}");
            }
        }
    }
}

fn assert_close(got: &[f32], expected: &[f32], what: &str) {
    assert_eq!(got.len(), expected.len(), "{what}: sizes");
    for (i, (g, e)) in got.iter().zip(expected).enumerate() {
        assert!((g - e).abs() <= 1e-5 * e.abs().max(1.0), "{what}[{i}]: {g} vs {e}");
    }
}

#[test]
fn odd_sizes_follow_the_footprint_rule() {
    // 1×7 → 1×3 → 1×1 with v_j = j²: odd n = 7 = 2·3 + 1 weighs texels 2j, 2j+1, 2j+2 by
    // (3 − j)/7, 3/7, (j + 1)/7: (0·3 + 1·3 + 4·1)/7 = 1, (4·2 + 9·3 + 16·2)/7 = 67/7,
    // (16·1 + 25·3 + 36·3)/7 = 199/7; then n = 3: thirds, (7 + 67 + 199)/21 = 13 = mean(j²).
    let squares: Vec<f32> = (0..7).map(|j| (j * j) as f32).collect();
    let column = MipChain::from_level0(grey_level(1, 7, &squares));
    assert_eq!(column.levels.iter().map(|l| (l.width, l.height)).collect::<Vec<_>>(), vec![(1, 7), (1, 3), (1, 1)]);
    assert_close(&reds(&column.levels[1]), &[1.0, 67.0 / 7.0, 199.0 / 7.0], "1×7 level 1");
    assert_close(&reds(&column.levels[2]), &[13.0], "1×7 level 2");
    let row = MipChain::from_level0(grey_level(7, 1, &squares));
    assert_eq!(reds(&row.levels[1]), reds(&column.levels[1]), "7×1 is 1×7 transposed");
    assert_eq!(reds(&row.levels[2]), reds(&column.levels[2]));

    // 5×3 → 2×1 → 1×1 with v = i + 10j: x weights (0.4, 0.4, 0.2) and (0.2, 0.4, 0.4), y thirds:
    // 10.8 and 13.2, then their mean 12.
    let ramp: Vec<f32> = (0..3).flat_map(|j| (0..5).map(move |i| (i + 10 * j) as f32)).collect();
    let chain = MipChain::from_level0(grey_level(5, 3, &ramp));
    assert_eq!(chain.levels.iter().map(|l| (l.width, l.height)).collect::<Vec<_>>(), vec![(5, 3), (2, 1), (1, 1)]);
    assert_close(&reds(&chain.levels[1]), &[10.8, 13.2], "5×3 level 1");
    assert_close(&reds(&chain.levels[2]), &[12.0], "5×3 level 2");

    // 3×3 → 1×1: all nine texels at 1/9.
    let nine: Vec<f32> = [1, 2, 4, 8, 16, 32, 64, 128, 256].map(|v| v as f32).to_vec();
    let chain = MipChain::from_level0(grey_level(3, 3, &nine));
    assert_close(&reds(&chain.levels[1]), &[511.0 / 9.0], "3×3 level 1");
}

#[test]
fn every_level_keeps_the_mean_for_every_size() {
    for (w, h) in [(5, 3), (1, 7), (7, 1), (3, 3), (13, 7), (33, 17), (64, 32), (100, 3)] {
        let chain = MipChain::build(&texture(w, h, test_pattern(w, h, w * 31 + h), ColorSpace::Srgb));
        assert_eq!(chain.levels.len() as u32, mip_level_count(w, h));
        assert_eq!((chain.levels.last().unwrap().width, chain.levels.last().unwrap().height), (1, 1));
        let mean = chain.levels[0].mean();
        for (i, level) in chain.levels.iter().enumerate() {
            assert!(level.mean().abs_diff_eq(mean, 2e-6), "{w}×{h} level {i}: mean {} vs {mean}", level.mean());
        }
    }
}

#[test]
fn gpu_chain_matches_cpu_chain_on_every_level() {
    let gpu = common::gpu();
    let generator = MipmapGenerator::new(&gpu.device);
    let mut worst = 0u8;
    for color_space in [ColorSpace::Srgb, ColorSpace::Linear] {
        for (w, h) in [(8, 8), (64, 32), (256, 256), (5, 3), (13, 7), (1, 7), (7, 1), (3, 3), (33, 17), (257, 129)] {
            let image = texture(w, h, test_pattern(w, h, w ^ (h << 8)), color_space);
            let uploaded = upload(gpu, &generator, "mipmaps::test", &image);
            assert_eq!(uploaded.texture.mip_level_count(), mip_level_count(w, h));
            assert_eq!(uploaded.texture.format(), texture_format(color_space));
            let chain = MipChain::build(&image);
            for (level, cpu_level) in chain.levels.iter().enumerate() {
                let gpu_bytes = read_level_rgba8(&gpu.device, &gpu.queue, &uploaded.texture, level as u32);
                let cpu_bytes = cpu_level.to_rgba8(color_space);
                assert_eq!(gpu_bytes.len(), cpu_bytes.len(), "{w}×{h} level {level}: size");
                for (i, (g, c)) in gpu_bytes.iter().zip(&cpu_bytes).enumerate() {
                    let difference = g.abs_diff(*c);
                    worst = worst.max(difference);
                    assert!(
                        difference <= 1,
                        "{color_space:?} {w}×{h} level {level}: byte {i} (texel {}, channel {}): GPU {g}, CPU {c}",
                        i / 4,
                        i % 4
                    );
                }
            }
        }
    }
    println!("largest GPU−CPU difference over all levels: {worst}/255");
}

#[test]
fn cpu_filters_give_known_answers() {
    // Level 0 a 4×4 checker of 0 and 1 (red), level 1 all ½, level 2 ½.
    let checker: Vec<f32> = (0..16).map(|i| ((i % 4 + i / 4) % 2) as f32).collect();
    let chain = MipChain::from_level0(grey_level(4, 4, &checker));
    let red = |uv: Vec2, lod: f32, filter: Filter| chain.sample(uv, lod, filter).x;
    let centre = |i: f32, j: f32| Vec2::new((i + 0.5) / 4.0, (j + 0.5) / 4.0);
    for filter in [Filter::Nearest, Filter::Bilinear] {
        // Texel centres return the texel, and level 0 is read whatever the lod.
        assert_eq!(red(centre(0.0, 0.0), 0.0, filter), 0.0);
        assert_eq!(red(centre(1.0, 0.0), 0.0, filter), 1.0);
        assert_eq!(red(centre(1.0, 0.0), 2.0, filter), 1.0);
        // Repeat wrapping.
        assert_eq!(red(centre(1.0, 0.0) + Vec2::new(1.0, -3.0), 0.0, filter), 1.0);
    }
    // Between two texel centres: nearest picks the square the point is in, bilinear blends.
    assert_eq!(red(Vec2::new(0.24, 0.125), 0.0, Filter::Nearest), 0.0);
    assert_eq!(red(Vec2::new(0.26, 0.125), 0.0, Filter::Nearest), 1.0);
    assert_eq!(red(Vec2::new(0.25, 0.125), 0.0, Filter::Bilinear), 0.5);
    assert_eq!(red(Vec2::new(0.0, 0.125), 0.0, Filter::Bilinear), 0.5, "wraps from texel 3 to texel 0");
    assert_eq!(red(Vec2::new(0.1875, 0.125), 0.0, Filter::Bilinear), 0.25, "a quarter of the way");
    // Nearest mip: λ = 0.5 rounds down to level 0, anything above to level 1.
    assert_eq!(red(centre(0.0, 0.0), 0.5, Filter::NearestMip), 0.0);
    assert_eq!(red(centre(0.0, 0.0), 0.51, Filter::NearestMip), 0.5);
    assert_eq!(red(centre(0.0, 0.0), 1.4, Filter::NearestMip), 0.5);
    // Trilinear: (1 − f)·level ⌊λ⌋ + f·level ⌊λ⌋+1.
    assert_eq!(red(centre(0.0, 0.0), 0.25, Filter::Trilinear), 0.125);
    assert_eq!(red(centre(1.0, 0.0), 0.25, Filter::Trilinear), 0.875);
    assert_eq!(red(centre(1.0, 0.0), 0.0, Filter::Trilinear), 1.0);
    assert_eq!(red(centre(1.0, 0.0), 1.0, Filter::Trilinear), 0.5);
    // λ is clamped to [0, levels − 1].
    assert_eq!(red(centre(1.0, 0.0), -3.0, Filter::Trilinear), 1.0);
    assert_eq!(red(centre(1.0, 0.0), 40.0, Filter::Trilinear), 0.5);
    assert_eq!(red(centre(1.0, 0.0), f32::NAN, Filter::Trilinear), 1.0);
    // The level-colour view: the palette with trilinear's weights, clamped to the last level.
    assert_eq!(chain.sample(centre(0.0, 0.0), 1.0, Filter::LevelColour), LEVEL_PALETTE[1].extend(1.0));
    assert_eq!(chain.sample(centre(0.0, 0.0), 1.5, Filter::LevelColour), level_colour(1.5).extend(1.0));
    assert_eq!(chain.sample(centre(0.0, 0.0), 9.0, Filter::LevelColour), LEVEL_PALETTE[2].extend(1.0));

    // A 2×1 level 1 under 4×2: bilinear at a level-0 texel centre of a level-1 texel's edge.
    let ramp = MipChain::from_level0(grey_level(4, 2, &[0.0, 2.0, 4.0, 6.0, 0.0, 2.0, 4.0, 6.0]));
    assert_eq!(reds(&ramp.levels[1]), vec![1.0, 5.0]);
    // u = 0.5 is midway between level 1's centres 0.25 and 0.75.
    assert_eq!(ramp.sample(Vec2::new(0.5, 0.5), 1.0, Filter::Trilinear).x, 3.0);
    assert_eq!(ramp.sample(Vec2::new(0.5, 0.5), 0.5, Filter::Trilinear).x, 3.0);
    assert_eq!(ramp.sample(Vec2::new(0.375, 0.5), 0.5, Filter::Trilinear).x, 0.5 * 2.0 + 0.5 * 2.0);
}

#[test]
fn sampler_descriptors_say_what_the_cpu_filters_do() {
    let nearest = sampler_descriptor(Filter::Nearest, 16);
    assert_eq!(
        (nearest.mag_filter, nearest.lod_max_clamp, nearest.anisotropy_clamp),
        (wgpu::FilterMode::Nearest, 0.0, 1)
    );
    let bilinear = sampler_descriptor(Filter::Bilinear, 1);
    assert_eq!((bilinear.min_filter, bilinear.lod_max_clamp), (wgpu::FilterMode::Linear, 0.0));
    let nearest_mip = sampler_descriptor(Filter::NearestMip, 8);
    assert_eq!((nearest_mip.mipmap_filter, nearest_mip.anisotropy_clamp), (wgpu::MipmapFilterMode::Nearest, 1));
    let trilinear = sampler_descriptor(Filter::Trilinear, 8);
    assert_eq!((trilinear.mipmap_filter, trilinear.anisotropy_clamp), (wgpu::MipmapFilterMode::Linear, 8));
    assert_eq!(trilinear.address_mode_u, wgpu::AddressMode::Repeat);
}

const SAMPLING_PROBE: &str = r#"
struct SampleCase { uv: vec2f, lod: f32, _pad: f32 }
@group(0) @binding(0) var probe_texture: texture_2d<f32>;
@group(0) @binding(1) var probe_sampler: sampler;
@group(0) @binding(2) var<storage, read> sample_cases: array<SampleCase>;
@group(0) @binding(3) var<storage, read_write> sample_results: array<vec4f>;

@compute @workgroup_size(1)
fn cs_sampling_probe(@builtin(global_invocation_id) id: vec3u) {
    let c = sample_cases[id.x];
    sample_results[id.x] = textureSampleLevel(probe_texture, probe_sampler, c.uv, c.lod);
}
"#;

/// The GPU sampler from `sampler_descriptor` reads what `MipChain::sample` reads, given the same
/// levels (the GPU's own, read back, so that only the filtering is compared).
#[test]
fn gpu_sampler_matches_cpu_sampling() {
    let gpu = common::gpu();
    let device = &gpu.device;
    let generator = MipmapGenerator::new(device);
    let (w, h) = (16, 8);
    let image = texture(w, h, test_pattern(w, h, 99), ColorSpace::Srgb);
    let uploaded = upload(gpu, &generator, "mipmaps::sampled", &image);
    let levels = (0..mip_level_count(w, h))
        .map(|level| {
            let bytes = read_level_rgba8(device, &gpu.queue, &uploaded.texture, level);
            let (lw, lh) = ((w >> level).max(1), (h >> level).max(1));
            MipLevel::from_texture(&texture(lw, lh, bytes, ColorSpace::Srgb))
        })
        .collect();
    let chain = MipChain { levels };
    // Texel centres and quarter points of level 0 (exact bilinear weights in any hardware's
    // sub-texel precision), and levels of detail away from nearest-mip's rounding point.
    let mut cases: Vec<[f32; 4]> = Vec::new();
    for (i, lod) in [-1.0f32, 0.0, 0.25, 0.4, 0.6, 1.0, 1.3, 2.0, 2.75, 3.6, 10.0].into_iter().enumerate() {
        for j in 0..12 {
            let uv =
                Vec2::new((j as f32 + 0.5 + 0.25 * (i % 2) as f32) / w as f32, ((j * 5 % 8) as f32 + 0.5) / h as f32);
            cases.push([uv.x, uv.y, lod, 0.0]);
        }
    }
    for filter in [Filter::Nearest, Filter::Bilinear, Filter::NearestMip, Filter::Trilinear] {
        let sampler = device.create_sampler(&sampler_descriptor(filter, 1));
        let extra = [
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&uploaded.view) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
        ];
        let bindings = common::ProbeBindings { input: 2, output: 3, extra: &extra };
        let results: Vec<[f32; 4]> =
            common::run_probe("sampling_probe", SAMPLING_PROBE, "cs_sampling_probe", &cases, bindings);
        for (c, r) in cases.iter().zip(&results) {
            let cpu = chain.sample(Vec2::new(c[0], c[1]), c[2], filter);
            let got = Vec4::from_array(*r);
            // Hardware blends with a few bits of weight precision (8 on most devices).
            assert!(
                got.abs_diff_eq(cpu, 4e-3),
                "{filter:?} at uv ({}, {}), λ = {}: GPU {got}, CPU {cpu}",
                c[0],
                c[1],
                c[2]
            );
        }
    }
}
