//! Driving a run: the step loop with outputs (snapshots, checkpoints, energy log), the
//! settling rule, progress and divergence handling. Everything in the output folder is
//! written atomically; `summary.json` is written last and marks a complete run.

use crate::files::write_atomic;
use crate::gpu::{DeviceState, GpuSimulation};
use crate::progress::Progress;
use crate::sim::{Divergence, Simulation};
use crate::{checkpoint, snapshot};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How many checkpoint files are kept (older ones are deleted).
const KEEP_CHECKPOINTS: usize = 3;

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out: PathBuf,
    pub quiet: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub backend: String,
    pub steps: u64,
    pub time: f64,
    pub particles: usize,
    pub mobile: usize,
    pub lost: u64,
    /// Whether the run ended by the settling rule (else at stop.time).
    pub settled: bool,
    pub kinetic_energy: f64,
    pub elastic_energy: f64,
    pub wall_seconds: f64,
    pub particle_steps_per_second: f64,
    pub final_snapshot: String,
    pub last_checkpoint: Option<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("run diverged at step {step} (t = {time:.6e}): {cause}; {checkpoint}")]
    Diverged {
        step: u64,
        time: f64,
        cause: Divergence,
        checkpoint: String,
    },
}

/// Removes the snapshots (with their VTK files) and checkpoints in a run folder whose
/// step is past `step`; returns how many files went.
fn remove_later_outputs(out: &Path, step: u64) -> Result<usize, RunError> {
    let mut removed = 0;
    for (sub, prefix) in [("snapshots", "snap_"), ("checkpoints", "ckpt_")] {
        let dir = out.join(sub);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            // snap_0000001000.json, .bin, _grains.vtp, _contacts.vtp; ckpt_0000001000.bin
            let later = (name.strip_prefix(prefix))
                .and_then(|rest| rest.get(..10))
                .and_then(|digits| digits.parse::<u64>().ok())
                .is_some_and(|s| s > step);
            if later {
                std::fs::remove_file(e.path()).map_err(io(&e.path()))?;
                removed += 1;
            }
        }
    }
    Ok(removed)
}

/// VTK files of the snapshot just written (`output.vtk`), and `snapshots.pvd` listing
/// every one so far.
fn write_vtk(json: &Path, entries: &mut Vec<(f64, String, String)>) -> Result<(), RunError> {
    let dir = json.parent().unwrap_or(Path::new("."));
    let stem = json
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let fail = |e: String| RunError::Io {
        path: json.display().to_string(),
        source: std::io::Error::other(e),
    };
    let input = crate::analyze::input::load(json, None).map_err(fail)?;
    if input.grains.is_empty() {
        return Ok(()); // nothing to draw yet (a pour before its first grain)
    }
    let time = input.time;
    let a = crate::analyze::analyze(input, &crate::analyze::Options::default()).map_err(fail)?;
    let prefix = format!("{stem}_");
    crate::render::vtk::write_named(&a, dir, &prefix).map_err(fail)?;
    entries.push((
        time,
        format!("{prefix}grains.vtp"),
        format!("{prefix}contacts.vtp"),
    ));
    let pvd = dir.join("snapshots.pvd");
    write_atomic(&pvd, crate::render::vtk::collection(entries).as_bytes()).map_err(io(&pvd))
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// The path that advances the state: the CPU reference path or the GPU path. Outputs
/// always read the host `Simulation` (for the GPU, a mirror refreshed by `download`).
pub enum Engine {
    Cpu(Box<Simulation>),
    Gpu(Box<GpuSimulation>),
}

impl Engine {
    pub fn cpu(sim: Simulation) -> Self {
        Self::Cpu(Box::new(sim))
    }

    /// The host state and, on the GPU path, the exact device state: what a checkpoint
    /// holds (reads the device back on the GPU path).
    pub fn checkpoint_state(&mut self) -> (&Simulation, Option<&DeviceState>) {
        match self {
            Self::Cpu(s) => (s, None),
            Self::Gpu(g) => g.checkpoint_state(),
        }
    }

    pub fn name(&self) -> String {
        match self {
            Self::Cpu(_) => "cpu".into(),
            Self::Gpu(g) => format!("gpu ({})", g.adapter_name()),
        }
    }

    pub fn step(&self) -> u64 {
        match self {
            Self::Cpu(s) => s.step,
            Self::Gpu(g) => g.step(),
        }
    }

    /// Active particles now (no readback on the GPU).
    pub fn active_count(&self) -> u64 {
        match self {
            Self::Cpu(s) => s.particles.active_count() as u64,
            Self::Gpu(g) => g.active_count(),
        }
    }

    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        match self {
            Self::Cpu(s) => s.advance(steps),
            Self::Gpu(g) => g.advance(steps),
        }
    }

    /// The host state, current (reads the device back on the GPU path).
    pub fn sim(&mut self) -> &Simulation {
        match self {
            Self::Cpu(s) => s,
            Self::Gpu(g) => g.download(),
        }
    }

    /// Every particle's position in id order (on the GPU path the state alone is read
    /// back: observers that follow particles step by step).
    pub fn positions(&mut self) -> Vec<[f64; 2]> {
        match self {
            Self::Cpu(s) => (0..s.particles.len())
                .map(|i| s.particles.position(i))
                .collect(),
            Self::Gpu(g) => g.positions(),
        }
    }

    /// The host copy without a readback: scene, law and grid are always current.
    pub fn host(&self) -> &Simulation {
        match self {
            Self::Cpu(s) => s,
            Self::Gpu(g) => &g.sim,
        }
    }
}

/// Steps between events that happen every `interval` of simulated time (0 = never).
fn every(interval: f64, dt: f64) -> Option<u64> {
    (interval > 0.0).then(|| ((interval / dt).round() as u64).max(1))
}

/// The step at which the run ends at the latest.
pub fn total_steps(sim: &Simulation) -> u64 {
    (sim.scene.stop.time / sim.dt() - 1e-9).ceil() as u64
}

pub fn run(engine: &mut Engine, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let out = &opts.out;
    std::fs::create_dir_all(out).map_err(io(out))?;
    // A summary marks a finished run; one left by an earlier run in this folder must not
    // vouch for this one until it has finished too.
    let summary_path = out.join("summary.json");
    if summary_path.exists() {
        std::fs::remove_file(&summary_path).map_err(io(&summary_path))?;
    }
    // Outputs an earlier run left here past this run's start belong to another run (a
    // reused --out) or will be written again (a resume): they go, so that no stale
    // snapshot or checkpoint sits beside this run's (issue 16).
    let removed = remove_later_outputs(out, engine.step())?
        + ["", "snapshots", "checkpoints"]
            .iter()
            .map(|sub| crate::files::remove_stale_temporaries(&out.join(sub)))
            .sum::<usize>();
    if removed > 0 && !opts.quiet {
        eprintln!(
            "talus: removed {removed} snapshot, checkpoint and temporary files of an earlier \
             run in {} (past step {})",
            out.display(),
            engine.step()
        );
    }
    let scene = engine.host().scene.clone();
    let scene_path = out.join("scene.json");
    let text = serde_json::to_string_pretty(&scene).expect("a scene always serialises");
    write_atomic(&scene_path, text.as_bytes()).map_err(io(&scene_path))?;

    let dt = scene.dt;
    let o = scene.output.clone();
    let snap_every = every(o.snapshot_every, dt);
    let ckpt_every = every(o.checkpoint_every.unwrap_or(0.1 * scene.stop.time), dt);
    let log_every = every(
        if o.log_every > 0.0 {
            o.log_every
        } else {
            scene.stop.time / 200.0
        },
        dt,
    );
    let check_every = every(scene.stop.check_every, dt).unwrap_or(1);
    let total = total_steps(engine.host());
    let snap_dir = out.join("snapshots");
    let ckpt_dir = out.join("checkpoints");
    let time = |step: u64| step as f64 * dt;

    let mut progress = Progress::new(engine.step(), total, opts.quiet);
    let start = Instant::now();
    let start_step = engine.step();
    let mut particle_steps = 0u64;
    let mut log = String::from(
        "step,time,particles,contacts,kinetic_translational,kinetic_rotational,elastic,potential\n",
    );
    // A resumed run continues the log of the run it resumes: its rows up to the start.
    if start_step > 0
        && let Ok(old) = std::fs::read_to_string(out.join("log.csv"))
        && old.starts_with(log.as_str())
    {
        for line in old.lines().skip(1) {
            match line.split(',').next().and_then(|s| s.parse::<u64>().ok()) {
                Some(step) if step <= start_step => {
                    log.push_str(line);
                    log.push('\n');
                }
                _ => break,
            }
        }
    }
    let mut checkpoints: Vec<PathBuf> = Vec::new();
    let mut settled = false;
    // The mean kinetic energy per particle when the relaxation began (`kinetic_drop`).
    let mut relaxing_from: Option<f64> = None;
    let mut vtk_entries = Vec::new();
    if engine.step() == 0 && snap_every.is_some() {
        let json = snapshot::write(engine.sim(), &snap_dir, &format!("snap_{:010}", 0))
            .map_err(io(&snap_dir))?;
        if o.vtk {
            write_vtk(&json, &mut vtk_entries)?;
        }
    }
    // The next step at which anything happens: an output, the settling check, or a
    // progress update. The engine runs freely in between (on the GPU: many steps per
    // submission).
    let due = |step: u64, k: Option<u64>| k.map_or(u64::MAX, |k| (step / k + 1) * k);
    const PROGRESS_EVERY: u64 = 256;

    while engine.step() < total {
        let now = engine.step();
        let next = [
            due(now, log_every),
            due(now, snap_every),
            due(now, ckpt_every),
            due(now, Some(check_every)),
            due(now, Some(PROGRESS_EVERY)),
            total,
        ]
        .into_iter()
        .min()
        .unwrap_or(total);
        let active = engine.active_count();
        if let Err(cause) = engine.advance(next - now) {
            progress.finish();
            let checkpoint = match checkpoints.last() {
                Some(p) => format!(
                    "last good checkpoint: {} (continue with `talus run --resume {}`)",
                    p.display(),
                    p.display()
                ),
                None => {
                    "no checkpoint was written before the divergence (see output.checkpoint_every)"
                        .into()
                }
            };
            let step = engine.step();
            return Err(RunError::Diverged {
                step,
                time: time(step),
                cause,
                checkpoint,
            });
        }
        particle_steps += active * (next - now);
        let step = next;
        if log_every.is_some_and(|k| step.is_multiple_of(k)) {
            let sim = engine.sim();
            let e = sim.energies();
            log.push_str(&format!(
                "{step},{:.9e},{},{},{:.9e},{:.9e},{:.9e},{:.9e}\n",
                sim.time(),
                sim.particles.active_count(),
                sim.pairs.len(),
                e.kinetic_translational,
                e.kinetic_rotational,
                e.elastic,
                e.potential
            ));
        }
        if snap_every.is_some_and(|k| step.is_multiple_of(k)) {
            let json = snapshot::write(engine.sim(), &snap_dir, &format!("snap_{step:010}"))
                .map_err(io(&snap_dir))?;
            if o.vtk {
                write_vtk(&json, &mut vtk_entries)?;
            }
        }
        if ckpt_every.is_some_and(|k| step.is_multiple_of(k)) {
            write_checkpoint(engine, &ckpt_dir, &mut checkpoints)?;
            let log_path = out.join("log.csv");
            write_atomic(&log_path, log.as_bytes()).map_err(io(&log_path))?;
        }
        if step.is_multiple_of(check_every) {
            progress.update(step, time(step), engine.active_count() as usize);
            if let Some(drop) = scene.stop.kinetic_drop
                && time(step) >= scene.stop.not_before
                && engine.sim().feeding_done()
            {
                // Paper 004's rule: the mean kinetic energy against its value when the
                // relaxation began (the first check after the sources are done).
                let sim = engine.sim();
                let n = sim.particles.active_count().max(1) as f64;
                let mean = sim.energies().kinetic() / n;
                let start = *relaxing_from.get_or_insert(mean);
                if mean < drop * start {
                    progress.note(&format!(
                        "relaxed at t = {:.4}: mean kinetic energy {mean:.3e}, {:.1e} of its {start:.3e} when the sources were done",
                        sim.time(),
                        mean / start
                    ));
                    settled = true;
                    break;
                }
            }
            if let Some(frac) = scene.stop.kinetic_fraction
                && time(step) >= scene.stop.not_before
            {
                let sim = engine.sim();
                if sim.feeding_done() {
                    let e = sim.energies();
                    if e.elastic > 0.0 && e.kinetic() < frac * e.elastic {
                        progress.note(&format!(
                            "settled at t = {:.4}: kinetic/elastic = {:.3e}",
                            sim.time(),
                            e.kinetic() / e.elastic
                        ));
                        settled = true;
                        break;
                    }
                }
            }
        } else if step.is_multiple_of(PROGRESS_EVERY) {
            progress.update(step, time(step), engine.active_count() as usize);
        }
    }
    progress.finish();

    let backend = engine.name();
    let last_step = engine.step();
    if checkpoints
        .last()
        .is_none_or(|p| !p.ends_with(format!("ckpt_{last_step:010}.bin")))
        && ckpt_every.is_some()
    {
        write_checkpoint(engine, &ckpt_dir, &mut checkpoints)?;
    }
    let sim = engine.sim();
    let log_path = out.join("log.csv");
    write_atomic(&log_path, log.as_bytes()).map_err(io(&log_path))?;
    let final_json = snapshot::write(sim, out, "final").map_err(io(out))?;
    let wall = start.elapsed().as_secs_f64();
    let e = sim.energies();
    let summary = RunSummary {
        scene: sim.scene.name.clone(),
        backend,
        steps: sim.step - start_step,
        time: sim.time(),
        particles: sim.particles.active_count(),
        mobile: sim.particles.mobile_count(),
        lost: sim.lost,
        settled,
        kinetic_energy: e.kinetic(),
        elastic_energy: e.elastic,
        wall_seconds: wall,
        particle_steps_per_second: particle_steps as f64 / wall.max(1e-9),
        final_snapshot: final_json.display().to_string(),
        last_checkpoint: checkpoints.last().map(|p| p.display().to_string()),
    };
    let text = serde_json::to_string_pretty(&summary).expect("summary serialises");
    write_atomic(&summary_path, text.as_bytes()).map_err(io(&summary_path))?;
    Ok(summary)
}

fn write_checkpoint(
    engine: &mut Engine,
    dir: &Path,
    written: &mut Vec<PathBuf>,
) -> Result<(), RunError> {
    let (sim, device) = engine.checkpoint_state();
    let path = dir.join(format!("ckpt_{:010}.bin", sim.step));
    checkpoint::write(sim, device, &path).map_err(io(&path))?;
    written.push(path);
    while written.len() > KEEP_CHECKPOINTS {
        let old = written.remove(0);
        let _ = std::fs::remove_file(old);
    }
    Ok(())
}
