//! `talus render`: pictures of an analysed snapshot, in PNG (tiny-skia) and SVG: the
//! grains in their true shapes coloured by a field, the force network with line width
//! proportional to the normal force (paper 000 Fig. 9 and 11), the principal stresses
//! of the moving-average windows as crosses (Fig. 12), and plots of the profiles
//! (plotters): S_zz and S_xx along the base, P(f/⟨f⟩), f(θ). Under each picture of
//! grains a legend strip (`legend`) gives a length scale and the key to its colours or
//! line sizes, with units.

mod clip;
pub mod dump;
mod legend;
pub mod plots;
pub mod text;
pub mod vtk;

use crate::analyze::Analysis;
use crate::base::files::write_atomic;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// Why a picture could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("a picture of {width} × {height} pixels is too large")]
    TooLarge { width: u32, height: u32 },
    #[error("PNG encoding: {0}")]
    Png(String),
    #[error("{}: {message}", path.display())]
    Plot { path: PathBuf, message: String },
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl RenderError {
    fn write(path: &Path) -> impl FnOnce(std::io::Error) -> RenderError + '_ {
        move |source| RenderError::Write {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// What colours the grains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// The grain's own pressure, (σ_max + σ_min)/2 of Σ f ⊗ l over its area.
    Pressure,
    /// Its number of contacts.
    Contacts,
    /// Its orientation (the long axis of a polygon).
    Orientation,
    /// One colour; fixed grains grey.
    Plain,
}

/// Perceptually even colours from dark blue through green to yellow (viridis, sampled),
/// for fields of one sign.
const RAMP: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Colours for a field of both signs, centred on zero (ColorBrewer's RdBu, 9 classes):
/// red for negative (tension) through near-white at zero to blue for positive
/// (compression), the colours of the stress crosses.
const DIVERGING: [[u8; 3]; 9] = [
    [178, 24, 43],
    [214, 96, 77],
    [244, 165, 130],
    [253, 219, 199],
    [247, 247, 247],
    [209, 229, 240],
    [146, 197, 222],
    [67, 147, 195],
    [33, 102, 172],
];

/// Which colour map a picture's field is drawn in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Map {
    /// viridis, from the field's low end to its high end.
    Sequential,
    /// red–white–blue, symmetric about zero (white).
    Diverging,
}

impl Map {
    fn stops(self) -> &'static [[u8; 3]; 9] {
        match self {
            Map::Sequential => &RAMP,
            Map::Diverging => &DIVERGING,
        }
    }

    /// The colour of `t` ∈ [0, 1] on this map (the colour bar, left to right), mixed
    /// linearly between its stops; NaN is the colour of 0.
    pub fn colour(self, t: f64) -> [u8; 3] {
        let stops = self.stops();
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = t * (stops.len() - 1) as f64;
        let k = (x.floor() as usize).min(stops.len() - 2);
        let f = x - k as f64;
        let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
        let (a, b) = (stops[k], stops[k + 1]);
        [mix(a[0], b[0]), mix(a[1], b[1]), mix(a[2], b[2])]
    }
}

/// The colour of `t` ∈ [0, 1] on the sequential map (`Map::Sequential`).
pub fn ramp(t: f64) -> [u8; 3] {
    Map::Sequential.colour(t)
}

/// The colour of `t` ∈ [0, 1] on the diverging map: 0.5 is zero.
pub fn diverging(t: f64) -> [u8; 3] {
    Map::Diverging.colour(t)
}

/// A unit as the pictures write it: the reduced units' length, the grain diameter
/// `sigma` in files, is σ.
pub(crate) fn shown(unit: &str) -> &str {
    match unit {
        "sigma" => "σ",
        u => u,
    }
}

/// What the colours of a picture mean: `label` (the quantity and its unit) from `lo`
/// at the map's 0 to `hi` at its 1.
struct Scale {
    label: String,
    lo: f64,
    hi: f64,
    map: Map,
}

/// The value of `field` per grain, scaled to [0, 1] (by its 2nd and 98th percentiles,
/// so that a few extreme grains do not wash out the rest), and the scale that maps it
/// (None for one colour). A pressure that takes both signs between those percentiles
/// (cohesive grains in tension) is drawn on the diverging map, symmetric about zero,
/// so that white is no stress and the two signs read apart.
fn field_values(a: &Analysis, field: Field) -> (Vec<f64>, Option<Scale>) {
    let raw: Vec<f64> = a
        .input
        .grains
        .iter()
        .enumerate()
        .map(|(k, g)| match field {
            Field::Pressure => {
                let (smax, smin, _) = a.moments[k].scaled(1.0 / g.area).principal();
                0.5 * (smax + smin)
            }
            Field::Contacts => a.counts[k] as f64,
            Field::Orientation => a.axes[k].unwrap_or(f64::NAN) / std::f64::consts::PI,
            Field::Plain => 0.6,
        })
        .collect();
    let label = match field {
        // The grain's stress is a 2D stress: force per length (CSV `sigma_* [f/l]`).
        Field::Pressure => format!(
            "pressure [{}/{}]",
            a.input.force_unit,
            shown(&a.input.length_unit)
        ),
        Field::Contacts => "contacts [-]".into(),
        Field::Orientation => {
            let scale = Scale {
                label: "long axis from horizontal [rad]".into(),
                lo: 0.0,
                hi: std::f64::consts::PI,
                map: Map::Sequential,
            };
            return (raw, Some(scale));
        }
        Field::Plain => return (raw, None),
    };
    let mut sorted: Vec<f64> = raw.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    if sorted.is_empty() {
        return (raw, None);
    }
    let q = |p: f64| sorted[((sorted.len() - 1) as f64 * p).round() as usize];
    let (mut lo, mut hi) = (q(0.02), q(0.98));
    let map = if field == Field::Pressure && lo < 0.0 && hi > 0.0 {
        let m = hi.max(-lo);
        (lo, hi) = (-m, m);
        Map::Diverging
    } else {
        Map::Sequential
    };
    if hi <= lo {
        // One value for all: it sits mid-scale, on a bar around it.
        let d = if lo == 0.0 { 1.0 } else { 0.5 * lo.abs() };
        (lo, hi) = (lo - d, hi + d);
    }
    let values = raw.iter().map(|v| (v - lo) / (hi - lo)).collect();
    (values, Some(Scale { label, lo, hi, map }))
}

/// World (length units, z up) to picture (pixels, y down).
#[derive(Clone, Copy)]
struct View {
    left: f64,
    top: f64,
    scale: f64,
    width: u32,
    height: u32,
}

impl View {
    /// The heap's outline with a margin (grains that rolled far away fall outside).
    fn of(a: &Analysis, width: u32) -> View {
        let o = &a.summary.outline;
        let pad = 0.04 * o.width.max(o.height);
        let (x0, x1, z0, z1) = (o.left - pad, o.right + pad, o.base - pad, o.top + pad);
        let scale = width as f64 / (x1 - x0);
        View {
            left: x0,
            top: z1,
            scale,
            width,
            height: (((z1 - z0) * scale).ceil() as u32).max(1),
        }
    }
    fn p(&self, x: f64, z: f64) -> (f32, f32) {
        (
            ((x - self.left) * self.scale) as f32,
            ((self.top - z) * self.scale) as f32,
        )
    }
}

/// One picture, drawn once into a pixmap and once into SVG text: the view of the heap,
/// and under it the legend strip.
struct Canvas {
    view: View,
    pixmap: Pixmap,
    svg: String,
}

impl Canvas {
    fn new(view: View) -> Result<Canvas, RenderError> {
        let height = view.height.saturating_add(legend::height(view.width));
        let mut pixmap = Pixmap::new(view.width, height).ok_or(RenderError::TooLarge {
            width: view.width,
            height,
        })?;
        pixmap.fill(Color::WHITE);
        let mut svg = String::new();
        let _ = writeln!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">
<rect width="100%" height="100%" fill="white"/>"#,
            w = view.width,
            h = height
        );
        Ok(Canvas { view, pixmap, svg })
    }

    fn shape(
        &mut self,
        g: &crate::analyze::input::Grain,
        fill: [u8; 3],
        stroke: Option<[u8; 3]>,
        line: f32,
    ) {
        let v = self.view;
        let path = if g.corners.len() >= 3 {
            let mut pb = PathBuilder::new();
            let (x, y) = v.p(g.corners[0][0], g.corners[0][1]);
            pb.move_to(x, y);
            for c in &g.corners[1..] {
                let (x, y) = v.p(c[0], c[1]);
                pb.line_to(x, y);
            }
            pb.close();
            let pts: Vec<String> = g
                .corners
                .iter()
                .map(|c| {
                    let (x, y) = v.p(c[0], c[1]);
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = write!(self.svg, r#"<polygon points="{}""#, pts.join(" "));
            pb.finish()
        } else {
            let (x, y) = v.p(g.x, g.z);
            let r = (g.radius * v.scale) as f32;
            let _ = write!(self.svg, r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}""#);
            PathBuilder::from_circle(x, y, r.max(0.1))
        };
        let _ = write!(
            self.svg,
            r#" fill="rgb({},{},{})""#,
            fill[0], fill[1], fill[2]
        );
        if let Some(s) = stroke {
            let _ = write!(
                self.svg,
                r#" stroke="rgb({},{},{})" stroke-width="{line}""#,
                s[0], s[1], s[2]
            );
        }
        self.svg.push_str("/>\n");
        let Some(path) = path else { return };
        let mut paint = Paint::default();
        paint.set_color_rgba8(fill[0], fill[1], fill[2], 255);
        paint.anti_alias = true;
        self.pixmap.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        if let Some(s) = stroke {
            paint.set_color_rgba8(s[0], s[1], s[2], 255);
            let st = Stroke {
                width: line,
                ..Default::default()
            };
            self.pixmap
                .stroke_path(&path, &paint, &st, Transform::identity(), None);
        }
    }

    /// `shape` of a grain and, in a domain periodic in x (`period` > 0), of its images
    /// one period to either side where they reach into the view (a grain astride the
    /// seam shows on both sides).
    fn shapes(
        &mut self,
        g: &crate::analyze::input::Grain,
        period: f64,
        fill: [u8; 3],
        stroke: Option<[u8; 3]>,
        width: f32,
    ) {
        self.shape(g, fill, stroke, width);
        if period <= 0.0 {
            return;
        }
        let (lo, hi) = (
            self.view.left,
            self.view.left + self.view.width as f64 / self.view.scale,
        );
        for shift in [-period, period] {
            if g.right() + shift > lo && g.left() + shift < hi {
                let mut image = g.clone();
                image.x += shift;
                image.corners.iter_mut().for_each(|c| c[0] += shift);
                self.shape(&image, fill, stroke, width);
            }
        }
    }

    fn line(&mut self, a: (f64, f64), b: (f64, f64), width: f32, color: [u8; 3]) {
        let v = self.view;
        let (p, q) = (v.p(a.0, a.1), v.p(b.0, b.1));
        let _ = writeln!(
            self.svg,
            r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="rgb({},{},{})" stroke-width="{width:.2}" stroke-linecap="round"/>"#,
            p.0, p.1, q.0, q.1, color[0], color[1], color[2]
        );
        let mut pb = PathBuilder::new();
        pb.move_to(p.0, p.1);
        pb.line_to(q.0, q.1);
        let Some(path) = pb.finish() else { return };
        let mut paint = Paint::default();
        paint.set_color_rgba8(color[0], color[1], color[2], 255);
        paint.anti_alias = true;
        let st = Stroke {
            width: width.max(0.2),
            line_cap: tiny_skia::LineCap::Round,
            ..Default::default()
        };
        self.pixmap
            .stroke_path(&path, &paint, &st, Transform::identity(), None);
    }

    /// The wall segments, each cut to the view (a floor far wider than the heap must not
    /// run into the legend strip under it).
    fn walls(&mut self, walls: &[[[f64; 2]; 2]], width: f32) {
        let v = self.view;
        let (right, bottom) = (
            v.left + v.width as f64 / v.scale,
            v.top - v.height as f64 / v.scale,
        );
        for w in walls {
            if let Some((a, b)) = clip::clip(w[0], w[1], [v.left, bottom], [right, v.top]) {
                self.line((a[0], a[1]), (b[0], b[1]), width, WALL);
            }
        }
    }

    /// A dashed line from a to b: dashes and gaps `dash` long (world units).
    fn dashed(&mut self, a: (f64, f64), b: (f64, f64), width: f32, color: [u8; 3], dash: f64) {
        let length = (b.0 - a.0).hypot(b.1 - a.1);
        let pieces = (length / dash).floor().max(1.0) as usize;
        let at = |t: f64| (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        for k in (0..pieces).step_by(2) {
            let (t0, t1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            self.line(at(t0), at(t1), width, color);
        }
    }

    fn save(mut self, dir: &Path, stem: &str, files: &mut Vec<PathBuf>) -> Result<(), RenderError> {
        self.svg.push_str("</svg>\n");
        let png = self
            .pixmap
            .encode_png()
            .map_err(|e| RenderError::Png(e.to_string()))?;
        for (ext, bytes) in [("png", png), ("svg", self.svg.into_bytes())] {
            let p = dir.join(format!("{stem}.{ext}"));
            write_atomic(&p, &bytes).map_err(RenderError::write(&p))?;
            files.push(p);
        }
        Ok(())
    }
}

const GREY: [u8; 3] = [200, 200, 200];
/// The walls' colour.
const WALL: [u8; 3] = [90, 70, 50];
const INK: [u8; 3] = [30, 30, 30];
const COMPRESSION: [u8; 3] = [30, 60, 200];
const TENSION: [u8; 3] = [200, 40, 40];
const MIDDLE: [u8; 3] = [30, 90, 210];
const APEX_TOE: [u8; 3] = [230, 130, 0];
const STEEPEST: [u8; 3] = [200, 30, 120];
/// The papers' numbers drawn beside talus's.
const PAPER: [u8; 3] = [0, 140, 70];

/// A number a paper reports, drawn beside talus's own (issue 40 item 5): its value, the
/// spread the paper gives with it, and where in the paper it is.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperNumber {
    pub value: f64,
    pub spread: Option<f64>,
    pub source: String,
}

impl PaperNumber {
    /// "source: value ± spread", as the keys show it.
    pub fn label(&self) -> String {
        match self.spread {
            Some(s) => format!("{}: {} ± {}", self.source, self.value, s),
            None => format!("{}: {}", self.source, self.value),
        }
    }
}

/// The papers' numbers that the pictures draw beside talus's (`talus reproduce`): the
/// angle of repose, in degrees, as lines from the apex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PaperMarks {
    pub repose_deg: Option<PaperNumber>,
}

/// Writes every picture of `a` into `dir`; `width` is the pictures' width in pixels.
pub fn render(
    a: &Analysis,
    dir: &Path,
    field: Field,
    width: u32,
) -> Result<Vec<PathBuf>, RenderError> {
    render_marked(a, dir, field, width, &PaperMarks::default())
}

/// [`render`], with the papers' numbers drawn beside talus's where a picture has room
/// for them.
pub fn render_marked(
    a: &Analysis,
    dir: &Path,
    field: Field,
    width: u32,
    marks: &PaperMarks,
) -> Result<Vec<PathBuf>, RenderError> {
    std::fs::create_dir_all(dir).map_err(RenderError::write(dir))?;
    let mut files = Vec::new();
    let view = View::of(a, width);
    let line = (0.04 * a.summary.mean_diameter * view.scale).clamp(0.3, 2.0) as f32;
    // A domain periodic in x: grains astride the seam drawn on both sides.
    let period = a.input.period_x;
    // Grains coloured by the field.
    let (values, scale) = field_values(a, field);
    let map = scale.as_ref().map_or(Map::Sequential, |s| s.map);
    let mut c = Canvas::new(view)?;
    for (k, g) in a.input.grains.iter().enumerate() {
        let fill = if g.fixed {
            [150, 150, 150]
        } else if values[k].is_finite() {
            map.colour(values[k])
        } else {
            GREY
        };
        c.shapes(g, period, fill, Some(INK), 0.5 * line);
    }
    c.walls(&a.input.walls, 2.0 * line);
    legend::length_scale(&mut c, &a.input.length_unit);
    legend::caption(&mut c, &a.input);
    if let Some(s) = scale {
        legend::colour_bar(&mut c, &s.label, s.lo, s.hi, s.map);
    }
    c.save(dir, "grains", &mut files)?;
    // Force network: grains faint, each contact a line from centre to centre (to the
    // contact point for a wall), its width proportional to the normal force.
    let mut c = Canvas::new(view)?;
    for g in &a.input.grains {
        c.shapes(g, period, [235, 235, 235], Some(GREY), 0.5 * line);
    }
    c.walls(&a.input.walls, 2.0 * line);
    let fmax = a
        .input
        .touches
        .iter()
        .map(|t| t.normal_force)
        .fold(0.0, f64::max);
    let wmax = (0.5 * a.summary.mean_diameter * view.scale) as f32;
    if fmax > 0.0 {
        for t in &a.input.touches {
            if t.normal_force <= 0.0 {
                continue;
            }
            let ga = &a.input.grains[t.a];
            let end = match t.b {
                // Across a periodic seam, to the partner's image beside ga.
                Some(b) => {
                    let gb = &a.input.grains[b];
                    (
                        ga.x + crate::state::nearest_image(gb.x - ga.x, period),
                        gb.z,
                    )
                }
                None => (t.point[0], t.point[1]),
            };
            c.line(
                (ga.x, ga.z),
                end,
                wmax * (t.normal_force / fmax) as f32,
                INK,
            );
        }
        let label = format!("normal force [{}]", a.input.force_unit);
        legend::width_key(&mut c, &label, fmax, wmax);
    }
    legend::length_scale(&mut c, &a.input.length_unit);
    legend::caption(&mut c, &a.input);
    c.save(dir, "forces", &mut files)?;
    // Principal stresses of the moving-average windows: crosses at the window centres
    // (every `row` height along each row), arms along φ and φ + π/2 proportional to σ_max
    // and σ_min, blue for compression and red for tension.
    let mut c = Canvas::new(view)?;
    for g in &a.input.grains {
        c.shapes(
            g,
            period,
            [240, 240, 240],
            Some([225, 225, 225]),
            0.5 * line,
        );
    }
    let windows: Vec<&crate::analyze::stress::Window> =
        a.windows.iter().filter(|w| w.particles > 0).collect();
    let smax = windows
        .iter()
        .map(|w| {
            let (s1, s2, _) = w.sigma.principal();
            s1.abs().max(s2.abs())
        })
        .fold(0.0, f64::max);
    if let Some(w0) = windows.first() {
        let row_h = w0.z_hi - w0.z_lo;
        let every =
            ((row_h / (a.summary.options.step * a.summary.mean_diameter)).round() as usize).max(1);
        for (k, w) in a.windows.iter().enumerate() {
            let column =
                (w.x - a.summary.outline.left) / (a.summary.options.step * a.summary.mean_diameter);
            if w.particles == 0 || !(column.round() as usize).is_multiple_of(every) || smax <= 0.0 {
                continue;
            }
            let _ = k;
            let (s1, s2, phi) = w.sigma.principal();
            let z = 0.5 * (w.z_lo + w.z_hi);
            for (s, ang) in [(s1, phi), (s2, phi + std::f64::consts::FRAC_PI_2)] {
                let half = 0.45 * row_h * s.abs() / smax;
                let (dx, dz) = (half * ang.cos(), half * ang.sin());
                let color = if s >= 0.0 { COMPRESSION } else { TENSION };
                c.line((w.x - dx, z - dz), (w.x + dx, z + dz), 1.5 * line, color);
            }
        }
        if smax > 0.0 {
            let label = format!(
                "principal stress [{}/{}]",
                a.input.force_unit,
                shown(&a.input.length_unit)
            );
            let arms = [(COMPRESSION, "compression"), (TENSION, "tension")];
            let thick = (1.5 * line).round().max(1.0) as u32;
            legend::arm_key(&mut c, &label, smax, 0.9 * row_h * view.scale, thick, arms);
        }
    }
    legend::length_scale(&mut c, &a.input.length_unit);
    legend::caption(&mut c, &a.input);
    c.save(dir, "stress_crosses", &mut files)?;
    repose_lines(a, view, line, marks)?.save(dir, "repose", &mut files)?;
    files.extend(plots::write_plots(a, dir)?);
    Ok(files)
}

/// The angle of repose as each rule reads it (`analyze::heap::Readings`): the surface
/// points (the band's fitted ones dark), and the lines of the band fit, the middle
/// third, apex to toe and the steepest stretch over faint grains, each flank's angle
/// in the key; and the paper's angle, when given, dashed from the apex down to the base.
fn repose_lines(
    a: &Analysis,
    view: View,
    line: f32,
    marks: &PaperMarks,
) -> Result<Canvas, RenderError> {
    let mut c = Canvas::new(view)?;
    for g in &a.input.grains {
        let fill = if g.fixed {
            [190, 190, 190]
        } else {
            [235, 235, 235]
        };
        c.shapes(g, a.input.period_x, fill, Some(GREY), 0.5 * line);
    }
    let s = &a.summary;
    let r = &s.repose_readings;
    let readings = [
        (INK, "band", [&s.repose_left, &s.repose_right]),
        (MIDDLE, "middle", [&r.middle[0], &r.middle[1]]),
        (APEX_TOE, "apex-toe", [&r.apex_toe[0], &r.apex_toe[1]]),
        (STEEPEST, "steepest", [&r.steepest[0], &r.steepest[1]]),
    ];
    let mut key = Vec::new();
    for (colour, name, flanks) in readings {
        for f in flanks {
            let [p, q] = f.line;
            if p.iter().chain(&q).all(|v| v.is_finite()) {
                c.line((p[0], p[1]), (q[0], q[1]), 2.0 * line, colour);
            }
        }
        let deg = |v: f64| {
            if v.is_finite() {
                format!("{v:.1}")
            } else {
                "-".into()
            }
        };
        let (l, r) = (flanks[0].angle_deg, flanks[1].angle_deg);
        key.push((colour, format!("{name} {}/{}", deg(l), deg(r))));
    }
    if let Some(p) = &marks.repose_deg {
        let o = &s.outline;
        let run = o.height / p.value.to_radians().tan();
        let dash = a.summary.mean_diameter;
        for side in [-1.0, 1.0] {
            let toe = (o.apex_x + side * run, o.base);
            c.dashed((o.apex_x, o.top), toe, 1.5 * line, PAPER, dash);
        }
        key.push((PAPER, p.label()));
    }
    legend::length_scale(&mut c, &a.input.length_unit);
    legend::caption(&mut c, &a.input);
    legend::line_key(&mut c, "angle of repose [deg], left/right", &key);
    Ok(c)
}
