//! Contact laws against analytic two-particle collisions (paper 000 sec. 2.1, SPEC 2.1),
//! the collisions on both paths (the GPU path in f32 to the same bounds).

mod common;
use common::*;
use serde_json::json;

/// m1 = m2 = 1 → m12 = 1/2.
const M12: f64 = 0.5;

/// Paper 000 sec. 2.1: t_c = π/ω, r = exp(−η t_c), ω = sqrt(ω0² − η²), ω0² = k/m12,
/// η = γ/(2 m12). Valid for the unclamped linear law (the damping may pull at the end).
#[test]
fn linear_spring_dashpot_contact_time_and_restitution() {
    let k = 1.0e4;
    for (path, eta_over_omega0) in PATHS
        .into_iter()
        .flat_map(|p| [0.0, 0.05, 0.2, 0.4, 0.6].map(|x| (p, x)))
    {
        let omega0 = (k / M12).sqrt();
        let eta = eta_over_omega0 * omega0;
        let gamma = 2.0 * M12 * eta;
        let omega = (omega0 * omega0 - eta * eta).sqrt();
        let tc = std::f64::consts::PI / omega;
        let r = (-eta * tc).exp();
        let law = json!({ "law": "spring_dashpot", "k_n": k, "gamma_n": gamma, "clamp": false });
        let Some((t, e)) = head_on_on(path, law, 1.0, tc / 400.0, "gear5") else {
            continue;
        };
        assert!(
            (t / tc - 1.0).abs() < 1e-3,
            "{path:?}, η/ω0 = {eta_over_omega0}: t_c {t} vs {tc}"
        );
        assert!(
            (e / r - 1.0).abs() < 1e-3,
            "{path:?}, η/ω0 = {eta_over_omega0}: r {e} vs {r}"
        );
    }
}

/// With the SPEC 2 clamp f_n ≥ 0 the force vanishes at the time t* where k δ + γ δ̇ = 0,
/// tan(ω t*) = −2ηω/(ω0² − 2η²); afterwards the disks fly apart at δ̇(t*). So
/// r* = e^(−η t*) |cos ω t* − (η/ω) sin ω t*| (from δ = (v0/ω) e^(−ηt) sin ωt).
#[test]
fn clamped_spring_dashpot_restitution_matches_its_own_analytic_value() {
    let k = 1.0e4;
    let omega0 = (k / M12).sqrt();
    for (path, eta_over_omega0) in PATHS
        .into_iter()
        .flat_map(|p| [0.1, 0.3, 0.5].map(|x| (p, x)))
    {
        let eta = eta_over_omega0 * omega0;
        let omega = (omega0 * omega0 - eta * eta).sqrt();
        let wt =
            std::f64::consts::PI - (2.0 * eta * omega / (omega0 * omega0 - 2.0 * eta * eta)).atan();
        let t_star = wt / omega;
        let r_star = (-eta * t_star).exp() * (wt.cos() - eta / omega * wt.sin()).abs();
        let r_unclamped = (-eta * std::f64::consts::PI / omega).exp();
        let law = json!({ "law": "spring_dashpot", "k_n": k, "gamma_n": 2.0 * M12 * eta });
        // The force has a kink at t*, which costs Gear its high order there: finer dt.
        let Some((_, e)) = head_on_on(path, law, 1.0, t_star / 4000.0, "gear5") else {
            continue;
        };
        assert!(
            (e / r_star - 1.0).abs() < 1e-3,
            "{path:?}, η/ω0 = {eta_over_omega0}: r {e} vs {r_star}"
        );
        assert!(
            e > r_unclamped,
            "the clamp removes the attractive pull, so less energy is lost"
        );
    }
}

/// Issue 20: the material form (`restitution` e and `contact_time` t_c instead of k_n and
/// γ_n, src/law/restitution.rs) gives the e and t_c asked for in a head-on collision, to
/// 1e-3, whoever collides: two equal moving disks, a disk on a fixed disk (counted as
/// infinitely heavy), and a light disk on a heavy one of another material whose pair has
/// its own e and t_c. With and without the clamp f_n ≥ 0, on both paths.
#[test]
fn material_form_round_trips_restitution_and_contact_time() {
    let (e, t_c) = (0.6, 0.02);
    let (e_pair, t_pair) = (0.85, 0.03);
    for path in PATHS {
        for clamp in [true, false] {
            let law = json!({ "law": "spring_dashpot", "restitution": e, "contact_time": t_c,
                              "clamp": clamp, "mu": 0.5,
                              "pairs": [{ "materials": ["m", "heavy"],
                                          "restitution": e_pair, "contact_time": t_pair }] });
            let cases = [
                ("two moving disks", false, 1.0, e, t_c),
                ("a fixed partner", true, 1.0, e, t_c),
                (
                    "a heavy disk of another material",
                    false,
                    2.0,
                    e_pair,
                    t_pair,
                ),
            ];
            for (case, fixed, d1, e_want, t_want) in cases {
                let (r0, r1) = (0.5, 0.5 * d1);
                let mut v = scene_value(
                    law.clone(),
                    json!([
                        { "kind": "list", "material": "m", "particles": [
                            { "position": [-r0 - 0.001, 0.0], "diameter": 1.0, "velocity": [1.0, 0.0] }]},
                        { "kind": "list", "material": if d1 == 1.0 { "m" } else { "heavy" }, "particles": [
                            { "position": [r1 + 0.001, 0.0], "diameter": d1, "fixed": fixed }]}
                    ]),
                );
                v["materials"]["heavy"] = json!({ "density": 3.0 });
                // The damping's jump of the force at first touch (and the clamp's kink)
                // cost Gear its high order: e is off by ~2e-3 at t_c/400 depending on
                // where in a step the touch falls, ~1e-4 at t_c/4000.
                v["dt"] = json!(t_want / 4000.0);
                let Some((t, got)) = head_on_scene(path, &v, 1.0, r0 + r1) else {
                    continue;
                };
                assert!(
                    (t / t_want - 1.0).abs() < 1e-3,
                    "{path:?}, clamp {clamp}, {case}: t_c {t} vs {t_want}"
                );
                assert!(
                    (got / e_want - 1.0).abs() < 1e-3,
                    "{path:?}, clamp {clamp}, {case}: e {got} vs {e_want}"
                );
            }
        }
    }
}

/// Issue 20: a nonlinear law (Hertz, ν = 3/2, with ψ = 1/2 damping) in the material form
/// gives the e and t_c asked for at its `impact_speed`, to 1e-3, on a moving and on a
/// fixed partner, both paths; at twice the speed it gives what the same solver predicts
/// there (src/law/restitution.rs `collision_power`), which differs from the values asked.
#[test]
fn material_form_of_a_nonlinear_law_holds_at_its_impact_speed() {
    let (e, t_c, v) = (0.6, 0.02, 1.0);
    let shape = (1.5, 0.5, 0.01);
    let (kappa, c) = talus::law::restitution::per_mass_power(e, t_c, v, shape, true).unwrap();
    let (e2, t2) =
        talus::law::restitution::collision_power(kappa, c, 2.0 * v, shape, true).unwrap();
    assert!(
        (e2 / e - 1.0).abs() > 1e-2 && (t2 / t_c - 1.0).abs() > 1e-2,
        "{e2} {t2}"
    );
    for path in PATHS {
        for (fixed, speed, e_want, t_want) in [
            (false, v, e, t_c),
            (true, v, e, t_c),
            (false, 2.0 * v, e2, t2),
        ] {
            let law = json!({ "law": "spring_dashpot", "restitution": e, "contact_time": t_c,
                              "nu": 1.5, "psi": 0.5, "delta0": 0.01, "impact_speed": v });
            let mut v = scene_value(
                law,
                json!([{ "kind": "list", "material": "m", "particles": [
                    { "position": [-0.501, 0.0], "diameter": 1.0, "velocity": [speed, 0.0] },
                    { "position": [0.501, 0.0], "diameter": 1.0, "fixed": fixed }]}]),
            );
            v["dt"] = json!(t_c / 4000.0);
            let Some((t, got)) = head_on_scene(path, &v, speed, 1.0) else {
                continue;
            };
            let case = format!("{path:?}, fixed {fixed}, speed {speed}");
            assert!(
                (t / t_want - 1.0).abs() < 1e-3,
                "{case}: t_c {t} vs {t_want}"
            );
            assert!(
                (got / e_want - 1.0).abs() < 1e-3,
                "{case}: e {got} vs {e_want}"
            );
        }
    }
}

/// Issue 20: the overlap-area law's material form is calibrated on a face-to-face
/// collision (src/law/overlap_area.rs): two hexagons meeting face to face, moving or
/// one fixed, give the e and t_c asked for to 5e-3 (measured: t_c 3.0e-3 short, e 1.4e-3
/// low, the same on both paths: the force point moves in by half the penetration, so L/l
/// stiffens by up to p/2a ≈ 0.4 % during the contact).
#[test]
fn material_form_of_polygons_is_exact_face_to_face() {
    let (e, t_c) = (0.5, 0.02);
    let a = 0.5 * (std::f64::consts::PI / 6.0).cos(); // inradius of a hexagon of diameter 1
    for path in PATHS {
        for fixed in [false, true] {
            let law =
                json!({ "law": "overlap_area", "restitution": e, "contact_time": t_c, "mu": 0.5 });
            // A face along ±x: the corners at 30° + 60° k.
            let theta = std::f64::consts::PI / 6.0;
            let mut v = scene_value(
                law,
                json!([
                    { "kind": "list", "material": "m", "polygon": { "corners": 6 }, "particles": [
                        { "position": [-a - 0.001, 0.0], "diameter": 1.0, "theta": theta, "velocity": [1.0, 0.0] },
                        { "position": [a + 0.001, 0.0], "diameter": 1.0, "theta": theta, "fixed": fixed }]}
                ]),
            );
            v["dt"] = json!(t_c / 4000.0);
            let Some((t, got)) = head_on_scene(path, &v, 1.0, 2.0 * a) else {
                continue;
            };
            assert!(
                (t / t_c - 1.0).abs() < 5e-3,
                "{path:?}, fixed {fixed}: t_c {t} vs {t_c}"
            );
            assert!(
                (got / e - 1.0).abs() < 5e-3,
                "{path:?}, fixed {fixed}: e {got} vs {e}"
            );
        }
    }
}

/// Hertz, F = k' δ^(3/2) with k' = k_n δ0^(−1/2) (paper 000 eq. 2 with ν = 3/2), no damping:
/// δ_max = (5 m12 v0² / (4 k'))^(2/5) and t_c = 2 (δ_max/v0) ∫0^1 (1 − u^(5/2))^(−1/2) du,
/// the integral being √π Γ(7/5)/Γ(9/10).
#[test]
fn hertz_contact_time() {
    let (k_n, delta0): (f64, f64) = (1.0e4, 0.01);
    let integral = std::f64::consts::PI.sqrt() * 0.887_263_817_503_075 / 1.068_628_702_119_319;
    for (path, v0) in PATHS
        .into_iter()
        .flat_map(|p| [0.5, 1.0, 2.0].map(|x| (p, x)))
    {
        let k = k_n / delta0.sqrt();
        let delta_max = (5.0 * M12 * v0 * v0 / (4.0 * k)).powf(0.4);
        let tc = 2.0 * delta_max / v0 * integral;
        let law = json!({ "law": "spring_dashpot", "k_n": k_n, "nu": 1.5, "delta0": delta0 });
        let Some((t, e)) = head_on_on(path, law, v0, tc / 1000.0, "gear5") else {
            continue;
        };
        assert!(
            (t / tc - 1.0).abs() < 1e-3,
            "{path:?}, v0 = {v0}: t_c {t} vs {tc}"
        );
        assert!(
            (e - 1.0).abs() < 1e-3,
            "{path:?}: elastic collision, r = {e}"
        );
    }
}

/// Leapfrog on the same linear collision: second order, so a looser 1e-2 bound.
#[test]
fn leapfrog_linear_collision() {
    let k = 1.0e4;
    let omega0 = (k / M12).sqrt();
    let tc = std::f64::consts::PI / omega0;
    let law = json!({ "law": "spring_dashpot", "k_n": k, "clamp": false });
    for path in PATHS {
        let Some((t, e)) = head_on_on(path, law.clone(), 1.0, tc / 400.0, "leapfrog") else {
            continue;
        };
        assert!((t / tc - 1.0).abs() < 1e-2, "{path:?}: t_c {t} vs {tc}");
        assert!((e - 1.0).abs() < 1e-2, "{path:?}: r = {e}");
    }
}

/// Paper 001: a disk resting on an equal fixed disk under gravity sits at r = σ, where
/// F_e = m g, for n = 36 and r0 = 1.2σ; both integrators.
#[test]
fn continuous_law_rests_at_one_diameter() {
    let runs = PATHS
        .into_iter()
        .flat_map(|p| [(p, "gear5"), (p, "leapfrog")]);
    for (path, integrator) in runs {
        let mut v = scene_value(
            json!({ "law": "continuous", "n": 36, "r0": 1.2, "mu": 0.5 }),
            json!([{ "kind": "list", "material": "m", "particles": [
                { "position": [0.0, 0.0], "diameter": 1.0, "fixed": true },
                { "position": [0.0, 1.05], "diameter": 1.0 }
            ]}]),
        );
        v["gravity"] = json!({ "g": [0.0, -1.0] });
        v["dt"] = json!(1e-3);
        v["integrator"] = json!(integrator);
        let Some(mut e) = engine(path, "continuous_law_rests_at_one_diameter", sim(&v)) else {
            continue;
        };
        e.advance(40_000).unwrap();
        let r = distance(e.sim().unwrap(), 0, 1);
        assert!(
            (r - 1.0).abs() < 1e-6,
            "{path:?} {integrator}: rest separation {r}"
        );
    }
}

/// Equivalent Hooke law (paper 001 eq. 14): a resting pair compresses to σ − 1/k.
#[test]
fn equivalent_hooke_law_rests_at_its_overlap() {
    let mut v = scene_value(
        json!({ "law": "hooke_equivalent", "n": 36, "r0": 1.2, "r_i": 0.915 }),
        json!([{ "kind": "list", "material": "m", "particles": [
            { "position": [0.0, 0.0], "diameter": 1.0, "fixed": true },
            { "position": [0.0, 1.0], "diameter": 1.0 }
        ]}]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(1e-3);
    let k = talus::law::continuous::equivalent_hooke_constant(36.0, 1.2, 0.915);
    for path in PATHS {
        let Some(mut e) = engine(path, "equivalent_hooke_law_rests_at_its_overlap", sim(&v)) else {
            continue;
        };
        e.advance(40_000).unwrap();
        let r = distance(e.sim().unwrap(), 0, 1);
        assert!(
            (1.0 - r - 1.0 / k).abs() < 1e-6 / k * 1e3,
            "{path:?}: overlap {} vs {}",
            1.0 - r,
            1.0 / k
        );
    }
}

/// Total energy (kinetic with spin + elastic with the tangential spring + potential) of a
/// disk rocking undamped in the pocket of two fixed disks 1.1σ apart (R4's base) under
/// paper 001's law, set spinning: the largest excursion from the start over 20 time
/// units (5 on the GPU path), relative to the energy put in, and how far the disk's
/// spin went.
fn pocket_energy_excursion(path: Path, reading: serde_json::Value) -> Option<(f64, f64)> {
    let mut law = json!({ "law": "continuous", "n": 36, "r0": 1.2, "mu": 0.5,
                          "damping_fraction": 0.0 });
    for (k, v) in reading.as_object().unwrap() {
        law[k] = v.clone();
    }
    // At rest in the pocket: 2 F_e(r) z/r = m g with F_e = m g (σ/r)^37, z = sqrt(r² − 0.55²).
    let weight_carried = |r: f64| 2.0 * r.powi(-37) * (r * r - 0.3025).sqrt() / r - 1.0;
    let (mut lo, mut hi) = (1.0, 1.2);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if weight_carried(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let z = (lo * lo - 0.3025f64).sqrt();
    let mut v = scene_value(
        law,
        json!([{ "kind": "list", "material": "m", "particles": [
            { "position": [-0.55, 0.0], "diameter": 1.0, "fixed": true },
            { "position": [0.55, 0.0], "diameter": 1.0, "fixed": true },
            { "position": [0.0, z], "diameter": 1.0, "velocity": [0.005, 0.0], "omega": 0.02 }
        ]}]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(1e-4);
    v["integrator"] = json!("leapfrog");
    let mut e = engine(path, "pocket_energy", sim(&v))?;
    e.advance(1).unwrap();
    let total = |s: &talus::sim::Simulation| {
        let e = s.energies();
        e.kinetic() + e.elastic + e.potential
    };
    let s = e.sim().unwrap();
    let (e0, k0) = (total(s), s.energies().kinetic());
    let (mut worst, mut spin): (f64, f64) = (0.0, 0.0);
    // The GPU path (a readback per sample) over 5 time units, sampled every 1000 steps.
    let (samples, every) = if path == Path::Cpu {
        (1000, 200)
    } else {
        (50, 1000)
    };
    for _ in 0..samples {
        e.advance(every).unwrap();
        let s = e.sim().unwrap();
        worst = worst.max((total(s) - e0).abs() / k0);
        spin = spin.max(s.particles.velocity(2, 1e-4)[2].abs());
    }
    Some((worst, spin))
}

/// Paper 001 eq. 6 turns the spins through the centre distance r_ij and eq. 13 applies
/// the tangential force's torque on the same lever, so the tapered spring's work equals
/// what δ_F stores: undamped, a disk set rocking and spinning in a pocket keeps its
/// energy (measured on the CPU path: 6.3e-4 of the energy put in over 20 time units,
/// leapfrog at dt = 1e-4, no sliding). Torques on the contact point's arms with eq. 6's
/// lever (talus from stop 49 to 52) leak or pump (r/2) f_t (θ̇_i + θ̇_j): the same disk's
/// energy moved by 0.67 of what was put in. The physical reading (`rolling_arm:
/// contact_point`: slip and torques on the contact point) conserves it too (7.9e-4).
/// The GPU path in f32 over 5 time units: 6.5e-3 and 5.5e-3, the f32 rounding of the
/// potential energy (0.8 m g σ) against the 4e-5 put in. Bound: 1e-2.
#[test]
fn continuous_law_conserves_energy_with_spins_on_both_levers() {
    for path in PATHS {
        for reading in [json!({}), json!({ "rolling_arm": "contact_point" })] {
            let Some((worst, spin)) = pocket_energy_excursion(path, reading.clone()) else {
                continue;
            };
            eprintln!("{path:?} {reading}: energy excursion {worst:.2e}, spin up to {spin:.3}");
            assert!(
                spin > 0.01,
                "{path:?} {reading}: the disk must spin ({spin})"
            );
            assert!(
                worst < 1e-2,
                "{path:?} {reading}: energy moved by {worst:.3e} of the input"
            );
        }
    }
}
