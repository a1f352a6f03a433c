//! Reading a rendered texture back to the CPU.
//!
//! `copy_texture_to_buffer` needs every row to start at a multiple of 256 bytes, so a
//! 230-pixel-wide RGBA8 image (920 bytes a row) is copied with 1024-byte rows and the padding is
//! dropped on the way out. Any width works.

/// Copies mip level 0 of a 2D texture with 4 bytes per texel into a tightly packed `Vec<u8>`,
/// rows from the top.
pub fn read_rgba8(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture) -> Vec<u8> {
    read_texels(device, queue, texture, 4)
}

/// Copies mip level 0 of a 2D texture of `bytes_per_texel` bytes per texel, tightly packed.
pub fn read_texels(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Vec<u8> {
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_texel;
    let padded_row = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback::buffer"),
        size: u64::from(padded_row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback::encoder") });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row),
                rows_per_image: Some(height),
            },
        },
        texture.size(),
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |result| result.expect("mapping the readback buffer"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the readback copy");
    let mapped = slice.get_mapped_range().expect("the buffer was mapped for reading above");
    let mut packed = Vec::with_capacity((row * height) as usize);
    for padded in mapped.chunks_exact(padded_row as usize) {
        packed.extend_from_slice(&padded[..row as usize]);
    }
    drop(mapped);
    buffer.unmap();
    packed
}
