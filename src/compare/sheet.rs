//! Side-by-side sheets: labelled panels in a row, for `mirador compare` and the teaching
//! examples (technique off | on | ray traced). Text is drawn with egui's own default font
//! (Ubuntu Light, from `epaint_default_fonts`), rasterized by `ab_glyph`.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use image::{Rgba, RgbaImage};

/// The sheets' background and text colours.
pub const BACKGROUND: Rgba<u8> = Rgba([24, 24, 28, 255]);
pub const TEXT: Rgba<u8> = Rgba([235, 235, 235, 255]);
const MARGIN: u32 = 8;
const LABEL_HEIGHT: u32 = 28;

/// One labelled image of a sheet.
pub struct Panel {
    pub label: String,
    pub image: RgbaImage,
}

impl Panel {
    pub fn new(label: impl Into<String>, image: RgbaImage) -> Panel {
        Panel { label: label.into(), image }
    }
}

fn font() -> FontRef<'static> {
    FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT).expect("egui's bundled font parses")
}

/// Draws `text` with its top-left corner at `(x, y)`, `size` pixels tall, blending over `image`.
pub fn draw_text(image: &mut RgbaImage, text: &str, x: f32, y: f32, size: f32, color: Rgba<u8>) {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size));
    let mut caret = x;
    let baseline = y + scaled.ascent();
    let mut previous = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = previous {
            caret += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(PxScale::from(size), ab_glyph::point(caret, baseline));
        caret += scaled.h_advance(id);
        previous = Some(id);
        let Some(outline) = font.outline_glyph(glyph) else { continue };
        let bounds = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let (px, py) = (bounds.min.x as i64 + i64::from(gx), bounds.min.y as i64 + i64::from(gy));
            if px < 0 || py < 0 || px >= i64::from(image.width()) || py >= i64::from(image.height()) {
                return;
            }
            let under = image.get_pixel_mut(px as u32, py as u32);
            for k in 0..3 {
                under[k] = (f32::from(under[k]) * (1.0 - coverage) + f32::from(color[k]) * coverage).round() as u8;
            }
        });
    }
}

/// Width of `text` in pixels at `size`.
pub fn text_width(text: &str, size: f32) -> f32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size));
    text.chars().map(|c| scaled.h_advance(font.glyph_id(c))).sum()
}

/// Panels side by side, each under its label, on a dark background. Panels of different heights
/// are top-aligned.
pub fn sheet(panels: &[Panel]) -> RgbaImage {
    let width = MARGIN + panels.iter().map(|p| p.image.width() + MARGIN).sum::<u32>();
    let height = LABEL_HEIGHT + MARGIN + panels.iter().map(|p| p.image.height()).max().unwrap_or(0);
    let mut out = RgbaImage::from_pixel(width, height, BACKGROUND);
    let mut x = MARGIN;
    for panel in panels {
        image::imageops::replace(&mut out, &panel.image, i64::from(x), i64::from(LABEL_HEIGHT));
        draw_text(&mut out, &panel.label, x as f32, 6.0, 18.0, TEXT);
        x += panel.image.width() + MARGIN;
    }
    out
}

/// A horizontal colour bar for the FLIP error map, from 0 (black) to 1 (light yellow), with its
/// two end values written beside it, `width` pixels wide.
pub fn flip_legend(width: u32) -> RgbaImage {
    let entries = flip_rs::MAGMA.len() as u32;
    let (bar_height, height) = (14u32, 40u32);
    let mut legend = RgbaImage::from_pixel(width, height, BACKGROUND);
    let (left, right) = (24u32, width.saturating_sub(24).max(25));
    for x in left..right {
        let t = (x - left) as f32 / (right - left - 1).max(1) as f32;
        let [r, g, b] = super::magma((t * (entries - 1) as f32).round() / (entries - 1) as f32);
        for y in 4..4 + bar_height {
            legend.put_pixel(x, y, Rgba([r, g, b, 255]));
        }
    }
    draw_text(&mut legend, "0", left as f32 - 14.0, 2.0, 16.0, TEXT);
    draw_text(&mut legend, "1", right as f32 + 4.0, 2.0, 16.0, TEXT);
    let caption = "FLIP error per pixel";
    draw_text(&mut legend, caption, (width as f32 - text_width(caption, 14.0)) / 2.0, 22.0, 14.0, TEXT);
    legend
}

/// Rows of panels (each made by [`sheet`]) one under the other, left-aligned.
pub fn rows(rows: &[RgbaImage]) -> RgbaImage {
    let width = rows.iter().map(RgbaImage::width).max().unwrap_or(0);
    let height = rows.iter().map(RgbaImage::height).sum();
    let mut out = RgbaImage::from_pixel(width, height, BACKGROUND);
    let mut y = 0;
    for row in rows {
        image::imageops::replace(&mut out, row, 0, i64::from(y));
        y += row.height();
    }
    out
}

/// Puts `footer` under `image`, right-aligned with the last panel's edge, on the sheet background.
pub fn with_footer(image: &RgbaImage, footer: &RgbaImage) -> RgbaImage {
    let width = image.width().max(footer.width() + MARGIN);
    let mut out = RgbaImage::from_pixel(width, image.height() + footer.height(), BACKGROUND);
    image::imageops::replace(&mut out, image, 0, 0);
    let x = width - footer.width() - MARGIN;
    image::imageops::replace(&mut out, footer, i64::from(x), i64::from(image.height()));
    out
}
