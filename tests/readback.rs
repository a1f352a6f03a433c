//! Reading images back and the GPU's errors: a readback in bands gives the same bytes as one
//! band, image sizes are checked against the device's limits, and a wgpu validation error comes
//! back as an `Err` instead of a panic.

mod common;

use mirador::gpu::readback::{ReadbackError, read_texels, read_texels_in_bands};
use mirador::gpu::{GpuError, check_image_size};

/// An RGBA8 texture that can be read back, filled with bytes that differ from row to row and
/// column to column (so a band copied to the wrong place shows), and those bytes.
fn pattern_texture(width: u32, height: u32) -> (wgpu::Texture, Vec<u8>) {
    let gpu = common::gpu();
    let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("readback::pattern"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bytes: Vec<u8> = (0..width * height * 4).map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8).collect();
    gpu.queue.write_texture(
        texture.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 4), rows_per_image: Some(height) },
        size,
    );
    (texture, bytes)
}

#[test]
fn bands_of_any_height_read_back_the_same_bytes_as_one_band() {
    let gpu = common::gpu();
    // 230 pixels make 920-byte rows, padded to 1024 in the buffer.
    let (width, height) = (230, 101);
    let (texture, uploaded) = pattern_texture(width, height);
    let padded_row = 1024;
    let one_band = read_texels_in_bands(&gpu.device, &gpu.queue, &texture, 4, u64::MAX).unwrap();
    assert_eq!(one_band, uploaded, "a single band reads back what was uploaded");
    // One row a band, 7 rows (the last band short), one row less than the image, and one byte
    // short of 2 rows (the band rounds down to whole rows).
    for band_bytes in [padded_row, 7 * padded_row, 100 * padded_row, 2 * padded_row - 1] {
        let banded = read_texels_in_bands(&gpu.device, &gpu.queue, &texture, 4, band_bytes).unwrap();
        assert!(banded == one_band, "bands of {band_bytes} bytes read back different bytes");
    }
    assert!(read_texels(&gpu.device, &gpu.queue, &texture, 4).unwrap() == one_band, "the device's own band size");
}

#[test]
fn a_rendered_frame_reads_back_the_same_in_bands() {
    let gpu = common::gpu();
    let scene = common::load("scenes/seed-simple.toml");
    let mut headless = mirador::raster::Headless::new(gpu, &scene);
    let image = headless.render(gpu, &scene, &scene.settings);
    // seed-simple is 230 pixels wide: 1024-byte padded rows, so 3 rows a band, 77 bands.
    let banded = read_texels_in_bands(&gpu.device, &gpu.queue, &headless.output.texture, 4, 3 * 1024).unwrap();
    assert!(banded == image.as_raw().as_slice(), "the frame read back in 3-row bands differs from one band");
}

#[test]
fn a_band_smaller_than_one_row_is_an_error_naming_the_limit() {
    let gpu = common::gpu();
    let (texture, _) = pattern_texture(300, 4);
    let error = read_texels_in_bands(&gpu.device, &gpu.queue, &texture, 4, 1000).unwrap_err();
    assert!(matches!(error, ReadbackError::RowTooWide { width: 300, row_bytes: 1280, limit: 1000 }), "{error:?}");
    assert!(error.to_string().contains("max_buffer_size"), "{error}");
}

#[test]
fn image_sizes_are_checked_against_the_texture_limit() {
    let small = wgpu::Limits::downlevel_defaults();
    assert_eq!(small.max_texture_dimension_2d, 2048);
    assert_eq!(check_image_size(&small, (2048, 2048)), Ok(()));
    assert_eq!(check_image_size(&small, (2049, 10)), Err(2048));
    assert_eq!(check_image_size(&small, (10, 2049)), Err(2048));
    let gpu = common::gpu();
    let limit = gpu.device.limits().max_texture_dimension_2d;
    let error = gpu.check_image_size((limit + 1, 1)).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("max_texture_dimension_2d") && message.contains(&limit.to_string()), "{message}");
}

#[test]
fn a_validation_error_is_returned_not_raised() {
    let gpu = common::gpu();
    let limit = gpu.device.limits().max_texture_dimension_2d;
    let result = gpu.checked(|| too_wide_texture(limit + 1)).map(drop);
    match result {
        Err(GpuError::Reported { kind, message }) => {
            assert!(kind.contains("validation"), "{kind}");
            assert!(message.contains("readback::too_wide"), "the error names the object: {message}");
            assert!(message.contains(&format!("exceeds the limit of {limit}")), "{message}");
            assert!(!message.contains('\n'), "one line: {message}");
        }
        other => panic!("expected a reported validation error, got {other:?}"),
    }
    // The scopes were popped: the device goes on working, and work without errors is `Ok`.
    assert_eq!(gpu.checked(|| 7).unwrap(), 7);
}

/// A texture one row high and `width` wide.
fn too_wide_texture(width: u32) -> wgpu::Texture {
    common::gpu().device.create_texture(&wgpu::TextureDescriptor {
        label: Some("readback::too_wide"),
        size: wgpu::Extent3d { width, height: 1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}
