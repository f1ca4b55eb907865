//! Benchmark workloads (`talus bench`, `benches/`): particle-steps per second of each
//! backend on settled disk packings of several sizes, polygon piles, and the reduced R4
//! pour.
//!
//! A "settled packing" is a triangular block of equal disks resting on a floor between
//! two walls, slightly compressed by gravity: every disk has four to six contacts, as in
//! the interior of a heap. A "polygon pile" is a 60° lattice pile of regular 12-gons
//! (R8's particles) whose faces touch; gravity presses them into about six area contacts
//! each. The first tenth of the steps is a warm-up and not timed.

pub mod agree;

use crate::gpu::GpuSimulation;
use crate::gpu::device::BackendChoice;
use crate::run::Engine;
use crate::scene;
use crate::sim::Simulation;
use serde::Serialize;
use serde_json::json;
use std::time::Instant;

#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    pub workload: String,
    pub backend: String,
    pub shape: String,
    /// Moving particles (the mean of the start and the end): what
    /// `particle_steps_per_second` counts; fixed ones are `fixed`.
    pub particles: u64,
    pub fixed: u64,
    pub steps: u64,
    pub seconds: f64,
    pub particle_steps_per_second: f64,
    pub steps_per_second: f64,
    pub microseconds_per_step: f64,
    /// GPU path: compute dispatches that ran workgroups and queue submissions (batches
    /// of steps and readbacks) per step; the dispatches of a step between rebuilds of
    /// the neighbour lists; and the rebuild stages' indirect dispatches that ran none
    /// (encoded every step, empty between rebuilds: issue 14 item 2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dispatches_per_step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dispatches_between_rebuilds: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub empty_dispatches_per_step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub submissions_per_step: Option<f64>,
    /// GPU path: every dispatch recorded per step, those that ran no workgroups
    /// included (issue 38: each is a command the device must take in order).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub commands_per_step: Option<f64>,
    /// Neighbour-list rebuilds per 1000 steps (both paths), and on the CPU path the
    /// candidate pairs and contacts per particle at the end (issue 13).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rebuilds_per_1000_steps: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pairs_per_particle: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts_per_particle: Option<f64>,
    /// GPU path with `--kernels`: device time per kernel and step, the costliest first.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kernels: Option<crate::gpu::KernelTimes>,
    /// Why `kernels` is missing where it was asked for (no timestamps on the adapter,
    /// a profiled step that failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kernels_error: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub cpu: String,
    pub cores: usize,
    /// Threads of the CPU path.
    pub threads: usize,
    pub results: Vec<Measurement>,
    /// Workloads that could not run on a backend (too large for the adapter, a
    /// divergence), with the reason; the others still ran.
    pub failures: Vec<Failure>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    pub workload: String,
    pub backend: String,
    pub error: String,
}

/// Why a workload could not be built or measured.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A built-in workload's scene is invalid: a bug in this file.
    #[error("{workload}: {source}")]
    Scene {
        workload: String,
        source: scene::SceneError,
    },
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    #[error(transparent)]
    Diverged(#[from] crate::sim::Divergence),
}

/// A triangular packing of `n` unit disks, about twice as wide as high, on a floor:
/// rows of `cols` disks, every other one shifted by half a diameter, as `row` blocks
/// (a list of 4 · 10⁶ particles took a minute and 12 GB to write and parse).
pub fn packing_scene(n: usize) -> String {
    let cols = ((2.0 * n as f64).sqrt().ceil() as usize).max(2);
    let h = 3f64.sqrt() / 2.0;
    let rows: Vec<_> = (0..n.div_ceil(cols))
        .map(|r| {
            let shift = if r % 2 == 1 { 0.5 } else { 0.0 };
            json!({ "kind": "row", "material": "m", "count": cols.min(n - r * cols),
                    "diameter": 1.0, "spacing": 1.0, "start": [shift + 0.5, 0.5 + r as f64 * h],
                    "fixed": false })
        })
        .collect();
    let w = cols as f64 + 1.0;
    let top = (n / cols + 2) as f64 * h + 2.0;
    json!({
        "name": format!("packing-{n}"),
        "dt": 0.002,
        "stop": { "time": 1e9 },
        "gravity": { "g": [0.0, -1.0] },
        "domain": { "x": [-2.0, w + 2.0], "z": [-2.0, top] },
        "materials": { "m": { "density": 1.2732395447351628 } },
        "contact": { "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0, "k_t": 571.4,
                     "gamma_t": 2.0, "mu": 0.5 },
        "walls": [{ "from": [0.0, 0.0], "to": [w, 0.0] }, { "from": [0.0, 0.0], "to": [0.0, top] },
                  { "from": [w, 0.0], "to": [w, top] }],
        "particles": rows,
        "output": { "checkpoint_every": 0 }
    })
    .to_string()
}

/// A 60° lattice pile of about `n` regular 12-gons (face-to-face diameter 1) on a fixed
/// bottom row.
pub fn polygon_pile_scene(n: usize) -> String {
    // Row M of a 60° pile holds L − M particles: L (L + 1)/2 in all.
    let l = (((8 * n + 1) as f64).sqrt() - 1.0) / 2.0;
    let l = (l.round() as u32).max(2);
    let w = l as f64 + 2.0;
    json!({
        "name": format!("polygon-pile-{n}"),
        "dt": 0.002,
        "stop": { "time": 1e9 },
        "gravity": { "g": [0.0, -1.0] },
        "domain": { "x": [-w, w], "z": [-2.0, w] },
        "materials": { "m": { "density": 1.2732395447351628 } },
        "contact": { "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 },
        "particles": [{ "kind": "lattice_pile", "material": "m", "slope": 60, "bottom_row": l,
                        "diameter": 1.0, "polygon": { "corners": 12 } }],
        "output": { "checkpoint_every": 0 }
    })
    .to_string()
}

/// About `n` rods of aspect 5 and width 1 under paper 004's law, lying in rows on each
/// other in a box 20 rods wide (a settled deposit: two sub-contacts per pair of
/// neighbours in a column, leapfrog as in R9).
pub fn rod_pile_scene(n: usize) -> String {
    let cols = 20usize;
    let rows = n.div_ceil(cols).max(1);
    let pitch = 5.05;
    let w = cols as f64 * pitch;
    let list: Vec<serde_json::Value> = (0..rows * cols)
        .map(|k| {
            let (c, r) = ((k % cols) as f64, (k / cols) as f64);
            // Each row 2·10⁻³ into the one below, about the load of a deep deposit.
            json!({ "position": [(c + 0.5) * pitch - 0.5 * w, 0.498 + 0.998 * r],
                    "diameter": 1.0 })
        })
        .collect();
    let h = rows as f64 + 5.0;
    json!({
        "name": format!("rod-pile-{n}"),
        "dt": 1.5e-4,
        "integrator": "leapfrog",
        "stop": { "time": 1e9 },
        "gravity": { "g": [0.0, -10.0] },
        "domain": { "x": [-0.5 * w - 5.0, 0.5 * w + 5.0], "z": [-5.0, h + 5.0] },
        "materials": { "m": { "density": 1.0 } },
        "contact": { "law": "hertz_cohesive", "k_n": 1.0e7, "k_t": 1.0e6, "gamma_n": 300.0,
                     "gamma_t": 100.0, "mu": 0.5, "bond": 0.0, "d_c": 1.0e-4 },
        "walls": [{ "from": [-0.5 * w, 0.0], "to": [0.5 * w, 0.0] },
                  { "from": [-0.5 * w, 0.0], "to": [-0.5 * w, h] },
                  { "from": [0.5 * w, 0.0], "to": [0.5 * w, h] }],
        "particles": [{ "kind": "list", "material": "m", "rod": { "aspect": 5.0 },
                        "particles": list }],
        "output": { "checkpoint_every": 0 }
    })
    .to_string()
}

fn engine(sim: Simulation, backend: BackendChoice) -> Result<Engine, BenchError> {
    Ok(match backend {
        BackendChoice::Gpu => Engine::Gpu(Box::new(GpuSimulation::new(sim)?)),
        _ => Engine::cpu(sim),
    })
}

fn gpu_counters(e: &Engine) -> Option<crate::gpu::Counters> {
    match e {
        Engine::Gpu(g) => Some(g.counters()),
        Engine::Cpu(_) => None,
    }
}

/// Times `steps` steps after a warm-up of a tenth as many, or with a `budget` of
/// seconds, as many as fit in it (up to `steps`, in doubling batches); the particle
/// count is the mean of start and end.
fn measure(
    workload: &str,
    sim: Simulation,
    backend: BackendChoice,
    steps: u64,
    budget: Option<f64>,
    kernels: bool,
) -> Result<Measurement, BenchError> {
    let mut e = engine(sim, backend)?;
    let warm = if budget.is_some() { 10 } else { steps / 10 };
    e.advance(warm.clamp(1, steps.max(1)))?;
    let n0 = e.mobile_count();
    let counters0 = gpu_counters(&e);
    let rebuilds0 = match &e {
        Engine::Cpu(s) => s.neighbours.rebuilds,
        Engine::Gpu(g) => g.rebuilds(),
    };
    let t = Instant::now();
    let steps = match budget {
        None => {
            e.advance(steps)?;
            steps
        }
        Some(budget) => {
            let (mut done, mut batch) = (0, 8u64);
            while done < steps {
                let k = batch.min(steps - done);
                e.advance(k)?;
                done += k;
                if t.elapsed().as_secs_f64() >= budget {
                    break;
                }
                batch *= 2;
            }
            done
        }
    };
    let seconds = t.elapsed().as_secs_f64();
    let per_step = |c: u64| c as f64 / steps as f64;
    let (mut dispatches, mut between, mut empty, mut submissions) = (None, None, None, None);
    let mut commands = None;
    if let (Some(c0), Some(c)) = (counters0, gpu_counters(&e)) {
        let stages = crate::gpu::REBUILD_STAGES.len() as u64;
        let (direct, indirect) = (c.direct - c0.direct, c.indirect - c0.indirect);
        let ran = (stages * (c.rebuilds - c0.rebuilds)).min(indirect);
        dispatches = Some(per_step(direct + ran));
        between = Some(per_step(direct));
        empty = Some(per_step(indirect - ran));
        submissions = Some(per_step(c.submissions - c0.submissions));
        commands = Some(per_step(direct + indirect));
    }
    // Moving particles (fixed ones are never integrated), as other DEM codes count.
    let n = (n0 + e.mobile_count()) / 2;
    let fixed = e.active_count() - e.mobile_count();
    let (rebuilds, pairs, contacts) = match &e {
        Engine::Cpu(s) => {
            let per = |k: usize| Some(k as f64 / s.particles.active_count().max(1) as f64);
            (
                Some(1000.0 * (s.neighbours.rebuilds - rebuilds0) as f64 / steps as f64),
                per(s.neighbours.pairs.len()),
                per(s.pairs.len()),
            )
        }
        Engine::Gpu(g) => (
            Some(1000.0 * (g.rebuilds() - rebuilds0) as f64 / steps as f64),
            None,
            None,
        ),
    };
    // After the timing, so that the timestamps cost the figures above nothing. An
    // adapter without timestamps inside passes gets none (`run` says so), and a
    // profile that fails is noted beside the figures, which stand.
    let (mut kernel_times, mut kernels_error) = (None, None);
    if let Engine::Gpu(g) = &mut e
        && kernels
    {
        match g.profile(KERNEL_STEPS) {
            Ok(t) => kernel_times = Some(t),
            Err(e) => kernels_error = Some(e.to_string()),
        }
    }
    Ok(Measurement {
        workload: workload.into(),
        backend: e.name(),
        shape: if workload.starts_with("polygon") {
            "polygon-12".into()
        } else {
            "disk".into()
        },
        particles: n,
        fixed,
        steps,
        seconds,
        particle_steps_per_second: (n * steps) as f64 / seconds.max(1e-12),
        steps_per_second: steps as f64 / seconds.max(1e-12),
        microseconds_per_step: 1e6 * seconds / steps as f64,
        dispatches_per_step: dispatches,
        dispatches_between_rebuilds: between,
        empty_dispatches_per_step: empty,
        submissions_per_step: submissions,
        commands_per_step: commands,
        rebuilds_per_1000_steps: rebuilds,
        pairs_per_particle: pairs,
        contacts_per_particle: contacts,
        kernels: kernel_times,
        kernels_error,
    })
}

pub(crate) fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// The workloads by name, with their scenes: packings, polygon piles, rod piles, and
/// with `pour` the reduced R4 pour in its own domain and in a wide one.
fn workloads(
    sizes: &[usize],
    polygon_sizes: &[usize],
    rod_sizes: &[usize],
    pour: bool,
) -> Vec<(String, String)> {
    let mut workloads: Vec<(String, String)> = sizes
        .iter()
        .map(|&n| (format!("packing-{n}"), packing_scene(n)))
        .collect();
    workloads.extend(
        polygon_sizes
            .iter()
            .map(|&n| (format!("polygon-pile-{n}"), polygon_pile_scene(n))),
    );
    workloads.extend(
        rod_sizes
            .iter()
            .map(|&n| (format!("rod-pile-{n}"), rod_pile_scene(n))),
    );
    if pour {
        let text = include_str!("../../scenes/r4_pour_reduced.json");
        workloads.push(("r4-pour-reduced".into(), text.into()));
        // The same pour in a domain 10⁴ σ wide and 10³ σ high: the cell search costs
        // what the particles cost, not what the domain's area does (both paths).
        let mut wide: serde_json::Value = serde_json::from_str(text).expect("scene file");
        wide["domain"] = json!({ "x": [-5000.0, 5000.0], "z": [-1.0, 1000.0] });
        workloads.push(("r4-pour-reduced-wide".into(), wide.to_string()));
    }
    workloads
}

/// How each workload is timed.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// Steps timed (after a warm-up), or with `budget` the most steps timed.
    pub steps: u64,
    /// Seconds per measurement instead of a fixed step count.
    pub budget: Option<f64>,
    /// Also time the reduced R4 pour.
    pub pour: bool,
    /// GPU path: also time each kernel (`KERNEL_STEPS` steps with a timestamp after
    /// every dispatch; `GpuSimulation::profile`).
    pub kernels: bool,
}

/// Steps of the profiled run of `Timing::kernels`.
pub const KERNEL_STEPS: u64 = 128;

/// Runs every workload on every backend; `log` receives one line per measurement and
/// `partial` the report so far after each (`talus bench --out` writes it, so that a run
/// stopped at a time limit keeps what it measured: issue 38). A workload that cannot
/// run on a backend is recorded in `failures` and the rest go on.
pub fn run(
    backends: &[BackendChoice],
    sizes: &[usize],
    polygon_sizes: &[usize],
    rod_sizes: &[usize],
    timing: Timing,
    log: &mut dyn FnMut(String),
    partial: &mut dyn FnMut(&Report),
) -> Result<Report, BenchError> {
    let Timing {
        steps,
        budget,
        pour,
        kernels,
    } = timing;
    let mut report = Report {
        cpu: cpu_name(),
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        threads: rayon::current_num_threads(),
        results: Vec::new(),
        failures: Vec::new(),
    };
    // `auto`: the GPU path on a hardware adapter; a software one (lavapipe) only when
    // asked for by `gpu` (it would take minutes and measure the CPU twice).
    let mut backends = backends.to_vec();
    if backends.contains(&BackendChoice::Auto) {
        let hardware = crate::gpu::device::choose_adapter()
            .map(|a| a.get_info().device_type != wgpu::DeviceType::Cpu);
        let gpu = match hardware {
            Ok(true) => Some(BackendChoice::Gpu),
            Ok(false) => {
                log("no hardware GPU adapter: the GPU path is not measured (--backend gpu measures the software one)".into());
                None
            }
            Err(e) => {
                log(format!("the GPU path is not measured: {e}"));
                None
            }
        };
        backends.retain(|b| *b != BackendChoice::Auto);
        if let Some(g) = gpu.filter(|g| !backends.contains(g)) {
            backends.push(g);
        }
    }
    for (name, text) in &workloads(sizes, polygon_sizes, rod_sizes, pour) {
        let invalid = |source| BenchError::Scene {
            workload: name.clone(),
            source,
        };
        let scene = scene::parse(text, &[]).map_err(invalid)?;
        for &b in &backends {
            let sim = Simulation::new(scene.clone()).map_err(invalid)?;
            // The pour starts nearly empty: time ten times longer to see it fill.
            let k = if name.starts_with("r4") {
                10 * steps
            } else {
                steps
            };
            let m = match measure(name, sim, b, k, budget, kernels) {
                Ok(m) => m,
                Err(error) => {
                    let backend = format!("{b:?}").to_lowercase();
                    log(format!("{name:>18} {backend:>28} failed: {error}"));
                    report.failures.push(Failure {
                        workload: name.clone(),
                        backend,
                        error: error.to_string(),
                    });
                    partial(&report);
                    continue;
                }
            };
            let lists = match (m.rebuilds_per_1000_steps, m.pairs_per_particle) {
                (Some(r), Some(p)) => {
                    format!(", {r:.0} rebuilds per 1000 steps, {p:.2} pairs per particle")
                }
                (Some(r), None) => format!(", {r:.0} rebuilds per 1000 steps"),
                _ => String::new(),
            };
            let gpu = match (
                m.dispatches_per_step,
                m.dispatches_between_rebuilds,
                m.empty_dispatches_per_step,
                m.submissions_per_step,
                m.commands_per_step,
            ) {
                (Some(d), Some(b), Some(e), Some(s), Some(c)) => format!(
                    ", {d:.1} dispatches ({b:.0} between rebuilds, {e:.1} empty), {c:.1} \
                     commands and {s:.3} submissions per step"
                ),
                _ => String::new(),
            };
            log(format!(
                "{:>18} {:>28} {:>7} particles {:>10.3e} particle-steps/s, {:.0} µs per step{lists}{gpu}",
                m.workload,
                m.backend,
                m.particles,
                m.particle_steps_per_second,
                m.microseconds_per_step
            ));
            if let Some(why) = &m.kernels_error {
                log(format!("{:>18} {:>28} no kernel times: {why}", "", ""));
            }
            if let Some(t) = &m.kernels {
                log(format!(
                    "{:>18} {:>28} device time per step by kernel ({} steps): {:.0} µs",
                    "", "", t.steps, t.microseconds_per_step
                ));
                for k in &t.kernels {
                    log(format!(
                        "{:>18} {:>28} {:>22} {:>9.1} µs {:>5.1} %  {:.2} dispatches",
                        "",
                        "",
                        k.kernel,
                        k.microseconds_per_step,
                        100.0 * k.microseconds_per_step / t.microseconds_per_step.max(1e-12),
                        k.dispatches_per_step
                    ));
                }
            }
            report.results.push(m);
            partial(&report);
        }
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_packing_is_a_triangular_lattice_of_free_disks() {
        // n = 1000: 45 columns, the last of 23 rows partly filled.
        for n in [7, 1000] {
            let scene = crate::scene::parse(&packing_scene(n), &[]).unwrap();
            let p = crate::create::initial_particles(&scene, &mut crate::base::rng::Rng::new(1));
            assert_eq!(p.len(), n);
            let cols = ((2.0 * n as f64).sqrt().ceil() as usize).max(2);
            let h = 3f64.sqrt() / 2.0;
            for k in 0..n {
                let (c, r) = (k % cols, k / cols);
                let x = c as f64 + if r % 2 == 1 { 0.5 } else { 0.0 } + 0.5;
                let q = p.q[0][k];
                assert_eq!([q[0], q[1]], [x, 0.5 + r as f64 * h], "disk {k} of {n}");
                assert_eq!(p.radius[k], 0.5);
                assert!(!p.fixed[k] && p.active[k] && p.shape[k].is_empty());
            }
        }
    }
}
