//! The numbers a reproduction is judged by: each variant's findings from its analysis,
//! the profiles averaged over seeds, and the variants' profiles compared.

use crate::analyze::Analysis;
use serde::Serialize;

/// The numbers a reproduction is judged by, from one variant's analysis.
#[derive(Clone, Debug, Serialize)]
pub struct Findings {
    pub variant: String,
    pub grains: usize,
    pub time: f64,
    pub repose_left_deg: f64,
    pub repose_right_deg: f64,
    /// S_xx/S_zz averaged over the windows of row 1 with |X − 1/2| ≤ 0.2.
    pub stress_ratio_interior_row1: f64,
    /// The base row's S_zz: under the apex (the window nearest it), its maximum, and the
    /// dip (max − centre)/max (0 when the centre is the maximum); and the same for row 1.
    pub base_szz_centre: f64,
    pub base_szz_max: f64,
    pub base_dip: f64,
    pub row1_szz_centre: f64,
    pub row1_szz_max: f64,
    pub row1_dip: f64,
    /// S_zz of row 1 against X − X_apex (the apex at 0), for averages over seeds.
    pub row1_profile: Vec<(f64, f64)>,
    pub coordination_interior: f64,
    pub packing_fraction_lower_half: f64,
    pub kinetic_over_elastic: Option<f64>,
    /// The normal force on the fixed base particles in units of m g (paper 001 Fig. 3b),
    /// averaged over `analyze::BASE_SPAN` of them: under the apex and the largest on
    /// the left and on the right; an M profile has both maxima above the centre.
    pub base_load_centre_mg: Option<f64>,
    pub base_load_left_max_mg: Option<f64>,
    pub base_load_right_max_mg: Option<f64>,
    /// Of the grains with a long axis (polygons, rods), the fractions lying within 20° of
    /// the horizontal and standing within 20° of the vertical (from f(θ)).
    pub lying_fraction: f64,
    pub standing_fraction: f64,
    /// The trace of the mean stress against depth (`analyze::janssen`: depth / W,
    /// σ_xx + σ_zz in units of ρ g W), and its Janssen fit: the saturation stress σ_m in
    /// units of ρ g W and the saturation depth h_s in units of W (paper 004 Fig. 6).
    pub stress_depth: Vec<(f64, f64)>,
    pub janssen: Option<crate::analyze::janssen::Janssen>,
    /// Of the loaded grains, the fraction whose principal stress direction (the larger
    /// eigenvalue of its own stress) lies within 20° of the vertical (paper 004 Fig. 5;
    /// uniform: 22 %).
    pub vertical_stress_fraction: f64,
    /// Q(r) (paper 004 eq. 2, Fig. 4) of the grains with a long axis: at its first bin
    /// (contact), and the mean of |Q| over its bins (to 10 mean diameters): how strongly
    /// its maxima and minima stand out. Bins with fewer than `Q_PAIRS` pairs are left out.
    pub q_contact: Option<f64>,
    pub q_order: Option<f64>,
    /// What the run cost, from its summary.json (issue 40 item 6); None where the run's
    /// summary was not read (a sweep's measures).
    pub cost: Option<RunCost>,
}

/// A run's cost as its summary.json records it: wall-clock seconds, steps, the moving
/// particles' steps per second, and on what it ran.
#[derive(Clone, Debug, Serialize)]
pub struct RunCost {
    pub wall_seconds: f64,
    pub steps: u64,
    pub particle_steps_per_second: f64,
    pub threads: u64,
    pub backend: String,
}

impl RunCost {
    /// The cost recorded in a run folder's summary.json; None when it is missing or
    /// lacks a field.
    pub fn of_run(dir: &std::path::Path) -> Option<RunCost> {
        let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
        let s: serde_json::Value = serde_json::from_str(&text).ok()?;
        Some(RunCost {
            wall_seconds: s["wall_seconds"].as_f64()?,
            steps: s["steps"].as_u64()?,
            particle_steps_per_second: s["particle_steps_per_second"].as_f64()?,
            threads: s["provenance"]["threads"].as_u64()?,
            backend: s["backend"].as_str()?.to_string(),
        })
    }
}

/// Pairs a bin of Q(r) needs to count in `Findings::q_contact` and `q_order`.
pub const Q_PAIRS: usize = 20;

pub fn findings(variant: &str, a: &Analysis) -> Findings {
    let s = &a.summary;
    let sc = s.stress_scale;
    let interior: Vec<f64> = a
        .windows
        .iter()
        .filter(|w| w.row == 1 && w.particles > 0)
        .filter(|w| ((w.x - s.outline.left) / s.outline.width - 0.5).abs() <= 0.2)
        .filter(|w| w.sigma.zz != 0.0)
        .map(|w| w.sigma.xx / w.sigma.zz)
        .collect();
    // (S_zz under the apex, max S_zz, dip) of a row of windows.
    let profile = |row: usize| {
        let pts: Vec<(f64, f64)> = a
            .windows
            .iter()
            .filter(|w| w.row == row)
            .map(|w| (w.x, w.sigma.zz / sc))
            .collect();
        let apex = s.outline.apex_x;
        let centre = pts
            .iter()
            .min_by(|p, q| (p.0 - apex).abs().total_cmp(&(q.0 - apex).abs()))
            .map_or(f64::NAN, |p| p.1);
        let max = pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        (
            centre,
            max,
            if max > 0.0 {
                (max - centre) / max
            } else {
                f64::NAN
            },
        )
    };
    let (centre, max, dip) = profile(0);
    let (c1, m1, d1) = profile(1);
    let row1_profile = a
        .windows
        .iter()
        .filter(|w| w.row == 1)
        .map(|w| ((w.x - s.outline.apex_x) / s.outline.width, w.sigma.zz / sc))
        .collect();
    Findings {
        variant: variant.into(),
        grains: s.grains,
        time: s.time,
        repose_left_deg: s.repose_left.angle_deg,
        repose_right_deg: s.repose_right.angle_deg,
        stress_ratio_interior_row1: interior.iter().sum::<f64>() / interior.len().max(1) as f64,
        base_szz_centre: centre,
        base_szz_max: max,
        base_dip: dip,
        row1_szz_centre: c1,
        row1_szz_max: m1,
        row1_dip: d1,
        row1_profile,
        coordination_interior: s.coordination.interior,
        packing_fraction_lower_half: s.packing_fraction_lower_half,
        kinetic_over_elastic: s.energy.as_ref().map(|e| e.kinetic_over_elastic),
        base_load_centre_mg: s.base_load.as_ref().map(|b| b.centre / b.grain_weight),
        base_load_left_max_mg: s.base_load.as_ref().map(|b| b.left_max / b.grain_weight),
        base_load_right_max_mg: s.base_load.as_ref().map(|b| b.right_max / b.grain_weight),
        lying_fraction: orientation_fraction(&a.orientation, |t| {
            t.min(PI - t) < 20f64.to_radians()
        }),
        standing_fraction: orientation_fraction(&a.orientation, |t| {
            (t - 0.5 * PI).abs() < 20f64.to_radians()
        }),
        stress_depth: a.stress_depth.clone(),
        janssen: s.janssen,
        vertical_stress_fraction: orientation_fraction(&a.principal_directions, |t| {
            (t - 0.5 * PI).abs() < 20f64.to_radians()
        }),
        q_contact: q_bins(&a.correlation).next(),
        q_order: {
            let q: Vec<f64> = q_bins(&a.correlation).map(f64::abs).collect();
            (!q.is_empty()).then(|| q.iter().sum::<f64>() / q.len() as f64)
        },
        cost: None,
    }
}

/// The values of Q(r)'s bins with at least `Q_PAIRS` pairs, from contact outwards.
pub(super) fn q_bins(correlation: &[(f64, f64, usize)]) -> impl Iterator<Item = f64> + '_ {
    (correlation.iter())
        .filter(|(_, _, pairs)| *pairs >= Q_PAIRS)
        .map(|(_, q, _)| *q)
}

use std::f64::consts::PI;

/// The fraction of f(θ) (bins of equal width over [0, π)) whose bin centres satisfy `at`.
pub(super) fn orientation_fraction(f: &[(f64, f64)], at: impl Fn(f64) -> bool) -> f64 {
    let width = PI / f.len().max(1) as f64;
    f.iter()
        .filter(|(t, _)| at(*t))
        .map(|(_, p)| p * width)
        .sum()
}

/// The row-1 S_zz profile averaged over the seeds of one setting (variants named
/// `SETTING-seedN`), on the X − X_apex grid of the first seed; with its value under the
/// apex, its maximum and the dip between them.
#[derive(Clone, Debug, Serialize)]
pub struct SeedAverage {
    pub setting: String,
    pub seeds: usize,
    pub row1_szz_apex: f64,
    pub row1_szz_max: f64,
    pub row1_dip: f64,
    pub coordination_interior: f64,
    pub profile: Vec<(f64, f64)>,
}

pub fn seed_averages(found: &[Findings]) -> Vec<SeedAverage> {
    let mut settings: Vec<String> = Vec::new();
    for f in found {
        if let Some((setting, _)) = f.variant.split_once("-seed")
            && !settings.iter().any(|s| s == setting)
        {
            settings.push(setting.to_string());
        }
    }
    settings
        .into_iter()
        .map(|setting| {
            let runs: Vec<&Findings> = found
                .iter()
                .filter(|f| {
                    f.variant
                        .split_once("-seed")
                        .is_some_and(|(s, _)| s == setting)
                })
                .collect();
            // Each run's S_zz interpolated at the first run's offsets from the apex.
            let grid: Vec<f64> = runs[0].row1_profile.iter().map(|p| p.0).collect();
            let profile: Vec<(f64, f64)> = grid
                .iter()
                .map(|&x| {
                    (
                        x,
                        runs.iter()
                            .map(|r| interpolate(&r.row1_profile, x))
                            .sum::<f64>()
                            / runs.len() as f64,
                    )
                })
                .collect();
            let apex = profile
                .iter()
                .min_by(|p, q| p.0.abs().total_cmp(&q.0.abs()))
                .map_or(f64::NAN, |p| p.1);
            let max = profile
                .iter()
                .map(|p| p.1)
                .fold(f64::NEG_INFINITY, f64::max);
            SeedAverage {
                setting,
                seeds: runs.len(),
                row1_szz_apex: apex,
                row1_szz_max: max,
                row1_dip: if max > 0.0 {
                    (max - apex) / max
                } else {
                    f64::NAN
                },
                coordination_interior: runs.iter().map(|r| r.coordination_interior).sum::<f64>()
                    / runs.len() as f64,
                profile,
            }
        })
        .collect()
}

/// A profile's value at `x`, linear between its points (sorted by x), its end values
/// beyond them.
fn interpolate(p: &[(f64, f64)], x: f64) -> f64 {
    let k = p.partition_point(|q| q.0 < x);
    if k == 0 || k == p.len() {
        return p.get(k.min(p.len() - 1)).map_or(0.0, |q| q.1);
    }
    let (a, b) = (p[k - 1], p[k]);
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

/// Two variants whose stress the paper finds the same (R1: ν = 1 and 3/2; R8: the three
/// μ): how far apart their row-1 S_zz profiles are.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub variants: [String; 2],
    /// max |S_zz^a − S_zz^b| over row 1 (b interpolated at a's windows), over a's maximum.
    pub row1_szz_max_difference: f64,
    /// The same, averaged over the windows.
    pub row1_szz_mean_difference: f64,
    pub stress_ratio_interior_row1: [f64; 2],
}

/// The comparisons reproduction `id` is judged by: every pair of its variants built the
/// same way for R1 and R8 (R8's `mu-…` with each other, its `layered-mu-…` with each
/// other), none for the others.
pub fn comparisons(id: &str, found: &[Findings]) -> Vec<Comparison> {
    if !matches!(id, "R1" | "R8") {
        return Vec::new();
    }
    let built = |f: &Findings| f.variant.rsplit_once("mu-").map(|(b, _)| b.to_string());
    let mut out = Vec::new();
    for (i, a) in found.iter().enumerate() {
        for b in found[i + 1..].iter().filter(|b| built(b) == built(a)) {
            let max = a
                .row1_profile
                .iter()
                .map(|p| p.1)
                .fold(f64::NEG_INFINITY, f64::max);
            let diff: Vec<f64> = a
                .row1_profile
                .iter()
                .map(|p| (p.1 - interpolate(&b.row1_profile, p.0)).abs() / max)
                .collect();
            out.push(Comparison {
                variants: [a.variant.clone(), b.variant.clone()],
                row1_szz_max_difference: diff.iter().copied().fold(0.0, f64::max),
                row1_szz_mean_difference: diff.iter().sum::<f64>() / diff.len().max(1) as f64,
                stress_ratio_interior_row1: [
                    a.stress_ratio_interior_row1,
                    b.stress_ratio_interior_row1,
                ],
            });
        }
    }
    out
}
