//! Text captions rendered with an embedded font (no system fonts needed).

use super::Image;
use ab_glyph::{Font, FontRef, PxScale, ScaleFont};

fn font() -> FontRef<'static> {
    FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT).expect("the embedded font parses")
}

/// Draws `text` with its top-left corner at `(x, y)`, `size` pixels high; returns the width.
/// Lines are separated by `\n`.
pub fn draw_text(img: &mut Image, x: f32, y: f32, size: f32, text: &str, rgb: [u8; 3]) -> f32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size));
    let mut max_w: f32 = 0.0;
    for (li, line) in text.lines().enumerate() {
        let mut caret = x;
        let base = y + scaled.ascent() + li as f32 * (scaled.height() + scaled.line_gap());
        let mut prev = None;
        for ch in line.chars() {
            let id = scaled.glyph_id(ch);
            if let Some(p) = prev {
                caret += scaled.kern(p, id);
            }
            let g = id.with_scale_and_position(PxScale::from(size), ab_glyph::point(caret, base));
            caret += scaled.h_advance(id);
            prev = Some(id);
            if let Some(og) = font.outline_glyph(g) {
                let b = og.px_bounds();
                og.draw(|gx, gy, c| img.blend(b.min.x as i64 + gx as i64, b.min.y as i64 + gy as i64, rgb, c));
            }
        }
        max_w = max_w.max(caret - x);
    }
    max_w
}
