//! Integrators: convergence order of Gear on a harmonic oscillator, and energy
//! conservation of a whole undamped scene (SPEC 3).

mod common;
use common::*;
use serde_json::json;
use talus::integrate::gear::{CORRECTOR, CORRECTOR_POSITION_ONLY, correct_one, predict_one};
use talus::integrate::leapfrog::kick_drift_one;
use talus::state::Dof;

/// Integrates the damped oscillator x'' = −x − 2ζx' (a velocity-dependent force, like a
/// dashpot) from its exact solution x = e^(−ζt) cos(ωt), ω = sqrt(1 − ζ²), with exact
/// initial derivatives, to t = 10; returns the final position error.
fn gear_error(dt: f64, c: &[f64; 6], zeta: f64) -> f64 {
    let w = (1.0 - zeta * zeta).sqrt();
    // x = Re e^{λt} with λ = −ζ + iω: the k-th derivative at 0 is Re λ^k.
    let lambda_pow = |k: i32| {
        let (r, phi) = (1.0f64, (w).atan2(-zeta));
        r.powi(k) * (phi * k as f64).cos()
    };
    let fact = [1.0, 1.0, 2.0, 6.0, 24.0, 120.0];
    let mut q: [Dof; 6] =
        std::array::from_fn(|k| [lambda_pow(k as i32) * dt.powi(k as i32) / fact[k], 0.0, 0.0]);
    let steps = (10.0 / dt).round() as usize;
    for _ in 0..steps {
        predict_one(&mut q);
        let (x, v) = (q[0][0], q[1][0] / dt);
        correct_one(&mut q, [-x - 2.0 * zeta * v, 0.0, 0.0], dt, c);
    }
    let t = steps as f64 * dt;
    (q[0][0] - (-zeta * t).exp() * (w * t).cos()).abs()
}

fn order(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// Gear's global error shrinks as dt^p with p ≈ 5 for the six-value scheme (local error
/// O(dt^6)). Measured here (dt = 0.1 → 0.0125, t = 10): c0 = 3/16 gives p ≈ 5.1 on the
/// undamped oscillator; c0 = 3/20, our choice for velocity-dependent forces, gives
/// p ≈ 5–6 with and without damping. The bound p > 4.7 fails for any lower-order
/// scheme (leapfrog is 2, a wrong coefficient drops Gear to 2–3).
#[test]
fn gear_converges_at_fifth_order() {
    for (c, zeta) in [
        (&CORRECTOR, 0.0),
        (&CORRECTOR, 0.2),
        (&CORRECTOR_POSITION_ONLY, 0.0),
    ] {
        let errors: Vec<f64> = [0.1, 0.05, 0.025, 0.0125]
            .iter()
            .map(|&dt| gear_error(dt, c, zeta))
            .collect();
        let p = order(&errors);
        eprintln!("c0 = {}, ζ = {zeta}: errors {errors:?}, orders {p:?}", c[0]);
        for o in &p {
            assert!(*o > 4.7 && *o < 6.5, "order {o} (errors {errors:?})");
        }
    }
}

/// Leapfrog is second order.
#[test]
fn leapfrog_converges_at_second_order() {
    let err = |dt: f64| {
        // q0 = x(0), q1 = dt v(−dt/2) = dt sin(dt/2) for x = cos t.
        let (mut q0, mut q1) = ([1.0, 0.0, 0.0], [dt * (dt / 2.0).sin(), 0.0, 0.0]);
        let steps = (10.0 / dt).round() as usize;
        for _ in 0..steps {
            let a = -q0[0];
            kick_drift_one(&mut q0, &mut q1, [a, 0.0, 0.0], dt);
        }
        (q0[0] - (steps as f64 * dt).cos()).abs()
    };
    let errors: Vec<f64> = [0.04, 0.02, 0.01].iter().map(|&dt| err(dt)).collect();
    for o in order(&errors) {
        assert!((o - 2.0).abs() < 0.1, "order {o} (errors {errors:?})");
    }
}

/// The largest relative drift of the total energy of 30 disks bouncing in a box without
/// damping, sampled every `every` steps over `time`, and the contact-steps seen at the
/// samples; None for the GPU path without an adapter.
fn energy_drift(path: Path, time: f64, every: u64) -> Option<(f64, usize)> {
    let particles: Vec<serde_json::Value> = (0..30)
        .map(|k| {
            let (x, z) = ((k % 6) as f64 * 1.5 - 3.75, 1.0 + (k / 6) as f64 * 1.5);
            json!({ "position": [x, z], "diameter": 0.8 + 0.04 * (k % 5) as f64, "velocity": [((k * 7) % 5) as f64 - 2.0, ((k * 3) % 4) as f64 - 1.5] })
        })
        .collect();
    let mut v = scene_value(
        json!({ "law": "spring_dashpot", "k_n": 1.0e4 }),
        json!([{ "kind": "list", "material": "m", "particles": particles }]),
    );
    v["walls"] = json!([
        { "from": [-5.0, 0.0], "to": [5.0, 0.0] },
        { "from": [-5.0, 0.0], "to": [-5.0, 12.0] },
        { "from": [5.0, 0.0], "to": [5.0, 12.0] },
        { "from": [-5.0, 12.0], "to": [5.0, 12.0] }
    ]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    // t_c = π / sqrt(k/m12) for the lightest pair (m ≈ 0.5, m12 ≈ 0.25): ≈ 0.016.
    v["dt"] = json!(1.5e-4);
    let mut e = engine(path, "energy_drift", sim(&v))?;
    e.advance(1).unwrap();
    let total = |s: &talus::sim::Simulation| {
        let e = s.energies();
        e.kinetic() + e.elastic + e.potential
    };
    let e0 = total(e.sim().unwrap());
    let mut worst: f64 = 0.0;
    let mut contacts_seen = 0;
    for _ in 0..(time / 1.5e-4) as u64 / every {
        e.advance(every).unwrap();
        let s = e.sim().unwrap();
        contacts_seen += s.pairs.len();
        worst = worst.max((total(s) - e0).abs() / e0.abs());
    }
    Some((worst, contacts_seen))
}

/// Undamped, frictionless disks bouncing in a walled box under gravity: kinetic +
/// elastic + potential energy stays constant. Gear is not symplectic and each contact
/// onset (a kink in the force) costs a little: measured drift 2.1e-4 at dt = t_c/60 and
/// 2–5e-5 at t_c/120 over 20 time units (thousands of contact-steps). The collisions are
/// chaotic, so the drift is a property of the trajectory: moving one disk by 1e-13 gave
/// 2.9e-5 to 5.3e-5 (measured). Bound: 1e-4 at dt = t_c/120, twice the largest seen.
/// On both paths: the CPU path sampled at every step over 20 time units, the GPU path
/// (a readback per sample) every 20 steps over 4 (measured on lavapipe: 1.7e-5).
#[test]
fn energy_is_conserved_without_damping() {
    for (path, time, every) in [(Path::Cpu, 20.0, 1), (Path::Gpu, 4.0, 20)] {
        let Some((worst, contacts_seen)) = energy_drift(path, time, every) else {
            continue;
        };
        assert!(
            contacts_seen * every as usize > 1000,
            "{path:?}: the particles must collide ({contacts_seen} contact-steps sampled)"
        );
        eprintln!("{path:?}: relative energy drift {worst}");
        assert!(worst < 1e-4, "{path:?}: relative energy drift {worst}");
    }
}

/// A straight column of disks on a floor, created at its exact equilibrium (contact k
/// from the bottom carries the 6 − k disks above it: overlap (6 − k) m g / k_n), stays
/// there: Gear is seeded with the initial forces, (F/m + g) dt²/2, not g dt²/2 alone,
/// which would kick the column by g dt²/2 and set it ringing (1 % of the top overlap
/// here, decaying over seconds).
#[test]
fn a_column_created_at_equilibrium_stays_there() {
    let (n, k_n) = (6, 1.0e5);
    let mut list = Vec::new();
    let mut z = 0.5 - n as f64 / k_n;
    for k in 0..n {
        list.push(json!({ "position": [0.0, z], "diameter": 1.0 }));
        z += 1.0 - (n - k - 1) as f64 / k_n;
    }
    let mut v = scene_value(
        json!({ "law": "spring_dashpot", "k_n": k_n, "gamma_n": 5.0, "k_t": 0.0, "gamma_t": 0.0, "mu": 0.0 }),
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    v["dt"] = json!(5e-4);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-1.0, 0.0], "to": [1.0, 0.0] }]);
    // The GPU path reads overlaps from f32 offsets of positions held in fixed point
    // (issue 14): measured on lavapipe 2.5e-8 (the CPU path 1.4e-10); bounds 4-70x above.
    for (path, bound) in [(Path::Cpu, 1e-8), (Path::Gpu, 1e-7)] {
        let test = "a_column_created_at_equilibrium_stays_there";
        let Some(mut e) = engine(path, test, sim(&v)) else {
            continue;
        };
        let mut worst: f64 = 0.0;
        for _ in 0..2000 {
            e.advance(1).unwrap();
            let s = e.sim().unwrap();
            assert_eq!(s.pairs.len(), n, "{path:?}");
            for (p, c) in s.pairs.iter().zip(&s.contacts) {
                let above = if p.is_wall() { n } else { n - p.i as usize - 1 };
                let exact = above as f64 / k_n;
                worst = worst.max((c.overlap - exact).abs() / exact);
            }
        }
        eprintln!("{path:?}: overlaps left the equilibrium by {worst:.2e}");
        assert!(
            worst < bound,
            "{path:?}: overlaps left the equilibrium by {worst:.2e}"
        );
    }
}

/// A grain in free fall for 2·10⁴ steps has v = g t and z = z0 − g t²/2 on both paths, to
/// 1e-6.
/// Gear adds the same small increment 2 q2 to q1 = v dt at every step; the GPU path keeps
/// q1 in whole position units plus an f32 rest (issue 14 item 5), so the sum is exact
/// and only the increment rounds. (With q1 in f32 alone the velocity drifted by ~6e-5
/// over such a fall.)
#[test]
fn free_fall_keeps_its_velocity_exact_on_both_paths() {
    for path in PATHS {
        let mut v = scene_value(
            json!({ "law": "spring_dashpot", "k_n": 1.0e4 }),
            json!([{ "kind": "list", "material": "m", "particles": [
                { "position": [0.0, 50.0], "diameter": 1.0 }
            ]}]),
        );
        v["gravity"] = json!({ "g": [0.0, -1.0] });
        v["dt"] = json!(1e-4);
        let Some(mut e) = engine(path, "free_fall", sim(&v)) else {
            continue;
        };
        let steps = 20_000;
        e.advance(steps).unwrap();
        let s = e.sim().unwrap();
        let t = steps as f64 * 1e-4;
        let vz = s.particles.velocity(0, s.dt())[1];
        let z = s.particles.position(0)[1];
        assert!(
            (vz / -t - 1.0).abs() < 1e-6,
            "{path:?}: v = {vz} against −g t = {}",
            -t
        );
        // f32 holds g dt²/2 (q2) to 6e-8 of itself: as much of the fall, 1.2e-7 d here.
        assert!(
            (z - (50.0 - 0.5 * t * t)).abs() < 1e-6 * 0.5 * t * t,
            "{path:?}: z = {z} against {}",
            50.0 - 0.5 * t * t
        );
    }
}
