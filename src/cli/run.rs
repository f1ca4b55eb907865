//! `talus run`: a scene from its start, a run resumed from one of its checkpoints, or the
//! next stage of a multi-stage run (`--from`: the state of an earlier run under a new
//! scene); then the final state measured and drawn.

use super::choices::Backend;
use super::failure::Failure;
use super::{build_simulation, choose_engine, load_scene, measure_and_draw, on_interrupt};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use talus::{io::checkpoint, run};

/// What `talus run` was asked.
#[derive(clap::Args)]
pub(super) struct RunArgs {
    /// Scene file (JSON). Omit for the built-in default heap.
    pub scene: Option<PathBuf>,
    /// Output folder (default: runs/<scene name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a scene key, e.g. --set contact.mu=0.3 (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub overrides: Vec<String>,
    /// Continue from a checkpoint file (only stop.*, output.* and skin may be --set),
    /// in the checkpoint's own run folder unless --out says otherwise.
    #[arg(long, conflicts_with = "scene")]
    pub resume: Option<PathBuf>,
    /// Start from the state of an earlier run (its folder, for its newest
    /// checkpoint, or a checkpoint) under this scene: the next stage of a
    /// multi-stage run. The scene may change gravity, the contact law, walls, the
    /// domain, stop and output; its particles, materials and dt must be the
    /// earlier run's. Time goes on from the state's.
    #[arg(long, conflicts_with = "resume", value_name = "RUN_DIR|CHECKPOINT")]
    pub from: Option<PathBuf>,
    /// Clear another run's outputs from the output folder first (otherwise such a
    /// folder is refused).
    #[arg(long)]
    pub force: bool,
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    pub backend: Backend,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

pub(super) fn cmd_run(args: RunArgs) -> Result<(), Failure> {
    let RunArgs {
        scene: path,
        out,
        overrides,
        resume,
        from,
        force,
        backend,
        quiet,
    } = args;
    let start = match (&resume, &from) {
        (Some(ckpt), _) => checkpoint::read(ckpt, &overrides)?,
        (None, Some(from)) => {
            let ckpt = stage_start(from)?;
            let scene = load_scene(&path, &overrides)?;
            checkpoint::read_as_stage(&ckpt, scene)?
        }
        (None, None) => checkpoint::Checkpoint::fresh(build_simulation(&path, &overrides)?),
    };
    let sim = &start.sim;
    // A resumed run continues in its checkpoint's own folder unless told otherwise.
    let out = out
        .or_else(|| resume.as_deref().and_then(run_folder_of))
        .unwrap_or_else(|| PathBuf::from("runs").join(&sim.scene.name));
    if let (Some(from), false) = (&from, quiet) {
        eprintln!(
            "talus: a stage from {} at t = {} (step {}), {} particles",
            from.display(),
            sim.time(),
            sim.step,
            sim.particles.active_count()
        );
    }
    if !quiet {
        eprintln!(
            "talus: scene `{}`, {} particles, dt = {}, until t = {} -> {}",
            sim.scene.name,
            sim.particles.active_count(),
            sim.dt(),
            sim.scene.stop.time,
            out.display()
        );
    }
    // Before the engine is made (a GPU takes a while): `run::run` would refuse it too.
    run::folder::refuse_another_run(&out, resume.as_deref(), force)?;
    let mut engine = choose_engine(start, backend, quiet)?;
    if !quiet {
        eprintln!("backend: {}", engine.name());
    }
    let interrupt = on_interrupt();
    let s = run::run(
        &mut engine,
        &run::RunOptions {
            out: out.clone(),
            quiet,
            force,
            resumed_from: resume,
            interrupt: interrupt.clone(),
            ..Default::default()
        },
    )?;
    if !quiet {
        eprintln!(
            "done: {} steps to t = {:.4} ({}), {} particles ({} moving, {} lost), {:.3e} particle-steps/s of the moving ones; results in {}",
            s.steps,
            s.time,
            if s.settled { "settled" } else { "end time" },
            s.particles,
            s.mobile,
            s.lost,
            s.particle_steps_per_second,
            out.display()
        );
    }
    if interrupt.load(Ordering::Relaxed) {
        return Err(Failure::interrupted(format!(
            "interrupted after the run finished: its final state was not analysed \
             (`talus analyze {}` does it)",
            out.display()
        )));
    }
    // The final state's measurements and pictures; a failure here does not undo the run.
    // With copies of the scene, each copy's (their heaps lie on top of each other in the
    // whole state).
    let folders: Vec<PathBuf> = match engine.host().scene.replicas {
        1 => vec![out.clone()],
        k => (0..k).map(|c| run::copy_dir(&out, c)).collect(),
    };
    for dir in &folders {
        match measure_and_draw(
            dir,
            &dir.join("analysis"),
            &dir.join("pictures"),
            &talus::analyze::Options::default(),
            None,
            talus::render::Field::Pressure,
            1600,
        ) {
            Ok(n) if !quiet => eprintln!(
                "measurements in {}/analysis, pictures in {}/pictures ({n} files)",
                dir.display(),
                dir.display()
            ),
            Ok(_) => {}
            Err(e) => eprintln!(
                "warning: the final state of {} could not be analysed: {}",
                dir.display(),
                e.message
            ),
        }
    }
    Ok(())
}

/// The folder of the run that wrote checkpoint `ckpt` (`RUN/checkpoints/ckpt_*.bin`).
fn run_folder_of(ckpt: &Path) -> Option<PathBuf> {
    let dir = ckpt.parent()?;
    (dir.file_name()? == "checkpoints").then(|| dir.parent().map(Path::to_path_buf))?
}

/// The checkpoint a stage starts from: `from` itself, or a run folder's newest (a run
/// writes one at its end). A snapshot is refused: it holds neither the tangential
/// springs nor the integrator's state, so it cannot be continued exactly.
fn stage_start(from: &Path) -> Result<PathBuf, Failure> {
    if from.is_dir() {
        let newest = std::fs::read_dir(from.join("checkpoints"))
            .ok()
            .into_iter()
            .flatten()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension().is_some_and(|e| e == "bin")
                    && p.file_name()
                        .is_some_and(|n| n.to_string_lossy().starts_with("ckpt_"))
            })
            .max();
        return newest.ok_or_else(|| {
            Failure::input(format!(
                "--from {}: no checkpoint in {}/checkpoints (a run writes one at its end; \
                 an interrupted one may have none)",
                from.display(),
                from.display()
            ))
        });
    }
    // A snapshot is a .json with its .bin beside it; a checkpoint stands alone.
    let is_snapshot =
        from.extension().is_some_and(|e| e == "json") || from.with_extension("json").is_file();
    if is_snapshot {
        return Err(Failure::input(format!(
            "--from {}: a snapshot holds no tangential springs or integrator state; give \
             the run folder or one of its checkpoints",
            from.display()
        )));
    }
    Ok(from.to_path_buf())
}
