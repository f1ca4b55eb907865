//! `talus analyze`: the measurements of SPEC 5 on one snapshot, written as CSV tables
//! (units in the headers) and a JSON summary. One concept per module: `input` (reading
//! the snapshot and its run), `stress` (paper 000 eq. 8–9 and moving averages), `heap`
//! (outline, free surface, angle of repose, base pressure), `network` (coordination,
//! force distribution), `structure` (packing fraction, f(θ), Q(r)), `spread` (bootstrap
//! standard errors of the base load and the stress windows), `janssen` (the mean stress
//! against depth and its saturation).

pub mod heap;
pub mod input;
pub mod janssen;
pub mod network;
pub mod spread;
pub mod stress;
pub mod structure;

use crate::files::write_atomic;
use input::Input;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Why an analysis could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum AnalyzeError {
    #[error(transparent)]
    Snapshot(#[from] crate::snapshot::SnapshotError),
    #[error("{}: no such file or folder", .0.display())]
    NoSuchPath(PathBuf),
    #[error(
        "{}: a run folder needs final.json (the run has not finished; give a snapshot's .json instead)",
        .0.display()
    )]
    Unfinished(PathBuf),
    #[error("the snapshot has no column {0}")]
    MissingColumn(String),
    #[error("{}: the snapshot has no particles", .0.display())]
    NoParticles(PathBuf),
    #[error("{}: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Sizes of the averaging, in mean grain diameters d (the equal-area diameter).
#[derive(Clone, Debug, Serialize)]
pub struct Options {
    /// Width of the horizontal moving-average windows (paper 000: about 10–14 d).
    pub window: f64,
    /// Spacing of the window centres.
    pub step: f64,
    /// Height of a row of windows; the lowest row gives the base profile.
    pub row: f64,
    /// Height of the packing-fraction layers.
    pub layer: f64,
    /// Free-surface bins, and the height fractions between which slopes are fitted.
    pub surface_bin: f64,
    pub fit_from: f64,
    pub fit_to: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            window: 14.0,
            step: 1.0,
            row: 2.0,
            layer: 2.0,
            surface_bin: 1.0,
            fit_from: 0.15,
            fit_to: 0.85,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct ForceSummary {
    pub contacts: usize,
    pub wall_contacts: usize,
    pub mean_normal: f64,
    pub max_normal: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct EnergySummary {
    pub kinetic: f64,
    pub elastic: f64,
    pub kinetic_over_elastic: f64,
}

/// Base particles over which `BaseLoad` smooths the load profile.
pub const BASE_SPAN: usize = 5;

/// The normal force on the fixed base particles (paper 001 Fig. 3b), in force units:
/// its sum (the mobile grains' weight, for a static heap), and, averaged over
/// `BASE_SPAN` neighbouring base particles, its value under the apex and its largest
/// value on each side (from `BASE_SPAN` particles beyond the one under the apex, so that
/// the sides share no particle with the centre's average). An M profile has side maxima
/// above the centre; `spread` says whether they stand above it by more than noise
/// (issue 20 item 6).
#[derive(Clone, Debug, Serialize)]
pub struct BaseLoad {
    pub particles: usize,
    pub total: f64,
    pub mobile_weight: f64,
    /// The mean mobile grain's weight m g, the unit of paper 001's F_B/mg.
    pub grain_weight: f64,
    pub centre: f64,
    pub left_max: f64,
    pub right_max: f64,
    /// Standard errors, the dip D and its verdict (`spread::base_dip`), as fields of
    /// `base_load` in summary.json.
    #[serde(flatten)]
    pub spread: spread::DipSpread,
}

/// The scalar results (summary.json).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub snapshot: String,
    pub scene: String,
    pub units: String,
    pub step: u64,
    pub time: f64,
    pub grains: usize,
    pub mean_diameter: f64,
    /// Mass per area of the grains (ρ · thickness), the ρ of S = 2σ/(ρ g h).
    pub density: f64,
    pub g: f64,
    /// ρ g h / 2: the stress unit of S.
    pub stress_scale: f64,
    pub outline: heap::Outline,
    pub repose_left: heap::Slope,
    pub repose_right: heap::Slope,
    /// The angle of each flank read three more ways (`heap::Readings`).
    pub repose_readings: heap::Readings,
    pub coordination: network::Coordination,
    pub forces: ForceSummary,
    /// Mean packing fraction of the layers below half the height.
    pub packing_fraction_lower_half: f64,
    pub oriented_grains: usize,
    /// The loads on the fixed base particles, when the heap stands on some.
    pub base_load: Option<BaseLoad>,
    pub energy: Option<EnergySummary>,
    /// Σ_grains Σ_c σ-moment zz (= ∫σ_zz dA) and W (z_cm − base): equal for a static
    /// heap on a flat base (the virial of the vertical forces), a check on the data.
    pub stress_integral_zz: f64,
    pub weight_times_height: f64,
    /// The Janssen fit of `stress_depth.csv` (paper 004 Fig. 6; averaged over the snapshots
    /// with `--from`), when the deposit is at least half as deep as it is wide and its
    /// stress saturates.
    pub janssen: Option<janssen::Janssen>,
    /// Snapshots whose stresses (`stress.csv`, `base_profile.csv`) are averaged: 1, or
    /// more with `--from`.
    pub averaged_snapshots: usize,
    pub averaged_from_time: f64,
    pub options: Options,
}

/// Everything an analysis finds.
pub struct Analysis {
    pub summary: Summary,
    pub input: Input,
    pub moments: Vec<stress::Tensor>,
    pub counts: Vec<usize>,
    pub rattler: Vec<bool>,
    pub on_surface: Vec<bool>,
    pub windows: Vec<stress::Window>,
    pub surface: Vec<heap::SurfacePoint>,
    pub wall_pressure: Vec<(f64, f64)>,
    pub base_forces: Vec<heap::BaseForce>,
    /// The bootstrap standard error of each base particle's smoothed load.
    pub base_load_se: Vec<f64>,
    /// The bootstrap standard errors [σ_xx, σ_zz] of each window (of the last snapshot's
    /// grains when the windows average several).
    pub window_se: Vec<[f64; 2]>,
    pub force_pdf: Vec<(f64, f64)>,
    pub layers: Vec<structure::Layer>,
    pub axes: Vec<Option<f64>>,
    pub orientation: Vec<(f64, f64)>,
    pub correlation: Vec<(f64, f64, usize)>,
    /// P(φ) of the particles' principal stress directions.
    pub principal_directions: Vec<(f64, f64)>,
    /// The trace of the mean stress against depth (`janssen::stress_against_depth`).
    pub stress_depth: Vec<(f64, f64)>,
}

/// As `analyze`, with the stress tables averaged over `earlier` snapshots as well (same
/// run, windows placed by the last snapshot's outline): time averages for packings that
/// keep vibrating.
pub fn analyze_series(
    input: Input,
    earlier: Vec<Input>,
    opt: &Options,
) -> Result<Analysis, AnalyzeError> {
    let mut a = analyze(input, opt)?;
    if earlier.is_empty() {
        return Ok(a);
    }
    let o = a.summary.outline.clone();
    let d = a.summary.mean_diameter;
    let n = earlier.len() + 1;
    let mut from = a.summary.time;
    for e in &earlier {
        from = from.min(e.time);
        let m = stress::moments(&e.grains, &e.touches);
        let w =
            stress::moving_averages(&e.grains, &m, &o, opt.row * d, opt.window * d, opt.step * d);
        let p = heap::wall_pressure(&e.grains, &e.touches, &o, opt.window * d, opt.step * d);
        for (acc, x) in a.windows.iter_mut().zip(&w) {
            acc.sigma = acc.sigma.plus(x.sigma);
            acc.particles += x.particles;
        }
        for (acc, x) in a.wall_pressure.iter_mut().zip(&p) {
            acc.1 += x.1;
        }
        // The slabs of each snapshot below its own surface, in the same places.
        let depth = janssen::stress_against_depth(&e.grains, &m, &o, a.summary.density, e.g);
        a.stress_depth.truncate(depth.len());
        for (acc, x) in a.stress_depth.iter_mut().zip(&depth) {
            acc.1 += x.1;
        }
    }
    a.stress_depth.iter_mut().for_each(|p| p.1 /= n as f64);
    a.summary.janssen = janssen::fit(&a.stress_depth);
    for w in &mut a.windows {
        w.sigma = w.sigma.scaled(1.0 / n as f64);
        w.particles = (w.particles as f64 / n as f64).round() as usize;
    }
    a.wall_pressure.iter_mut().for_each(|p| p.1 /= n as f64);
    a.summary.averaged_snapshots = n;
    a.summary.averaged_from_time = from;
    Ok(a)
}

pub fn analyze(input: Input, opt: &Options) -> Result<Analysis, AnalyzeError> {
    let grains = &input.grains;
    if grains.is_empty() {
        return Err(AnalyzeError::NoParticles(input.source.clone()));
    }
    let total_area: f64 = grains.iter().map(|g| g.area).sum();
    let total_mass: f64 = grains.iter().map(|g| g.mass).sum();
    let d = grains
        .iter()
        .map(|g| 2.0 * (g.area / std::f64::consts::PI).sqrt())
        .sum::<f64>()
        / grains.len() as f64;
    let density = total_mass / total_area;
    let o = heap::trimmed(grains, d);
    let scale = 0.5 * density * input.g * o.height;
    let moments = stress::moments(grains, &input.touches);
    let windows = stress::moving_averages(
        grains,
        &moments,
        &o,
        opt.row * d,
        opt.window * d,
        opt.step * d,
    );
    let mut surface = heap::surface(grains, &o, opt.surface_bin * d);
    let (left, right) = heap::repose(&mut surface, &o, opt.fit_from, opt.fit_to);
    let repose_readings = heap::readings(&surface, &o);
    let mut on_surface = vec![false; grains.len()];
    surface.iter().for_each(|p| on_surface[p.grain] = true);
    let counts = network::contact_counts(grains, &input.touches);
    let frictionless = input.mu == Some(0.0);
    let (coordination, rattler) =
        network::coordination(grains, &input.touches, &counts, &on_surface, frictionless);
    let (force_pdf, mean_f, max_f) = network::force_distribution(&input.touches, 0.1);
    let wall_pressure =
        heap::wall_pressure(grains, &input.touches, &o, opt.window * d, opt.step * d);
    let base_forces = heap::base_forces(grains, &input.touches);
    let mobile: Vec<&input::Grain> = grains.iter().filter(|g| !g.fixed).collect();
    let grain_weight =
        mobile.iter().map(|g| g.mass).sum::<f64>() / mobile.len().max(1) as f64 * input.g;
    let mut base_load_se = Vec::new();
    let base_load = (!base_forces.is_empty()).then(|| {
        let loads: Vec<f64> = base_forces.iter().map(|b| b.load).collect();
        // The centre: the base particle nearest under the apex.
        let c = (0..base_forces.len())
            .min_by(|&p, &q| {
                (base_forces[p].x - o.apex_x)
                    .abs()
                    .total_cmp(&(base_forces[q].x - o.apex_x).abs())
            })
            .unwrap_or(0);
        let dip = spread::Dip::of(&loads, c, BASE_SPAN);
        let (dip_spread, se) =
            spread::base_dip(&loads, c, BASE_SPAN, spread::BASE_REPLICAS, spread::SEED);
        base_load_se = se;
        BaseLoad {
            particles: base_forces.len(),
            total: loads.iter().sum(),
            mobile_weight: mobile.iter().map(|g| g.mass).sum::<f64>() * input.g,
            grain_weight,
            centre: dip.centre,
            left_max: dip.left_max,
            right_max: dip.right_max,
            spread: dip_spread,
        }
    });
    let window_se = spread::window_se(
        grains,
        &moments,
        &windows,
        o.base,
        opt.row * d,
        opt.window * d,
        BASE_SPAN,
    );
    let layers = structure::packing(grains, &o, opt.layer * d, d);
    let lower: Vec<f64> = layers
        .iter()
        .filter(|l| l.z < o.base + 0.5 * o.height)
        .map(|l| l.fraction)
        .collect();
    let axes: Vec<Option<f64>> = grains.iter().map(structure::long_axis).collect();
    let (orientation, oriented) = structure::orientation(&axes, 18);
    let (principal_directions, _) = stress::principal_directions(&moments, 18);
    let correlation = structure::orientation_correlation(grains, &axes, 0.5 * d, 10.0 * d);
    let energy = input.log.as_ref().and_then(|(h, rows)| {
        let last = rows.last()?;
        let col = |name: &str| h.iter().position(|c| c == name).map(|k| last[k]);
        let kin = col("kinetic_translational")? + col("kinetic_rotational")?;
        let el = col("elastic")?;
        Some(EnergySummary {
            kinetic: kin,
            elastic: el,
            kinetic_over_elastic: kin / el,
        })
    });
    let weight_height: f64 = grains
        .iter()
        .map(|g| g.mass * input.g * (g.z - o.base))
        .sum();
    let stress_depth = janssen::stress_against_depth(grains, &moments, &o, density, input.g);
    let summary = Summary {
        snapshot: input.source.display().to_string(),
        scene: input.scene.clone(),
        units: input.units.clone(),
        step: input.step,
        time: input.time,
        grains: grains.len(),
        mean_diameter: d,
        density,
        g: input.g,
        stress_scale: scale,
        outline: o,
        repose_left: left,
        repose_right: right,
        repose_readings,
        coordination,
        forces: ForceSummary {
            contacts: input.touches.len(),
            wall_contacts: input.touches.iter().filter(|t| t.b.is_none()).count(),
            mean_normal: mean_f,
            max_normal: max_f,
        },
        packing_fraction_lower_half: lower.iter().sum::<f64>() / lower.len().max(1) as f64,
        oriented_grains: oriented,
        base_load,
        energy,
        stress_integral_zz: moments.iter().map(|m| m.zz).sum(),
        weight_times_height: weight_height,
        janssen: janssen::fit(&stress_depth),
        averaged_snapshots: 1,
        averaged_from_time: input.time,
        options: opt.clone(),
    };
    Ok(Analysis {
        summary,
        input,
        moments,
        counts,
        rattler,
        on_surface,
        windows,
        surface,
        wall_pressure,
        base_forces,
        base_load_se,
        window_se,
        force_pdf,
        layers,
        axes,
        orientation,
        correlation,
        principal_directions,
        stress_depth,
    })
}

/// Number formatting for the tables: full precision, NaN written as "nan".
fn v(x: f64) -> String {
    format!("{x:e}")
}

fn table(header: &[String], rows: impl Iterator<Item = Vec<String>>) -> String {
    let mut s = header.join(",");
    s.push('\n');
    for r in rows {
        let _ = writeln!(s, "{}", r.join(","));
    }
    s
}

/// Writes the tables and summary.json into `dir` (each file atomically); returns the
/// files written.
pub fn write(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>, AnalyzeError> {
    std::fs::create_dir_all(dir).map_err(|source| AnalyzeError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let (l, f) = (&a.input.length_unit, &a.input.force_unit);
    let stress_unit = format!("{f}/{l}");
    let s = &a.summary;
    let o = &s.outline;
    let xs = |x: f64| (x - o.left) / o.width;
    let mut files = Vec::new();
    let mut put = |name: &str, text: String| -> Result<(), AnalyzeError> {
        let p = dir.join(name);
        write_atomic(&p, text.as_bytes()).map_err(|source| AnalyzeError::Write {
            path: p.clone(),
            source,
        })?;
        files.push(p);
        Ok(())
    };
    let h = |names: &[&str]| names.iter().map(|n| n.to_string()).collect::<Vec<_>>();
    let su = |n: &str| format!("{n} [{stress_unit}]");
    // Per grain: the moments Σ f ⊗ l (compression positive) and the grain's own
    // stress (moment over its area) in principal form.
    let mom = format!("[{f} {l}]");
    put(
        "grains.csv",
        table(
            &[
                "id".into(),
                format!("x [{l}]"),
                format!("z [{l}]"),
                "theta [rad]".into(),
                format!("area [{l}^2]"),
                "contacts".into(),
                "rattler".into(),
                "surface".into(),
                "long_axis [rad]".into(),
                format!("m_xx {mom}"),
                format!("m_xz {mom}"),
                format!("m_zx {mom}"),
                format!("m_zz {mom}"),
                su("sigma_max"),
                su("sigma_min"),
                "phi [rad]".into(),
            ],
            a.input.grains.iter().enumerate().map(|(k, g)| {
                let m = a.moments[k];
                // The grain's own stress: its moment over its area.
                let (smax, smin, phi) = m.scaled(1.0 / g.area).principal();
                vec![
                    g.id.to_string(),
                    v(g.x),
                    v(g.z),
                    v(g.theta),
                    v(g.area),
                    a.counts[k].to_string(),
                    (a.rattler[k] as u8).to_string(),
                    (a.on_surface[k] as u8).to_string(),
                    a.axes[k].map_or("nan".into(), v),
                    v(m.xx),
                    v(m.xz),
                    v(m.zx),
                    v(m.zz),
                    v(smax),
                    v(smin),
                    v(phi),
                ]
            }),
        ),
    )?;
    let window_header = |first: &[String]| {
        let mut hd = first.to_vec();
        hd.extend([
            format!("x [{l}]"),
            "X = (x - left)/width".into(),
            "grains".into(),
            su("sigma_xx"),
            su("sigma_xz"),
            su("sigma_zx"),
            su("sigma_zz"),
            su("sigma_max"),
            su("sigma_min"),
            "phi [rad]".into(),
            "S_xx".into(),
            "S_xz".into(),
            "S_zz".into(),
            "S_max".into(),
            "S_min".into(),
        ]);
        hd
    };
    let window_row = |w: &stress::Window| {
        let (smax, smin, phi) = w.sigma.principal();
        let sc = s.stress_scale;
        vec![
            v(w.x),
            v(xs(w.x)),
            w.particles.to_string(),
            v(w.sigma.xx),
            v(w.sigma.xz),
            v(w.sigma.zx),
            v(w.sigma.zz),
            v(smax),
            v(smin),
            v(phi),
            v(w.sigma.xx / sc),
            v(0.5 * (w.sigma.xz + w.sigma.zx) / sc),
            v(w.sigma.zz / sc),
            v(smax / sc),
            v(smin / sc),
        ]
    };
    // The bootstrap standard errors of a window's σ_xx and σ_zz, and of S_xx and S_zz;
    // after the other columns, so that those keep their places.
    let se_header = [
        format!("se sigma_xx [{stress_unit}]"),
        format!("se sigma_zz [{stress_unit}]"),
        "se S_xx".into(),
        "se S_zz".into(),
    ];
    let se_row = |k: usize| {
        let [xx, zz] = a.window_se[k];
        vec![v(xx), v(zz), v(xx / s.stress_scale), v(zz / s.stress_scale)]
    };
    put(
        "stress.csv",
        table(
            &{
                let mut hd =
                    window_header(&["row".into(), format!("z_lo [{l}]"), format!("z_hi [{l}]")]);
                hd.extend(se_header.clone());
                hd
            },
            a.windows.iter().enumerate().map(|(k, w)| {
                let mut r = vec![w.row.to_string(), v(w.z_lo), v(w.z_hi)];
                r.extend(window_row(w));
                r.extend(se_row(k));
                r
            }),
        ),
    )?;
    put(
        "base_profile.csv",
        table(
            &{
                let mut hd = window_header(&[]);
                hd.push(format!("wall pressure [{stress_unit}]"));
                hd.push("S_wall".into());
                hd.extend(se_header.clone());
                hd
            },
            (a.windows.iter().enumerate())
                .filter(|(_, w)| w.row == 0)
                .zip(&a.wall_pressure)
                .map(|((k, w), &(_, p))| {
                    let mut r = window_row(w);
                    r.push(v(p));
                    r.push(v(p / s.stress_scale));
                    r.extend(se_row(k));
                    r
                }),
        ),
    )?;
    if !a.base_forces.is_empty() {
        let smooth = heap::smoothed_loads(&a.base_forces, BASE_SPAN);
        let mg = s.base_load.as_ref().map_or(f64::NAN, |b| b.grain_weight);
        put(
            "base_forces.csv",
            table(
                &h(&[
                    "id",
                    &format!("x [{l}]"),
                    "X = (x - left)/width",
                    &format!("F_B [{f}]"),
                    "F_B/mg",
                    &format!("F_B over {BASE_SPAN} base particles/mg"),
                    &format!("se of F_B over {BASE_SPAN} base particles/mg"),
                ]),
                (a.base_forces.iter().zip(&smooth).zip(&a.base_load_se)).map(|((b, sm), se)| {
                    vec![
                        a.input.grains[b.grain].id.to_string(),
                        v(b.x),
                        v(xs(b.x)),
                        v(b.load),
                        v(b.load / mg),
                        v(sm.1 / mg),
                        v(se / mg),
                    ]
                }),
            ),
        )?;
    }
    put(
        "surface.csv",
        table(
            &h(&[&format!("x [{l}]"), &format!("z [{l}]"), "side", "fitted"]),
            a.surface.iter().map(|p| {
                vec![
                    v(p.x),
                    v(p.z),
                    p.side.to_string(),
                    (p.fitted as u8).to_string(),
                ]
            }),
        ),
    )?;
    put(
        "force_distribution.csv",
        table(
            &h(&["f/<f>", "P(f/<f>)"]),
            a.force_pdf.iter().map(|&(x, p)| vec![v(x), v(p)]),
        ),
    )?;
    put(
        "packing.csv",
        table(
            &h(&[
                &format!("z [{l}]"),
                &format!("depth [{l}]"),
                &format!("width [{l}]"),
                "grains",
                "packing fraction",
            ]),
            a.layers.iter().map(|y| {
                vec![
                    v(y.z),
                    v(y.depth),
                    v(y.width),
                    y.grains.to_string(),
                    v(y.fraction),
                ]
            }),
        ),
    )?;
    put(
        "orientation.csv",
        table(
            &h(&["theta [rad]", "f(theta) [1/rad]"]),
            a.orientation.iter().map(|&(t, p)| vec![v(t), v(p)]),
        ),
    )?;
    put(
        "principal_directions.csv",
        table(
            &h(&["phi [rad]", "P(phi) [1/rad]"]),
            a.principal_directions
                .iter()
                .map(|&(t, p)| vec![v(t), v(p)]),
        ),
    )?;
    put(
        "stress_depth.csv",
        table(
            &h(&["depth / W", "sigma_xx + sigma_zz / (rho g W)"]),
            a.stress_depth.iter().map(|&(x, p)| vec![v(x), v(p)]),
        ),
    )?;
    put(
        "orientation_correlation.csv",
        table(
            &h(&[&format!("r [{l}]"), "Q(r)", "pairs"]),
            a.correlation
                .iter()
                .map(|&(r, q, n)| vec![v(r), v(q), n.to_string()]),
        ),
    )?;
    if let Some((hd, rows)) = &a.input.log {
        let e = if a.input.units == "si" {
            "J"
        } else {
            "m g sigma"
        };
        let t = if a.input.units == "si" {
            "s"
        } else {
            "sqrt(sigma/g)"
        };
        let named: Vec<String> = hd
            .iter()
            .map(|c| match c.as_str() {
                "time" => format!("time [{t}]"),
                "step" | "particles" | "contacts" => c.clone(),
                other => format!("{other} [{e}]"),
            })
            .collect();
        put(
            "energy.csv",
            table(
                &named,
                rows.iter().map(|r| r.iter().map(|&x| v(x)).collect()),
            ),
        )?;
    }
    // Plain numbers and strings (NaN becomes null): serialising cannot fail.
    let json = serde_json::to_string_pretty(&a.summary).expect("a summary serialises");
    put("summary.json", json)?;
    Ok(files)
}
