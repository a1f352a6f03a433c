//! The image loop: pixels in tiles over rayon's threads, with a progress bar, cancellation and
//! ray statistics; and progressive refinement (docs/course/10-anti-aliasing.md#progressive-refinement), which shows a coarse image first.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use web_time::Instant;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::Tracer;
use super::sampling::{jittered_offsets, regular_offsets, subdivide, uses_corner_grid};
use super::whitted::RayCounts;
use crate::base::Ray;
use crate::settings::AntiAliasing;

/// Side of the square tiles the image is cut into: small enough to balance threads, large enough
/// to keep the per-tile overhead invisible.
pub const TILE: u32 = 32;

/// Linear radiance, one value per pixel, row-major from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RadianceImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl RadianceImage {
    /// Through the output transform shared with the rasterizer.
    pub fn to_rgba8(&self, transform: crate::output::OutputTransform) -> image::RgbaImage {
        crate::output::encode_image(self.width, self.height, &self.pixels, transform)
    }
}

/// What a finished render measured.
#[derive(Clone, Copy, Debug, Default)]
pub struct TraceStats {
    pub rays: RayCounts,
    pub elapsed: Duration,
}

impl TraceStats {
    pub fn mrays_per_second(&self) -> f64 {
        self.rays.total() as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }
}

impl std::fmt::Display for TraceStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = &self.rays;
        write!(
            f,
            "rays: {} primary, {} shadow, {} reflected, {} refracted; {} in {:.3} s = {:.2} Mrays/s",
            r.primary,
            r.shadow,
            r.reflected,
            r.refracted,
            r.total(),
            self.elapsed.as_secs_f64(),
            self.mrays_per_second()
        )?;
        if r.volume_samples > 0 {
            let planned = r.volume_samples + r.volume_samples_saved;
            write!(
                f,
                "; volume samples: {} taken, {} saved by early termination ({:.1} %)",
                r.volume_samples,
                r.volume_samples_saved,
                100.0 * r.volume_samples_saved as f64 / planned as f64
            )?;
        }
        Ok(())
    }
}

/// The render was cancelled before it finished.
#[derive(Debug, thiserror::Error)]
#[error("the render was cancelled")]
pub struct Cancelled;

/// Options of one render that are not image settings.
#[derive(Default)]
pub struct RenderControl<'a> {
    /// Set from another thread to stop the render at the next tile.
    pub cancel: Option<&'a AtomicBool>,
    /// Show a progress bar on the terminal (only drawn when stderr is one).
    pub progress: bool,
}

impl Tracer<'_> {
    /// Renders the whole image with the configured anti-aliasing.
    pub fn render(&self, control: &RenderControl) -> Result<(RadianceImage, TraceStats), Cancelled> {
        let start = Instant::now();
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let mut counts = RayCounts::default();
        let corners = if uses_corner_grid(self.settings.anti_aliasing) {
            Some(self.corner_grid(&mut counts, control)?)
        } else {
            None
        };
        let tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
            .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
            .collect();
        let bar = progress_bar(control.progress, tiles.len() as u64, "tracing");
        let cancelled = |c: &RenderControl| c.cancel.is_some_and(|flag| flag.load(Ordering::Relaxed));
        let rendered: Vec<Option<TracedTile>> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                if cancelled(control) {
                    return None;
                }
                let mut tile_counts = RayCounts::default();
                let (x1, y1) = ((x0 + TILE).min(width), (y0 + TILE).min(height));
                let pixels = if self.settings.anti_aliasing == AntiAliasing::Center {
                    self.centred_tile(x0..x1, y0..y1, &mut tile_counts)
                } else {
                    let mut pixels = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
                    for j in y0..y1 {
                        for i in x0..x1 {
                            pixels.push(self.pixel(i, j, corners.as_ref(), &mut tile_counts));
                        }
                    }
                    pixels
                };
                bar.inc(1);
                Some((x0, y0, pixels, tile_counts))
            })
            .collect();
        bar.finish_and_clear();
        let mut image = RadianceImage { width, height, pixels: vec![Vec3::ZERO; (width * height) as usize] };
        for tile in rendered {
            let (x0, y0, pixels, tile_counts) = tile.ok_or(Cancelled)?;
            counts += tile_counts;
            let tile_width = (x0 + TILE).min(width) - x0;
            for (k, value) in pixels.into_iter().enumerate() {
                let (i, j) = (x0 + k as u32 % tile_width, y0 + k as u32 / tile_width);
                image.pixels[(j * width + i) as usize] = value;
            }
        }
        Ok((image, TraceStats { rays: counts, elapsed: start.elapsed() }))
    }

    /// Rows `rows` of the image, top to bottom, with the configured anti-aliasing: the same values
    /// [`Tracer::render`] gives them. How the browser, which has one thread, traces between frames
    /// (`src/viewer/traced.rs`).
    pub fn render_rows(&self, rows: Range<u32>) -> (Vec<Vec3>, RayCounts) {
        let width = self.scene.camera.width;
        let mut counts = RayCounts::default();
        let corners = uses_corner_grid(self.settings.anti_aliasing).then(|| {
            self.corner_rows(rows.start..rows.end + 1, &mut counts, &RenderControl::default())
                .expect("no cancellation flag, no cancellation")
        });
        let mut pixels = Vec::with_capacity((width * rows.len() as u32) as usize);
        for j in rows {
            for i in 0..width {
                pixels.push(self.pixel(i, j, corners.as_ref(), &mut counts));
            }
        }
        (pixels, counts)
    }

    /// A tile's pixels, row by row, each sampled at its centre: the primary rays traced in
    /// packets of 4 × 4 neighbours ([`crate::trace::accel::wide::packets`]), which find the same
    /// hits as ray by ray, so the image is the one [`Self::pixel`] makes.
    fn centred_tile(&self, columns: Range<u32>, rows: Range<u32>, counts: &mut RayCounts) -> Vec<Vec3> {
        let (width, block) = (columns.len(), 4);
        let mut order = Vec::with_capacity(width * rows.len());
        for by in rows.clone().step_by(block) {
            for bx in columns.clone().step_by(block) {
                for j in by..(by + block as u32).min(rows.end) {
                    order.extend((bx..(bx + block as u32).min(columns.end)).map(|i| (i, j)));
                }
            }
        }
        let camera = self.primary_rays;
        let rays: Vec<Ray> = order.iter().map(|&(i, j)| camera.through(i as f32 + 0.5, j as f32 + 0.5)).collect();
        let mut hits = vec![None; rays.len()];
        let whitted = &self.whitted;
        whitted.accelerator.closest_packets(&whitted.primitives, &rays, 0.0, f32::INFINITY, &mut hits);
        counts.primary += rays.len() as u64;
        let mut pixels = vec![Vec3::ZERO; order.len()];
        for ((&(i, j), ray), hit) in order.iter().zip(&rays).zip(hits) {
            let at = (j - rows.start) as usize * width + (i - columns.start) as usize;
            pixels[at] = whitted.radiance_from_hit(ray, self.primary_cone, hit, counts);
        }
        pixels
    }

    /// One pixel's radiance under the configured anti-aliasing.
    fn pixel(&self, i: u32, j: u32, corners: Option<&CornerGrid>, counts: &mut RayCounts) -> Vec3 {
        let corner = Vec2::new(i as f32, j as f32);
        let mean = |offsets: Vec<Vec2>, counts: &mut RayCounts| {
            let n = offsets.len() as f32;
            offsets.into_iter().map(|o| self.primary(corner + o, counts)).sum::<Vec3>() / n
        };
        let settings = &self.settings;
        match settings.anti_aliasing {
            AntiAliasing::Center => self.primary(corner + 0.5, counts),
            AntiAliasing::Regular => mean(regular_offsets(settings.samples), counts),
            AntiAliasing::Jittered => mean(jittered_offsets(settings.samples, i, j, settings.seed), counts),
            AntiAliasing::Corners | AntiAliasing::Adaptive => {
                let grid = corners.expect("corner modes compute the corner grid first");
                let values = [grid.at(i, j), grid.at(i + 1, j), grid.at(i, j + 1), grid.at(i + 1, j + 1)];
                if settings.anti_aliasing == AntiAliasing::Corners {
                    return values.iter().sum::<Vec3>() / 4.0;
                }
                let mut shoot = |p: Vec2| self.primary(p, counts);
                subdivide(&mut shoot, corner, 1.0, values, 0, settings, self.output)
            }
        }
    }

    /// Radiance at every pixel corner, `(width + 1) × (height + 1)` rays, rows in parallel.
    fn corner_grid(&self, counts: &mut RayCounts, control: &RenderControl) -> Result<CornerGrid, Cancelled> {
        self.corner_rows(0..self.scene.camera.height + 1, counts, control)
    }

    /// Radiance at the pixel corners of corner rows `rows`, rows in parallel.
    fn corner_rows(
        &self,
        rows: Range<u32>,
        counts: &mut RayCounts,
        control: &RenderControl,
    ) -> Result<CornerGrid, Cancelled> {
        let (width, first_row) = (self.scene.camera.width + 1, rows.start);
        let rows: Vec<Option<(Vec<Vec3>, RayCounts)>> = rows
            .into_par_iter()
            .map(|j| {
                if control.cancel.is_some_and(|flag| flag.load(Ordering::Relaxed)) {
                    return None;
                }
                let mut row_counts = RayCounts::default();
                let row = (0..width).map(|i| self.primary(Vec2::new(i as f32, j as f32), &mut row_counts)).collect();
                Some((row, row_counts))
            })
            .collect();
        let mut values = Vec::with_capacity(width as usize * rows.len());
        for row in rows {
            let (row, row_counts) = row.ok_or(Cancelled)?;
            values.extend(row);
            *counts += row_counts;
        }
        Ok(CornerGrid { width, first_row, values })
    }
}

/// A finished tile: its top-left pixel, its pixels row by row, and the rays it took.
type TracedTile = (u32, u32, Vec<Vec3>, RayCounts);

/// Radiance at pixel corners: `width` (the image's + 1) values a row, corner rows from
/// `first_row` on.
struct CornerGrid {
    width: u32,
    first_row: u32,
    values: Vec<Vec3>,
}

impl CornerGrid {
    fn at(&self, i: u32, j: u32) -> Vec3 {
        self.values[((j - self.first_row) * self.width + i) as usize]
    }
}

fn progress_bar(show: bool, length: u64, message: &'static str) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(length);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} tiles, {elapsed} (eta {eta})")
            .expect("the progress template is valid")
            .progress_chars("=> "),
    );
    bar.set_message(message);
    bar
}

/// Progressive refinement (docs/course/10-anti-aliasing.md#progressive-refinement): the image is first traced one ray per `start × start`
/// block and each block filled with it, then each level halves the blocks, tracing only the
/// pixels not traced before, until every pixel has its own centre ray. The final image equals a
/// `center` render exactly; the viewer calls [`Progressive::refine`] between frames, with the
/// tracer of the image's scene.
pub struct Progressive {
    block: u32,
    traced: Vec<Option<Vec3>>,
    image: RadianceImage,
    counts: RayCounts,
}

impl Progressive {
    /// The image `tracer` renders, from blocks of `start` (rounded up to a power of two) pixels a
    /// side.
    pub fn new(tracer: &Tracer, start: u32) -> Progressive {
        let (width, height) = (tracer.scene.camera.width, tracer.scene.camera.height);
        let pixels = (width * height) as usize;
        Progressive {
            block: start.max(1).next_power_of_two() * 2,
            traced: vec![None; pixels],
            image: RadianceImage { width, height, pixels: vec![Vec3::ZERO; pixels] },
            counts: RayCounts::default(),
        }
    }

    /// Traces the next level with `tracer` (the one the image was made for) and returns its block
    /// size, or `None` once the image is complete.
    pub fn refine(&mut self, tracer: &Tracer) -> Option<u32> {
        if self.block == 1 {
            return None;
        }
        self.block /= 2;
        let (b, width, height) = (self.block, self.image.width, self.image.height);
        let traced = &self.traced;
        let new: Vec<(u32, Vec3, RayCounts)> = (0..height.div_ceil(b))
            .into_par_iter()
            .flat_map_iter(|row| {
                let j = row * b;
                (0..width.div_ceil(b)).filter_map(move |col| {
                    let i = col * b;
                    let index = j * width + i;
                    if traced[index as usize].is_some() {
                        return None;
                    }
                    let mut counts = RayCounts::default();
                    let value = tracer.primary(Vec2::new(i as f32 + 0.5, j as f32 + 0.5), &mut counts);
                    Some((index, value, counts))
                })
            })
            .collect();
        for (index, value, counts) in new {
            self.traced[index as usize] = Some(value);
            self.counts += counts;
        }
        for j in 0..height {
            for i in 0..width {
                let anchor = (j - j % b) * width + (i - i % b);
                self.image.pixels[(j * width + i) as usize] =
                    self.traced[anchor as usize].expect("every block's anchor is traced at its level");
            }
        }
        Some(b)
    }

    pub fn image(&self) -> &RadianceImage {
        &self.image
    }

    pub fn rays(&self) -> RayCounts {
        self.counts
    }
}
