//! Text in the PNG pictures: tiny-skia draws no text, so the legends are rasterised with
//! fontdue from a subset of DejaVu Sans bundled in `assets/fonts/` (Latin-1, Greek and
//! the mathematical signs the labels use: σ, ⟨f⟩, √, −; its licence beside it), each
//! glyph's coverage blended onto the picture. The SVG names the same face, so both
//! pictures read alike. A character the subset lacks is drawn as the font's empty box.
//!
//! A line of text is `CELL · k` pixels high (k the legend's scale); the glyphs are
//! `SIZE · CELL · k` pixels to the em, their baseline `baseline(k)` below the line's top.

use fontdue::{Font, FontSettings};
use std::sync::OnceLock;
use tiny_skia::{Pixmap, PremultipliedColorU8};

/// The height of one line of text per unit of the legend's scale, in picture pixels.
pub const CELL: u32 = 8;

/// The em size per line height: DejaVu's capitals are 0.73 em high and its descenders
/// 0.24 em deep, so at 1.2 a line holds a capital and a descender with a pixel to spare.
const SIZE: f32 = 1.2;

/// The face the SVG asks for (the viewer's own copy, else its sans-serif).
pub const FAMILY: &str = "DejaVu Sans, sans-serif";

static FONT: OnceLock<Font> = OnceLock::new();

fn font() -> &'static Font {
    FONT.get_or_init(|| {
        let bytes = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");
        Font::from_bytes(bytes as &[u8], FontSettings::default())
            .expect("the bundled font parses (tested)")
    })
}

/// The glyphs' size in pixels to the em at scale k.
pub fn font_size(scale: u32) -> f32 {
    SIZE * (CELL * scale) as f32
}

/// Pixels from a line's top to its baseline at scale k: the capitals' tops then sit
/// about a tenth of a line below the top.
pub fn baseline(scale: u32) -> u32 {
    (0.95 * (CELL * scale) as f32).round() as u32
}

/// Whether the bundled font has a glyph for `c`.
pub fn has_glyph(c: char) -> bool {
    font().lookup_glyph_index(c) != 0
}

/// Width in picture pixels of `text` drawn at `scale`: the sum of its glyphs' advances,
/// rounded up.
pub fn width(text: &str, scale: u32) -> u32 {
    let px = font_size(scale);
    let w: f32 = text
        .chars()
        .map(|c| font().metrics(c, px).advance_width)
        .sum();
    w.ceil() as u32
}

/// Draws `text` with its line's top-left corner at (x, y) in `rgb`, each glyph's
/// coverage blended over what is there; what falls outside the pixmap is clipped.
pub fn draw(pixmap: &mut Pixmap, x: i64, y: i64, text: &str, scale: u32, rgb: [u8; 3]) {
    let (w, h) = (pixmap.width() as i64, pixmap.height() as i64);
    let px = font_size(scale);
    let base = y + baseline(scale) as i64;
    let pixels = pixmap.pixels_mut();
    let mut pen = x as f32;
    for c in text.chars() {
        let (m, coverage) = font().rasterize(c, px);
        // fontdue's box: xmin right of the pen, ymin above the baseline (its bottom),
        // rows from the top.
        let left = (pen + m.xmin as f32).round() as i64;
        let top = base - (m.ymin as i64 + m.height as i64);
        for row in 0..m.height {
            for col in 0..m.width {
                let a = coverage[row * m.width + col];
                let (px_, py) = (left + col as i64, top + row as i64);
                if a == 0 || !(0..w).contains(&px_) || !(0..h).contains(&py) {
                    continue;
                }
                let p = &mut pixels[(py * w + px_) as usize];
                *p = blend(*p, rgb, a);
            }
        }
        pen += m.advance_width;
    }
}

/// `rgb` at coverage a over the premultiplied pixel p (source-over).
fn blend(p: PremultipliedColorU8, rgb: [u8; 3], a: u8) -> PremultipliedColorU8 {
    let (a, keep) = (a as u32, 255 - a as u32);
    let mix = |s: u8, d: u8| ((s as u32 * a + d as u32 * keep + 127) / 255) as u8;
    let alpha = (255 * a + p.alpha() as u32 * keep + 127) / 255;
    PremultipliedColorU8::from_rgba(
        mix(rgb[0], p.red()).min(alpha as u8),
        mix(rgb[1], p.green()).min(alpha as u8),
        mix(rgb[2], p.blue()).min(alpha as u8),
        alpha as u8,
    )
    .expect("channels are clamped to alpha")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inked(p: &Pixmap) -> Vec<(u32, u32)> {
        (0..p.height())
            .flat_map(|y| (0..p.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| p.pixel(x, y).unwrap().alpha() > 0)
            .collect()
    }

    #[test]
    fn the_font_has_the_legends_signs() {
        for c in "σ ρ φ θ ⟨f⟩ √ − · ° ² ⁻ ≤ μ τ Δ".chars() {
            assert!(has_glyph(c), "{c:?}");
        }
        assert!(!has_glyph('漢'), "outside the subset");
    }

    #[test]
    fn text_lies_in_its_line_and_within_its_width() {
        for k in [1, 2, 3] {
            let s = "Pg σ [m g/σ] 123";
            let (u, wid) = ((CELL * k) as i64, width(s, k) as i64);
            let mut p = Pixmap::new(400, 100).unwrap();
            draw(&mut p, 10, 20, s, k, [0, 0, 0]);
            let ink = inked(&p);
            assert!(ink.len() > 20 * k as usize, "scale {k}: some ink");
            for &(x, y) in &ink {
                let (x, y) = (x as i64, y as i64);
                // The line's box, a pixel of antialiasing and the descender's room.
                assert!((9..=10 + wid + 1).contains(&x), "scale {k}: x = {x}");
                assert!((20..=20 + u + u / 4).contains(&y), "scale {k}: y = {y}");
            }
            // Capitals reach the top tenth of the line, descenders below the baseline.
            let top = ink.iter().map(|p| p.1 as i64).min().unwrap();
            let bottom = ink.iter().map(|p| p.1 as i64).max().unwrap();
            assert!(top <= 20 + u / 5, "scale {k}: top {top}");
            assert!(bottom > 20 + baseline(k) as i64, "scale {k}: 'g' descends");
        }
        assert!(width("mm", 1) > width("ii", 1), "proportional");
        assert_eq!(width("", 2), 0);
    }

    #[test]
    fn text_is_clipped_at_the_edge_and_blends_over_colour() {
        let mut p = Pixmap::new(60, 24).unwrap();
        p.fill(tiny_skia::Color::from_rgba8(255, 255, 255, 255));
        draw(&mut p, -6, 0, "HHHHHH", 2, [200, 0, 0]);
        let px: Vec<_> = (0..24)
            .flat_map(|y| (0..60).map(move |x| (x, y)))
            .map(|(x, y)| p.pixel(x, y).unwrap())
            .collect();
        // Opaque everywhere, red in the strokes (H's upright ones cover whole pixels),
        // shades of pink at their edges.
        assert!(px.iter().all(|c| c.alpha() == 255));
        assert!(px.iter().any(|c| c.red() == 200 && c.green() == 0));
        assert!(
            px.iter()
                .any(|c| c.green() > 0 && c.green() < 255 && c.red() > 200)
        );
    }
}
