//! A view's traced terms on their way to its traced image, in a buffer the GPU copies them from,
//! layer after layer, each row padded to wgpu's copy alignment. The buffers of terms no frame
//! draws any more are mapped again for the next terms: a moving view's terms (16 bytes a pixel
//! for each layer, 74 MB a frame for the showcase's main view with all four terms) go into memory
//! already there, not into a new buffer that the driver must zero and the kernel must find fresh
//! pages for, as they did before (docs/performance.md).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use crate::trace::Tracer;
use crate::trace::terms::{TermsLayout, TracedTerms, ViewRays, Wanted};
use crate::trace::whitted::RayCounts;

/// Bytes of one pixel of one layer (`Rgba32Float`).
const PIXEL_BYTES: usize = 16;

/// The most buffers kept spare (a moving view needs one; its mirrors' windows and a cube's faces
/// more): past it, the oldest is let go.
const MAX_SPARE: usize = 4;

/// One view's terms in a buffer: the window they cover and the image layer of each.
#[derive(Clone)]
pub(super) struct Upload {
    buffer: wgpu::Buffer,
    window: [u32; 4],
    layers: Vec<u32>,
    /// A number no other terms written have ([`WRITTEN`]): an image that holds these terms
    /// records it, and a frame that would copy them into it again need not.
    pub(super) number: u64,
}

/// Numbers the terms written into buffers, in the whole process (a spare buffer's next terms
/// are new terms: a new number).
static WRITTEN: AtomicU64 = AtomicU64::new(1);

/// Buffers whose terms no frame draws any more, each mapped again once the frames that copy from
/// it are done.
#[derive(Default)]
pub(super) struct SpareBuffers {
    spare: Vec<(wgpu::Buffer, Arc<AtomicBool>)>,
    /// The rows the terms are traced into, kept for the next.
    rows: Vec<[f32; 4]>,
    /// The spare buffers taken since [`Self::reused`] was last asked.
    reused: u64,
}

impl SpareBuffers {
    /// A buffer of at least `size` bytes, mapped for writing: the smallest spare one already
    /// mapped, else a new one.
    fn take(&mut self, device: &wgpu::Device, size: usize) -> wgpu::Buffer {
        // Runs the callbacks of the mappings done (where the backend needs asking).
        let _ = device.poll(wgpu::PollType::Poll);
        let size = size.max(PIXEL_BYTES) as u64;
        let ready = |(_, (buffer, mapped)): &(usize, &(wgpu::Buffer, Arc<AtomicBool>))| {
            buffer.size() >= size && mapped.load(Ordering::Acquire)
        };
        let best = self.spare.iter().enumerate().filter(ready).min_by_key(|(_, (buffer, _))| buffer.size());
        match best.map(|(i, _)| i) {
            Some(i) => {
                self.reused += 1;
                self.spare.swap_remove(i).0
            }
            None => device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("traced::terms"),
                size,
                usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: true,
            }),
        }
    }

    /// Keeps the buffer of `upload`, which no frame will copy from again, for later terms.
    pub(super) fn give_back(&mut self, upload: Upload) {
        let mapped = Arc::new(AtomicBool::new(false));
        let done = Arc::clone(&mapped);
        upload.buffer.map_async(wgpu::MapMode::Write, .., move |result| done.store(result.is_ok(), Ordering::Release));
        self.spare.push((upload.buffer, mapped));
        if self.spare.len() > MAX_SPARE {
            self.spare.remove(0);
        }
    }

    /// How many spare buffers were taken since the last call.
    pub(super) fn reused(&mut self) -> u64 {
        std::mem::take(&mut self.reused)
    }

    /// Lets every spare buffer go.
    pub(super) fn clear(&mut self) {
        *self = SpareBuffers::default();
    }

    /// The terms `wanted` of `view`, traced by `tracer` into a buffer; and the rays.
    pub(super) fn traced(
        &mut self,
        device: &wgpu::Device,
        tracer: &Tracer,
        (view, wanted): (&ViewRays, Wanted),
    ) -> (Upload, RayCounts) {
        let layout = TermsLayout::new(view, wanted);
        // Traced into the rows kept, then copied: the mapped memory is write-only, and its
        // writer cannot be handed to the tracer's threads.
        let mut rows = std::mem::take(&mut self.rows);
        rows.resize(rows.len().max(layout.pixels()), [0.0; 4]);
        let rays = tracer.terms_into(view, wanted, &layout, &mut rows);
        let upload = self.upload(device, (layout.window, &layout.layers), |k, y| layout.line(&rows, k, y));
        self.rows = rows;
        (upload, rays)
    }

    /// The buffer of `terms`, traced elsewhere.
    pub(super) fn terms(&mut self, device: &wgpu::Device, terms: &TracedTerms) -> Upload {
        let width = terms.window[2] as usize;
        let layers: Vec<u32> = terms.layers.iter().map(|(layer, _)| *layer).collect();
        self.upload(device, (terms.window, &layers), |k, y| &terms.layers[k].1[y * width..][..width])
    }

    /// A buffer of the terms of `window`, layer after layer, each of its rows padded: layer `k`'s
    /// pixels of row `y` are `line(k, y)`.
    fn upload<'a>(
        &mut self,
        device: &wgpu::Device,
        (window, layers): ([u32; 4], &[u32]),
        line: impl Fn(usize, usize) -> &'a [[f32; 4]],
    ) -> Upload {
        let [_, _, width, height] = window;
        let (row, height) = (padded_row(width), height as usize);
        let buffer = self.take(device, row * height * layers.len());
        let mut mapping = buffer.get_mapped_range_mut(..).expect("a buffer mapped for writing");
        for k in 0..layers.len() {
            for y in 0..height {
                let line: &[u8] = bytemuck::cast_slice(line(k, y));
                let start = (k * height + y) * row;
                mapping.slice(start..start + line.len()).copy_from_slice(line);
            }
        }
        drop(mapping);
        buffer.unmap();
        Upload { buffer, window, layers: layers.to_vec(), number: WRITTEN.fetch_add(1, Ordering::Relaxed) }
    }
}

impl Upload {
    /// Records the copy of every layer into its layer of `image` (from `first_layer`).
    pub(super) fn copy(&self, encoder: &mut wgpu::CommandEncoder, image: &wgpu::Texture, first_layer: u32) {
        let [x, y, width, height] = self.window;
        let row = padded_row(width) as u32;
        for (k, &layer) in self.layers.iter().enumerate() {
            encoder.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: k as u64 * u64::from(row * height),
                        bytes_per_row: Some(row),
                        rows_per_image: Some(height),
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: image,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x, y, z: first_layer + layer },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
        }
    }
}

/// A layer's row, in bytes, padded to wgpu's copy alignment.
fn padded_row(width: u32) -> usize {
    crate::gpu::readback::padded_row((width as usize * PIXEL_BYTES) as u64) as usize
}
