//! `talus sweep`: runs a sweep's runs here, J at a time, each on its own share of the
//! cores (`start`), or hands them to Slurm as a job array (`--slurm`); `run-one` is one
//! run (what an array task calls), `collect` the statistics (`talus::sweep::collect`).
//! The plan, the folders and the statistics are the library's (`talus::sweep`).

use super::choices::Backend;
use super::failure::Failure;
use super::{choose_engine, on_interrupt};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use talus::sweep::{self, Plan, RunState, slurm::SlurmOptions};
use talus::{io::checkpoint, run, sim::Simulation};

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    action: Option<SweepAction>,
    /// Scene file (JSON). Omit for the built-in default heap.
    scene: Option<PathBuf>,
    /// The sweep's folder (default: runs/sweep-<scene name>). The same command run again
    /// continues the sweep there: measured runs are skipped, stopped ones resumed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seeds: A..B (A to B, both included: 1..8 is eight runs) or A,B,C (default: the
    /// scene's own seed).
    #[arg(long, value_name = "A..B")]
    seeds: Option<String>,
    /// A swept key and its values, e.g. --grid contact.mu=0.3,0.5 (repeatable: the runs
    /// are the product of all grids and the seeds).
    #[arg(long = "grid", value_name = "KEY=V1,V2,...")]
    grid: Vec<String>,
    /// Override a scene key for every run, e.g. --set stop.time=10 (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    overrides: Vec<String>,
    /// Runs at once here (default: one per core, the cores shared among them; 1 with
    /// --backend gpu). With --slurm: at most this many array tasks at once.
    #[arg(long)]
    jobs: Option<usize>,
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    backend: Backend,
    /// Moving-average window width of each run's analysis, in mean diameters (as
    /// `talus analyze --window`; default 14).
    #[arg(long)]
    window: Option<f64>,
    /// Height of a row of windows of each run's analysis, in mean diameters (as
    /// `talus analyze --row`; default 2).
    #[arg(long)]
    row: Option<f64>,
    /// Remove another sweep's files from the folder first (otherwise it is refused).
    #[arg(long)]
    force: bool,
    /// Write DIR/sweep.sbatch, a Slurm job array of one task per run, instead of running.
    #[arg(long)]
    slurm: bool,
    /// Slurm partition of the tasks.
    #[arg(long, requires = "slurm")]
    partition: Option<String>,
    /// Slurm wall-time limit per task (e.g. 02:00:00).
    #[arg(long, requires = "slurm")]
    time: Option<String>,
    /// CPU cores per Slurm task (the threads of its run; default 1).
    #[arg(long, requires = "slurm")]
    cpus: Option<usize>,
    /// Submit the job array with sbatch.
    #[arg(long, requires = "slurm")]
    submit: bool,
    /// No progress bar or progress lines; still a line per finished run.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Subcommand)]
enum SweepAction {
    /// One run of a sweep (what a Slurm array task runs): run, or resume, then measure;
    /// nothing when it is measured already.
    RunOne {
        /// The sweep's folder.
        dir: PathBuf,
        /// The run's index in the sweep (0, 1, …; sweep.json lists them).
        #[arg(long)]
        index: usize,
        #[arg(long, short)]
        quiet: bool,
    },
    /// Gather the sweep's measured runs into tables and plots: DIR/collect/ (runs.csv,
    /// points.csv with mean, std and standard error over seeds, collect.json, profiles).
    Collect {
        /// The sweep's folder.
        dir: PathBuf,
    },
}

pub fn cmd_sweep(args: SweepArgs, threads: usize) -> Result<(), Failure> {
    match args.action {
        Some(SweepAction::RunOne { dir, index, quiet }) => {
            let plan = sweep::read_plan(&dir)?;
            let backend = backend_of(&plan)?;
            let interrupt = on_interrupt();
            let step = Arc::new(AtomicU64::new(0));
            match run_one(&dir, &plan, index, backend, quiet, &interrupt, &step)? {
                Outcome::AlreadyMeasured => {
                    eprintln!("{}: measured already, nothing to do", plan.runs[index].name)
                }
                Outcome::Measured => eprintln!(
                    "{}: measured ({})",
                    plan.runs[index].name,
                    sweep::run_dir(&dir, &plan.runs[index]).display()
                ),
            }
            Ok(())
        }
        Some(SweepAction::Collect { dir }) => collect(&dir),
        None => start(args, threads),
    }
}

fn backend_of(plan: &Plan) -> Result<Backend, Failure> {
    Backend::from_str(&plan.backend, true)
        .map_err(|_| Failure::input(format!("sweep.json: unknown backend `{}`", plan.backend)))
}

fn collect(dir: &Path) -> Result<(), Failure> {
    let plan = sweep::read_plan(dir)?;
    let c = sweep::collect::gather(dir, &plan);
    let files = sweep::collect::write(dir, &c)?;
    let measured = c.runs.iter().filter(|r| r.status == "measured").count();
    out!(
        "collected {measured} of {} runs over {} points into {} ({} files)",
        c.runs.len(),
        c.points.len(),
        dir.join("collect").display(),
        files.len()
    );
    for p in &c.points {
        if let Some(d) = &p.dip {
            out!(
                "  point {}{}: base-load dip above noise {:.2} ± {:.2} m g (se over {} seeds), z = {:.2}: {} ({} of {} heaps M alone)",
                p.point,
                (p.values.iter())
                    .map(|v| format!(" {v}"))
                    .collect::<String>(),
                d.excess.mean,
                d.excess.se,
                d.excess.n,
                d.z,
                d.verdict,
                d.heaps_called_m,
                d.excess.n
            );
        }
    }
    for r in c.runs.iter().filter(|r| r.status != "measured") {
        out!(
            "  {}: {}{}",
            r.name,
            r.status,
            r.error
                .as_deref()
                .map_or(String::new(), |e| format!(": {e}"))
        );
    }
    Ok(())
}

/// Plans the sweep, claims its folder, and runs it here or writes its Slurm array.
fn start(a: SweepArgs, threads: usize) -> Result<(), Failure> {
    let base = super::load_scene(&a.scene, &a.overrides)?;
    let seeds = match &a.seeds {
        Some(s) => sweep::parse_seeds(s)?,
        None => vec![base.seed],
    };
    let grid = (a.grid.iter().map(|g| sweep::parse_axis(g))).collect::<Result<Vec<_>, _>>()?;
    let default = sweep::Measuring::default();
    let measuring = sweep::Measuring {
        window: a.window.unwrap_or(default.window),
        row: a.row.unwrap_or(default.row),
    };
    for (key, v) in [("--window", measuring.window), ("--row", measuring.row)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Failure::input(format!(
                "{key} {v}: must be a positive number"
            )));
        }
    }
    if a.jobs == Some(0) {
        return Err(Failure::input("--jobs: must be at least 1, got 0"));
    }
    let backend = a
        .backend
        .to_possible_value()
        .map_or("auto".into(), |v| v.get_name().to_string());
    let plan = sweep::plan(&base, &seeds, &grid, &backend, measuring)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("sweep-{}", base.name)));
    sweep::claim(&dir, &plan, &base, a.force)?;
    if a.slurm {
        return write_slurm(&dir, &plan, &a);
    }
    let jobs = a.jobs.unwrap_or(match a.backend {
        Backend::Gpu => 1,
        _ => threads,
    });
    run_here(&dir, &plan, a.backend, jobs, threads, a.quiet)?;
    collect(&dir)
}

fn write_slurm(dir: &Path, plan: &Plan, a: &SweepArgs) -> Result<(), Failure> {
    let absolute = |p: &Path, what: &str| {
        p.canonicalize()
            .map_err(|e| Failure::failed(format!("{what} {}: {e}", p.display())))
    };
    let dir_abs = absolute(dir, "the sweep folder")?;
    let exe = std::env::current_exe()
        .map_err(|e| Failure::failed(format!("cannot find the talus binary: {e}")))?;
    let exe = absolute(&exe, "the talus binary")?;
    let options = SlurmOptions {
        partition: a.partition.clone(),
        time: a.time.clone(),
        cpus: a.cpus,
        throttle: a.jobs,
    };
    let text = sweep::slurm::sbatch(plan, &dir_abs, &exe, &options).map_err(Failure::input)?;
    let logs = dir.join("slurm");
    std::fs::create_dir_all(&logs)
        .map_err(|e| Failure::failed(format!("cannot create {}: {e}", logs.display())))?;
    let path = dir.join("sweep.sbatch");
    talus::base::files::write_atomic(&path, text.as_bytes())
        .map_err(|e| Failure::failed(format!("cannot write {}: {e}", path.display())))?;
    if !a.submit {
        out!(
            "{} runs as a Slurm job array: {}\nsubmit with `sbatch {}`, then `talus sweep collect {}`",
            plan.runs.len(),
            path.display(),
            path.display(),
            dir.display()
        );
        return Ok(());
    }
    let result = std::process::Command::new("sbatch")
        .arg("--parsable")
        .arg(&path)
        .output()
        .map_err(|e| Failure::failed(format!("cannot run sbatch: {e} (is Slurm installed?)")))?;
    if !result.status.success() {
        return Err(Failure::failed(format!(
            "sbatch {} failed ({}): {}",
            path.display(),
            result.status,
            String::from_utf8_lossy(&result.stderr).trim()
        )));
    }
    let id = String::from_utf8_lossy(&result.stdout);
    let id = id.trim().split(';').next().unwrap_or("").to_string();
    out!("Submitted batch job {id}");
    eprintln!(
        "{} runs submitted as Slurm job array {id}; when it has finished: `talus sweep collect {}`",
        plan.runs.len(),
        dir.display()
    );
    Ok(())
}

enum Outcome {
    AlreadyMeasured,
    Measured,
}

/// One run of the sweep: skipped when measured, measured when run, resumed from its
/// newest readable checkpoint when stopped, otherwise run from the start (clearing
/// whatever an attempt without a checkpoint left). A failure is kept in the run's folder
/// (`failed.json`) for `collect`; an interruption is not a failure.
fn run_one(
    dir: &Path,
    plan: &Plan,
    index: usize,
    backend: Backend,
    quiet: bool,
    interrupt: &Arc<AtomicBool>,
    step: &Arc<AtomicU64>,
) -> Result<Outcome, Failure> {
    let run = plan.run(dir, index)?;
    let folder = sweep::run_dir(dir, run);
    let result = attempt(dir, plan, run, &folder, backend, quiet, interrupt, step);
    if let Err(f) = &result
        && f.code != super::failure::INTERRUPTED
    {
        let failed = sweep::Failed {
            run: run.name.clone(),
            error: f.message.clone(),
            code: f.code,
        };
        if let Err(e) = sweep::write_failed(&folder, &failed) {
            eprintln!("warning: {}: {e}", run.name);
        }
    }
    result.map_err(|f| f.within(&run.name))
}

#[allow(clippy::too_many_arguments)]
fn attempt(
    dir: &Path,
    plan: &Plan,
    run: &sweep::PlannedRun,
    folder: &Path,
    backend: Backend,
    quiet: bool,
    interrupt: &Arc<AtomicBool>,
    step: &Arc<AtomicU64>,
) -> Result<Outcome, Failure> {
    let state = sweep::state(folder);
    if state == RunState::Measured {
        return Ok(Outcome::AlreadyMeasured);
    }
    sweep::clear_failed(folder);
    if state != RunState::Ran {
        let scene = sweep::run_scene(dir, run)?;
        // The newest checkpoint of this run that reads back, else the start.
        let resumed = match &state {
            RunState::Stopped(checkpoints) => checkpoints.iter().find_map(|c| {
                let start = checkpoint::read(c, &[]).ok()?;
                let same = serde_json::to_value(&start.sim.scene).ok()
                    == serde_json::to_value(&scene).ok();
                same.then(|| (c.clone(), start))
            }),
            _ => None,
        };
        let (start, resumed_from) = match resumed {
            Some((c, start)) => (start, Some(c)),
            None => (checkpoint::Checkpoint::fresh(Simulation::new(scene)?), None),
        };
        step.store(start.sim.step, Ordering::Relaxed);
        let mut engine = choose_engine(start, backend, true)?;
        run::run(
            &mut engine,
            &run::RunOptions {
                out: folder.to_path_buf(),
                quiet,
                // The folder is this run's own: what a stopped attempt without a usable
                // checkpoint left is cleared.
                force: resumed_from.is_none(),
                resumed_from,
                interrupt: interrupt.clone(),
                step: step.clone(),
            },
        )?;
    }
    let options = talus::analyze::Options {
        window: plan.measuring.window,
        row: plan.measuring.row,
        ..Default::default()
    };
    let input = talus::analyze::input::load(folder, None)?;
    let a = talus::analyze::analyze(input, &options)?;
    talus::analyze::write(&a, &folder.join("analysis"))?;
    sweep::write_measures(folder, &sweep::Measures::of(&a))?;
    Ok(Outcome::Measured)
}

/// The steps a run takes at most (its end time over dt).
fn planned_steps(dir: &Path, run: &sweep::PlannedRun) -> u64 {
    sweep::run_scene(dir, run).map_or(0, |s| (s.stop.time / s.dt - 1e-9).ceil() as u64)
}

/// A line above the bar; straight to stderr where the bar is not drawn (not a terminal,
/// or `--quiet`), where `println` would drop it.
fn say(bar: &ProgressBar, line: String) {
    if bar.is_hidden() {
        eprintln!("{line}");
    } else {
        bar.println(line);
    }
}

/// Runs the plan here, `jobs` runs at once, each on threads/jobs cores (at least one),
/// with a bar over all runs' steps and a line per finished run; a failed run is reported
/// and the others go on.
pub(super) fn run_here(
    dir: &Path,
    plan: &Plan,
    backend: Backend,
    jobs: usize,
    threads: usize,
    quiet: bool,
) -> Result<(), Failure> {
    let todo: Vec<usize> = (plan.runs.iter())
        .filter(|r| sweep::state(&sweep::run_dir(dir, r)) != RunState::Measured)
        .map(|r| r.index)
        .collect();
    let jobs = jobs.min(todo.len()).max(1);
    let per_run = (threads / jobs).max(1);
    let planned: Vec<u64> = plan.runs.iter().map(|r| planned_steps(dir, r)).collect();
    let total: u64 = planned.iter().sum();
    let skipped = plan.runs.len() - todo.len();
    eprintln!(
        "talus sweep: {} runs ({} points × {} seeds) in {}; {skipped} measured already, {} to do, {jobs} at a time on {per_run} thread(s) each",
        plan.runs.len(),
        plan.points(),
        plan.seeds.len(),
        dir.display(),
        todo.len()
    );
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr_with_hz(2));
        b.set_style(
            ProgressStyle::with_template("{bar:30.cyan/blue} {percent:>3}% {msg} ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let interrupt = on_interrupt();
    let next = AtomicUsize::new(0);
    // Steps of the finished runs (counted whole: a run that settles early ends there),
    // and each worker's current run and its step.
    let finished_steps = AtomicU64::new(
        (plan.runs.iter())
            .filter(|r| !todo.contains(&r.index))
            .map(|r| planned[r.index])
            .sum(),
    );
    let current: Vec<(AtomicUsize, Arc<AtomicU64>)> = (0..jobs)
        .map(|_| (AtomicUsize::new(usize::MAX), Arc::new(AtomicU64::new(0))))
        .collect();
    let failed: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let done = AtomicUsize::new(0);
    let start = Instant::now();
    let at_start = finished_steps.load(Ordering::Relaxed);
    let mut next_line = at_start + (total / 10).max(1);
    std::thread::scope(|s| {
        for worker in &current {
            let (next, todo, failed, done) = (&next, &todo, &failed, &done);
            let (bar, interrupt, finished_steps, planned) =
                (&bar, &interrupt, &finished_steps, &planned);
            s.spawn(move || {
                let pool = match rayon::ThreadPoolBuilder::new().num_threads(per_run).build() {
                    Ok(p) => p,
                    Err(e) => {
                        say(bar, format!("error: a worker's threads: {e}"));
                        return;
                    }
                };
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= todo.len() || interrupt.load(Ordering::Relaxed) {
                        return;
                    }
                    let index = todo[k];
                    let name = &plan.runs[index].name;
                    worker.1.store(0, Ordering::Relaxed);
                    worker.0.store(index, Ordering::Relaxed);
                    let t = Instant::now();
                    let result = pool
                        .install(|| run_one(dir, plan, index, backend, true, interrupt, &worker.1));
                    worker.0.store(usize::MAX, Ordering::Relaxed);
                    match result {
                        Ok(_) => {
                            finished_steps.fetch_add(planned[index], Ordering::Relaxed);
                            done.fetch_add(1, Ordering::Relaxed);
                            say(
                                bar,
                                format!("  {name}: measured ({:.1} s)", t.elapsed().as_secs_f64()),
                            );
                        }
                        Err(f) if f.code == super::failure::INTERRUPTED => {}
                        Err(f) => {
                            finished_steps.fetch_add(planned[index], Ordering::Relaxed);
                            say(bar, format!("  failed: {}", f.message));
                            failed
                                .lock()
                                .unwrap_or_else(|e| e.into_inner())
                                .push(name.clone());
                        }
                    }
                }
            });
        }
        // The bar: finished runs whole, running ones at their step.
        while done.load(Ordering::Relaxed) + failed.lock().unwrap_or_else(|e| e.into_inner()).len()
            < todo.len()
            && !(interrupt.load(Ordering::Relaxed)
                && current
                    .iter()
                    .all(|w| w.0.load(Ordering::Relaxed) == usize::MAX))
        {
            let running: Vec<usize> = (current.iter())
                .map(|w| w.0.load(Ordering::Relaxed))
                .filter(|&i| i != usize::MAX)
                .collect();
            let at: u64 = (current.iter())
                .filter(|w| w.0.load(Ordering::Relaxed) != usize::MAX)
                .map(|w| w.1.load(Ordering::Relaxed))
                .sum();
            let position = finished_steps.load(Ordering::Relaxed) + at;
            let message = format!(
                "{}/{} runs done, {} running, {} failed",
                skipped + done.load(Ordering::Relaxed),
                plan.runs.len(),
                running.len(),
                failed.lock().unwrap_or_else(|e| e.into_inner()).len()
            );
            bar.set_position(position);
            bar.set_message(message.clone());
            // Without a bar (CI, pipes): a line about every tenth of the steps.
            if bar.is_hidden() && !quiet && position >= next_line && position < total {
                let done_here = position.saturating_sub(at_start) as f64;
                let eta =
                    (total - position) as f64 * start.elapsed().as_secs_f64() / done_here.max(1.0);
                eprintln!(
                    "  {:>3.0}% {message}, ETA {eta:.0} s",
                    100.0 * position as f64 / total.max(1) as f64
                );
                next_line = position + (total / 10).max(1);
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    });
    bar.finish_and_clear();
    let failed = failed.into_inner().unwrap_or_else(|e| e.into_inner());
    let done = done.into_inner();
    eprintln!(
        "talus sweep: {done} runs measured in {:.1} s, {} failed, {skipped} measured before",
        start.elapsed().as_secs_f64(),
        failed.len()
    );
    if interrupt.load(Ordering::Relaxed) {
        return Err(Failure::interrupted(format!(
            "sweep interrupted: {} of {} runs measured; the same command continues it (stopped runs resume from their checkpoints)",
            skipped + done,
            plan.runs.len()
        )));
    }
    if !failed.is_empty() {
        // The others ran; collect what there is, then report.
        collect(dir)?;
        return Err(Failure::failed(format!(
            "{} of {} runs failed: {} (why: runs/NAME/failed.json, or `talus sweep collect {}`)",
            failed.len(),
            plan.runs.len(),
            failed.join(", "),
            dir.display()
        )));
    }
    Ok(())
}
