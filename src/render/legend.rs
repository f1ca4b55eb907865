//! The legend strip under each picture of grains, drawn into the PNG and the SVG alike:
//! at the left the snapshot's time and number of grains over a length scale, and at the
//! right the key to what the picture encodes
//! (the colour bar of the field, the width of the force lines, the length of the
//! stress arms), each with its quantity's name, unit and values. The strip lies below
//! the heap's view, so it never covers a grain.

use super::text::{self, CELL};
use super::{Canvas, INK, Map, shown};
use crate::analyze::input::Input;
use std::fmt::Write as _;
use tiny_skia::{FillRule, Paint, PathBuilder, Rect, Transform};

/// Glyphs are 8·k pixels, k growing with the picture so that text stays legible.
fn text_scale(width: u32) -> u32 {
    (width.saturating_add(400) / 800).max(1)
}

/// Height in pixels of the strip under a picture `width` pixels wide: five text lines
/// (a margin, the label, the bar, the numbers under it, a margin).
pub(super) fn height(width: u32) -> u32 {
    5 * CELL * text_scale(width)
}

/// Where the parts of the strip go, in picture pixels.
struct Strip {
    /// Text height (one glyph cell).
    u: u32,
    k: u32,
    label_y: u32,
    bar_y: u32,
    numbers_y: u32,
    /// The key's span along x (the colour bar's ends).
    x0: u32,
    x1: u32,
}

impl Strip {
    fn of(c: &Canvas) -> Strip {
        let (w, k) = (c.view.width, text_scale(c.view.width));
        let u = CELL * k;
        let top = c.view.height;
        Strip {
            u,
            k,
            label_y: top + u / 2,
            bar_y: top + 7 * u / 4,
            numbers_y: top + 3 * u,
            x0: w / 2,
            x1: w.saturating_sub(u).max(w / 2),
        }
    }
}

#[derive(Clone, Copy)]
enum Anchor {
    Start,
    End,
}

/// The largest 1, 2 or 5 × 10ⁿ not above `x`, with its text; None for x ≤ 0 or NaN.
pub(super) fn round_down(x: f64) -> Option<(f64, String)> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    let e = x.log10().floor() as i32;
    let decade = 10f64.powi(e);
    let m = [5, 2, 1]
        .into_iter()
        .find(|&m| m as f64 * decade <= x)
        .unwrap_or(1);
    let value = m as f64 * decade;
    let text = match e {
        0..=5 => format!("{}", m as i64 * 10i64.pow(e as u32)),
        -4..=-1 => format!("{value:.*}", (-e) as usize),
        _ => format!("{m}e{e}"),
    };
    Some((value, text))
}

/// A value as printed on a key: three significant digits (whole numbers below 10⁵ in
/// full, without decimals), in powers of ten outside 10⁻³ .. 10⁵.
pub(super) fn number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if v.fract() == 0.0 && v.abs() < 1e5 {
        // A count: no decimals that would suggest a fraction of a contact.
        format!("{v:.0}")
    } else if (-3..5).contains(&e) {
        format!("{v:.*}", (2 - e).max(0) as usize)
    } else {
        format!("{v:.2e}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn rgb(c: [u8; 3]) -> String {
    format!("rgb({},{},{})", c[0], c[1], c[2])
}

impl Canvas {
    /// `s` with its top at `y`, starting (or ending, by `anchor`) at `x`; `class` names
    /// its role in the SVG.
    fn text(&mut self, x: u32, y: u32, s: &str, anchor: Anchor, colour: [u8; 3], class: &str) {
        let k = text_scale(self.view.width);
        let left = match anchor {
            Anchor::Start => x as i64,
            Anchor::End => x as i64 - text::width(s, k) as i64,
        };
        text::draw(&mut self.pixmap, left, y as i64, s, k, colour);
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::End => "end",
        };
        // SVG places text by its baseline.
        let _ = writeln!(
            self.svg,
            r#"<text class="{class}" x="{x}" y="{}" font-family="{}" font-size="{:.1}" text-anchor="{anchor}" fill="{}">{}</text>"#,
            y + text::baseline(k),
            text::FAMILY,
            text::font_size(k),
            rgb(colour),
            escape(s)
        );
    }

    /// A filled rectangle in whole pixels, unsmoothed.
    fn rect(&mut self, x: u32, y: u32, w: u32, h: u32, colour: [u8; 3]) {
        let _ = writeln!(
            self.svg,
            r#"<rect x="{x}" y="{y}" width="{w}" height="{h}" fill="{}"/>"#,
            rgb(colour)
        );
        let Some(r) = Rect::from_xywh(x as f32, y as f32, w as f32, h as f32) else {
            return;
        };
        let mut paint = Paint::default();
        paint.set_color_rgba8(colour[0], colour[1], colour[2], 255);
        paint.anti_alias = false;
        self.pixmap
            .fill_rect(r, &paint, Transform::identity(), None);
    }
}

/// A bar for a round length near a fifth of the picture's width, labelled with the
/// length and `unit`.
pub(super) fn length_scale(c: &mut Canvas, unit: &str) {
    let s = Strip::of(c);
    let v = c.view;
    let Some((len, value)) = round_down(0.2 * v.width as f64 / v.scale) else {
        return;
    };
    let length = (len * v.scale).round() as u32;
    let thick = (s.u / 4).max(2);
    c.svg.push_str("<g id=\"length-scale\">\n");
    c.rect(s.u, s.bar_y + s.u / 2 - thick / 2, length, thick, INK);
    // End ticks, so the bar reads as a measure rather than a line.
    for x in [s.u, s.u + length.saturating_sub(s.k)] {
        c.rect(x, s.bar_y, s.k, s.u, INK);
    }
    c.text(
        s.u,
        s.numbers_y,
        &format!("{value} {}", shown(unit)),
        Anchor::Start,
        INK,
        "label",
    );
    c.svg.push_str("</g>\n");
}

/// What the picture shows, above the length scale: the snapshot's time in the scene's
/// units (s, or √(σ/g) in reduced units) and its number of grains, fixed ones included.
pub(super) fn caption(c: &mut Canvas, input: &Input) {
    let s = Strip::of(c);
    let unit = if input.units == "si" {
        "s"
    } else {
        "√(σ/g)"
    };
    let words = format!(
        "t = {} {unit} · {} grains",
        number(input.time),
        input.grains.len()
    );
    c.svg.push_str("<g id=\"caption\">\n");
    c.text(s.u, s.label_y, &words, Anchor::Start, INK, "caption");
    c.svg.push_str("</g>\n");
}

/// The colour map from `lo` (left, the map's 0) to `hi` (right, its 1), `label` above
/// it; a diverging map has its zero marked under the middle.
pub(super) fn colour_bar(c: &mut Canvas, label: &str, lo: f64, hi: f64, map: Map) {
    let s = Strip::of(c);
    if s.x1 <= s.x0 + 1 {
        return;
    }
    let n = s.x1 - s.x0;
    c.svg
        .push_str("<g id=\"colour-bar\">\n<defs><linearGradient id=\"ramp\">");
    let stops = map.stops();
    for (k, col) in stops.iter().enumerate() {
        let _ = write!(
            c.svg,
            r#"<stop offset="{:.4}" stop-color="{}"/>"#,
            k as f64 / (stops.len() - 1) as f64,
            rgb(*col)
        );
    }
    c.svg.push_str("</linearGradient></defs>\n");
    let _ = writeln!(
        c.svg,
        r#"<rect x="{}" y="{}" width="{n}" height="{}" fill="url(#ramp)"/>"#,
        s.x0, s.bar_y, s.u
    );
    // In the PNG one column per pixel, each the map's colour at its place.
    let mut paint = Paint {
        anti_alias: false,
        ..Default::default()
    };
    for i in 0..n {
        let col = map.colour(i as f64 / (n - 1) as f64);
        paint.set_color_rgba8(col[0], col[1], col[2], 255);
        if let Some(r) = Rect::from_xywh((s.x0 + i) as f32, s.bar_y as f32, 1.0, s.u as f32) {
            c.pixmap.fill_rect(r, &paint, Transform::identity(), None);
        }
    }
    c.text(s.x1, s.label_y, label, Anchor::End, INK, "label");
    c.text(s.x0, s.numbers_y, &number(lo), Anchor::Start, INK, "min");
    c.text(s.x1, s.numbers_y, &number(hi), Anchor::End, INK, "max");
    if map == Map::Diverging {
        let mid = s.x0 + n / 2;
        c.rect(mid, s.bar_y + s.u, s.k.max(1), s.u / 4, INK);
        let half = text::width("0", s.k) / 2;
        c.text(mid - half, s.numbers_y, "0", Anchor::Start, INK, "zero");
    }
    c.svg.push_str("</g>\n");
}

/// The force network's key: a wedge from width 0 to the width a line has for a round
/// force (at most the one that `fmax` has, `wmax` pixels, and at most a text line
/// thick), labelled with that force; `label` names the quantity and its unit.
pub(super) fn width_key(c: &mut Canvas, label: &str, fmax: f64, wmax: f32) {
    let s = Strip::of(c);
    let fits = (s.u as f64 / wmax as f64).min(1.0);
    let Some((f, value)) = round_down(fmax * fits) else {
        return;
    };
    if s.x1 <= s.x0 + 1 {
        return;
    }
    let thick = wmax * (f / fmax) as f32;
    let mid = (s.bar_y + s.u / 2) as f32;
    let (x0, x1) = (s.x0 as f32, s.x1 as f32);
    let half = 0.5 * thick;
    c.svg.push_str("<g id=\"width-key\">\n");
    let _ = writeln!(
        c.svg,
        r#"<polygon points="{x0},{mid} {x1},{:.2} {x1},{:.2}" fill="{}"/>"#,
        mid - half,
        mid + half,
        rgb(INK)
    );
    let mut pb = PathBuilder::new();
    pb.move_to(x0, mid);
    pb.line_to(x1, mid - half);
    pb.line_to(x1, mid + half);
    pb.close();
    if let Some(path) = pb.finish() {
        let mut paint = Paint::default();
        paint.set_color_rgba8(INK[0], INK[1], INK[2], 255);
        paint.anti_alias = true;
        c.pixmap.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
    c.text(s.x1, s.label_y, label, Anchor::End, INK, "label");
    c.text(s.x0, s.numbers_y, "0", Anchor::Start, INK, "min");
    c.text(s.x1, s.numbers_y, &value, Anchor::End, INK, "max");
    c.svg.push_str("</g>\n");
}

/// The stress crosses' key: an arm `thick` wide for a round stress (at most `smax`,
/// whose arm is `full` pixels long, and at most a third of the key's span), once in each
/// colour of the crosses with what the colour means; `label` names the quantity.
pub(super) fn arm_key(
    c: &mut Canvas,
    label: &str,
    smax: f64,
    full: f64,
    thick: u32,
    arms: [([u8; 3], &str); 2],
) {
    let s = Strip::of(c);
    // A third of the span leaves room for the words after the arm.
    let fits = ((s.x1 - s.x0) as f64 / 3.0 / full).min(1.0);
    let Some((stress, value)) = round_down(smax * fits) else {
        return;
    };
    let length = (full * stress / smax).round() as u32;
    c.svg.push_str("<g id=\"arm-key\">\n");
    c.text(s.x1, s.label_y, label, Anchor::End, INK, "label");
    for ((colour, meaning), y) in arms.into_iter().zip([s.bar_y, s.numbers_y]) {
        c.rect(s.x0, y + s.u / 2 - thick / 2, length, thick, colour);
        let x = s.x0 + length + s.u / 2;
        c.text(
            x,
            y,
            &format!("{value} {meaning}"),
            Anchor::Start,
            colour,
            "value",
        );
    }
    c.svg.push_str("</g>\n");
}

/// A key of coloured lines: a short stroke in each colour and its text after it, in
/// columns of two rows under `label`, each column after the previous one's longest text.
pub(super) fn line_key(c: &mut Canvas, label: &str, entries: &[([u8; 3], String)]) {
    let s = Strip::of(c);
    if s.x1 <= s.x0 + 1 {
        return;
    }
    // A column: the stroke and its gap (5u/2), the longest text, u to the next column.
    let texts: Vec<u32> = (entries.chunks(2))
        .map(|pair| (pair.iter().map(|e| text::width(&e.1, s.k)).max()).unwrap_or(0))
        .collect();
    let total = texts
        .iter()
        .map(|w| 7 * s.u / 2 + w)
        .sum::<u32>()
        .saturating_sub(s.u);
    // Ending at the strip's right edge when it is longer than the right half (a narrow
    // picture), so that no text is clipped.
    let x0 = s.x0.min(s.x1.saturating_sub(total));
    let thick = (s.u / 4).max(2);
    c.svg.push_str("<g id=\"line-key\">\n");
    c.text(s.x1, s.label_y, label, Anchor::End, INK, "label");
    let mut x = x0;
    for (pair, width) in entries.chunks(2).zip(&texts) {
        for (k, (colour, text)) in pair.iter().enumerate() {
            let y = if k == 0 { s.bar_y } else { s.numbers_y };
            c.rect(x, y + s.u / 2 - thick / 2, 2 * s.u, thick, *colour);
            c.text(x + 5 * s.u / 2, y, text, Anchor::Start, *colour, "value");
        }
        x += 7 * s.u / 2 + width;
    }
    c.svg.push_str("</g>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_lengths_are_round_and_not_above_the_target() {
        for (x, value, text) in [
            (0.296, 0.2, "0.2"),
            (7.9, 5.0, "5"),
            (10.0, 10.0, "10"),
            (1999.0, 1000.0, "1000"),
            (3.3e-6, 2e-6, "2e-6"),
            (0.0012, 0.001, "0.001"),
        ] {
            let (v, t) = round_down(x).unwrap();
            assert!((v - value).abs() < 1e-12 * value, "{x}: {v}");
            assert_eq!(t, text, "{x}");
        }
        assert!(round_down(0.0).is_none() && round_down(f64::NAN).is_none());
    }

    #[test]
    fn numbers_have_three_significant_digits() {
        let cases = [
            (1.0 / std::f64::consts::PI, "0.318"),
            (11.0 / std::f64::consts::PI, "3.50"),
            (-1234.4, "-1234"),
            (2.5e-5, "2.50e-5"),
            (0.0, "0"),
            (6.0, "6"),
        ];
        for (v, text) in cases {
            assert_eq!(number(v), text);
        }
    }
}
