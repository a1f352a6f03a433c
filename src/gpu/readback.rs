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
//!
//! [`Pending`] reads a texture back without waiting: the copy is submitted and the mapping asked
//! for, and a later call takes the texels once the GPU is done. The browser cannot wait for the
//! GPU (its mappings complete only after the page returns to its event loop), so the viewer reads
//! its images back this way everywhere; natively it waits for the device right after asking.

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
    #[error(
        "a {width}×{height} image needs {bytes} bytes to read back at once, more than the device's max_buffer_size of {limit}"
    )]
    TooLarge { width: u32, height: u32, bytes: u64, limit: u64 },
}

/// A readback under way (see the module's header): one buffer, the whole image.
pub struct Pending {
    buffer: wgpu::Buffer,
    mapped: std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>,
    width: u32,
    height: u32,
    row: u64,
    padded_row: u64,
}

impl Pending {
    /// Copies mip level 0 of a 2D texture of `bytes_per_texel` bytes per texel into a buffer and
    /// asks for its mapping.
    pub fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        bytes_per_texel: u32,
    ) -> Result<Pending, ReadbackError> {
        let (width, height) = (texture.width(), texture.height());
        let row = u64::from(width) * u64::from(bytes_per_texel);
        let padded_row = padded_row(row);
        let bytes = padded_row * u64::from(height);
        let limit = device.limits().max_buffer_size;
        if bytes > limit {
            return Err(ReadbackError::TooLarge { width, height, bytes, limit });
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback::pending"),
            size: bytes.max(4),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback::pending") });
        copy_rows(&mut encoder, texture, &buffer, 0..height, padded_row);
        queue.submit([encoder.finish()]);
        let (sender, mapped) = std::sync::mpsc::channel();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |result| {
            // The receiver is gone only if the readback was dropped unread.
            let _ = sender.send(result);
        });
        Ok(Pending { buffer, mapped, width, height, row, padded_row })
    }

    /// The texels, tightly packed, rows from the top, once the GPU has copied them; `None` before.
    pub fn take(&self, device: &wgpu::Device) -> Option<Result<Vec<u8>, ReadbackError>> {
        if let Err(e) = device.poll(wgpu::PollType::Poll) {
            return Some(Err(e.into()));
        }
        let result = match self.mapped.try_recv() {
            Ok(result) => result,
            Err(std::sync::mpsc::TryRecvError::Empty) => return None,
            // A callback dropped uncalled (the device was lost) counts as a failed mapping.
            Err(std::sync::mpsc::TryRecvError::Disconnected) => Err(wgpu::BufferAsyncError),
        };
        Some(result.map_err(ReadbackError::from).and_then(|()| {
            let mapped = self.buffer.slice(..).get_mapped_range()?;
            let mut packed = Vec::with_capacity((self.row * u64::from(self.height)) as usize);
            for padded in mapped.chunks_exact(self.padded_row as usize).take(self.height as usize) {
                packed.extend_from_slice(&padded[..self.row as usize]);
            }
            Ok(packed)
        }))
    }

    /// The image's size in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The texels, once the GPU has copied them: a future that is ready when [`Pending::take`]
    /// is. Its driver polls it again after the device made progress ([`block_on`], or the
    /// page's next frame); it registers no waker.
    pub async fn texels(self, device: &wgpu::Device) -> Result<Vec<u8>, ReadbackError> {
        std::future::poll_fn(|_| match self.take(device) {
            Some(result) => std::task::Poll::Ready(result),
            None => std::task::Poll::Pending,
        })
        .await
    }
}

/// Runs `future` (whose only waits are GPU readbacks) to its end, waiting for the device whenever
/// it is not ready: how the native side drives code the page drives a frame at a time.
#[cfg(not(target_arch = "wasm32"))]
pub fn block_on<T>(device: &wgpu::Device, future: impl std::future::Future<Output = T>) -> T {
    let mut future = std::pin::pin!(future);
    loop {
        if let Some(value) = poll_once(future.as_mut()) {
            return value;
        }
        // An error here is a lost device, which the readback then reports as a failed mapping.
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// Polls `future` once: its value when it is done, `None` while a readback is under way.
pub fn poll_once<F: std::future::Future + ?Sized>(future: std::pin::Pin<&mut F>) -> Option<F::Output> {
    match future.poll(&mut std::task::Context::from_waker(std::task::Waker::noop())) {
        std::task::Poll::Ready(value) => Some(value),
        std::task::Poll::Pending => None,
    }
}

/// A row of `bytes` bytes in a buffer a texture is copied from or to, padded to wgpu's copy
/// alignment.
pub fn padded_row(bytes: u64) -> u64 {
    bytes.next_multiple_of(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
}

/// Records the copy of rows `rows` of mip level 0 into `buffer`, `padded_row` bytes a row.
fn copy_rows(
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    buffer: &wgpu::Buffer,
    rows: std::ops::Range<u32>,
    padded_row: u64,
) {
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d { x: 0, y: rows.start, z: 0 },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row as u32),
                rows_per_image: Some(rows.len() as u32),
            },
        },
        wgpu::Extent3d { width: texture.width(), height: rows.len() as u32, depth_or_array_layers: 1 },
    );
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
    let padded_row = padded_row(row);
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
        copy_rows(&mut encoder, texture, &buffer, first_row..first_row + rows, padded_row);
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
