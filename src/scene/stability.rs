//! Whether the time step resolves the scene's contacts: the shortest contact time
//! (an error when dt exceeds t_c/5), and the warnings where an integrator is known to
//! go unstable with the scene's damping (measured bounds, each with its runs).

use super::sizes::{material_of, max_diameter, size_bounds, smallest_area};
use super::{Creation, Scene, SceneError};
use crate::law::ContactLaw;

/// A contact must last at least this many steps; beyond t_c/10 only a warning (SPEC 3).
pub const MIN_STEPS_PER_CONTACT: f64 = 5.0;
pub const RECOMMENDED_STEPS_PER_CONTACT: f64 = 10.0;

/// The time-step checks of a valid scene with its law: Err when dt is too large for the
/// stiffest contact, else the warnings.
pub(super) fn time_step(scene: &Scene, law: &ContactLaw) -> Result<Vec<String>, SceneError> {
    let mut warnings = Vec::new();
    if let Some(tc) = shortest_contact_time(scene, law) {
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
        if let (crate::law::ContactLaw::SpringDashpot(l), Some(m)) = (law, lightest_mass(scene)) {
            // A grain in a packing feels ~6 dashpots at once; explicit Gear goes unstable
            // (a limit cycle, then divergence) once 6 γ_n dt / m approaches 1. Measured on
            // the R1 pile: 0.25 oscillates forever, 0.08 settles.
            // In the material form γ_n = m_eff · (γ_n/m) with m_eff ≤ m: the bound is
            // 6 (γ_n/m) dt, the largest over the pairs.
            let (ratio, what, fix) = match &l.pairs {
                None => (
                    6.0 * l.gamma_n * scene.dt / m,
                    "6·gamma_n·dt/m",
                    "contact.gamma_n",
                ),
                Some(t) => (
                    6.0 * t.coeffs.iter().map(|c| c.gamma_n).fold(0.0, f64::max) * scene.dt,
                    "6·(gamma_n/m_eff)·dt",
                    "raise contact.restitution or contact.contact_time",
                ),
            };
            if ratio > DAMPING_STABILITY {
                warnings.push(format!(
                "{what} = {ratio:.2} for the lightest particle exceeds {DAMPING_STABILITY}: strong damping may make the integrator oscillate or diverge; reduce dt or {fix}"
            ));
            }
        }
        if let (
            crate::law::ContactLaw::OverlapArea(l),
            Some(m),
            crate::scene::IntegratorKind::Gear5,
        ) = (law, lightest_mass(scene), scene.integrator)
        {
            // The same bound for the overlap-area law, whose damping γ^n = η^n sqrt(m12 k^n)
            // acts through L/l ≈ FACE_STIFFNESS and also turns the grains. Measured on the
            // R8 pile with Gear (μ = 0, η^n = 1): 0.8 and 0.4 pump the kinetic energy up to
            // the elastic energy, 0.1 settles; leapfrog settles at 0.4.
            // In the material form k^n = m_eff (k^n/m) per pair: the largest γ^n/m over the
            // pairs, at m12 = m/2 as above.
            let gamma_over_m = match &l.pairs {
                None => l.eta_n * (0.5 * m * l.k_n).sqrt() / m,
                Some(t) => (t.coeffs.iter())
                    .map(|c| c.gamma_n * 0.5 * c.k_n.sqrt())
                    .fold(0.0, f64::max),
            };
            let gamma = gamma_over_m * m * crate::law::overlap_area::FACE_STIFFNESS;
            let ratio = 6.0 * gamma * scene.dt / m;
            if ratio > DAMPING_STABILITY {
                warnings.push(format!(
                "6·gamma_n·(L/l)·dt/m = {ratio:.2} for the lightest polygon exceeds {DAMPING_STABILITY}: Gear's predictor-corrector pumps energy into damped polygon contacts at this step (a steady vibration instead of a settled pile); use \"integrator\": \"leapfrog\" or dt ≤ {:.3e}",
                scene.dt * DAMPING_STABILITY / ratio
            ));
            }
        }
        if let (crate::law::ContactLaw::HertzCohesive(l), crate::scene::IntegratorKind::Gear5) =
            (law, scene.integrator)
        {
            // Rods: γ^N is a rate (times m12). Measured on the reduced R9 pile (k^N = 10⁷,
            // γ^N = 300): Gear at 6 γ^N dt = 0.36 pumped energy in until rods flew out of
            // the box; 0.09 stayed put, and so did leapfrog at 0.36.
            let ratio = 6.0 * l.gamma_n * scene.dt;
            if ratio > DAMPING_STABILITY {
                warnings.push(format!(
                "6·gamma_n·dt = {ratio:.2} exceeds {DAMPING_STABILITY}: Gear's predictor-corrector pumps energy into damped rod contacts at this step; use \"integrator\": \"leapfrog\" or dt ≤ {:.3e}",
                scene.dt * DAMPING_STABILITY / ratio
            ));
            }
        }
        if let Some(w) = rolling_spring_check(scene, law)? {
            warnings.push(w);
        }
        if let Some(w) = impact_warning(scene, law) {
            warnings.push(w);
        }
        if let Some(w) = gpu_resolution_warning(scene, law) {
            warnings.push(w);
        }
        if scene.dt > tc / RECOMMENDED_STEPS_PER_CONTACT {
            warnings.push(format!("dt = {} exceeds t_c/10 = {:.4e} for the stiffest contact; contacts are resolved by fewer than 10 steps", scene.dt, tc / 10.0));
        }
    }
    Ok(warnings)
}

/// The rolling spring (src/law/rolling.rs, model `spring_dashpot`) must be resolved like
/// a contact: the spin of the lightest disk (I = m R²/2) against a wall oscillates at
/// ω² = k_r/I = 2 k_roll/m, half a period of which must last MIN_STEPS_PER_CONTACT
/// steps (an error naming `rolling.stiffness`); and its dashpot, C_r/I = 4 η_r
/// sqrt(1.5 k_roll/m) there, six at once, is held to `ROLLING_DAMPING_STABILITY` (a
/// warning). Each pair of `rolling.pairs` is held to it on its own, named by its key.
fn rolling_spring_check(scene: &Scene, law: &ContactLaw) -> Result<Option<String>, SceneError> {
    let (Some(spec), Some(m)) = (&scene.rolling, lightest_mass(scene)) else {
        return Ok(None);
    };
    let mut worst: Option<(f64, String)> = None;
    for (at, entry) in spec.entries() {
        let Some(r) = crate::law::rolling::Rolling::of(Some(&entry), law.linear_k_n()) else {
            continue;
        };
        if !r.has_spring() {
            continue;
        }
        let t_r = std::f64::consts::PI / (2.0 * r.k_roll / m).sqrt();
        if scene.dt > t_r / MIN_STEPS_PER_CONTACT {
            return Err(SceneError::invalid(
                format!("{at}.stiffness"),
                format!(
                    "{:.4e} is too stiff for dt = {}: the lightest disk's spin against a wall oscillates with half-period {t_r:.4e}, and dt must be at most a {MIN_STEPS_PER_CONTACT}th of it",
                    r.k_roll, scene.dt
                ),
            ));
        }
        let ratio = 6.0 * 4.0 * r.eta_r * (1.5 * r.k_roll / m).sqrt() * scene.dt;
        if ratio > ROLLING_DAMPING_STABILITY && worst.as_ref().is_none_or(|w| ratio > w.0) {
            worst = Some((ratio, at));
        }
    }
    Ok(worst.map(|(ratio, at)| {
        format!(
            "6·C_r·dt/I = {ratio:.2} for the lightest disk ({at}) exceeds {ROLLING_DAMPING_STABILITY}: Gear's predictor-corrector pumps energy into the rolling dashpots at this step (a heap that slumps); reduce dt, {at}.damping or {at}.stiffness"
        )
    }))
}

/// Bound on 6 C_r dt / I (`rolling_spring_check`) above which a warning is given.
/// Measured on the 300-disk heap of tests/rolling.rs (Gear, μ_r = 0.4, four seeds):
/// at 0.21 and 0.34 the heaps stand at 24°–25°, at 0.62 at 18°, at 1.07 at 14°, below
/// the 15.5° of the same heap without rolling resistance.
pub const ROLLING_DAMPING_STABILITY: f64 = 0.4;

/// Bound on 6 γ_n dt / m_min above which a warning is given.
pub const DAMPING_STABILITY: f64 = 0.15;

/// Mass of the lightest particle the scene can create.
fn lightest_mass(scene: &Scene) -> Option<f64> {
    scene
        .particles
        .iter()
        .filter_map(|c| {
            let m = scene.materials.get(material_of(c))?;
            Some(m.density * smallest_area(c) * m.thickness)
        })
        .reduce(f64::min)
}

/// How finely the GPU path resolves an overlap, in position units (cell/2³⁰): a disk's
/// overlap is exact to about a unit; a polygon face contact's A/l carries the difference
/// of the device's corners (whole units, turned by Q31 sin and cos) from the exact
/// shapes, measured up to 1.4 units (tests/gpu_precision.rs, README "Precision").
pub const GPU_RESOLUTION_DISKS: f64 = 1.0;
pub const GPU_RESOLUTION_POLYGONS: f64 = 1.5;

/// A warning when resting contacts would be shallower than the GPU path resolves to
/// 1e-3 (issue 19): the lightest particle resting on one contact overlaps by m g / k^n
/// (δ0 (m g/(k^n δ0))^(1/ν) for ν ≠ 1; the continuous laws rest at a separation, not
/// an overlap, and are not checked).
fn gpu_resolution_warning(scene: &Scene, law: &ContactLaw) -> Option<String> {
    let g = scene.gravity.g[0].hypot(scene.gravity.g[1]);
    let m = lightest_mass(scene)?;
    let weight = m * g;
    // The material form's stiffness of that particle on a fixed partner: m (k^n/m), the
    // stiffest pair's.
    let k_n = |k_abs: f64| match law.pair_table() {
        Some(t) => m * t.coeffs.iter().map(|c| c.k_n).fold(0.0, f64::max),
        None => k_abs,
    };
    let (overlap, resolution) = match law {
        ContactLaw::OverlapArea(l) => (weight / k_n(l.k_n), GPU_RESOLUTION_POLYGONS),
        ContactLaw::SpringDashpot(l) => (
            l.delta0 * (weight / (k_n(l.k_n) * l.delta0)).powf(1.0 / l.nu),
            GPU_RESOLUTION_DISKS,
        ),
        ContactLaw::Continuous(_) | ContactLaw::HertzCohesive(_) => return None,
    };
    let unit = law.range_factor() * max_diameter(scene) / (1u64 << 30) as f64;
    let limit = 1e3 * resolution * unit;
    if overlap.is_nan() || overlap <= 0.0 || overlap >= limit {
        return None;
    }
    Some(format!(
        "resting contacts overlap by about {overlap:.2e} (m g/k_n for the lightest particle); the GPU path resolves overlaps to about {:.1e} (whole position units of cell/2^30{}), so its contact forces are right to 1e-3 only from overlaps of {limit:.1e} up and may be off by ~{:.0e} here (docs/GUIDE.md, \"Precision\"); the CPU path (f64) has no such limit",
        resolution * unit,
        if matches!(law, ContactLaw::OverlapArea(_)) {
            ", polygon corners"
        } else {
            ""
        },
        resolution * unit / overlap
    ))
}

/// The shortest contact duration t_c = π/ω0 over the particles the scene creates: the
/// lightest pair (m12 = m_min/2) with the law's stiffness (undamped, so conservative).
pub fn shortest_contact_time(scene: &Scene, law: &ContactLaw) -> Option<f64> {
    let mut best: Option<f64> = None;
    for c in &scene.particles {
        let (d, _) = size_bounds(c);
        let Some(m) = scene.materials.get(material_of(c)) else {
            continue;
        };
        if !(d > 0.0 && d.is_finite()) {
            continue;
        }
        let mass = m.density * smallest_area(c) * m.thickness;
        let w2 = law.omega0_squared(0.5 * mass, d);
        let tc = std::f64::consts::PI / w2.sqrt();
        best = Some(best.map_or(tc, |b: f64| b.min(tc)));
    }
    best
}

/// The largest C_N dt / m12 under Gear at which poured grains of the unclamped
/// continuous law still settle. Measured on paper 001's pour (n = 36, r0 = 1.2σ,
/// dt = 0.001, issue 39): from 30σ (0.34 at the fastest impact) 8 seeds of 8 settled;
/// from 100σ (0.64) 7 of 8 diverged within t = 27–87 (leapfrog: see docs/REPRODUCTION.md).
pub const IMPACT_DAMPING_STABILITY: f64 = 0.45;

/// Gear with the continuous law unclamped (paper 001 eq. 3): a grain from a point
/// source lands at sqrt(v0² + 2 g h) (h: from the source down to the domain's floor),
/// and at its closest approach the damping C_N = ζ 2 sqrt(m k(r)) is hundreds of times
/// the resting one; Gear's predictor-corrector then amplifies it (the clamp happened
/// to stop that). Leapfrog, the paper's integrator (eq. 9–12), takes it.
fn impact_warning(scene: &Scene, law: &ContactLaw) -> Option<String> {
    let ContactLaw::Continuous(l) = law else {
        return None;
    };
    if l.reading.clamp || scene.integrator != crate::scene::IntegratorKind::Gear5 {
        return None;
    }
    let g = scene.gravity.g[0].hypot(scene.gravity.g[1]);
    let (k, rate) = (scene.particles.iter().enumerate())
        .filter_map(|(k, c)| match c {
            Creation::PointSource(p) => {
                let h = (p.position[1] - scene.domain.z[0]).max(0.0);
                let v0 = p.velocity[0].hypot(p.velocity[1]) + p.velocity_spread;
                let v = (v0 * v0 + 2.0 * g * h).sqrt();
                let (d, _) = size_bounds(c);
                Some((k, l.impact_damping_rate(d, v)))
            }
            _ => None,
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let ratio = rate * scene.dt;
    (ratio > IMPACT_DAMPING_STABILITY).then(|| {
        format!(
            "particles[{k}]: its grains land with a normal damping C_N dt/m12 = {ratio:.2} at their closest approach (continuous law, unclamped, paper 001 eq. 3), above {IMPACT_DAMPING_STABILITY}, where Gear diverged on paper 001's pour; use \"integrator\": \"leapfrog\" (the paper's) or dt ≤ {:.1e}",
            scene.dt * IMPACT_DAMPING_STABILITY / ratio
        )
    })
}
