//! Plots of the profiles as SVG (plotters): S_zz and S_xx along the base against
//! X = x/l (paper 000 Fig. 3, 6, 14), the force on fixed base particles (paper 001
//! Fig. 3b), P(f/⟨f⟩) on a logarithmic axis (the exponential tail of the force
//! distribution is a straight line there, as the field plots it), f(θ), and P(φ) of
//! the principal stress directions (paper 004 Fig. 5). The base profiles carry bands of ± one bootstrap standard error
//! (`analyze::spread`).

use super::RenderError;
use crate::analyze::Analysis;
use crate::analyze::janssen::Janssen;
use crate::base::files::write_atomic;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

type Series<'a> = (&'a str, RGBColor, Vec<(f64, f64)>);

/// A named series of (x, mean, standard deviation) for `write_bands`.
pub type Means = (String, Vec<(f64, f64, f64)>);

/// Colours of the series of a plot, in order.
const PALETTE: [RGBColor; 8] = [
    BLUE,
    RED,
    RGBColor(0, 140, 0),
    MAGENTA,
    BLACK,
    RGBColor(230, 140, 0),
    CYAN,
    RGBColor(120, 120, 120),
];

/// A shaded band (x, low, high) under a series of the same colour.
type Band = (RGBColor, Vec<(f64, f64, f64)>);

/// An axis of a plot: the quantity and its unit, drawn as "name [unit]"; the unit of a
/// ratio or a count is "-". A type rather than a string so that no axis goes without.
#[derive(Clone, Copy, Debug)]
pub struct Axis<'a> {
    pub name: &'a str,
    pub unit: &'a str,
}

impl<'a> Axis<'a> {
    pub const fn new(name: &'a str, unit: &'a str) -> Axis<'a> {
        Axis { name, unit }
    }
    fn label(&self) -> String {
        format!("{} [{}]", self.name, self.unit)
    }
}

/// The frame every plot shares: an 800 × 500 SVG on white with its title, margins and
/// room for the axis labels, into which `draw` puts the chart; written atomically.
fn framed(
    path: &Path,
    title: &str,
    draw: impl FnOnce(ChartBuilder<'_, '_, SVGBackend<'_>>) -> Result<(), String>,
) -> Result<(), RenderError> {
    let e = |message: String| RenderError::Plot {
        path: path.to_path_buf(),
        message,
    };
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (800, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root);
        chart
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70);
        draw(chart).map_err(e)?;
        root.present().map_err(|x| e(x.to_string()))?;
    }
    write_atomic(path, text.as_bytes()).map_err(RenderError::write(path))
}

/// One line plot; `series` share the axes.
fn plot(path: &Path, title: &str, x: Axis, y: Axis, series: &[Series]) -> Result<(), RenderError> {
    plot_with_bands(path, title, x, y, series, &[])
}

/// One line plot with shaded bands (drawn first, under the lines).
fn plot_with_bands(
    path: &Path,
    title: &str,
    x: Axis,
    y: Axis,
    series: &[Series],
    bands: &[Band],
) -> Result<(), RenderError> {
    let band_points = (bands.iter().flat_map(|b| b.1.iter()))
        .flat_map(|&(x, lo, hi)| [(x, lo), (x, hi)])
        .collect::<Vec<_>>();
    let pts = (series.iter().flat_map(|s| s.2.iter()))
        .chain(band_points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) =
        (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, f64::NEG_INFINITY);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    // An empty or flat series still gets axes (NaN bounds compare false too).
    if x1.partial_cmp(&x0) != Some(std::cmp::Ordering::Greater) {
        x0 = 0.0;
        x1 = 1.0;
    }
    if y1.partial_cmp(&y0) != Some(std::cmp::Ordering::Greater) {
        y1 = y0 + 1.0;
    }
    let y1 = y1 + 0.05 * (y1 - y0);
    framed(path, title, |mut builder| {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let mut chart = (builder.build_cartesian_2d(x0..x1, y0..y1)).map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc(x.label())
            .y_desc(y.label())
            .draw()
            .map_err(|x| e(&x))?;
        for (color, band) in bands {
            // The band's outline: along the upper edge, back along the lower one.
            let finite =
                |p: &&(f64, f64, f64)| p.0.is_finite() && p.1.is_finite() && p.2.is_finite();
            let edge: Vec<(f64, f64)> = (band.iter().filter(finite).map(|p| (p.0, p.2)))
                .chain(band.iter().rev().filter(finite).map(|p| (p.0, p.1)))
                .collect();
            if edge.len() >= 3 {
                chart
                    .draw_series(std::iter::once(Polygon::new(edge, color.mix(0.2).filled())))
                    .map_err(|x| e(&x))?;
            }
        }
        for (name, color, data) in series {
            let c = *color;
            chart
                .draw_series(LineSeries::new(
                    data.iter().copied().filter(|p| p.1.is_finite()),
                    c.stroke_width(2),
                ))
                .map_err(|x| e(&x))?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        }
        if series.len() > 1 {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|x| e(&x))?;
        }
        Ok(())
    })
}

/// One line plot on a logarithmic y axis: points with y ≤ 0 (an empty bin) are left
/// out, since they have no place on it; the axis spans the positive points' decades.
fn plot_log_y(
    path: &Path,
    title: &str,
    x: Axis,
    y: Axis,
    series: &[Series],
) -> Result<(), RenderError> {
    let shown = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite() && p.1 > 0.0;
    let pts = series.iter().flat_map(|s| s.2.iter()).filter(shown);
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x1.partial_cmp(&x0) != Some(std::cmp::Ordering::Greater) {
        (x0, x1) = (0.0, 1.0);
    }
    // Whole decades around the points (one decade for none or one value).
    let (y0, y1) = if y1 >= y0 {
        (
            10f64.powf(y0.log10().floor()),
            10f64.powf((y1.log10() + 1e-9).ceil().max(y0.log10().floor() + 1.0)),
        )
    } else {
        (0.1, 1.0)
    };
    x0 = x0.min(0.0);
    framed(path, title, |mut builder| {
        let e = |x: &dyn std::fmt::Display| x.to_string();
        let mut chart =
            (builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())).map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc(x.label())
            .y_desc(y.label())
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|x| e(&x))?;
        for (_, color, data) in series {
            let c = *color;
            let line = data.iter().filter(shown).copied();
            chart
                .draw_series(LineSeries::new(line, c.stroke_width(2)))
                .map_err(|x| e(&x))?;
            let dots = data
                .iter()
                .filter(shown)
                .map(|&p| Circle::new(p, 3, c.filled()));
            chart.draw_series(dots).map_err(|x| e(&x))?;
        }
        Ok(())
    })
}

pub fn write_plots(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, RenderError> {
    let o = &a.summary.outline;
    let sc = a.summary.stress_scale;
    let base: Vec<&crate::analyze::stress::Window> =
        a.windows.iter().filter(|w| w.row == 0).collect();
    let xs = |x: f64| (x - o.left) / o.width;
    let mut files = Vec::new();
    // Bands of ± one bootstrap standard error (`analyze::spread`).
    let band = |value: &dyn Fn(usize) -> f64, se: &dyn Fn(usize) -> f64| -> Vec<(f64, f64, f64)> {
        (a.windows.iter().enumerate())
            .filter(|(_, w)| w.row == 0)
            .map(|(k, w)| (xs(w.x), value(k) - se(k), value(k) + se(k)))
            .collect()
    };
    let p = dir.join("base_profile.svg");
    plot_with_bands(
        &p,
        &format!(
            "{}: stress along the base (moving averages, ± one se)",
            a.summary.scene
        ),
        Axis::new("X = x / l", "-"),
        Axis::new("S = 2σ / (ρ g h)", "-"),
        &[
            (
                "S_zz",
                BLUE,
                base.iter().map(|w| (xs(w.x), w.sigma.zz / sc)).collect(),
            ),
            (
                "S_xx",
                RED,
                base.iter().map(|w| (xs(w.x), w.sigma.xx / sc)).collect(),
            ),
        ],
        &[
            (
                BLUE,
                band(&|k| a.windows[k].sigma.zz / sc, &|k| a.window_se[k][1] / sc),
            ),
            (
                RED,
                band(&|k| a.windows[k].sigma.xx / sc, &|k| a.window_se[k][0] / sc),
            ),
        ],
    )?;
    files.push(p);
    if let Some(load) = &a.summary.base_load {
        // Paper 001 Fig. 3b: the normal force on each base particle in units of m g.
        let mg = load.grain_weight;
        let smooth =
            crate::analyze::heap::smoothed_loads(&a.base_forces, crate::analyze::BASE_SPAN);
        let p = dir.join("base_forces.svg");
        let over = (smooth.iter().zip(&a.base_load_se))
            .map(|(&(x, f), se)| (xs(x), (f - se) / mg, (f + se) / mg))
            .collect();
        plot_with_bands(
            &p,
            &format!(
                "{}: normal force on the base particles ({}: z = {:.1})",
                a.summary.scene, load.spread.verdict, load.spread.dip_z
            ),
            Axis::new("X = x / l", "-"),
            Axis::new("F_B / (m g)", "-"),
            &[
                (
                    "each",
                    RGBColor(150, 150, 150),
                    a.base_forces
                        .iter()
                        .map(|b| (xs(b.x), b.load / mg))
                        .collect(),
                ),
                (
                    "over 5, ± one se",
                    BLUE,
                    smooth.iter().map(|&(x, f)| (xs(x), f / mg)).collect(),
                ),
            ],
            &[(BLUE, over)],
        )?;
        files.push(p);
    }
    let p = dir.join("force_distribution.svg");
    plot_log_y(
        &p,
        "normal forces between grains",
        Axis::new("f / ⟨f⟩", "-"),
        Axis::new("P(f / ⟨f⟩)", "-"),
        &[("P", BLACK, a.force_pdf.clone())],
    )?;
    files.push(p);
    let p = dir.join("principal_directions.svg");
    plot(
        &p,
        "principal stress directions of the grains",
        Axis::new("φ", "rad"),
        Axis::new("P(φ)", "1/rad"),
        &[("P", BLACK, a.principal_directions.clone())],
    )?;
    files.push(p);
    if a.summary.oriented_grains > 0 {
        let p = dir.join("orientation.svg");
        plot(
            &p,
            "orientation of the long axes",
            Axis::new("θ", "rad"),
            Axis::new("f(θ)", "1/rad"),
            &[("f", BLACK, a.orientation.clone())],
        )?;
        files.push(p);
    }
    Ok(files)
}

/// Row-1 profiles S_zz(X − X_apex) of several runs in one plot, as the papers compare
/// them (paper 000 Fig. 3a, 8, 10): one line per variant, or per seed average.
pub fn write_profiles(
    path: &Path,
    title: &str,
    profiles: &[(String, Vec<(f64, f64)>)],
) -> Result<(), RenderError> {
    let series: Vec<Series> = profiles
        .iter()
        .enumerate()
        .map(|(k, (name, data))| (name.as_str(), PALETTE[k % PALETTE.len()], data.clone()))
        .collect();
    plot(
        path,
        title,
        Axis::new("X - X_apex", "heap widths"),
        Axis::new("S_zz(1) = 2σ_zz / (ρ g h)", "-"),
        &series,
    )
}

/// The trace of the mean stress against depth of several deposits, each beside its
/// Janssen fit when it has one (paper 004 Fig. 6).
pub fn write_janssen(
    path: &Path,
    title: &str,
    profiles: &[(String, Vec<(f64, f64)>, Option<Janssen>)],
) -> Result<(), RenderError> {
    let mut names = Vec::new();
    let mut lines = Vec::new();
    for (name, data, fit) in profiles {
        names.push(name.clone());
        lines.push(data.clone());
        if let Some(j) = fit {
            let deepest = data.iter().map(|p| p.0).fold(0.0, f64::max);
            names.push(format!(
                "{name}: fit, σ_m {:.3}, h_s {:.2} W",
                j.sigma_m, j.h_s
            ));
            lines.push(
                (0..=50)
                    .map(|k| deepest * k as f64 / 50.0)
                    .map(|x| (x, j.sigma_m * (1.0 - (-x / j.h_s).exp())))
                    .collect(),
            );
        }
    }
    let series: Vec<Series> = (names.iter().zip(lines).enumerate())
        .map(|(k, (name, line))| (name.as_str(), PALETTE[k % PALETTE.len()], line))
        .collect();
    plot(
        path,
        title,
        Axis::new("depth / W", "-"),
        Axis::new("(σ_xx + σ_zz) / (ρ g W)", "-"),
        &series,
    )
}

/// Means with a band of ± one standard deviation, one colour per named series
/// (`talus sweep collect`: the seed average of each grid point). A point is
/// (x, mean, standard deviation); an undefined deviation (one seed) draws no band there.
pub fn write_bands(
    path: &Path,
    title: &str,
    x: Axis,
    y: Axis,
    means: &[Means],
) -> Result<(), RenderError> {
    let colour = |k: usize| PALETTE[k % PALETTE.len()];
    let series: Vec<Series> = (means.iter().enumerate())
        .map(|(k, (name, data))| {
            let line = data.iter().map(|p| (p.0, p.1)).collect();
            (name.as_str(), colour(k), line)
        })
        .collect();
    let bands: Vec<Band> = (means.iter().enumerate())
        .map(|(k, (_, data))| {
            let band = data.iter().map(|p| (p.0, p.1 - p.2, p.1 + p.2)).collect();
            (colour(k), band)
        })
        .collect();
    plot_with_bands(path, title, x, y, &series, &bands)
}
