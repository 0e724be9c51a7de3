//! An 8-bit RGB image: what the renderer makes and the encoders take.

use plotters::prelude::*;

/// Row-major RGB, 3 bytes a pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// The pixels.
    pub rgb: Vec<u8>,
}

impl Image {
    /// A `width` × `height` image of one colour.
    pub fn filled(width: u32, height: u32, rgb: [u8; 3]) -> Image {
        Image {
            width,
            height,
            rgb: rgb.repeat((width * height) as usize),
        }
    }

    /// The pixel at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = 3 * (y * self.width + x) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Writes `text` in the top-left corner, white on a dark band.
    pub fn caption(&mut self, text: &str) {
        crate::plot::font();
        let size = (f64::from(self.height) / 22.0).clamp(11.0, 28.0);
        let (w, h) = (self.width, self.height);
        let root = BitMapBackend::with_buffer(&mut self.rgb, (w, h)).into_drawing_area();
        let band = (size * 1.5) as i32;
        let width = (text.chars().count() as f64 * size * 0.6) as i32 + 12;
        // Drawing on an in-memory buffer only fails on impossible sizes.
        let _ = root.draw(&Rectangle::new(
            [(0, 0), (width, band)],
            RGBColor(10, 16, 24).mix(0.6).filled(),
        ));
        let _ = root.draw(&Text::new(
            text.to_string(),
            (6, (size * 0.25) as i32),
            ("sans-serif", size).into_font().color(&WHITE),
        ));
        let _ = root.present();
    }

    /// Tiles `images` (all of the first one's size) `columns` across,
    /// row by row; empty places are black.
    pub fn sheet(images: &[Image], columns: u32) -> Image {
        let Some(first) = images.first() else {
            return Image::filled(1, 1, [0, 0, 0]);
        };
        let (w, h) = (first.width, first.height);
        let columns = columns.clamp(1, images.len() as u32);
        let rows = (images.len() as u32).div_ceil(columns);
        let mut out = Image::filled(w * columns, h * rows, [0, 0, 0]);
        for (k, im) in images.iter().enumerate() {
            let (cx, cy) = (k as u32 % columns, k as u32 / columns);
            for y in 0..h.min(im.height) {
                let src = 3 * (y * im.width) as usize;
                let dst = 3 * ((cy * h + y) * out.width + cx * w) as usize;
                let n = 3 * w.min(im.width) as usize;
                out.rgb[dst..dst + n].copy_from_slice(&im.rgb[src..src + n]);
            }
        }
        out
    }

    /// PNG bytes.
    pub fn png(&self) -> Result<Vec<u8>, String> {
        crate::png_file::encode_rgb(self.width, self.height, &self.rgb)
    }
}
