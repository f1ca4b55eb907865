//! `talus reproduce`: a paper's scene run as its variants (or as sweeps over seeds),
//! measured, drawn and judged in reproduce.json.

use super::choices::Backend;
use super::failure::Failure;
use super::sweep::run_here;
use super::{choose_engine, degrees, on_interrupt};
use clap::ValueEnum;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use talus::sweep;
use talus::{io::checkpoint, run, scene, sim::Simulation};

/// Whether `dir` holds a finished run (its `summary.json` is written last) of exactly
/// `scene`.
pub(super) fn finished_run_of(dir: &std::path::Path, scene: &scene::Scene) -> bool {
    let read = |name: &str| -> Option<serde_json::Value> {
        serde_json::from_str(&std::fs::read_to_string(dir.join(name)).ok()?).ok()
    };
    read("summary.json").is_some()
        && read("scene.json").is_some_and(|s| serde_json::to_value(scene).ok() == Some(s))
}

/// `--full` and `--rods` as one size (clap refuses both at once).
pub(super) fn reproduction_size(full: bool, rods: Option<usize>) -> talus::reproduce::Size {
    use talus::reproduce::Size;
    match (rods, full) {
        (Some(n), _) => Size::Rods(n),
        (None, true) => Size::Full,
        (None, false) => Size::Reduced,
    }
}

/// The variants of reproduction `id` that `only` picks (`reproduce::pick`), if given.
pub(super) fn chosen_variants(
    id: &str,
    size: talus::reproduce::Size,
    only: Option<&str>,
) -> Result<Vec<talus::reproduce::Variant>, Failure> {
    let mut variants = talus::reproduce::variants(id, size)?;
    if let Some(only) = only {
        let names: Vec<String> = variants.iter().map(|v| v.name.clone()).collect();
        variants = talus::reproduce::pick(variants, only);
        if variants.is_empty() {
            return Err(Failure::input(format!(
                "--only {only}: no variant of {id} matches; they are {}",
                names.join(", ")
            )));
        }
    }
    Ok(variants)
}

pub(super) fn cmd_reproduce(
    id: &str,
    size: talus::reproduce::Size,
    only: Option<&str>,
    reuse: bool,
    out: Option<PathBuf>,
    backend: Backend,
    quiet: bool,
) -> Result<(), Failure> {
    use talus::reproduce;
    let id = id.to_uppercase();
    let variants = chosen_variants(&id, size, only)?;
    let root = out.unwrap_or_else(|| PathBuf::from("runs/reproduce").join(&id));
    let interrupt = on_interrupt();
    let mut found = Vec::new();
    let mut failed = Vec::new();
    for v in &variants {
        if interrupt.load(Ordering::Relaxed) {
            return Err(Failure::interrupted(format!(
                "{id}: interrupted before {}",
                v.name
            )));
        }
        let within = |e| Failure::from(e).within(format!("{id} {}", v.name));
        let scene = scene::parse(v.scene, &v.overrides).map_err(within)?;
        let sim = Simulation::new(scene).map_err(within)?;
        let dir = root.join(&v.name);
        let finished = reuse && finished_run_of(&dir, &sim.scene);
        if !quiet {
            let how = if finished {
                " (finished run reused)"
            } else {
                ""
            };
            eprintln!(
                "{id} {}: {} -> {}{how}",
                v.name,
                sim.scene.name,
                dir.display()
            );
        }
        if finished {
            // Measured and drawn below like a fresh run.
        } else if let Err(e) = run::run(
            &mut choose_engine(checkpoint::Checkpoint::fresh(sim), backend, quiet)?,
            &run::RunOptions {
                out: dir.clone(),
                quiet,
                // A variant's folder is this reproduction's own: run again, it replaces
                // the run there (--reuse keeps a finished one instead).
                force: true,
                resumed_from: None,
                interrupt: interrupt.clone(),
                ..Default::default()
            },
        ) {
            if let run::RunError::Interrupted { .. } = e {
                return Err(Failure::from(e).within(format!("{id} {}", v.name)));
            }
            // A variant that fails is reported and the others still run.
            eprintln!("error: {id} {}: {e}", v.name);
            failed.push(serde_json::json!({ "variant": v.name, "error": e.to_string() }));
            continue;
        }
        let opt = talus::analyze::Options {
            window: v.window,
            row: v.row,
            ..Default::default()
        };
        let input = talus::analyze::input::load(&dir, None)?;
        let a = talus::analyze::analyze(input, &opt)?;
        talus::analyze::write(&a, &dir.join("analysis"))?;
        talus::render::render_marked(
            &a,
            &dir.join("pictures"),
            talus::render::Field::Pressure,
            1600,
            &reproduce::paper::marks(&id, &v.name),
        )?;
        talus::render::vtk::write(&a, &dir.join("pictures"))?;
        let mut f = reproduce::findings(&v.name, &a);
        f.cost = reproduce::RunCost::of_run(&dir);
        out!(
            "{id} {}: {} grains, t = {:.3}; repose {} / {}; S_xx/S_zz (row 1, interior) {:.3}; S_zz under the apex / max: base {:.3} / {:.3} (dip {:.2}), row 1 {:.3} / {:.3} (dip {:.2}); Z interior {:.2}",
            v.name,
            f.grains,
            f.time,
            degrees(f.repose_left_deg),
            degrees(f.repose_right_deg),
            f.stress_ratio_interior_row1,
            f.base_szz_centre,
            f.base_szz_max,
            f.base_dip,
            f.row1_szz_centre,
            f.row1_szz_max,
            f.row1_dip,
            f.coordination_interior
        );
        if let (Some(c), Some(l), Some(r)) = (
            f.base_load_centre_mg,
            f.base_load_left_max_mg,
            f.base_load_right_max_mg,
        ) {
            out!(
                "{id} {}: load on the base particles (over {} of them) under the apex {c:.2} m g, largest left {l:.2}, right {r:.2}",
                v.name,
                talus::analyze::BASE_SPAN
            );
        }
        if let Some(c) = &f.cost {
            out!(
                "{id} {}: {} steps in {:.1} s ({:.3e} particle-steps/s, {} thread(s), {})",
                v.name,
                c.steps,
                c.wall_seconds,
                c.particle_steps_per_second,
                c.threads,
                c.backend
            );
        }
        found.push(f);
    }
    let averages = reproduce::seed_averages(&found);
    // Row-1 profiles side by side: the seed averages where there are seeds.
    let profiles: Vec<(String, Vec<(f64, f64)>)> = if averages.is_empty() {
        found
            .iter()
            .map(|f| (f.variant.clone(), f.row1_profile.clone()))
            .collect()
    } else {
        averages
            .iter()
            .map(|a| {
                (
                    format!("{} ({} seeds)", a.setting, a.seeds),
                    a.profile.clone(),
                )
            })
            .collect()
    };
    if !profiles.is_empty() {
        let path = root.join("profiles.svg");
        talus::render::plots::write_profiles(
            &path,
            &format!("{id}: vertical stress in row 1"),
            &profiles,
        )?;
    }
    let deep: Vec<_> = (found.iter())
        .filter(|f| f.stress_depth.len() >= 3)
        .map(|f| (f.variant.clone(), f.stress_depth.clone(), f.janssen))
        .collect();
    if !deep.is_empty() {
        let path = root.join("janssen.svg");
        talus::render::plots::write_janssen(
            &path,
            &format!("{id}: mean stress against depth"),
            &deep,
        )?;
    }
    for a in &averages {
        out!(
            "{id} {} (average of {} seeds): S_zz(1) under the apex {:.3}, max {:.3}, dip {:.2}; Z interior {:.2}",
            a.setting,
            a.seeds,
            a.row1_szz_apex,
            a.row1_szz_max,
            a.row1_dip,
            a.coordination_interior
        );
    }
    let trends = if id == "R9" {
        reproduce::r9_trends(&found)
    } else {
        Vec::new()
    };
    for t in &trends {
        out!("{id}: {t}");
    }
    let comparisons = reproduce::comparisons(&id, &found);
    for c in &comparisons {
        out!(
            "{id} {} against {}: row-1 S_zz differs by {:.3} of the maximum at most, {:.3} on average",
            c.variants[0],
            c.variants[1],
            c.row1_szz_max_difference,
            c.row1_szz_mean_difference
        );
    }
    let report = serde_json::json!({
        "id": id,
        "full": size != reproduce::Size::Reduced,
        "size": size,
        "claim": reproduce::claim(&id),
        "seed_averages": averages,
        "comparisons": comparisons,
        "trends": trends,
        "variants": found,
        "failed": failed,
    });
    finish_reproduction(&id, &root, &report, failed.len(), variants.len(), "failed")
}

/// Writes `root/reproduce.json`, says where the results are, and fails when `failed` of
/// the `of` variants `what` (failed, or had failed runs).
pub(super) fn finish_reproduction(
    id: &str,
    root: &std::path::Path,
    report: &serde_json::Value,
    failed: usize,
    of: usize,
    what: &str,
) -> Result<(), Failure> {
    let path = root.join("reproduce.json");
    talus::base::files::write_atomic(
        &path,
        serde_json::to_string_pretty(report).unwrap().as_bytes(),
    )
    .map_err(|e| Failure::failed(format!("cannot write {}: {e}", path.display())))?;
    // The paper's claim, said as the paper's: whether this run bears it out is in the
    // measurements above and in reproduce.json, not in this line.
    out!(
        "{id}: the paper reports {}; compare the measurements above; results in {}",
        talus::reproduce::claim(id),
        root.display()
    );
    if failed > 0 {
        return Err(Failure::failed(format!(
            "{id}: {failed} of {of} variants {what} (listed in reproduce.json)"
        )));
    }
    Ok(())
}

/// `talus reproduce ID --seeds ...`: how many seeds, runs at once, and the threads.
pub struct Seeds {
    pub seeds: String,
    pub jobs: Option<usize>,
    pub threads: usize,
}

/// `talus reproduce ID --seeds A..B`: every variant as a sweep over the seeds in
/// `ROOT/<variant>/` (continued when run again, replaced when its plan changed), collected
/// there, and the statistics of all variants in `ROOT/reproduce.json` with their row-1
/// S_zz profiles in `ROOT/profiles.svg` (seed means with ± one standard deviation).
pub fn reproduce(
    id: &str,
    size: talus::reproduce::Size,
    only: Option<&str>,
    seeds: &Seeds,
    out: Option<PathBuf>,
    backend: Backend,
    quiet: bool,
) -> Result<(), Failure> {
    use talus::reproduce;
    let id = id.to_uppercase();
    let variants = super::reproduce::chosen_variants(&id, size, only)?;
    let list = sweep::parse_seeds(&seeds.seeds)?;
    if seeds.jobs == Some(0) {
        return Err(Failure::input("--jobs: must be at least 1, got 0"));
    }
    let root = out.unwrap_or_else(|| PathBuf::from("runs/reproduce").join(&id));
    let backend_name = backend
        .to_possible_value()
        .map_or("auto".into(), |v| v.get_name().to_string());
    // Every variant planned (and its scenes checked) before any runs.
    let mut planned = Vec::new();
    for v in &variants {
        let within = |e| Failure::from(e).within(format!("{id} {}", v.name));
        let base = scene::parse(v.scene, &v.overrides).map_err(within)?;
        let measuring = sweep::Measuring {
            window: v.window,
            row: v.row,
        };
        let plan = sweep::plan(&base, &list, &[], &backend_name, measuring)
            .map_err(|e| Failure::from(e).within(format!("{id} {}", v.name)))?;
        planned.push((v, base, plan));
    }
    let mut statistics = Vec::new();
    let mut failed = Vec::new();
    let mut bands = Vec::new();
    for (v, base, plan) in &planned {
        let dir = root.join(&v.name);
        // The variant's folder is this reproduction's own: the same plan continues, a
        // changed one replaces it.
        sweep::claim(&dir, plan, base, true)?;
        if !quiet {
            eprintln!("{id} {}: {} seeds -> {}", v.name, list.len(), dir.display());
        }
        let jobs = seeds.jobs.unwrap_or(match backend {
            Backend::Gpu => 1,
            _ => seeds.threads,
        });
        match run_here(&dir, plan, backend, jobs, seeds.threads, quiet) {
            Ok(()) => {}
            Err(f) if f.code == super::failure::INTERRUPTED => return Err(f.within(&id)),
            Err(f) => {
                eprintln!("error: {id} {}: {}", v.name, f.message);
                failed.push(serde_json::json!({ "variant": v.name, "error": f.message }));
            }
        }
        let c = sweep::collect::gather(&dir, plan);
        sweep::collect::write(&dir, &c)?;
        let Some(point) = c.points.first() else {
            continue;
        };
        if point.measured == 0 {
            out!("{id} {}: none of {} seeds measured", v.name, point.runs);
        } else {
            let stat = |name: &str| point.stats.iter().find(|s| s.0 == name).map(|s| s.1);
            let show = |name: &str, unit: &str| {
                stat(name).map_or(String::new(), |s| {
                    format!(
                        "{:.3}{unit} ± {:.3} (se {:.3}, n {})",
                        s.mean, s.std, s.se, s.n
                    )
                })
            };
            out!(
                "{id} {} ({} of {} seeds measured): repose left {}, right {}, mean {} (middle third {}, apex to toe {}, steepest stretch {}); height {} d; packing {}; Z interior {}; S_zz(1) apex {} max {}; base load centre {} side max {} m g, ratio {}, dip above noise {} m g",
                v.name,
                point.measured,
                point.runs,
                show("repose_left_deg", "°"),
                show("repose_right_deg", "°"),
                show("repose_mean_deg", "°"),
                show("repose_middle_deg", "°"),
                show("repose_apex_toe_deg", "°"),
                show("repose_steepest_deg", "°"),
                show("height_d", ""),
                show("packing_fraction_lower_half", ""),
                show("coordination_interior", ""),
                show("row1_szz_centre", ""),
                show("row1_szz_max", ""),
                show("base_load_centre_mg", ""),
                show("base_load_side_max_mg", ""),
                show("base_load_centre_over_side_max", ""),
                show("base_load_dip_excess_mg", "")
            );
        }
        if let Some((_, profile)) = point.profiles.iter().find(|p| p.0 == "szz_row1")
            && !profile.is_empty()
        {
            let line = profile.iter().map(|b| (b.x, b.mean, b.std)).collect();
            bands.push((format!("{} ({} seeds)", v.name, point.measured), line));
        }
        statistics.push(serde_json::json!({
            "variant": v.name,
            "folder": dir.display().to_string(),
            "seeds": list,
            "measured": point.measured,
            "statistics": point.stats.iter().map(|(k, s)| (k.clone(), serde_json::json!(s))).collect::<serde_json::Map<_, _>>(),
            "profiles": point.profiles,
            "runs": c.runs,
        }));
    }
    if !bands.is_empty() {
        let path = root.join("profiles.svg");
        talus::render::plots::write_bands(
            &path,
            &format!("{id}: vertical stress in row 1, seed means ± one standard deviation"),
            talus::render::plots::Axis::new("X - X_apex", "heap widths"),
            talus::render::plots::Axis::new("S_zz(1) = 2σ_zz / (ρ g h)", "-"),
            &bands,
        )?;
    }
    let report = serde_json::json!({
        "id": id,
        "full": size != reproduce::Size::Reduced,
        "size": size,
        "claim": reproduce::claim(&id),
        "seeds": list,
        "variants": statistics,
        "failed": failed,
    });
    super::reproduce::finish_reproduction(
        &id,
        &root,
        &report,
        failed.len(),
        planned.len(),
        "had failed runs",
    )
}
