//! The budget's sheet: the raster, traced and fully swapped images with their figures, then a
//! bar per approximation (what it costs alone, and left alone) beside its error map (the raster
//! image against the one with that approximation traced), so a teacher sees where each one errs.

use image::{Rgba, RgbaImage};

use super::Budget;
use crate::compare::sheet::{
    BACKGROUND, Panel, TEXT, draw_text, flip_legend, rows, sheet as panels_sheet, with_footer,
};

const ALONE: Rgba<u8> = Rgba([236, 120, 60, 255]);
const LEFT_ALONE: Rgba<u8> = Rgba([90, 150, 230, 255]);
const FLOOR: Rgba<u8> = Rgba([140, 140, 140, 255]);

/// The sheet of `budget`.
pub fn sheet(budget: &Budget) -> RgbaImage {
    let width = budget.raster.width();
    let top = panels_sheet(&[
        Panel::new(format!("raster (FLIP {:.4})", budget.whole), budget.raster.clone()),
        Panel::new("ray traced", budget.traced.clone()),
        Panel::new(format!("every approximation traced (floor {:.4})", budget.floor), budget.hybrid.clone()),
    ]);
    let scale = budget.items.iter().map(|i| i.alone.max(i.left_alone)).fold(budget.whole.max(budget.floor), f32::max);
    let mut lines = vec![top];
    for item in &budget.items {
        let bars = bars(
            width,
            &[
                ("alone", item.alone, ALONE),
                ("left alone", item.left_alone, LEFT_ALONE),
                ("floor", budget.floor, FLOOR),
            ],
            scale,
        );
        lines.push(panels_sheet(&[
            Panel::new(item.name, bars),
            Panel::new(format!("{}: raster against raster with it traced", item.name), item.error_map.clone()),
        ]));
    }
    with_footer(&rows(&lines), &flip_legend(width.clamp(200, 400)))
}

/// A panel `width` wide of horizontal bars, each `(label, value, colour)`, on a common `scale`.
fn bars(width: u32, values: &[(&str, f32, Rgba<u8>)], scale: f32) -> RgbaImage {
    let mut image = RgbaImage::from_pixel(width, 8 + 44 * values.len() as u32, BACKGROUND);
    let left = 110.min(width / 3);
    let length = width.saturating_sub(left + 80);
    for (k, &(label, value, colour)) in values.iter().enumerate() {
        let y = 8 + 44 * k as u32;
        draw_text(&mut image, label, 8.0, y as f32 + 4.0, 16.0, TEXT);
        let bar = ((value / scale.max(1e-6)).clamp(0.0, 1.0) * length as f32).round() as u32;
        for yy in y..(y + 24).min(image.height()) {
            for xx in left..left + bar {
                image.put_pixel(xx, yy, colour);
            }
        }
        draw_text(&mut image, &format!("{value:.4}"), (left + bar + 6) as f32, y as f32 + 4.0, 16.0, TEXT);
    }
    image
}
