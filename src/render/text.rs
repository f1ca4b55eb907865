//! Text in the PNG pictures: tiny-skia draws no text, so the legends are written with
//! the public-domain 8 × 8 bitmap glyphs of font8x8, each pixel of a glyph a square of
//! `scale` × `scale` picture pixels. ASCII only (the labels are written so); any other
//! character is drawn as '?'.

use tiny_skia::{Pixmap, PremultipliedColorU8};

/// The side of one glyph cell in font pixels (the glyphs fill 8 × 8, spacing included).
pub const CELL: u32 = 8;

/// The glyph of `c`: eight rows, bit k of a row the k-th pixel from the left.
pub fn glyph(c: char) -> [u8; 8] {
    let code = if c.is_ascii() {
        c as usize
    } else {
        '?' as usize
    };
    font8x8::legacy::BASIC_LEGACY[code]
}

/// Width in picture pixels of `text` drawn at `scale`.
pub fn width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * CELL * scale
}

/// Draws `text` with its top-left corner at (x, y), opaque, without smoothing; what
/// falls outside the pixmap is clipped.
pub fn draw(pixmap: &mut Pixmap, x: i64, y: i64, text: &str, scale: u32, rgb: [u8; 3]) {
    let (w, h) = (pixmap.width() as i64, pixmap.height() as i64);
    let ink = PremultipliedColorU8::from_rgba(rgb[0], rgb[1], rgb[2], 255)
        .expect("an opaque colour is premultiplied as it is");
    let s = scale as i64;
    let pixels = pixmap.pixels_mut();
    for (k, c) in text.chars().enumerate() {
        let left = x + k as i64 * CELL as i64 * s;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..CELL as i64 {
                if bits >> col & 1 == 0 {
                    continue;
                }
                for py in y + row as i64 * s..y + (row as i64 + 1) * s {
                    for px in left + col * s..left + (col + 1) * s {
                        if (0..w).contains(&px) && (0..h).contains(&py) {
                            pixels[(py * w + px) as usize] = ink;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_glyph_is_drawn_scaled_and_clipped_at_the_edge() {
        let mut p = Pixmap::new(40, 20).unwrap();
        draw(&mut p, -4, 2, "AI", 2, [0, 0, 0]);
        let inked = |x: u32, y: u32| p.pixel(x, y).unwrap().alpha() == 255;
        // 'I' starts 16 − 4 = 12 pixels in; its glyph has bit k of each row at column k.
        for (row, bits) in glyph('I').iter().enumerate() {
            for col in 0..8 {
                let on = bits >> col & 1 == 1;
                for (dx, dy) in [(0, 0), (1, 1)] {
                    let (x, y) = (12 + 2 * col + dx, 2 + 2 * row as u32 + dy);
                    assert_eq!(inked(x, y), on, "'I' at row {row}, column {col}");
                }
            }
        }
        assert_eq!(width("AI", 2), 32);
        assert_eq!(glyph('σ'), glyph('?'), "outside ASCII");
        assert!(glyph('?').iter().any(|&r| r != 0));
    }
}
