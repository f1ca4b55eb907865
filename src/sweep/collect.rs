//! `talus sweep collect DIR`: every run's measures in one table, and per grid point the
//! mean, standard deviation and standard error over seeds of each scalar, with the
//! seed-averaged profiles and their spread (tables and plots with bands).
//!
//! Written to `DIR/collect/`: `runs.csv` (a row per run), `points.csv` (a row per grid
//! point), `collect.json` (both, with the profiles), `profiles/point<K>_<name>.csv` and
//! `<name>.svg` for the profiles S_zz(1), the base force F_B/mg and the packing fraction
//! against depth. Nothing in them depends on wall time or on where a run ran, so a sweep
//! run on a cluster collects to the same bytes as the same sweep run locally.

use super::{Failed, Measures, Plan, PlannedRun, RunState, SweepError};
use crate::base::files::write_atomic;
use crate::render::plots;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Mean, sample standard deviation and standard error of the finite values among `n`
/// runs (a quantity a run could not measure, NaN, is left out and not counted).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stat {
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (n − 1 in the denominator); NaN for fewer than two.
    pub std: f64,
    /// std/√n.
    pub se: f64,
}

pub fn stat(values: &[f64]) -> Stat {
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let n = finite.len();
    let mean = finite.iter().sum::<f64>() / n as f64;
    let std = if n >= 2 {
        (finite.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        f64::NAN
    };
    Stat {
        n,
        mean,
        std,
        se: std / (n as f64).sqrt(),
    }
}

/// A profile averaged over seeds at one abscissa.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Band {
    pub x: f64,
    pub mean: f64,
    pub std: f64,
    /// Seeds whose profile reaches this x.
    pub n: usize,
}

/// The seed average of profiles (each sorted by x): at the abscissae of the first, every
/// profile interpolated linearly, counted only where it reaches (no extrapolation: heaps
/// of different widths are averaged where they overlap).
pub fn average_profiles(profiles: &[&[(f64, f64)]]) -> Vec<Band> {
    let Some(first) = profiles.first() else {
        return Vec::new();
    };
    (first.iter())
        .map(|&(x, _)| {
            let values: Vec<f64> = (profiles.iter())
                .filter_map(|p| interpolate(p, x))
                .collect();
            let s = stat(&values);
            Band {
                x,
                mean: s.mean,
                std: s.std,
                n: s.n,
            }
        })
        .filter(|b| b.n > 0)
        .collect()
}

/// A profile's value at `x`, linear between its points; None outside them.
fn interpolate(p: &[(f64, f64)], x: f64) -> Option<f64> {
    let k = p.partition_point(|q| q.0 < x);
    if k < p.len() && p[k].0 == x {
        return Some(p[k].1);
    }
    if k == 0 || k == p.len() {
        return None;
    }
    let (a, b) = (p[k - 1], p[k]);
    Some(a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

/// A profile a sweep averages: its name (file names), title, axis labels, and where a
/// run's measures keep it.
struct Profile {
    name: &'static str,
    title: &'static str,
    x: plots::Axis<'static>,
    y: plots::Axis<'static>,
    of: fn(&Measures) -> &[(f64, f64)],
}

const PROFILES: [Profile; 3] = [
    Profile {
        name: "szz_row1",
        title: "S_zz in row 1, seed average ± one standard deviation",
        x: plots::Axis::new("X - X_apex", "heap widths"),
        y: plots::Axis::new("S_zz(1) = 2σ_zz / (ρ g h)", "-"),
        of: |m| &m.szz_row1,
    },
    Profile {
        name: "base_force",
        title: "Force on the fixed base particles, seed average ± one standard deviation",
        x: plots::Axis::new("x - x_apex", "mean diameters"),
        y: plots::Axis::new("F_B / (m g)", "-"),
        of: |m| &m.base_force,
    },
    Profile {
        name: "packing",
        title: "Packing fraction against depth, seed average ± one standard deviation",
        x: plots::Axis::new("depth below the top", "mean diameters"),
        y: plots::Axis::new("packing fraction", "-"),
        of: |m| &m.packing,
    },
];

/// One run in the tables.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    pub index: usize,
    pub name: String,
    pub point: usize,
    pub seed: u64,
    /// `measured`, `failed`, `ran` (not measured), `stopped` or `not run`.
    pub status: &'static str,
    pub error: Option<String>,
    /// The run's scalars (`Measures::scalars`), when measured.
    pub scalars: Vec<(String, f64)>,
}

/// One grid point.
#[derive(Clone, Debug, Serialize)]
pub struct PointRow {
    pub point: usize,
    /// Its grid values, `key=value`.
    pub values: Vec<String>,
    pub runs: usize,
    pub measured: usize,
    pub stats: Vec<(String, Stat)>,
    /// The seed-averaged profiles, by name (`PROFILES`).
    pub profiles: Vec<(String, Vec<Band>)>,
    /// The base-load dip over the seeds, when the runs stand on fixed base particles.
    pub dip: Option<DipOverSeeds>,
}

/// Whether a point's heaps have an M base load (issue 20 item 6): the seed mean of each
/// heap's dip less what noise gives it (`base_load_dip_excess_mg`: unbiased by the
/// maxima of noise) against its standard error over seeds, and how many heaps alone
/// were called M.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DipOverSeeds {
    /// In m g.
    pub excess: Stat,
    /// excess.mean / excess.se.
    pub z: f64,
    pub heaps_called_m: usize,
    /// `M` (z ≥ 2), `no significant dip`, or `one seed` (no spread over seeds: see the
    /// run's own verdict).
    pub verdict: &'static str,
}

pub fn dip_over_seeds(measured: &[&Measures]) -> Option<DipOverSeeds> {
    let excess: Vec<f64> = (measured.iter())
        .filter_map(|m| Some(m.base_load_dip_mg? - m.base_load_dip_null_mg?))
        .collect();
    let s = stat(&excess);
    if s.n == 0 {
        return None;
    }
    let z = s.mean / s.se;
    let z_significant = crate::analyze::spread::Z_SIGNIFICANT;
    Some(DipOverSeeds {
        excess: s,
        z,
        heaps_called_m: (measured.iter())
            .filter(|m| m.base_load_dip_z.is_some_and(|z| z >= z_significant))
            .count(),
        verdict: if s.n < 2 {
            "one seed"
        } else if z >= z_significant {
            "M"
        } else {
            "no significant dip"
        },
    })
}

#[derive(Clone, Debug, Serialize)]
pub struct Collection {
    pub scene: String,
    pub seeds: Vec<u64>,
    pub grid: Vec<super::Axis>,
    pub runs: Vec<RunRow>,
    pub points: Vec<PointRow>,
}

/// Gathers the runs of `plan` from their folders under `dir`.
pub fn gather(dir: &Path, plan: &Plan) -> Collection {
    let found: Vec<(RunRow, Option<Measures>)> =
        (plan.runs.iter()).map(|r| row_of(dir, r)).collect();
    let points = (0..plan.points())
        .map(|point| {
            let of_point: Vec<&(RunRow, Option<Measures>)> =
                found.iter().filter(|f| f.0.point == point).collect();
            let measured: Vec<&Measures> = of_point.iter().filter_map(|f| f.1.as_ref()).collect();
            point_row(
                point,
                plan.point_overrides(point),
                of_point.len(),
                &measured,
            )
        })
        .collect();
    Collection {
        scene: plan.scene.clone(),
        seeds: plan.seeds.clone(),
        grid: plan.grid.clone(),
        runs: found.into_iter().map(|f| f.0).collect(),
        points,
    }
}

fn row_of(dir: &Path, run: &PlannedRun) -> (RunRow, Option<Measures>) {
    let folder = super::run_dir(dir, run);
    let mut row = RunRow {
        index: run.index,
        name: run.name.clone(),
        point: run.point,
        seed: run.seed,
        status: "not run",
        error: None,
        scalars: Vec::new(),
    };
    if let Some(Failed { error, .. }) = super::read_failed(&folder) {
        row.status = "failed";
        row.error = Some(error);
        return (row, None);
    }
    match super::state(&folder) {
        RunState::Measured => match super::read_measures(&folder) {
            Ok(m) => {
                row.status = "measured";
                row.scalars = (m.scalars().into_iter())
                    .map(|(k, v)| (k.to_string(), v))
                    .collect();
                return (row, Some(m));
            }
            Err(e) => {
                row.status = "failed";
                row.error = Some(e.to_string());
            }
        },
        RunState::Ran => row.status = "ran",
        RunState::Stopped(_) => row.status = "stopped",
        RunState::New => {}
    }
    (row, None)
}

/// A point's statistics over its measured runs.
pub fn point_row(
    point: usize,
    values: Vec<String>,
    runs: usize,
    measured: &[&Measures],
) -> PointRow {
    let names: Vec<&str> = (measured.first())
        .map(|m| m.scalars().into_iter().map(|s| s.0).collect())
        .unwrap_or_default();
    let stats = (names.iter().enumerate())
        .map(|(k, name)| {
            let values: Vec<f64> = measured.iter().map(|m| m.scalars()[k].1).collect();
            (name.to_string(), stat(&values))
        })
        .collect();
    let profiles = (PROFILES.iter())
        .map(|p| {
            let each: Vec<&[(f64, f64)]> = measured.iter().map(|m| (p.of)(m)).collect();
            (p.name.to_string(), average_profiles(&each))
        })
        .collect();
    PointRow {
        point,
        values,
        runs,
        measured: measured.len(),
        stats,
        profiles,
        dip: dip_over_seeds(measured),
    }
}

/// A number in a CSV cell: the shortest text that reads back the same; empty when
/// undefined.
fn cell(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// A CSV cell of text, quoted when it holds a comma, a quote or a line break.
fn text_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn scalar_names(c: &Collection) -> Vec<String> {
    (c.points.iter().find(|p| !p.stats.is_empty()))
        .map(|p| p.stats.iter().map(|s| s.0.clone()).collect())
        .unwrap_or_default()
}

pub fn runs_csv(c: &Collection) -> String {
    let names = scalar_names(c);
    let mut out = String::from("index,name,point,seed");
    for axis in &c.grid {
        out.push(',');
        out.push_str(&text_cell(&axis.key));
    }
    out.push_str(",status");
    for n in &names {
        out.push(',');
        out.push_str(n);
    }
    out.push_str(",error\n");
    for r in &c.runs {
        let _ = write!(
            out,
            "{},{},{},{}",
            r.index,
            text_cell(&r.name),
            r.point,
            r.seed
        );
        for v in &c.points[r.point].values {
            let value = v.split_once('=').map_or("", |kv| kv.1);
            out.push(',');
            out.push_str(&text_cell(value));
        }
        let _ = write!(out, ",{}", r.status);
        for k in 0..names.len() {
            out.push(',');
            out.push_str(&r.scalars.get(k).map_or(String::new(), |s| cell(s.1)));
        }
        let _ = writeln!(out, ",{}", text_cell(r.error.as_deref().unwrap_or("")));
    }
    out
}

pub fn points_csv(c: &Collection) -> String {
    let names = scalar_names(c);
    let mut out = String::from("point");
    for axis in &c.grid {
        out.push(',');
        out.push_str(&text_cell(&axis.key));
    }
    out.push_str(",runs,measured");
    for n in &names {
        let _ = write!(out, ",{n}_mean,{n}_std,{n}_se,{n}_n");
    }
    out.push('\n');
    for p in &c.points {
        out.push_str(&p.point.to_string());
        for v in &p.values {
            out.push(',');
            out.push_str(&text_cell(v.split_once('=').map_or("", |kv| kv.1)));
        }
        let _ = write!(out, ",{},{}", p.runs, p.measured);
        for k in 0..names.len() {
            match p.stats.get(k) {
                Some((_, s)) => {
                    let _ = write!(
                        out,
                        ",{},{},{},{}",
                        cell(s.mean),
                        cell(s.std),
                        cell(s.se),
                        s.n
                    );
                }
                None => out.push_str(",,,,0"),
            }
        }
        out.push('\n');
    }
    out
}

/// A point's name in legends: its grid values, or the scene's name without a grid.
fn point_label(c: &Collection, p: &PointRow) -> String {
    if p.values.is_empty() {
        c.scene.clone()
    } else {
        p.values.join(" ")
    }
}

/// Writes `DIR/collect/` and returns its files.
pub fn write(dir: &Path, c: &Collection) -> Result<Vec<PathBuf>, SweepError> {
    let out = dir.join("collect");
    let profiles_dir = out.join("profiles");
    std::fs::create_dir_all(&profiles_dir).map_err(super::io(&profiles_dir))?;
    let mut files = Vec::new();
    let mut put = |path: PathBuf, text: &str| -> Result<(), SweepError> {
        write_atomic(&path, text.as_bytes()).map_err(super::io(&path))?;
        files.push(path);
        Ok(())
    };
    put(out.join("runs.csv"), &runs_csv(c))?;
    put(out.join("points.csv"), &points_csv(c))?;
    // NaN (an undefined deviation) is written as null.
    let json = serde_json::to_string_pretty(c).expect("a collection serialises");
    put(out.join("collect.json"), &json)?;
    for p in &c.points {
        for (name, bands) in &p.profiles {
            let mut text = String::from("x,mean,std,n\n");
            for b in bands {
                let _ = writeln!(
                    text,
                    "{},{},{},{}",
                    cell(b.x),
                    cell(b.mean),
                    cell(b.std),
                    b.n
                );
            }
            put(
                profiles_dir.join(format!("point{}_{name}.csv", p.point)),
                &text,
            )?;
        }
    }
    for (k, profile) in PROFILES.iter().enumerate() {
        let means: Vec<plots::Means> = (c.points.iter())
            .filter(|p| !p.profiles[k].1.is_empty())
            .map(|p| {
                let line = p.profiles[k]
                    .1
                    .iter()
                    .map(|b| (b.x, b.mean, b.std))
                    .collect();
                (point_label(c, p), line)
            })
            .collect();
        if means.is_empty() {
            continue;
        }
        let path = out.join(format!("{}.svg", profile.name));
        let (title, x, y) = (profile.title, profile.x, profile.y);
        plots::write_bands(&path, title, x, y, &means).map_err(|e| SweepError::Damaged {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        files.push(path);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_against_hand_computed_values() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, squared deviations sum to 32, s² = 32/7.
        let s = stat(&[2.0, 4.0, 4.0, 4.0, 5.0, f64::NAN, 5.0, 7.0, 9.0]);
        assert_eq!(s.n, 8);
        assert_eq!(s.mean, 5.0);
        assert!((s.std - (32.0f64 / 7.0).sqrt()).abs() < 1e-15);
        assert!((s.se - (32.0f64 / 7.0 / 8.0).sqrt()).abs() < 1e-15);
        let one = stat(&[3.0]);
        assert_eq!((one.n, one.mean), (1, 3.0));
        assert!(one.std.is_nan());
        assert_eq!(stat(&[]).n, 0);
    }

    #[test]
    fn profiles_average_where_they_overlap() {
        let a = [(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)];
        let b = [(0.5, 2.0), (1.5, 4.0)];
        let bands = average_profiles(&[&a, &b]);
        // At x = 0 only a reaches; at 1, b interpolates to 3; at 2 only a.
        assert_eq!(bands.len(), 3);
        assert_eq!((bands[0].mean, bands[0].n), (1.0, 1));
        assert_eq!((bands[1].mean, bands[1].n, bands[1].std), (3.0, 2, 0.0));
        assert_eq!((bands[2].mean, bands[2].n), (5.0, 1));
    }

    /// A run's measures with only the base-load dip set (None: a measures.json from
    /// before the dip).
    fn measures(dip: Option<(f64, f64, f64)>) -> Measures {
        let mut v = serde_json::json!({
            "grains": 1, "time": 1.0, "repose_left_deg": 20.0, "repose_right_deg": 20.0,
            "height_d": 1.0, "packing_fraction_lower_half": 0.8, "coordination_interior": 4.0,
            "stress_ratio_interior_row1": 0.5, "row1_szz_centre": 1.0, "row1_szz_max": 1.0,
            "base_load_centre_mg": 10.0, "base_load_left_max_mg": 11.0,
            "base_load_right_max_mg": 11.0, "szz_row1": [], "base_force": [], "packing": []
        });
        if let Some((d, null, z)) = dip {
            v["base_load_dip_mg"] = d.into();
            v["base_load_dip_null_mg"] = null.into();
            v["base_load_dip_z"] = z.into();
        }
        serde_json::from_value(v).unwrap()
    }

    #[test]
    fn the_dip_over_seeds_is_the_mean_excess_over_noise_against_its_se() {
        // Excesses 1.0, 1.2, 0.8 m g: mean 1, sd 0.2, se 0.2/√3, z = 5√3: an M, two of the
        // three heaps called M alone.
        let m = [
            measures(Some((2.0, 1.0, 2.5))),
            measures(Some((2.0, 0.8, 1.0))),
            measures(Some((1.5, 0.7, 3.0))),
        ];
        let d = dip_over_seeds(&m.iter().collect::<Vec<_>>()).unwrap();
        assert_eq!((d.excess.n, d.heaps_called_m, d.verdict), (3, 2, "M"));
        assert!((d.excess.mean - 1.0).abs() < 1e-12 && (d.z - 5.0 * 3f64.sqrt()).abs() < 1e-9);
        // Excesses 1, −1, 0.5 straddle zero; one seed has no spread; old measures none.
        let m = [
            measures(Some((2.0, 1.0, 2.5))),
            measures(Some((0.0, 1.0, -1.0))),
            measures(Some((1.5, 1.0, 0.5))),
        ];
        let d = dip_over_seeds(&m.iter().collect::<Vec<_>>()).unwrap();
        assert_eq!(d.verdict, "no significant dip");
        assert_eq!(dip_over_seeds(&[&m[0]]).unwrap().verdict, "one seed");
        assert_eq!(dip_over_seeds(&[&measures(None)]), None);
        // The scalars carry the excess per run for runs.csv and points.csv.
        let sc = m[1].scalars();
        assert!(sc.contains(&("base_load_dip_excess_mg", -1.0)), "{sc:?}");
    }

    #[test]
    fn csv_cells_are_quoted_when_needed() {
        assert_eq!(text_cell("[0,10]"), "\"[0,10]\"");
        assert_eq!(text_cell("a\"b"), "\"a\"\"b\"");
        assert_eq!(text_cell("x,\"y\""), "\"x,\"\"y\"\"\"");
        assert_eq!(cell(f64::NAN), "");
        assert_eq!(cell(0.1), "0.1");
    }
}
