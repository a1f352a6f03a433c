//! Reading a rendered texture back to the CPU.
//!
//! `copy_texture_to_buffer` needs every row to start at a multiple of 256 bytes, so a
//! 230-pixel-wide RGBA8 image (920 bytes a row) is copied with 1024-byte rows and the padding is
//! dropped on the way out. Any width works.
//!
//! One buffer may hold at most the device's `max_buffer_size` (256 MiB with the limits Mirador
//! asks for), less than a 10000×7000 RGBA8 image needs (280 MB). So the image is copied in bands
//! of whole rows, each band into the same buffer sized to fit, and the bands are joined on the
//! CPU: every size the texture limits allow can be read back, and the buffer never holds more
//! than one band.

/// Why a texture could not be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReadbackError {
    #[error(
        "one {width}-pixel row needs a {row_bytes}-byte readback buffer, more than the device's \
         max_buffer_size limit of {limit} bytes"
    )]
    RowTooWide { width: u32, row_bytes: u64, limit: u64 },
    #[error("the readback buffer could not be mapped: {0}")]
    Map(#[from] wgpu::BufferAsyncError),
    #[error("the readback buffer could not be viewed: {0}")]
    View(#[from] wgpu::MapRangeError),
    #[error("waiting for the readback copy failed: {0}")]
    Poll(#[from] wgpu::PollError),
}

/// Copies mip level 0 of a 2D texture with 4 bytes per texel into a tightly packed `Vec<u8>`,
/// rows from the top.
pub fn read_rgba8(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<Vec<u8>, ReadbackError> {
    read_texels(device, queue, texture, 4)
}

/// Copies mip level 0 of an `Rgba16Float` texture (the rasterizer's HDR target) and widens its
/// R, G and B to `f32` (exactly: every half-float is an `f32`), rows from the top; alpha is
/// dropped.
pub fn read_rgb16f(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<Vec<glam::Vec3>, ReadbackError> {
    assert_eq!(texture.format(), wgpu::TextureFormat::Rgba16Float, "read_rgb16f reads half-float RGBA textures");
    let bytes = read_texels(device, queue, texture, 8)?;
    let half = |b: &[u8]| half::f16::from_le_bytes([b[0], b[1]]).to_f32();
    Ok(bytes.chunks_exact(8).map(|t| glam::Vec3::new(half(&t[0..2]), half(&t[2..4]), half(&t[4..6]))).collect())
}

/// Copies mip level 0 of a 2D texture of `bytes_per_texel` bytes per texel, tightly packed, in
/// bands as large as the device's `max_buffer_size` allows.
pub fn read_texels(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>, ReadbackError> {
    read_texels_in_bands(device, queue, texture, bytes_per_texel, device.limits().max_buffer_size)
}

/// [`read_texels`] with bands of at most `max_band_bytes` bytes (padded rows included). The
/// band size is a parameter so that tests can force many bands on a small image; the result
/// does not depend on it.
pub fn read_texels_in_bands(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    max_band_bytes: u64,
) -> Result<Vec<u8>, ReadbackError> {
    let (width, height) = (texture.width(), texture.height());
    let row = u64::from(width) * u64::from(bytes_per_texel);
    let padded_row = row.next_multiple_of(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT));
    let band_rows = max_band_bytes / padded_row;
    if band_rows == 0 {
        return Err(ReadbackError::RowTooWide { width, row_bytes: padded_row, limit: max_band_bytes });
    }
    let band_rows = band_rows.min(u64::from(height.max(1))) as u32;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::band"),
        size: padded_row * u64::from(band_rows),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut packed = Vec::with_capacity((row * u64::from(height)) as usize);
    for first_row in (0..height).step_by(band_rows as usize) {
        let rows = band_rows.min(height - first_row);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback::encoder") });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: first_row, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row as u32),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d { width, height: rows, depth_or_array_layers: 1 },
        );
        queue.submit([encoder.finish()]);
        let slice = buffer.slice(..padded_row * u64::from(rows));
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            // The receiver waits below; it is gone only if this function already returned.
            let _ = sender.send(result);
        });
        device.poll(wgpu::PollType::wait_indefinitely())?;
        // A callback dropped uncalled (the device was lost) counts as a failed mapping.
        receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
        let mapped = slice.get_mapped_range()?;
        for padded in mapped.chunks_exact(padded_row as usize) {
            packed.extend_from_slice(&padded[..row as usize]);
        }
        drop(mapped);
        buffer.unmap();
    }
    Ok(packed)
}
