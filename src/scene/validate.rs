//! Value checks on a parsed scene. Each error names the key path and the reason; the
//! contact law's own parameters are checked where its coefficients are built
//! (`ContactLaw::from_spec`).

use super::{Creation, Scene, SceneError};
use crate::law::ContactLaw;

/// A contact must last at least this many steps; beyond t_c/10 only a warning (SPEC 3).
pub const MIN_STEPS_PER_CONTACT: f64 = 5.0;
pub const RECOMMENDED_STEPS_PER_CONTACT: f64 = 10.0;

fn finite_positive(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be positive, got {v}"),
        ))
    }
}

fn finite_non_negative(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be zero or positive, got {v}"),
        ))
    }
}

fn material(scene: &Scene, path: &str, name: &str) -> Result<(), SceneError> {
    if scene.materials.contains_key(name) {
        Ok(())
    } else {
        let known: Vec<&str> = scene.materials.keys().map(|s| s.as_str()).collect();
        Err(SceneError::invalid(
            path,
            format!("unknown material `{name}` (defined: {})", known.join(", ")),
        ))
    }
}

fn inside(scene: &Scene, path: &str, p: [f64; 2]) -> Result<(), SceneError> {
    let d = &scene.domain;
    if p[0] >= d.x[0] && p[0] <= d.x[1] && p[1] >= d.z[0] && p[1] <= d.z[1] {
        Ok(())
    } else {
        Err(SceneError::invalid(
            path,
            format!("({}, {}) lies outside the domain", p[0], p[1]),
        ))
    }
}

/// Largest diameter any creation block can produce.
pub fn max_diameter(scene: &Scene) -> f64 {
    scene
        .particles
        .iter()
        .map(|c| diameter_bounds(c).1)
        .fold(0.0, f64::max)
}

fn diameter_bounds(c: &Creation) -> (f64, f64) {
    match c {
        Creation::LatticePile(p) => (
            p.diameter * (1.0 - 0.5 * p.size_disorder),
            p.diameter * (1.0 + 0.5 * p.size_disorder),
        ),
        Creation::Row(r) => (r.diameter, r.diameter),
        Creation::PointSource(s) => s.diameter.bounds(),
        Creation::List(l) => l.particles.iter().fold((f64::MAX, 0.0), |(lo, hi), p| {
            (lo.min(p.diameter), hi.max(p.diameter))
        }),
    }
}

fn material_of(c: &Creation) -> &str {
    match c {
        Creation::LatticePile(p) => &p.material,
        Creation::Row(r) => &r.material,
        Creation::PointSource(s) => &s.material,
        Creation::List(l) => &l.material,
    }
}

/// Bound on 6 γ_n dt / m_min above which a warning is given.
pub const DAMPING_STABILITY: f64 = 0.15;

/// Mass of the lightest particle the scene can create.
fn lightest_mass(scene: &Scene) -> Option<f64> {
    scene
        .particles
        .iter()
        .filter_map(|c| {
            let (d, _) = diameter_bounds(c);
            let m = scene.materials.get(material_of(c))?;
            Some(m.density * std::f64::consts::PI * 0.25 * d * d * m.thickness)
        })
        .reduce(f64::min)
}

/// The shortest contact duration t_c = π/ω0 over the particles the scene creates: the
/// lightest pair (m12 = m_min/2) with the law's stiffness (undamped, so conservative).
pub fn shortest_contact_time(scene: &Scene, law: &ContactLaw) -> Option<f64> {
    let mut best: Option<f64> = None;
    for c in &scene.particles {
        let (d, _) = diameter_bounds(c);
        let Some(m) = scene.materials.get(material_of(c)) else {
            continue;
        };
        if !(d > 0.0 && d.is_finite()) {
            continue;
        }
        let mass = m.density * std::f64::consts::PI * 0.25 * d * d * m.thickness;
        let w2 = law.omega0_squared(0.5 * mass, d);
        let tc = std::f64::consts::PI / w2.sqrt();
        best = Some(best.map_or(tc, |b: f64| b.min(tc)));
    }
    best
}

/// Checks every value; returns warnings that do not stop a run.
pub fn validate(scene: &Scene) -> Result<Vec<String>, SceneError> {
    let mut warnings = Vec::new();
    finite_positive("dt", scene.dt)?;
    finite_positive("stop.time", scene.stop.time)?;
    finite_positive("stop.check_every", scene.stop.check_every)?;
    finite_non_negative("stop.not_before", scene.stop.not_before)?;
    if let Some(f) = scene.stop.kinetic_fraction {
        finite_positive("stop.kinetic_fraction", f)?;
    }
    finite_non_negative("gravity.ramp_time", scene.gravity.ramp_time)?;
    if !scene.gravity.g.iter().all(|g| g.is_finite()) {
        return Err(SceneError::invalid("gravity.g", "must be finite"));
    }
    let d = &scene.domain;
    if !(d.x[0] < d.x[1] && d.x.iter().all(|v| v.is_finite())) {
        return Err(SceneError::invalid(
            "domain.x",
            "must be [min, max] with min < max",
        ));
    }
    if !(d.z[0] < d.z[1] && d.z.iter().all(|v| v.is_finite())) {
        return Err(SceneError::invalid(
            "domain.z",
            "must be [min, max] with min < max",
        ));
    }
    if scene.materials.is_empty() {
        return Err(SceneError::invalid(
            "materials",
            "at least one material is required",
        ));
    }
    for (name, m) in &scene.materials {
        finite_positive(&format!("materials.{name}.density"), m.density)?;
        finite_positive(&format!("materials.{name}.thickness"), m.thickness)?;
    }
    for (k, w) in scene.walls.iter().enumerate() {
        if w.from == w.to || !w.from.iter().chain(&w.to).all(|v| v.is_finite()) {
            return Err(SceneError::invalid(
                format!("walls[{k}]"),
                "a wall needs two distinct finite end points",
            ));
        }
    }
    if scene.particles.is_empty() {
        return Err(SceneError::invalid(
            "particles",
            "at least one creation block is required",
        ));
    }
    for (k, c) in scene.particles.iter().enumerate() {
        let at = |key: &str| format!("particles[{k}].{key}");
        material(scene, &at("material"), material_of(c))?;
        match c {
            Creation::LatticePile(p) => {
                if p.slope != 30.0 && p.slope != 60.0 {
                    return Err(SceneError::invalid(
                        at("slope"),
                        format!("must be 30 or 60 (degrees), got {}", p.slope),
                    ));
                }
                if p.bottom_row < 2 {
                    return Err(SceneError::invalid(
                        at("bottom_row"),
                        format!("must be at least 2, got {}", p.bottom_row),
                    ));
                }
                finite_positive(&at("diameter"), p.diameter)?;
                if !(p.spacing_c > -0.5 && p.spacing_c < 1.0) {
                    return Err(SceneError::invalid(
                        at("spacing_c"),
                        format!("must be in (-0.5, 1), got {}", p.spacing_c),
                    ));
                }
                if !(p.size_disorder >= 0.0 && p.size_disorder < 1.0) {
                    return Err(SceneError::invalid(
                        at("size_disorder"),
                        format!("must be in [0, 1), got {}", p.size_disorder),
                    ));
                }
                inside(
                    scene,
                    &at("center_x"),
                    [p.center_x, p.base_z + 0.5 * p.diameter],
                )?;
            }
            Creation::Row(r) => {
                finite_positive(&at("diameter"), r.diameter)?;
                finite_positive(&at("spacing"), r.spacing)?;
                inside(scene, &at("start"), r.start)?;
                let end = [
                    r.start[0] + r.count.saturating_sub(1) as f64 * r.spacing,
                    r.start[1],
                ];
                inside(scene, &at("count"), end)?;
            }
            Creation::PointSource(s) => {
                inside(scene, &at("position"), s.position)?;
                finite_non_negative(&at("spread"), s.spread)?;
                finite_positive(&at("rate"), s.rate)?;
                finite_non_negative(&at("start_time"), s.start_time)?;
                let (lo, hi) = s.diameter.bounds();
                if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
                    return Err(SceneError::invalid(
                        at("diameter"),
                        format!("must be positive (and lo ≤ hi for a range), got {lo}..{hi}"),
                    ));
                }
            }
            Creation::List(l) => {
                for (q, p) in l.particles.iter().enumerate() {
                    finite_positive(
                        &format!("particles[{k}].particles[{q}].diameter"),
                        p.diameter,
                    )?;
                    inside(
                        scene,
                        &format!("particles[{k}].particles[{q}].position"),
                        p.position,
                    )?;
                }
            }
        }
    }
    let o = &scene.output;
    finite_non_negative("output.snapshot_every", o.snapshot_every)?;
    if let Some(c) = o.checkpoint_every {
        finite_non_negative("output.checkpoint_every", c)?;
    }
    finite_non_negative("output.log_every", o.log_every)?;
    finite_positive("limits.max_overlap", scene.limits.max_overlap)?;

    let g = scene.gravity.g;
    let law = ContactLaw::from_spec(&scene.contact, (g[0] * g[0] + g[1] * g[1]).sqrt())?;
    if let Some(tc) = shortest_contact_time(scene, &law) {
        if scene.dt > tc / MIN_STEPS_PER_CONTACT {
            return Err(SceneError::invalid(
                "dt",
                format!(
                    "{} is too large for the stiffness: the shortest contact lasts t_c = {tc:.4e}, and dt must be at most t_c/{MIN_STEPS_PER_CONTACT} = {:.4e} (t_c/{RECOMMENDED_STEPS_PER_CONTACT} recommended)",
                    scene.dt,
                    tc / MIN_STEPS_PER_CONTACT
                ),
            ));
        }
        if let (crate::law::ContactLaw::SpringDashpot(l), Some(m)) = (&law, lightest_mass(scene)) {
            // A grain in a packing feels ~6 dashpots at once; explicit Gear goes unstable
            // (a limit cycle, then divergence) once 6 γ_n dt / m approaches 1. Measured on
            // the R1 pile: 0.25 oscillates forever, 0.08 settles.
            let ratio = 6.0 * l.gamma_n * scene.dt / m;
            if ratio > DAMPING_STABILITY {
                warnings.push(format!(
                    "6·gamma_n·dt/m = {ratio:.2} for the lightest particle exceeds {DAMPING_STABILITY}: strong damping may make the integrator oscillate or diverge; reduce dt or contact.gamma_n"
                ));
            }
        }
        if scene.dt > tc / RECOMMENDED_STEPS_PER_CONTACT {
            warnings.push(format!("dt = {} exceeds t_c/10 = {:.4e} for the stiffest contact; contacts are resolved by fewer than 10 steps", scene.dt, tc / 10.0));
        }
    }
    Ok(warnings)
}
