//! Command line: clap turns arguments into a validated scene and options; errors are
//! printed once here. Exit codes (`failure`): 0 success, 1 failed run (divergence,
//! I/O), 2 bad input, 130 an interrupted run.

use clap::{Parser, Subcommand};

/// println! that ignores a closed stdout (`talus analyze ... | head`) instead of
/// panicking.
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}
mod analyze;
mod check;
mod choices;
mod failure;
mod reproduce;
#[path = "run.rs"]
mod run_cmd;
mod sweep;

use choices::Backend;
use failure::Failure;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use talus::gpu::GpuSimulation;
use talus::gpu::device;
use talus::run::Engine;
use talus::{bench, io::checkpoint, scene, sim::Simulation};

#[derive(Parser)]
#[command(
    name = "talus",
    version = talus::base::provenance::VERSION_LINE,
    about = "2D granular dynamics (DEM) of heaps and packings"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Threads of the CPU path (default: every core). Results are bitwise the same for
    /// any count.
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (the built-in default heap when none is given).
    Run(run_cmd::RunArgs),
    /// Check a scene and print what it would create, without running it.
    Check {
        scene: Option<PathBuf>,
        #[arg(long = "set", value_name = "PATH=VALUE")]
        overrides: Vec<String>,
        /// Also estimate the run time: the expected work (moving particles × steps, the
        /// sources' insertions at their rates) over the particle-steps per second of a
        /// few seconds of the scene itself on each backend (the CPU path, and a hardware
        /// GPU when there is one; --backend gpu takes any adapter).
        #[arg(long)]
        estimate: bool,
        /// The backends --estimate times (auto, the default: the CPU path and a hardware
        /// GPU). gpu also says whether the scene fits the adapter a run would take.
        #[arg(long, value_enum)]
        backend: Option<Backend>,
    },
    /// Print the built-in default scene.
    DefaultScene,
    /// List the GPU adapters, the limits talus uses, and what a run would choose.
    Info,
    /// Measure a snapshot (or a run folder's final state): stresses with moving
    /// averages, base pressure, angle of repose, coordination, force distribution,
    /// packing fraction, f(theta), Q(r), energies. Writes CSV tables and summary.json.
    Analyze {
        /// A snapshot's .json, or a run folder (its final.json).
        path: PathBuf,
        /// Output folder (default: `analysis/` in the run folder, or next to the snapshot).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Width of the horizontal moving-average windows, in mean diameters.
        #[arg(long, default_value_t = 14.0)]
        window: f64,
        /// Spacing of the window centres, in mean diameters.
        #[arg(long, default_value_t = 1.0)]
        step: f64,
        /// Height of a row of windows (the lowest gives the base profile), in mean diameters.
        #[arg(long, default_value_t = 2.0)]
        row: f64,
        /// Gravity's magnitude (default: the run's scene.json, else 9.81 or 1).
        #[arg(long)]
        g: Option<f64>,
        /// Average the stress tables over the run's snapshots from this time on (and
        /// the final state); needs a run folder.
        #[arg(long)]
        from: Option<f64>,
        /// The angle of repose is fitted to the free surface between these fractions of
        /// the height (leaving out toe and apex); raise the lower one for a heap on a
        /// wide layer.
        #[arg(long, num_args = 2, value_names = ["FROM", "TO"], default_values_t = [0.15, 0.85])]
        fit: Vec<f64>,
    },
    /// Pictures of a snapshot (or a run folder's final state) in PNG and SVG: grains
    /// coloured by a field, the force network, principal-stress crosses, profile plots;
    /// and VTK files (grains.vtp, contacts.vtp, walls.vtp) for ParaView.
    Render {
        /// A snapshot's .json, or a run folder (its final.json).
        path: PathBuf,
        /// Output folder (default: `pictures/` in the run folder, or next to the snapshot).
        #[arg(long)]
        out: Option<PathBuf>,
        /// What colours the grains.
        #[arg(long, value_enum, default_value_t = choices::Color::Pressure)]
        color: choices::Color,
        /// Width of the pictures in pixels.
        #[arg(long, default_value_t = 1600)]
        width: u32,
        /// Moving-average window for the stress crosses, in mean diameters.
        #[arg(long, default_value_t = 14.0)]
        window: f64,
        /// Gravity's magnitude (default: the run's scene.json, else 9.81 or 1).
        #[arg(long)]
        g: Option<f64>,
    },
    /// Run one of the papers' scenes (R1–R9; reduced unless --full), then
    /// measure and draw it; writes reproduce.json with the numbers it is judged by.
    Reproduce {
        /// R1 to R9.
        id: String,
        /// The paper's size instead of the reduced form.
        #[arg(long)]
        full: bool,
        /// R9: the paper's layout (as --full) with this many rods instead of 6000, the
        /// box and the end time sized for them: 1000–3000 rods give a deposit deep
        /// enough for the Janssen fit in hours of one CPU core, not days.
        #[arg(long, value_name = "N", conflicts_with = "full")]
        rods: Option<usize>,
        /// Only the variant of this name, or when none has it those whose name contains
        /// it (e.g. `wedge-poly`, `seed3`); several separated by commas
        /// (`d2-bo0,d5-bo1000`).
        #[arg(long)]
        only: Option<String>,
        /// Keep the variants whose folder already holds a finished run of the same
        /// scene: measure and draw them again without running them.
        #[arg(long, conflicts_with = "seeds")]
        reuse: bool,
        /// Run every variant for these seeds (A..B, both included, or A,B,C) as a sweep
        /// (`talus sweep`): each variant's folder is a sweep folder, and reproduce.json
        /// gets the mean, spread and standard error over seeds. Run again, it continues.
        #[arg(long, value_name = "A..B")]
        seeds: Option<String>,
        /// With --seeds: runs at once (default: one per core).
        #[arg(long, requires = "seeds")]
        jobs: Option<usize>,
        /// Output folder (default: runs/reproduce/ID).
        #[arg(long)]
        out: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = Backend::Auto)]
        backend: Backend,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Run a scene for every combination of seeds and parameter values (one folder
    /// each, J at a time here or as a Slurm job array), measure every run, and collect
    /// the statistics over seeds (`sweep collect`).
    Sweep(sweep::SweepArgs),
    /// Measure particle-steps per second per backend and workload; prints JSON.
    Bench {
        /// Backends to measure (auto: the GPU path on a hardware adapter, none on a
        /// software one; gpu: whatever adapter there is).
        #[arg(long, value_enum, default_values_t = [Backend::Cpu, Backend::Auto])]
        backend: Vec<Backend>,
        /// Packing sizes (disks) of the settled-packing workloads.
        #[arg(long, value_delimiter = ',', default_values_t = [1000, 10000, 100000])]
        sizes: Vec<usize>,
        /// Sizes (polygons) of the polygon-pile workloads (regular 12-gons).
        #[arg(long, value_delimiter = ',', default_values_t = [1000, 10000, 50000])]
        polygon_sizes: Vec<usize>,
        /// Sizes (rods of aspect 5, paper 004's law) of the rod-pile workloads.
        #[arg(long, value_delimiter = ',', default_values_t = [1000])]
        rod_sizes: Vec<usize>,
        /// Steps timed per workload (after a warm-up of a tenth as many); with --budget,
        /// the most steps timed.
        #[arg(long)]
        steps: Option<u64>,
        /// Seconds per workload and backend: time as many steps as fit (in doubling
        /// batches, after a warm-up of 10 steps) instead of a fixed count. Default: 3 s,
        /// unless --steps is given.
        #[arg(long)]
        budget: Option<f64>,
        /// Also time the reduced R4 pour.
        #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
        pour: bool,
        /// GPU path: also time each kernel on the device (128 more steps per workload,
        /// a timestamp after every dispatch; needs the adapter's timestamp queries).
        #[arg(long)]
        kernels: bool,
        /// Write the JSON here too (atomically).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the benchmark workloads on the GPU path and the CPU path for the same steps
    /// and compare the end states: positions, pair forces, contacts, each against a
    /// stated tolerance; prints JSON, exits non-zero when a workload disagrees
    Agree {
        /// Packing sizes (disks).
        #[arg(long, value_delimiter = ',', default_values_t = [100000])]
        sizes: Vec<usize>,
        /// Polygon-pile sizes (regular 12-gons).
        #[arg(long, value_delimiter = ',', default_values_t = [30000])]
        polygon_sizes: Vec<usize>,
        /// Rod-pile sizes (aspect 5, paper 004's law).
        #[arg(long, value_delimiter = ',')]
        rod_sizes: Vec<usize>,
        /// Steps run on each path.
        #[arg(long, default_value_t = 300)]
        steps: u64,
        /// Write the JSON here too (atomically).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

pub fn main() -> ExitCode {
    quiet_headless_vulkan();
    let cli = Cli::parse();
    let threads = match cli.threads {
        Some(0) => {
            eprintln!("error: --threads: must be at least 1, got 0");
            return ExitCode::from(failure::INPUT);
        }
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    // The command runs on a thread of the pool, so the stages' parallel loops split their
    // work there instead of handing it over from another thread every time.
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: --threads {threads}: {e}");
            return ExitCode::from(failure::FAILED);
        }
    };
    pool.install(|| command(cli.command, threads))
}

/// Mesa's Vulkan layer `VK_LAYER_MESA_device_select` looks for a Wayland display to
/// order the GPUs, and on a machine without a display session libwayland then prints
/// "error: XDG_RUNTIME_DIR is invalid or not set in the environment" several times per
/// process, into every log and Slurm output. talus picks its adapter itself
/// (`device::choose_adapter`), so there the layer is switched off by its own switch,
/// NODEVICE_SELECT, unless the user chose a device through it (MESA_VK_DEVICE_SELECT) or
/// set the switch.
fn quiet_headless_vulkan() {
    let set = |k: &str| std::env::var_os(k).is_some();
    if !set("XDG_RUNTIME_DIR") && !set("MESA_VK_DEVICE_SELECT") && !set("NODEVICE_SELECT") {
        // SAFETY: the first thing `main` does, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

fn command(command: Command, threads: usize) -> ExitCode {
    let result = match command {
        Command::Run(args) => run_cmd::cmd_run(args),
        Command::Check {
            scene,
            overrides,
            estimate,
            backend,
        } => check::cmd_check(scene, overrides, estimate, backend),
        Command::DefaultScene => {
            out!("{}", scene::DEFAULT_SCENE.trim_end());
            Ok(())
        }
        Command::Info => {
            out!("{}", device::describe().trim_end());
            Ok(())
        }
        Command::Analyze {
            path,
            out,
            window,
            step,
            row,
            g,
            from,
            fit,
        } => analyze::cmd_analyze(&path, out, window, step, row, g, from, [fit[0], fit[1]]),
        Command::Render {
            path,
            out,
            color,
            width,
            window,
            g,
        } => analyze::cmd_render(&path, out, color.into(), width, window, g),
        Command::Reproduce {
            id,
            full,
            rods,
            only,
            reuse: _,
            seeds: Some(seeds),
            jobs,
            out,
            backend,
            quiet,
        } => {
            let seeds = reproduce::Seeds {
                seeds,
                jobs,
                threads,
            };
            let size = reproduce::reproduction_size(full, rods);
            reproduce::reproduce(&id, size, only.as_deref(), &seeds, out, backend, quiet)
        }
        Command::Reproduce {
            id,
            full,
            rods,
            only,
            reuse,
            seeds: None,
            out,
            backend,
            quiet,
            ..
        } => {
            let size = reproduce::reproduction_size(full, rods);
            reproduce::cmd_reproduce(&id, size, only.as_deref(), reuse, out, backend, quiet)
        }
        Command::Sweep(args) => sweep::cmd_sweep(args, threads),
        Command::Bench {
            backend,
            sizes,
            polygon_sizes,
            rod_sizes,
            steps,
            budget,
            pour,
            kernels,
            out,
        } => cmd_bench(
            &backend,
            (&sizes, &polygon_sizes, &rod_sizes),
            (steps, budget),
            pour,
            kernels,
            out,
        ),
        Command::Agree {
            sizes,
            polygon_sizes,
            rod_sizes,
            steps,
            out,
        } => cmd_agree((&sizes, &polygon_sizes, &rod_sizes), steps, out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

/// Loads and validates a scene (the default one when no path is given), prints its
/// warnings, and builds the initial state.
fn build_simulation(path: &Option<PathBuf>, overrides: &[String]) -> Result<Simulation, Failure> {
    let name = path
        .as_ref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    let scene = load_scene(path, overrides)?;
    Simulation::new(scene).map_err(|e| Failure::from(e).within(format!("in {name}")))
}

/// Loads and validates a scene (the default one when no path is given) and prints its
/// warnings.
fn load_scene(path: &Option<PathBuf>, overrides: &[String]) -> Result<scene::Scene, Failure> {
    let loaded = match path {
        Some(p) => scene::load(p, overrides),
        None => scene::parse(scene::DEFAULT_SCENE, overrides),
    };
    let name = path
        .as_ref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    let within = |e| Failure::from(e).within(format!("in {name}"));
    let scene = loaded.map_err(within)?;
    for w in scene::warnings(&scene) {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// Where results of a run folder or snapshot go by default: `NAME/` in the run folder,
/// or `STEM_NAME/` next to the snapshot.
fn beside(path: &std::path::Path, name: &str) -> PathBuf {
    if path.is_dir() {
        return path.join(name);
    }
    let stem = path
        .file_stem()
        .map_or("snapshot".into(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}_{name}"))
}

/// An angle in degrees for a summary line, or "none" where there was nothing to fit
/// (a box deposit has no free slope).
fn degrees(a: f64) -> String {
    if a.is_finite() {
        format!("{a:.1}°")
    } else {
        "none".to_string()
    }
}

/// A flag that SIGINT and SIGTERM set: the run stops between two advances, removes its
/// temporaries and says where its last checkpoint is. A second signal ends the process
/// at once.
fn on_interrupt() -> Arc<AtomicBool> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        // The shutdown is registered first: it acts when the flag is already set.
        let code = failure::INTERRUPTED.into();
        let registered =
            signal_hook::flag::register_conditional_shutdown(signal, code, flag.clone())
                .and_then(|_| signal_hook::flag::register(signal, flag.clone()));
        if let Err(e) = registered {
            eprintln!("warning: signal {signal} will end the run without cleaning up: {e}");
        }
    }
    flag
}

/// `talus analyze` and `talus render` on a snapshot or run folder: tables into
/// `analysis`, pictures and VTK files into `pictures` (if given). Returns the file count.
fn measure_and_draw(
    path: &std::path::Path,
    analysis: &std::path::Path,
    pictures: &std::path::Path,
    opt: &talus::analyze::Options,
    g: Option<f64>,
    field: talus::render::Field,
    width: u32,
) -> Result<usize, Failure> {
    let input = talus::analyze::input::load(path, g)?;
    let a = talus::analyze::analyze(input, opt)?;
    let mut n = talus::analyze::write(&a, analysis)?.len();
    n += talus::render::render(&a, pictures, field, width)?.len();
    n += talus::render::vtk::write(&a, pictures)?.len();
    talus::render::dump::write_named(&a, pictures, "")?;
    n += 1;
    Ok(n)
}

/// The engine for `--backend`: `gpu` insists on a GPU adapter; `auto` takes a hardware
/// GPU when there is one and otherwise the CPU path, saying why. A software adapter
/// (lavapipe) counts as no GPU for `auto`: the CPU path is faster than it.
/// A checkpoint's device state (from a GPU run) resumes the GPU path bitwise; the CPU
/// path continues from the f64 state.
fn choose_engine(
    start: checkpoint::Checkpoint,
    backend: Backend,
    quiet: bool,
) -> Result<Engine, Failure> {
    match backend {
        Backend::Cpu => Ok(Engine::cpu(start.sim)),
        Backend::Gpu => Ok(Engine::Gpu(Box::new(GpuSimulation::resume(
            start.sim,
            start.device,
        )?))),
        Backend::Auto => {
            let why = match device::choose_adapter() {
                Ok(a) if a.get_info().device_type == wgpu::DeviceType::Cpu => format!(
                    "only a software GPU adapter ({}) was found, and the CPU path is faster; \
                     --backend gpu uses it anyway",
                    a.get_info().name
                ),
                Ok(_) => {
                    let fallback = start.sim.clone();
                    return match GpuSimulation::resume(start.sim, start.device) {
                        Ok(g) => Ok(Engine::Gpu(Box::new(g))),
                        Err(e) => {
                            if !quiet {
                                eprintln!(
                                    "note: the GPU path is unavailable ({e}); using the CPU reference path"
                                );
                            }
                            Ok(Engine::cpu(fallback))
                        }
                    };
                }
                Err(e) => e.to_string(),
            };
            if !quiet {
                eprintln!("note: using the CPU reference path: {why}");
            }
            Ok(Engine::cpu(start.sim))
        }
    }
}

/// Seconds per workload of a `talus bench` without --steps or --budget.
const DEFAULT_BUDGET: f64 = 3.0;

fn cmd_agree(
    (sizes, polygon_sizes, rod_sizes): (&[usize], &[usize], &[usize]),
    steps: u64,
    out: Option<PathBuf>,
) -> Result<(), Failure> {
    check_sizes(sizes, polygon_sizes, rod_sizes)?;
    if steps == 0 {
        return Err(Failure::input("--steps must be at least 1"));
    }
    let report = bench::agree::run(sizes, polygon_sizes, rod_sizes, steps, &mut |line| {
        eprintln!("{line}")
    })?;
    let text = serde_json::to_string_pretty(&report).expect("report serialises");
    out!("{text}");
    if let Some(path) = out {
        talus::base::files::write_atomic(&path, text.as_bytes())
            .map_err(|e| Failure::failed(format!("cannot write {}: {e}", path.display())))?;
    }
    let disagree = report.results.iter().filter(|a| !a.passed).count();
    if disagree + report.failures.len() > 0 {
        return Err(Failure::failed(format!(
            "{disagree} of the workloads disagree beyond their tolerance and {} could not run",
            report.failures.len()
        )));
    }
    Ok(())
}

/// A workload is built in memory first: at most 2·10⁷ particles (issue 16: --sizes 3e8
/// aborted on allocation).
fn check_sizes(
    sizes: &[usize],
    polygon_sizes: &[usize],
    rod_sizes: &[usize],
) -> Result<(), Failure> {
    for (flag, list) in [
        ("--sizes", sizes),
        ("--polygon-sizes", polygon_sizes),
        ("--rod-sizes", rod_sizes),
    ] {
        if let Some(n) = list.iter().find(|&&n| !(1..=20_000_000).contains(&n)) {
            return Err(Failure::input(format!(
                "{flag}: {n} particles; each size must be 1 to 2·10⁷"
            )));
        }
    }
    Ok(())
}

fn cmd_bench(
    backends: &[Backend],
    (sizes, polygon_sizes, rod_sizes): (&[usize], &[usize], &[usize]),
    (steps, budget): (Option<u64>, Option<f64>),
    pour: bool,
    kernels: bool,
    out: Option<PathBuf>,
) -> Result<(), Failure> {
    check_sizes(sizes, polygon_sizes, rod_sizes)?;
    if let Some(b) = budget.filter(|b| !(*b > 0.0 && b.is_finite())) {
        return Err(Failure::input(format!(
            "--budget must be a positive number of seconds, got {b}"
        )));
    }
    // A time budget per workload by default, so that the whole bench takes about a
    // minute on any machine; a step count only when asked for.
    let (steps, budget) = match (steps, budget) {
        (Some(n), None) => (n, None),
        (n, b) => (n.unwrap_or(100_000), Some(b.unwrap_or(DEFAULT_BUDGET))),
    };
    let backends: Vec<device::BackendChoice> = backends.iter().map(|&b| b.into()).collect();
    let report = bench::run(
        &backends,
        sizes,
        polygon_sizes,
        rod_sizes,
        bench::Timing {
            steps,
            budget,
            pour,
            kernels,
        },
        &mut |line| eprintln!("{line}"),
        &mut |so_far| {
            // Each measurement as it ends (issue 38: a bench stopped at a time limit keeps
            // the workloads it finished); a write that fails is reported at the end.
            if let Some(path) = &out {
                let text = serde_json::to_string_pretty(so_far).expect("report serialises");
                let _ = talus::base::files::write_atomic(path, text.as_bytes());
            }
        },
    )?;
    let text = serde_json::to_string_pretty(&report).expect("report serialises");
    out!("{text}");
    if let Some(path) = out {
        talus::base::files::write_atomic(&path, text.as_bytes())
            .map_err(|e| Failure::failed(format!("cannot write {}: {e}", path.display())))?;
    }
    if !report.failures.is_empty() {
        return Err(Failure::failed(format!(
            "{} of the workloads could not run (listed under \"failures\")",
            report.failures.len()
        )));
    }
    Ok(())
}
