//! `talus analyze` and `talus render`: a snapshot or a run folder's final state
//! measured (tables and summary.json) and drawn (pictures and VTK files).

use super::failure::Failure;
use super::{beside, degrees};
use std::path::PathBuf;

pub(super) fn cmd_analyze(
    path: &std::path::Path,
    out: Option<PathBuf>,
    window: f64,
    step: f64,
    row: f64,
    g: Option<f64>,
    from: Option<f64>,
    fit: [f64; 2],
) -> Result<(), Failure> {
    use talus::analyze;
    if !(0.0 <= fit[0] && fit[0] < fit[1] && fit[1] <= 1.0) {
        return Err(Failure::input(format!(
            "--fit {} {}: needs 0 <= FROM < TO <= 1 (fractions of the heap's height)",
            fit[0], fit[1]
        )));
    }
    for (name, v) in [("--window", window), ("--step", step), ("--row", row)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Failure::input(format!(
                "{name} must be a positive number of diameters, not {v}"
            )));
        }
    }
    if let Some(g) = g.filter(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(Failure::input(format!("--g must be positive, not {g}")));
    }
    // Windows are --window wide every --step (and rows every --row): a step far below
    // them only multiplies the windows (issue 16: --step 1e-9 aborted on allocation).
    if step < 1e-3 * window || row < 1e-3 * window {
        return Err(Failure::input(format!(
            "--step ({step}) and --row ({row}) must be at least a thousandth of --window \
             ({window}): windows that close only repeat each other"
        )));
    }
    let input = analyze::input::load(path, g)?;
    let dir = out.unwrap_or_else(|| beside(path, "analysis"));
    let opt = analyze::Options {
        window,
        step,
        row,
        fit_from: fit[0],
        fit_to: fit[1],
        ..Default::default()
    };
    let mut earlier = Vec::new();
    if let Some(t) = from {
        if !path.is_dir() {
            return Err(Failure::input(
                "--from needs a run folder (it averages the run's snapshots)",
            ));
        }
        for p in analyze::input::snapshots_from(path, t)? {
            let e = analyze::input::load(&p, g)?;
            if e.step < input.step {
                earlier.push(e);
            }
        }
    }
    let a = analyze::analyze_series(input, earlier, &opt)?;
    if a.summary.averaged_snapshots > 1 {
        out!(
            "stresses averaged over {} snapshots from t = {}",
            a.summary.averaged_snapshots,
            a.summary.averaged_from_time
        );
    }
    let files = analyze::write(&a, &dir)?;
    let s = &a.summary;
    let o = &s.outline;
    out!(
        "{}: {} grains at t = {}; heap {:.4} high, {:.4} wide ({})",
        s.scene,
        s.grains,
        s.time,
        o.height,
        o.width,
        a.input.length_unit
    );
    out!(
        "angle of repose: left {}, right {}",
        s.repose_left,
        s.repose_right
    );
    let r = &s.repose_readings;
    out!(
        "  read other ways (left / right): middle third of the height {} / {}, apex to toe {} / {}, steepest stretch {} / {}",
        degrees(r.middle[0].angle_deg),
        degrees(r.middle[1].angle_deg),
        degrees(r.apex_toe[0].angle_deg),
        degrees(r.apex_toe[1].angle_deg),
        degrees(r.steepest[0].angle_deg),
        degrees(r.steepest[1].angle_deg)
    );
    out!(
        "coordination: {:.3} all, {:.3} without {} rattlers, {:.3} interior; packing fraction {:.3} (lower half)",
        s.coordination.all,
        s.coordination.without_rattlers,
        s.coordination.rattlers,
        s.coordination.interior,
        s.packing_fraction_lower_half
    );
    if let Some(j) = &s.janssen {
        out!(
            "mean stress against depth (stress_depth.csv): Janssen fit sigma_xx + sigma_zz = sigma_m (1 - exp(-x/h_s)) with sigma_m = {:.3} rho g W, h_s = {:.2} W (slabs to {:.2} W deep)",
            j.sigma_m,
            j.h_s,
            a.stress_depth.last().map_or(0.0, |p| p.0)
        );
    }
    if let Some(b) = &s.base_load {
        let (mg, sp) = (b.grain_weight, &b.spread);
        out!(
            "base load over {} base particles, in m g (bootstrap se of {} replicas): centre {:.2} ± {:.2}, side maxima {:.2} ± {:.2} (left) and {:.2} ± {:.2} (right)",
            analyze::BASE_SPAN,
            sp.bootstrap_replicas,
            b.centre / mg,
            sp.centre_se / mg,
            b.left_max / mg,
            sp.left_max_se / mg,
            b.right_max / mg,
            sp.right_max_se / mg
        );
        out!(
            "dip D = mean side maximum - centre = {:.2} ± {:.2} m g; noise on a plateau gives {:.2} ± {:.2}: z = {:.2}, p = {:.3}: {}",
            sp.dip / mg,
            sp.dip_se / mg,
            sp.dip_null / mg,
            sp.dip_null_sd / mg,
            sp.dip_z,
            sp.dip_p,
            sp.verdict
        );
    }
    out!("wrote {} files to {}", files.len(), dir.display());
    Ok(())
}

pub(super) fn cmd_render(
    path: &std::path::Path,
    out: Option<PathBuf>,
    color: talus::render::Field,
    width: u32,
    window: f64,
    g: Option<f64>,
) -> Result<(), Failure> {
    if !(16..=20_000).contains(&width) {
        return Err(Failure::input(format!(
            "--width must be between 16 and 20000 pixels, not {width}"
        )));
    }
    if !(window.is_finite() && window > 0.0) {
        return Err(Failure::input(format!(
            "--window must be a positive number of diameters, not {window}"
        )));
    }
    let dir = out.unwrap_or_else(|| beside(path, "pictures"));
    let input = talus::analyze::input::load(path, g)?;
    let opt = talus::analyze::Options {
        window,
        ..Default::default()
    };
    let a = talus::analyze::analyze(input, &opt)?;
    let mut files = talus::render::render(&a, &dir, color, width)?;
    files.extend(talus::render::vtk::write(&a, &dir)?);
    files.push(talus::render::dump::write_named(&a, &dir, "")?);
    out!("wrote {} files to {}", files.len(), dir.display());
    Ok(())
}
