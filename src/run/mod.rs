//! Driving a run: the step loop and its outputs (`outputs`: snapshots, VTK files,
//! checkpoints, energy log, each on its own schedule), the settling rule, progress,
//! divergence and interruption. The output folder holds one run (`folder`); everything
//! in it is written atomically, and `summary.json` is written last and marks a complete
//! run.

mod engine;
pub mod estimate;
pub mod folder;
pub mod outputs;

pub use engine::Engine;

use crate::base::files::write_atomic;
use crate::base::progress::{Progress, Work};
use crate::io::snapshot;
use crate::sim::{Divergence, Simulation};
use folder::Claimed;
use outputs::{Outputs, Schedule, Settling};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out: PathBuf,
    pub quiet: bool,
    /// Clear another run's outputs found in `out` instead of refusing the folder.
    pub force: bool,
    /// The checkpoint the run starts from: one of `out`'s own continues that run there.
    pub resumed_from: Option<PathBuf>,
    /// Set (by a signal handler) to stop the run between two advances.
    pub interrupt: Arc<AtomicBool>,
    /// The run's step, updated as its progress is (for a caller showing the progress of
    /// several runs, as `talus sweep` does).
    pub step: Arc<AtomicU64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub backend: String,
    /// talus's version and commit, the command line and the threads (issue 41).
    pub provenance: crate::base::provenance::Provenance,
    pub steps: u64,
    pub time: f64,
    /// Active particles at the end, and of them the moving (not fixed) ones.
    pub particles: usize,
    pub mobile: usize,
    pub lost: u64,
    /// Whether the run ended by the settling rule (else at stop.time).
    pub settled: bool,
    pub kinetic_energy: f64,
    pub elastic_energy: f64,
    pub wall_seconds: f64,
    /// Moving (not fixed) particles times steps, per second of wall time, as other DEM
    /// codes count it: fixed particles are never integrated (issue 20: a pour's 200 base
    /// disks counted in flattered the figure).
    pub particle_steps_per_second: f64,
    pub final_snapshot: String,
    pub last_checkpoint: Option<String>,
    /// The point sources: how many particles each placed of its count, and since when
    /// its next one waits for a free spot at the outlet, if it does.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<crate::create::source::SourceProgress>,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(
        "{path} holds another run's outputs ({found}): pass --force to clear them first, or \
         --resume one of that folder's own checkpoints to continue its run"
    )]
    FolderInUse { path: String, found: String },
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("cannot remove {path}: {source}")]
    Remove {
        path: String,
        source: std::io::Error,
    },
    /// A snapshot's VTK files could not be made.
    #[error(transparent)]
    Analyze(#[from] crate::analyze::AnalyzeError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    /// The GPU could not be read back: nothing after the last checkpoint is trusted.
    #[error("the GPU failed: {0}")]
    Device(#[from] crate::gpu::GpuError),
    #[error("the GPU failed at step {step} (t = {time:.6e}): {reason}; {checkpoint}")]
    DeviceLost {
        step: u64,
        time: f64,
        reason: String,
        checkpoint: String,
    },
    /// A copy of the scene (`replicas`) could not be taken apart: a bug.
    #[error("copy of the scene: {0}")]
    Copy(crate::scene::SceneError),
    #[error("run diverged at step {step} (t = {time:.6e}): {cause}; {checkpoint}")]
    Diverged {
        step: u64,
        time: f64,
        cause: Divergence,
        checkpoint: String,
    },
    #[error(
        "run interrupted at step {step} (t = {time:.6e}), unfinished (no summary.json); {checkpoint}"
    )]
    Interrupted {
        step: u64,
        time: f64,
        checkpoint: String,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// The step at which the run ends at the latest.
pub fn total_steps(sim: &Simulation) -> u64 {
    (sim.scene.stop.time / sim.dt() - 1e-9).ceil() as u64
}

/// The moving particles expected at time `t` of a run now at `sim`: those there now
/// and what every copy's point sources and layered blocks will have added by then at
/// their rates (an insertion that has to wait for room comes later; lost particles are
/// not foreseen).
pub fn expected_moving(sim: &Simulation, t: f64) -> f64 {
    use crate::create;
    let (sources, layered) = crate::sim::creators(&sim.scene);
    let per_copy = (sources.len() + layered.len()).max(1);
    let mut n = sim.particles.mobile_count() as f64;
    for (k, state) in sim.sources.iter().enumerate() {
        let k = k % per_copy;
        if let Some(s) = sources.get(k) {
            let due = if t < s.start_time {
                0
            } else {
                (((t - s.start_time) * s.rate).floor() as u64 + 1).min(s.count as u64)
            };
            n += due.saturating_sub(state.inserted as u64) as f64;
        } else if let Some(l) = layered.get(k - sources.len()) {
            let rows = if t < l.start_time {
                0
            } else {
                (((t - l.start_time) / l.interval).floor() as u64 + 1)
                    .min(crate::scene::rows::max_rows(l) as u64)
            };
            n += (state.inserted as u64..rows.max(state.inserted as u64))
                .map(|r| create::layered::row_capacity(l, r as u32) as f64)
                .sum::<f64>();
        }
    }
    n
}

/// The particle-steps a run now at `sim` is expected to take until step `total`
/// (`expected_moving` at 200 points between), for its progress and ETA.
pub fn expected_work(sim: &Simulation, total: u64) -> Work {
    let start = sim.step;
    if total <= start {
        return Work::steps(start, total.max(start + 1));
    }
    let dt = sim.scene.dt;
    let points = 200.min(total - start);
    let step_at = |k: u64| start + (total - start) * k / points;
    let mut samples = vec![(start, 0.0)];
    let mut work = 0.0;
    let mut before = expected_moving(sim, start as f64 * dt);
    for k in 1..=points {
        let (a, b) = (step_at(k - 1), step_at(k));
        let now = expected_moving(sim, b as f64 * dt);
        work += 0.5 * (before + now) * (b - a) as f64;
        samples.push((b, work.max(1e-9 * b as f64)));
        before = now;
    }
    Work { samples }
}

/// Where to continue from: the newest checkpoint, in words for an error message.
fn resume_hint(checkpoint: Option<&Path>, what: &str) -> String {
    match checkpoint {
        Some(p) => format!(
            "last good checkpoint: {} (continue with `talus run --resume {}`)",
            p.display(),
            p.display()
        ),
        None => {
            format!("no checkpoint was written before the {what} (see output.checkpoint_every)")
        }
    }
}

/// Runs `engine` to the end of its scene (or until it settles), writing into
/// `opts.out`; the folder is claimed first (`folder::claim`).
pub fn run(engine: &mut Engine, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let claimed = folder::claim(
        &opts.out,
        engine.step(),
        opts.resumed_from.as_deref(),
        opts.force,
    )?;
    let result = drive(engine, opts, claimed);
    if result.is_err() {
        // Whatever stopped the run, no half-written file stays behind.
        folder::remove_temporaries(&opts.out);
    }
    result
}

fn drive(engine: &mut Engine, opts: &RunOptions, claimed: Claimed) -> Result<RunSummary, RunError> {
    let out = &opts.out;
    let start_step = engine.step();
    let total = total_steps(engine.host());
    let mut progress = Progress::new(
        start_step,
        total,
        opts.quiet,
        expected_work(engine.host(), total),
    );
    note_claim(&progress, &claimed, out, start_step);
    let scene = engine.host().scene.clone();
    let scene_path = out.join("scene.json");
    let text = serde_json::to_string_pretty(&scene).expect("a scene always serialises");
    write_atomic(&scene_path, text.as_bytes()).map_err(io(&scene_path))?;

    let provenance = crate::base::provenance::Provenance::here(&engine.name());
    let mut outputs = Outputs::new(&scene, out, start_step, &provenance);
    let mut settling = Settling::new(&scene);
    // Progress between checks as well, so that the engine runs freely in between (on
    // the GPU: many steps per submission).
    let progress_every = Schedule::steps(256);
    let time = |step: u64| step as f64 * scene.dt;
    // The checkpoint to continue from if the run stops here.
    let resume_from = |o: &Outputs| {
        (o.last_checkpoint())
            .or(opts.resumed_from.as_deref())
            .map(Path::to_path_buf)
    };

    let start = Instant::now();
    let mut particle_steps = 0u64;
    let mut settled = false;
    if start_step == 0 {
        outputs.write_start(engine)?;
    }
    while engine.step() < total {
        let now = engine.step();
        if opts.interrupt.load(Ordering::Relaxed) {
            progress.finish();
            return Err(RunError::Interrupted {
                step: now,
                time: time(now),
                checkpoint: resume_hint(resume_from(&outputs).as_deref(), "interruption"),
            });
        }
        // The next step at which anything happens: an output, the settling check, or a
        // progress update.
        let next = (outputs.next_after(now))
            .min(settling.every.next_after(now))
            .min(progress_every.next_after(now))
            .min(total);
        let moving = engine.mobile_count();
        if let Err(cause) = engine.advance(next - now) {
            progress.finish();
            let step = engine.step();
            let time = time(step);
            return Err(match cause {
                Divergence::Device(reason) => RunError::DeviceLost {
                    step,
                    time,
                    reason,
                    checkpoint: resume_hint(resume_from(&outputs).as_deref(), "failure"),
                },
                cause => RunError::Diverged {
                    step,
                    time,
                    cause,
                    checkpoint: resume_hint(resume_from(&outputs).as_deref(), "divergence"),
                },
            });
        }
        particle_steps += moving * (next - now);
        let step = next;
        outputs.write_due(engine)?;
        opts.step.store(step, Ordering::Relaxed);
        if settling.every.due(step) {
            progress.update(step, time(step), engine.active_count() as usize);
            if settling.settled(engine, time(step), &progress)? {
                settled = true;
                break;
            }
        } else if progress_every.due(step) {
            progress.update(step, time(step), engine.active_count() as usize);
        }
    }
    progress.finish();
    let backend = engine.name();
    outputs.write_end(engine)?;
    let sim = engine.sim()?;
    let final_json = snapshot::write_with(sim, out, "final", &provenance).map_err(io(out))?;
    let wall = start.elapsed().as_secs_f64();
    let e = sim.energies();
    let sources = sim.source_progress();
    // A source that fell behind its rate (its next particle due ten of its intervals
    // ago, its spot at the outlet taken when it last tried) leaves a deposit short of
    // what the scene asked for: say so. Whether it placed none since or only fewer
    // than its rate the state does not record, so the warning claims neither.
    for (p, _) in sources.iter().filter(|(_, stalled)| *stalled) {
        let copy = if sim.scene.replicas > 1 {
            format!("copy {}'s ", p.copy)
        } else {
            String::new()
        };
        let at = p.next_at.unwrap_or_default();
        progress.warn(&format!(
            "talus: warning: {copy}point source {} placed {} of its {} particles: it fell \
             behind its rate at t = {:.4} (its next particle fell due then) and its spot at \
             the outlet (x = {:.4}, z = {:.4}) was taken when it last tried (the deposit \
             reached the outlet, a grain stuck there, or grains crowd the outlet)",
            p.source,
            p.inserted,
            p.count,
            p.waiting_since.unwrap_or_default(),
            at[0],
            at[1]
        ));
    }
    let summary = RunSummary {
        scene: sim.scene.name.clone(),
        backend,
        provenance: provenance.clone(),
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
        last_checkpoint: outputs.last_checkpoint().map(|p| p.display().to_string()),
        sources: sources.into_iter().map(|(p, _)| p).collect(),
    };
    if sim.scene.replicas > 1 {
        write_copies(sim, out, &summary, &settling.copies_settled())?;
    }
    let text = serde_json::to_string_pretty(&summary).expect("summary serialises");
    let summary_path = out.join("summary.json");
    write_atomic(&summary_path, text.as_bytes()).map_err(io(&summary_path))?;
    Ok(summary)
}

/// The folder of copy `c` of a run with copies (`replicas`).
pub fn copy_dir(out: &Path, c: u32) -> PathBuf {
    out.join("copies").join(format!("copy_{c:04}"))
}

/// Each copy of a scene with `replicas` as a run of its own in `copies/copy_CCCC/`: its
/// scene (with the copy's seed), final state and summary, as the run of that seed alone
/// writes them (the folder can be analysed like any run's).
fn write_copies(
    sim: &Simulation,
    out: &Path,
    whole: &RunSummary,
    settled: &[bool],
) -> Result<(), RunError> {
    for c in 0..sim.scene.replicas {
        let copy = sim.replica(c).map_err(RunError::Copy)?;
        let dir = copy_dir(out, c);
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        let scene_path = dir.join("scene.json");
        let text = serde_json::to_string_pretty(&copy.scene).expect("a scene always serialises");
        write_atomic(&scene_path, text.as_bytes()).map_err(io(&scene_path))?;
        let final_json =
            snapshot::write_with(&copy, &dir, "final", &whole.provenance).map_err(io(&dir))?;
        let e = copy.energies();
        let summary = RunSummary {
            scene: copy.scene.name.clone(),
            particles: copy.particles.active_count(),
            mobile: copy.particles.mobile_count(),
            lost: copy.lost,
            settled: settled.get(c as usize).copied().unwrap_or(false),
            kinetic_energy: e.kinetic(),
            elastic_energy: e.elastic,
            final_snapshot: final_json.display().to_string(),
            last_checkpoint: None,
            sources: copy.source_progress().into_iter().map(|(p, _)| p).collect(),
            ..whole.clone()
        };
        let text = serde_json::to_string_pretty(&summary).expect("summary serialises");
        let path = dir.join("summary.json");
        write_atomic(&path, text.as_bytes()).map_err(io(&path))?;
    }
    Ok(())
}

/// Says what `folder::claim` removed.
fn note_claim(progress: &Progress, claimed: &Claimed, out: &Path, start_step: u64) {
    match claimed {
        Claimed::Cleared(found) => progress.note(&format!(
            "talus: --force: removed another run's {} from {}",
            found.join(", "),
            out.display()
        )),
        Claimed::Resumed(n) if *n > 0 => progress.note(&format!(
            "talus: removed {n} snapshot and checkpoint files past step {start_step} from {} \
             (this run writes them again)",
            out.display()
        )),
        _ => {}
    }
}
