//! An RGBA8 image with PNG output.

use std::io::{self, Write};

/// An 8-bit RGBA image.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGBA bytes.
    pub data: Vec<u8>,
}

impl Image {
    /// A blank image filled with `rgb`.
    pub fn new(width: u32, height: u32, rgb: [u8; 3]) -> Image {
        let mut data = Vec::with_capacity((width * height * 4) as usize);
        for _ in 0..width * height {
            data.extend_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
        Image { width, height, data }
    }

    /// Blends `rgb` with coverage `a ∈ [0, 1]` into pixel `(x, y)` (ignored outside).
    pub fn blend(&mut self, x: i64, y: i64, rgb: [u8; 3], a: f32) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 || a <= 0.0 {
            return;
        }
        let i = ((y as u32 * self.width + x as u32) * 4) as usize;
        let a = a.min(1.0);
        for (d, &c) in self.data[i..i + 3].iter_mut().zip(&rgb) {
            let old = *d as f32;
            *d = (old + (c as f32 - old) * a).round() as u8;
        }
    }

    /// Fills a rectangle.
    pub fn fill_rect(&mut self, x0: i64, y0: i64, w: i64, h: i64, rgb: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.blend(x, y, rgb, 1.0);
            }
        }
    }

    /// Copies `other` into this image with its top-left corner at `(x, y)`.
    pub fn paste(&mut self, other: &Image, x: u32, y: u32) {
        for j in 0..other.height {
            for i in 0..other.width {
                let (tx, ty) = (x + i, y + j);
                if tx < self.width && ty < self.height {
                    let s = ((j * other.width + i) * 4) as usize;
                    let d = ((ty * self.width + tx) * 4) as usize;
                    self.data[d..d + 4].copy_from_slice(&other.data[s..s + 4]);
                }
            }
        }
    }

    /// Encodes the image as PNG.
    pub fn write_png(&self, w: &mut dyn Write) -> io::Result<()> {
        let mut enc = png::Encoder::new(w, self.width, self.height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().map_err(io::Error::other)?;
        wr.write_image_data(&self.data).map_err(io::Error::other)?;
        wr.finish().map_err(io::Error::other)
    }

    /// Places images side by side (top-aligned) on a background.
    pub fn strip(images: &[Image], gap: u32, bg: [u8; 3]) -> Image {
        let w = images.iter().map(|i| i.width).sum::<u32>() + gap * images.len().saturating_sub(1) as u32;
        let h = images.iter().map(|i| i.height).max().unwrap_or(1);
        let mut out = Image::new(w.max(1), h, bg);
        let mut x = 0;
        for im in images {
            out.paste(im, x, 0);
            x += im.width + gap;
        }
        out
    }
}
