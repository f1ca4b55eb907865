//! Command line: clap turns arguments into a validated scene and options; errors are
//! printed once here. Exit codes: 0 success, 1 failed run (divergence, I/O), 2 bad input.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use talus::{checkpoint, run, scene, sim::Simulation};

#[derive(Parser)]
#[command(
    name = "talus",
    version,
    about = "2D granular dynamics (DEM) of heaps and packings"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (the built-in default heap when none is given).
    Run {
        /// Scene file (JSON). Omit for the built-in default heap.
        scene: Option<PathBuf>,
        /// Output folder (default: runs/<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key, e.g. --set contact.mu=0.3 (repeatable).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        overrides: Vec<String>,
        /// Continue from a checkpoint file (only stop.* and output.* may be --set).
        #[arg(long, conflicts_with = "scene")]
        resume: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = Backend::Auto)]
        backend: Backend,
        /// No progress output.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Check a scene and print what it would create, without running it.
    Check {
        scene: Option<PathBuf>,
        #[arg(long = "set", value_name = "PATH=VALUE")]
        overrides: Vec<String>,
    },
    /// Print the built-in default scene.
    DefaultScene,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Backend {
    Auto,
    Cpu,
    Gpu,
}

/// A failed command: its exit code and the message printed once by `main`.
struct Failure {
    code: u8,
    message: String,
}

/// Bad input: exit code 2.
fn bad_input(message: impl ToString) -> Failure {
    Failure {
        code: 2,
        message: message.to_string(),
    }
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            overrides,
            resume,
            backend,
            quiet,
        } => cmd_run(scene, out, overrides, resume, backend, quiet),
        Command::Check { scene, overrides } => cmd_check(scene, overrides),
        Command::DefaultScene => {
            print!("{}", scene::DEFAULT_SCENE);
            Ok(())
        }
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
    let loaded = match path {
        Some(p) => scene::load(p, overrides),
        None => scene::parse(scene::DEFAULT_SCENE, overrides),
    };
    let name = path
        .as_ref()
        .map_or("default scene".to_string(), |p| p.display().to_string());
    let scene = loaded.map_err(|e| bad_input(format!("in {name}: {e}")))?;
    for w in scene::warnings(&scene) {
        eprintln!("warning: {w}");
    }
    Simulation::new(scene).map_err(|e| bad_input(format!("in {name}: {e}")))
}

fn cmd_check(path: Option<PathBuf>, overrides: Vec<String>) -> Result<(), Failure> {
    let sim = build_simulation(&path, &overrides)?;
    println!(
        "scene `{}`: {} particles at start ({} fixed), {} steps of dt = {}",
        sim.scene.name,
        sim.particles.len(),
        sim.particles.len() - sim.particles.mobile_count(),
        run::total_steps(&sim),
        sim.dt()
    );
    Ok(())
}

fn cmd_run(
    path: Option<PathBuf>,
    out: Option<PathBuf>,
    overrides: Vec<String>,
    resume: Option<PathBuf>,
    backend: Backend,
    quiet: bool,
) -> Result<(), Failure> {
    match backend {
        Backend::Gpu => {
            return Err(bad_input(
                "the GPU path is not implemented yet; use --backend cpu",
            ));
        }
        Backend::Auto if !quiet => {
            eprintln!("note: using the CPU reference path (the GPU path is not implemented yet)")
        }
        _ => {}
    }
    let mut sim = match &resume {
        Some(ckpt) => checkpoint::read(ckpt, &overrides).map_err(bad_input)?,
        None => build_simulation(&path, &overrides)?,
    };
    let out = out.unwrap_or_else(|| PathBuf::from("runs").join(&sim.scene.name));
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
    let s = run::run(
        &mut sim,
        &run::RunOptions {
            out: out.clone(),
            quiet,
        },
    )
    .map_err(|e| Failure {
        code: 1,
        message: e.to_string(),
    })?;
    if !quiet {
        eprintln!(
            "done: {} steps to t = {:.4} ({}), {} particles ({} lost), {:.3e} particle-steps/s; results in {}",
            s.steps,
            s.time,
            if s.settled { "settled" } else { "end time" },
            s.particles,
            s.lost,
            s.particle_steps_per_second,
            out.display()
        );
    }
    Ok(())
}
