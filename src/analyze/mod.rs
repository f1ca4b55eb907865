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
pub mod outline;
pub mod spread;
pub mod stress;
pub mod structure;
mod tables;

pub use tables::write;

use input::Input;
use serde::Serialize;
use std::path::PathBuf;

/// Why an analysis could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum AnalyzeError {
    #[error(transparent)]
    Snapshot(#[from] crate::io::snapshot::SnapshotError),
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
    pub outline: outline::Outline,
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
        let m = stress::moments(&e.grains, &e.touches, e.period_x);
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
    let o = outline::trimmed(grains, d);
    let scale = 0.5 * density * input.g * o.height;
    let moments = stress::moments(grains, &input.touches, input.period_x);
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
