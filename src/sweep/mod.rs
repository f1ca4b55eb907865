//! Ensembles and parameter sweeps: a scene run for every combination of seeds and
//! parameter values (`talus sweep`), one folder each, and the statistics over seeds
//! (`collect`). Heap results are statistical (paper 000 averages its profiles over many
//! runs; one heap's two flanks routinely differ by 10–20°), so a result is a mean with
//! its spread.
//!
//! A sweep folder holds:
//! - `sweep.json`, the plan ([`Plan`]): the seeds, the grid of parameter values, and
//!   every run's name and overrides;
//! - `scene.json`, the base scene, resolved (with the sweep's own `--set`s): every run is
//!   this scene with its overrides applied;
//! - `runs/NAME/`, one run folder per run (as `talus run` writes it), with
//!   `measures.json` ([`Measures`]) once it has been measured, or `failed.json` when it
//!   failed;
//! - `sweep.sbatch` and `slurm/` for a sweep run as a Slurm job array (`slurm`);
//! - `collect/` (`collect`).
//!
//! How a run is executed (engine, analysis) is the CLI's business; this module plans,
//! names, tells a run's state from its folder, and aggregates.

pub mod collect;
mod measures;
pub mod slurm;

use crate::base::files::write_atomic;
use crate::scene::{self, Scene, SceneError};
pub use measures::{Measures, read_measures, write_measures};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What `sweep.json` says it is.
pub const FORMAT: &str = "talus-sweep";
pub const VERSION: u32 = 1;

#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("--seeds {0}: expected A..B (A to B, both included) or a list A,B,C of seeds")]
    Seeds(String),
    #[error("--grid {0}: expected KEY=V1,V2,... with at least one value")]
    Grid(String),
    #[error("--grid {0}: {1}")]
    GridKey(String, &'static str),
    #[error("run {run} ({overrides}): {source}")]
    Scene {
        run: String,
        overrides: String,
        source: SceneError,
    },
    #[error(
        "run {run}: a sweep's runs are single copies of a scene (replicas = 1); sweep seeds \
         with --seeds instead of replicas"
    )]
    Replicas { run: String },
    #[error(
        "{dir} holds a different sweep (its sweep.json or scene.json differs from this one's): \
         choose another --out, or pass --force to remove that sweep's files first"
    )]
    Different { dir: String },
    #[error("{dir}: not a sweep folder (no sweep.json): {reason}")]
    NotASweep { dir: String, reason: String },
    #[error("{path}: {reason}")]
    Damaged { path: String, reason: String },
    #[error("--index {index}: the sweep in {dir} has runs 0 to {last}")]
    Index {
        index: usize,
        dir: String,
        last: usize,
    },
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SweepError + '_ {
    move |source| SweepError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// One swept key and its values, as given (`contact.mu=0.3,0.5`): each value is read as
/// an override's value is (JSON, else a string).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    pub key: String,
    pub values: Vec<String>,
}

/// One run of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannedRun {
    pub index: usize,
    /// Folder name under `runs/`: the index, the grid values and the seed.
    pub name: String,
    /// Which combination of grid values (0 without a grid): the runs of one point
    /// differ only in their seed, and their results are averaged together.
    pub point: usize,
    pub seed: u64,
    /// Applied to the base scene, in this order: the grid values, then `seed`.
    pub overrides: Vec<String>,
}

/// The analysis options every run is measured with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measuring {
    /// Moving-average window width and row height, in mean diameters (`talus analyze
    /// --window/--row`).
    pub window: f64,
    pub row: f64,
}

impl Default for Measuring {
    fn default() -> Self {
        let o = crate::analyze::Options::default();
        Measuring {
            window: o.window,
            row: o.row,
        }
    }
}

/// `sweep.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    pub format: String,
    pub version: u32,
    /// The base scene's name.
    pub scene: String,
    pub seeds: Vec<u64>,
    pub grid: Vec<Axis>,
    /// `cpu`, `gpu` or `auto`, as `talus run --backend`.
    pub backend: String,
    pub measuring: Measuring,
    pub runs: Vec<PlannedRun>,
}

/// `--seeds`: `A..B` (both included: `1..8` is eight seeds) or `A,B,C`.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>, SweepError> {
    let bad = || SweepError::Seeds(text.to_string());
    let seeds: Vec<u64> = if let Some((a, b)) = text.split_once("..") {
        let (a, b): (u64, u64) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim()
                .trim_start_matches('=')
                .parse()
                .map_err(|_| bad())?,
        );
        if a > b || b - a >= 100_000 {
            return Err(bad());
        }
        (a..=b).collect()
    } else {
        (text.split(',').map(|s| s.trim().parse().map_err(|_| bad()))).collect::<Result<_, _>>()?
    };
    let mut sorted = seeds.clone();
    sorted.sort_unstable();
    sorted.dedup();
    if seeds.is_empty() || sorted.len() != seeds.len() {
        return Err(bad());
    }
    Ok(seeds)
}

/// `--grid KEY=V1,V2,...`. Values are split at commas outside brackets and braces, so
/// that `domain.x=[0,10],[0,20]` gives two arrays.
pub fn parse_axis(text: &str) -> Result<Axis, SweepError> {
    let (key, values) = (text.split_once('=')).ok_or_else(|| SweepError::Grid(text.into()))?;
    let key = key.trim();
    if key.is_empty() {
        return Err(SweepError::Grid(text.into()));
    }
    if key == "seed" {
        return Err(SweepError::GridKey(
            text.into(),
            "the seed is swept with --seeds",
        ));
    }
    let mut out = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (k, c) in values.char_indices() {
        match c {
            '[' | '{' => depth += 1,
            ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(values[start..k].trim().to_string());
                start = k + 1;
            }
            _ => {}
        }
    }
    out.push(values[start..].trim().to_string());
    if out.iter().any(String::is_empty) {
        return Err(SweepError::Grid(text.into()));
    }
    Ok(Axis {
        key: key.into(),
        values: out,
    })
}

/// Every combination of the grid's values (the last axis fastest), then every seed for
/// each: the runs of a point are consecutive. Each run's scene is checked here, so that a
/// bad value is refused before anything runs.
pub fn plan(
    base: &Scene,
    seeds: &[u64],
    grid: &[Axis],
    backend: &str,
    measuring: Measuring,
) -> Result<Plan, SweepError> {
    let text = base_text(base);
    let points: usize = grid.iter().map(|a| a.values.len()).product();
    let mut runs = Vec::with_capacity(points * seeds.len());
    for point in 0..points {
        // The point's value on each axis: a mixed-radix count, last axis fastest.
        let mut rest = point;
        let mut picked = vec![0; grid.len()];
        for (a, axis) in grid.iter().enumerate().rev() {
            picked[a] = rest % axis.values.len();
            rest /= axis.values.len();
        }
        for &seed in seeds {
            let index = runs.len();
            let mut overrides: Vec<String> = (grid.iter().zip(&picked))
                .map(|(axis, &v)| format!("{}={}", axis.key, axis.values[v]))
                .collect();
            overrides.push(format!("seed={seed}"));
            let mut name = format!("{index:04}");
            for (axis, &v) in grid.iter().zip(&picked) {
                name.push('-');
                name.push_str(&label(&axis.key, &axis.values[v]));
            }
            name.push_str(&format!("-seed{seed}"));
            let scene = scene::parse(&text, &overrides).map_err(|source| SweepError::Scene {
                run: name.clone(),
                overrides: overrides.join(" "),
                source,
            })?;
            // Each run is measured as one heap; copies would lie on top of each other.
            if scene.replicas > 1 {
                return Err(SweepError::Replicas { run: name });
            }
            runs.push(PlannedRun {
                index,
                name,
                point,
                seed,
                overrides,
            });
        }
    }
    Ok(Plan {
        format: FORMAT.into(),
        version: VERSION,
        scene: base.name.clone(),
        seeds: seeds.to_vec(),
        grid: grid.to_vec(),
        backend: backend.into(),
        measuring,
        runs,
    })
}

/// A grid value in a folder name: the key's last part and the value, with anything but
/// letters, digits, `.`, `+` and `-` made `_` (`particles[1].rate=2` → `rate2`).
fn label(key: &str, value: &str) -> String {
    let last = key
        .rsplit(['.', ']'])
        .find(|s| !s.is_empty())
        .unwrap_or(key);
    let last = last.trim_start_matches('[');
    let clean = |s: &str| -> String {
        s.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || ".+-".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    };
    let mut value = clean(value);
    value.truncate(24);
    format!("{}{value}", clean(last))
}

/// The base scene as it is stored (`scene.json`) and read back by every run.
fn base_text(base: &Scene) -> String {
    serde_json::to_string_pretty(base).expect("a scene always serialises")
}

/// A planned run's scene: the stored base scene with the run's overrides.
pub fn run_scene(dir: &Path, run: &PlannedRun) -> Result<Scene, SweepError> {
    let path = dir.join("scene.json");
    let text = std::fs::read_to_string(&path).map_err(|e| SweepError::NotASweep {
        dir: dir.display().to_string(),
        reason: format!("{}: {e}", path.display()),
    })?;
    scene::parse(&text, &run.overrides).map_err(|source| SweepError::Scene {
        run: run.name.clone(),
        overrides: run.overrides.join(" "),
        source,
    })
}

/// The files a sweep owns in its folder (what `--force` removes).
const OWN: [&str; 6] = [
    "sweep.json",
    "scene.json",
    "runs",
    "collect",
    "sweep.sbatch",
    "slurm",
];

/// Makes `dir` this sweep's folder: writes the plan and the base scene, or finds them
/// there already (the same sweep run again continues it). Another sweep's folder is
/// refused unless `force`, which removes that sweep's files first.
pub fn claim(dir: &Path, plan: &Plan, base: &Scene, force: bool) -> Result<(), SweepError> {
    let plan_text = serde_json::to_string_pretty(plan).expect("a plan always serialises");
    let scene_text = base_text(base);
    let (plan_path, scene_path) = (dir.join("sweep.json"), dir.join("scene.json"));
    let existing =
        (std::fs::read_to_string(&plan_path).ok()).zip(std::fs::read_to_string(&scene_path).ok());
    match existing {
        Some((p, s)) if p == plan_text && s == scene_text => return Ok(()),
        Some(_) if !force => {
            return Err(SweepError::Different {
                dir: dir.display().to_string(),
            });
        }
        _ if force => {
            for name in OWN {
                let path = dir.join(name);
                let removed = if path.is_dir() {
                    std::fs::remove_dir_all(&path)
                } else {
                    std::fs::remove_file(&path)
                };
                match removed {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(io(&path)(e));
                    }
                    _ => {}
                }
            }
        }
        _ => {}
    }
    std::fs::create_dir_all(dir.join("runs")).map_err(io(dir))?;
    // The scene first: a folder with a plan always has its scene.
    write_atomic(&scene_path, scene_text.as_bytes()).map_err(io(&scene_path))?;
    write_atomic(&plan_path, plan_text.as_bytes()).map_err(io(&plan_path))
}

/// Reads `DIR/sweep.json`.
pub fn read_plan(dir: &Path) -> Result<Plan, SweepError> {
    let path = dir.join("sweep.json");
    let text = std::fs::read_to_string(&path).map_err(|e| SweepError::NotASweep {
        dir: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let plan: Plan = serde_json::from_str(&text).map_err(|e| SweepError::Damaged {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    let valid = plan.format == FORMAT
        && plan.version == VERSION
        && plan.runs.iter().enumerate().all(|(k, r)| r.index == k)
        && (plan.runs.iter()).all(|r| !r.name.contains(['/', '\\']) && !r.name.starts_with('.'));
    if !valid {
        return Err(SweepError::Damaged {
            path: path.display().to_string(),
            reason: format!("not a {FORMAT} version {VERSION} plan with runs numbered 0, 1, …"),
        });
    }
    Ok(plan)
}

impl Plan {
    pub fn run(&self, dir: &Path, index: usize) -> Result<&PlannedRun, SweepError> {
        self.runs.get(index).ok_or_else(|| SweepError::Index {
            index,
            dir: dir.display().to_string(),
            last: self.runs.len().saturating_sub(1),
        })
    }

    /// The number of grid points (combinations of values).
    pub fn points(&self) -> usize {
        self.grid.iter().map(|a| a.values.len()).product()
    }

    /// A point's grid values, `key=value` each (empty without a grid).
    pub fn point_overrides(&self, point: usize) -> Vec<String> {
        let run = self.runs.iter().find(|r| r.point == point);
        run.map_or_else(Vec::new, |r| r.overrides[..self.grid.len()].to_vec())
    }
}

/// A run's folder.
pub fn run_dir(dir: &Path, run: &PlannedRun) -> PathBuf {
    dir.join("runs").join(&run.name)
}

/// Where a run stands, from its folder.
#[derive(Debug, PartialEq)]
pub enum RunState {
    /// Run and measured (`measures.json`).
    Measured,
    /// Run (`summary.json`), not yet measured.
    Ran,
    /// Started and stopped: its own checkpoints, newest first.
    Stopped(Vec<PathBuf>),
    /// Nothing to continue from.
    New,
}

pub fn state(run_dir: &Path) -> RunState {
    if run_dir.join("measures.json").is_file() {
        return RunState::Measured;
    }
    if run_dir.join("summary.json").is_file() {
        return RunState::Ran;
    }
    let mut checkpoints: Vec<PathBuf> = std::fs::read_dir(run_dir.join("checkpoints"))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    checkpoints.retain(|p| {
        p.file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with("ckpt_") && n.ends_with(".bin"))
    });
    checkpoints.sort();
    checkpoints.reverse();
    if checkpoints.is_empty() {
        RunState::New
    } else {
        RunState::Stopped(checkpoints)
    }
}

/// Why a run failed, kept in its folder (`failed.json`) for `collect` to report, until
/// the run is tried again.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Failed {
    pub run: String,
    pub error: String,
    /// The exit code `talus run` would have given (1 run failed, 2 bad input).
    pub code: u8,
}

pub fn write_failed(run_dir: &Path, failed: &Failed) -> Result<(), SweepError> {
    std::fs::create_dir_all(run_dir).map_err(io(run_dir))?;
    let path = run_dir.join("failed.json");
    let text = serde_json::to_string_pretty(failed).expect("serialises");
    write_atomic(&path, text.as_bytes()).map_err(io(&path))
}

pub fn read_failed(run_dir: &Path) -> Option<Failed> {
    let text = std::fs::read_to_string(run_dir.join("failed.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// Forgets an earlier failure when the run is tried again.
pub fn clear_failed(run_dir: &Path) {
    let _ = std::fs::remove_file(run_dir.join("failed.json"));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_are_ranges_or_lists() {
        assert_eq!(parse_seeds("1..4").unwrap(), vec![1, 2, 3, 4]);
        assert_eq!(parse_seeds("1..=2").unwrap(), vec![1, 2]);
        assert_eq!(parse_seeds("7").unwrap(), vec![7]);
        assert_eq!(parse_seeds("3, 1,9").unwrap(), vec![3, 1, 9]);
        for bad in ["", "4..1", "a..3", "1,1", "1..", "0..1000000", "-1"] {
            assert!(parse_seeds(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn grid_values_split_outside_brackets() {
        let a = parse_axis("contact.mu=0.3, 0.5").unwrap();
        assert_eq!(a.key, "contact.mu");
        assert_eq!(a.values, ["0.3", "0.5"]);
        let a = parse_axis("domain.x=[0,10],[0,20]").unwrap();
        assert_eq!(a.values, ["[0,10]", "[0,20]"]);
        for bad in ["mu", "=1", "mu=", "mu=1,", "seed=1,2"] {
            assert!(parse_axis(bad).is_err(), "{bad}");
        }
        assert_eq!(label("particles[1].rate", "2"), "rate2");
        assert_eq!(label("contact.mu", "0.3"), "mu0.3");
        assert_eq!(label("domain.x", "[0,10]"), "x_0_10_");
    }

    #[test]
    fn the_plan_is_the_product_of_points_and_seeds() {
        let base = scene::parse(scene::DEFAULT_SCENE, &[]).unwrap();
        let grid = [
            parse_axis("contact.mu=0.3,0.5").unwrap(),
            parse_axis("particles[1].rate=2,4,8").unwrap(),
        ];
        let p = plan(&base, &[1, 2], &grid, "cpu", Measuring::default()).unwrap();
        assert_eq!(p.runs.len(), 12);
        assert_eq!(p.points(), 6);
        let r = &p.runs[7];
        // Point 3 = (mu index 1, rate index 0), seed 2.
        assert_eq!(r.point, 3);
        assert_eq!(
            r.overrides,
            ["contact.mu=0.5", "particles[1].rate=2", "seed=2"]
        );
        assert_eq!(r.name, "0007-mu0.5-rate2-seed2");
        assert_eq!(
            p.point_overrides(3),
            ["contact.mu=0.5", "particles[1].rate=2"]
        );
        // The runs of a point are consecutive and differ only in the seed.
        assert!(p.runs.iter().all(|r| r.point == r.index / 2));
        // A value the scene refuses is refused with the run and the key.
        let bad = [parse_axis("contact.mu=0.3,-1").unwrap()];
        let e = plan(&base, &[1], &bad, "cpu", Measuring::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("run 0001-mu-1-seed1 (contact.mu=-1 seed=1): contact.mu"),
            "{e}"
        );
        let copies = [parse_axis("replicas=1,2").unwrap()];
        let e = plan(&base, &[1], &copies, "cpu", Measuring::default()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("run 0001-replicas2-seed1: a sweep's runs"),
            "{e}"
        );
    }
}
