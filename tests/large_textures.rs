//! Images as large as docs/scene-format.md promises: up to 32768 on a side is decoded (under
//! Mirador's own decoding limits, not the `image` crate's 512 MiB default) and downscaled to the
//! largest texture; beyond that, or beyond the memory limit, the image is refused by name before
//! any pixel is decoded.
//!
//! The large image is 30000 × 18000, grey, 8 bits: 540 MB decoded, just over the crate's default
//! limit of 512 MiB (536.9 MB), which refuses it as `Memory limit exceeded` as it did the issue's
//! 30000² PNG. The test checks that the default refuses it and Mirador reads it. It is not the
//! 30000² image itself for time, not for memory: the downscale costs about 18 s for 30000² on a
//! busy 2-core machine in the test profile, 60 % of that here, and takes 1.3 GB (the decoded
//! image, its downscale and the RGBA8 texture); an RGBA image of the same size is read the same
//! way with four times the bytes. The PNG is written row by row and compresses to well under a
//! megabyte, every row after the first being "same as above".

use std::path::{Path, PathBuf};

use mirador::scene::texture::{self, MAX_DECODED_SIDE};
use mirador::scene::{ColorSpace, SceneError, environment};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mirador-large-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating a scratch directory");
    dir
}

/// Writes a `width × height` 8-bit grey PNG whose pixel at column x is `shade(x)`, every row the
/// same, streaming one row at a time.
fn write_grey_png(path: &Path, width: u32, height: u32, shade: impl Fn(u32) -> u8) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Up);
    let mut writer = encoder.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row: Vec<u8> = (0..width).map(shade).collect();
    for _ in 0..height {
        std::io::Write::write_all(&mut stream, &row).unwrap();
    }
    stream.finish().unwrap();
}

fn texture_error(path: &Path) -> String {
    match texture::load(path, ColorSpace::Srgb) {
        Err(e @ SceneError::Texture { .. }) => e.to_string(),
        Err(e) => panic!("expected a texture error, got {e:?}"),
        Ok(t) => panic!("{} should be refused, got a {}×{} texture", path.display(), t.width, t.height),
    }
}

#[test]
fn a_png_over_the_image_crates_default_limit_is_decoded_and_downscaled() {
    let dir = scratch("30000");
    let path = dir.join("huge.png");
    // Black on the left half, white on the right.
    write_grey_png(&path, 30000, 18000, |x| if x < 15000 { 0 } else { 255 });
    let refused = image::ImageReader::open(&path).unwrap().decode();
    assert!(
        matches!(refused, Err(image::ImageError::Limits(_))),
        "the image crate's default limit refuses it (else this test proves nothing): {refused:?}"
    );
    let started = std::time::Instant::now();
    let texture = texture::load(&path, ColorSpace::Srgb).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("30000×18000 grey PNG decoded and downscaled in {:.1} s", started.elapsed().as_secs_f64());
    std::fs::remove_dir_all(&dir).unwrap();

    // 18000 · 16384/30000 = 9830.4 rows.
    assert_eq!((texture.width, texture.height), (16384, 9830));
    let texel = |x: usize, y: usize| &texture.rgba8[(y * 16384 + x) * 4..][..4];
    // Texel x is centred on source column (x + ½)·30000/16384 and reaches 1.83 columns either
    // side: texels up to 8189 see only black, from 8194 only white, and 8191 and 8192, which
    // straddle column 15000, mix both.
    for y in [0, 4915, 9829] {
        assert_eq!(texel(0, y), [0, 0, 0, 255]);
        assert_eq!(texel(8189, y), [0, 0, 0, 255]);
        assert_eq!(texel(8194, y), [255, 255, 255, 255]);
        assert_eq!(texel(16383, y), [255, 255, 255, 255]);
    }
    let edge = texel(8191, 100)[0].max(texel(8192, 100)[0]);
    assert!(edge > 0 && edge < 255, "the edge is filtered, not picked: {edge}");
}

#[test]
fn an_image_over_32768_on_a_side_is_refused_by_its_size() {
    let dir = scratch("40000");
    let path = dir.join("too-wide.png");
    write_grey_png(&path, 40000, 1, |_| 128);
    let message = texture_error(&path);
    assert!(message.contains("too-wide.png"), "names the file: {message}");
    assert!(message.contains("40000×1"), "names the size: {message}");
    assert!(message.contains(&MAX_DECODED_SIDE.to_string()), "names the limit: {message}");
    // Environment maps are read by the same decoder.
    let message = match environment::load_image(&path) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("the environment loader should refuse it too"),
    };
    assert!(message.contains("40000×1") && message.contains("32768"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_float_image_over_the_memory_limit_is_refused_from_its_header() {
    // A Radiance header announcing 32768² texels of 32-bit float RGB (12 GiB decoded) and no
    // pixels: refused by what it would take, before anything is allocated.
    let dir = scratch("hdr");
    let path = dir.join("huge.hdr");
    std::fs::write(&path, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32768 +X 32768\n").unwrap();
    let message = texture_error(&path);
    assert!(message.contains("huge.hdr") && message.contains("32768×32768"), "{message}");
    assert!(message.contains("12.0 GiB") && message.contains("at most 8 GiB"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}
