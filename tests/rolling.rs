//! Rolling resistance at disk contacts (scene `rolling`, src/law/rolling.rs; issue 43
//! item 1): the constant directional torque of Ai et al. (2011), on both paths.

mod common;
use common::*;
use serde_json::{Value, json};

const MU: f64 = 0.5;
const MU_R: f64 = 0.1;
const DT: f64 = 5e-4;

fn spring_dashpot() -> Value {
    json!({ "law": "spring_dashpot", "k_n": 1.0e4, "gamma_n": 20.0, "k_t": 2.0e3,
            "gamma_t": 10.0, "mu": MU })
}

/// A disk of unit mass and diameter rolling without slip along a floor at `v0`, g = 1,
/// under rolling resistance μ_r = `MU_R`: its speed at t = 1 and t = 3, the distance it
/// has covered at `t_end` and its speed then; None on the GPU path without an adapter.
fn rolling_disk(path: Path, v0: f64, t_end: f64) -> Option<([f64; 2], f64, f64)> {
    // Resting on the floor with its weight's overlap m g / k_n.
    let disk = json!({ "position": [0.0, 0.5 - 1e-4], "diameter": 1.0,
                       "velocity": [v0, 0.0], "omega": -2.0 * v0 });
    let mut v = scene_value(
        spring_dashpot(),
        json!([{ "kind": "list", "material": "m", "particles": [disk] }]),
    );
    v["walls"] = json!([{ "from": [-100.0, 0.0], "to": [100.0, 0.0] }]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(DT);
    v["rolling"] = json!({ "model": "constant_torque", "mu_r": MU_R });
    let mut e = engine(path, "rolling_disk", sim(&v))?;
    let steps = |t: f64| (t / DT).round() as u64;
    let speed = |e: &mut talus::run::Engine| {
        let s = e.sim().unwrap();
        s.particles.velocity(0, s.dt())[0]
    };
    e.advance(steps(1.0)).unwrap();
    let v1 = speed(&mut e);
    e.advance(steps(2.0)).unwrap();
    let v3 = speed(&mut e);
    e.advance(steps(t_end - 3.0)).unwrap();
    let x = e.sim().unwrap().particles.position(0)[0];
    Some(([v1, v3], x, speed(&mut e)))
}

#[test]
fn a_rolling_disk_stops_within_the_analytic_distance() {
    // Rolling without slip, the torque μ_r R m g decelerates a disk (I = m R²/2) at
    // a = μ_r g / (1 + I/(m R²)) = (2/3) μ_r g, so it stops after t = v0/a at
    // s = 3 v0² / (4 μ_r g) (the friction needed, m a, is far below μ m g). The
    // contact point lies δ/2 inside the disk, which moves a by 3·10⁻⁵, and the start
    // (rolling about the centre's radius, not the contact's) by 7·10⁻⁵.
    // Measured on both paths (GPU: lavapipe): the deceleration between t = 1 and 3
    // 3.3e-5 above (2/3) μ_r g (the contact's arm), the stop 1.1e-4 short of s, and at
    // rest (speed 7e-17) two time units later.
    let v0 = 0.5;
    let a = 2.0 / 3.0 * MU_R;
    let s = 3.0 * v0 * v0 / (4.0 * MU_R);
    let mut cpu = None;
    for path in PATHS {
        let Some(([v1, v3], x, v_end)) = rolling_disk(path, v0, v0 / a + 2.0) else {
            continue;
        };
        let decel = (v1 - v3) / 2.0;
        eprintln!(
            "{path:?}: deceleration {decel}, stopped at x = {x} (speed {v_end:e}); analytic {a}, {s}"
        );
        assert!(
            (decel / a - 1.0).abs() < 2e-4,
            "{path:?}: deceleration {decel} against (2/3) μ_r g = {a}"
        );
        assert!(
            (x / s - 1.0).abs() < 1e-3,
            "{path:?}: stopped at {x} against 3 v0² / (4 μ_r g) = {s}"
        );
        assert!(v_end.abs() < 1e-7, "{path:?}: still moving at {v_end}");
        match cpu {
            None => cpu = Some((decel, x)),
            Some((c1, c2)) => assert!(
                (decel / c1 - 1.0).abs() < 1e-4 && (x / c2 - 1.0).abs() < 1e-4,
                "GPU {decel}, {x} against CPU {c1}, {c2}"
            ),
        }
    }
}

/// Two rows of ten disks on a floor, each disk spinning and moving a little, g = 1:
/// contacts between mobile disks and with the floor, all of them rolling.
fn spinning_rows(mu_r: f64) -> Value {
    let mut list = Vec::new();
    for k in 0..20 {
        let (row, col) = (k / 10, k % 10);
        let x = col as f64 * 1.02 + 0.51 * row as f64;
        let z = 0.5 - 1e-4 + row as f64 * 0.87;
        let w = ((k * 7) % 5) as f64 - 2.0;
        list.push(json!({ "position": [x, z], "diameter": 1.0,
                          "velocity": [0.05 * w, 0.0], "omega": w }));
    }
    let mut v = scene_value(
        spring_dashpot(),
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    v["walls"] = json!([{ "from": [-100.0, 0.0], "to": [100.0, 0.0] }]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(DT);
    if mu_r > 0.0 {
        v["rolling"] = json!({ "mu_r": mu_r });
    }
    v
}

/// The largest difference of positions (in diameters) and of spins between two states.
fn differences(a: &talus::sim::Simulation, b: &talus::sim::Simulation) -> (f64, f64) {
    let (mut dx, mut dw) = (0.0f64, 0.0f64);
    for i in 0..a.particles.len() {
        let (p, q) = (a.particles.position(i), b.particles.position(i));
        dx = dx.max((p[0] - q[0]).hypot(p[1] - q[1]));
        let (u, w) = (
            a.particles.velocity(i, a.dt()),
            b.particles.velocity(i, b.dt()),
        );
        dw = dw.max((u[2] - w[2]).abs());
    }
    (dx, dw)
}

#[test]
fn gpu_rolling_resistance_agrees_with_the_cpu() {
    // 2000 steps (t = 1) of two spinning rows: the GPU path within f32 rounding of the
    // CPU path (measured 1.4e-6 d and 9e-5 in ω, lavapipe), while the same rows without
    // rolling resistance end far from both (0.03 d, 0.3 in ω): the torque is what the
    // two paths agree on.
    let steps = 2000;
    let run = |path: Path, mu_r: f64| {
        let mut e = engine(
            path,
            "gpu_rolling_resistance_agrees",
            sim(&spinning_rows(mu_r)),
        )?;
        e.advance(steps).unwrap();
        Some(e.sim().unwrap().clone())
    };
    let cpu = run(Path::Cpu, MU_R).unwrap();
    let free = run(Path::Cpu, 0.0).unwrap();
    let (fx, fw) = differences(&cpu, &free);
    eprintln!("with and without rolling resistance: {fx:.2e} d, {fw:.2e} in ω");
    assert!(fx > 1e-3 && fw > 0.1, "the rolling torque changed nothing");
    let Some(gpu) = run(Path::Gpu, MU_R) else {
        return;
    };
    let (dx, dw) = differences(&gpu, &cpu);
    eprintln!("GPU against CPU: {dx:.2e} d, {dw:.2e} in ω");
    assert!(
        dx < 1e-5 && dw < 1e-3,
        "GPU {dx:.2e} d, {dw:.2e} in ω off the CPU"
    );
}

#[test]
fn rolling_resistance_is_refused_where_it_does_not_apply() {
    let disk = json!([{ "kind": "list", "material": "m",
                        "particles": [{ "position": [0.0, 0.5], "diameter": 1.0 }] }]);
    let mut v = scene_value(
        json!({ "law": "overlap_area", "k_n": 1.0e4, "eta_n": 0.5, "eta_t": 1.0, "mu": MU }),
        disk.clone(),
    );
    v["rolling"] = json!({ "mu_r": 0.1 });
    let err = talus::scene::parse(&v.to_string(), &[]).expect_err("refused");
    let text = err.to_string();
    assert!(
        text.contains("rolling") && text.contains("overlap_area"),
        "{text}"
    );
    let mut v = scene_value(spring_dashpot(), disk);
    v["rolling"] = json!({ "mu_r": -0.1 });
    let text = talus::scene::parse(&v.to_string(), &[])
        .expect_err("refused")
        .to_string();
    assert!(text.contains("rolling.mu_r"), "{text}");
    v["rolling"] = json!({ "mu_r": 0.1, "model": "spring" });
    let text = talus::scene::parse(&v.to_string(), &[])
        .expect_err("refused")
        .to_string();
    assert!(text.contains("spring") || text.contains("model"), "{text}");
    v["rolling"] = json!({ "mu_r": 0.1, "model": "constant_torque" });
    talus::scene::parse(&v.to_string(), &[]).expect("a disk scene takes it");
}

/// A heap of 300 disks poured from 25 d onto a row of fixed disks, left to t = 100
/// (contact law in its material form: restitution 0.5): the slope of the triangle of
/// its height H and area A (grains' area / 0.82), tan θ = H² / A.
fn heap_slope(seed: u64, mu_r: f64) -> f64 {
    let mut v = json!({
        "name": "heap", "seed": seed, "dt": 0.002, "stop": { "time": 100.0 },
        "gravity": { "g": [0.0, -1.0] }, "domain": { "x": [-30.0, 30.0], "z": [-2.0, 40.0] },
        "materials": { "m": { "density": 1.2732395447351628 } },
        "contact": { "law": "spring_dashpot", "restitution": 0.5, "contact_time": 0.05,
                     "mu": 0.5 },
        "particles": [
            { "kind": "row", "material": "m", "count": 45, "diameter": 1.0, "spacing": 1.1,
              "start": [-24.2, 0.0] },
            { "kind": "point_source", "material": "m", "position": [0.0, 25.0], "spread": 1.0,
              "rate": 5.0, "count": 300, "velocity": [0.0, -3.0],
              "diameter": { "uniform": [0.9, 1.1] } }
        ],
        "output": { "checkpoint_every": 0 }
    });
    if mu_r > 0.0 {
        v["rolling"] = json!({ "mu_r": mu_r });
    }
    let mut s = sim(&v);
    s.advance(50_000).unwrap();
    let p = &s.particles;
    let (mut top, mut area) = (0.0f64, 0.0);
    for i in (0..p.len()).filter(|&i| p.active[i] && !p.fixed[i]) {
        top = top.max(p.q[0][i][1] + p.radius[i]);
        area += std::f64::consts::PI * p.radius[i] * p.radius[i];
    }
    // The row's tops are at z = 0.5.
    let h = top - 0.5;
    (h * h / (area / 0.82)).atan().to_degrees()
}

#[test]
fn a_heap_stands_steeper_with_rolling_resistance() {
    // Four seeds each. Measured: means 15.5° without rolling resistance and 19.6° with
    // μ_r = 0.4; single heaps (seeds 1–3) 14.9°–16.4° and 16.9°–22.8°. The spread
    // between seeds is 1°–3°, so the means are asked to differ by 2°.
    let mean = |mu_r: f64| (1..=4).map(|seed| heap_slope(seed, mu_r)).sum::<f64>() / 4.0;
    let (free, resisted) = (mean(0.0), mean(0.4));
    eprintln!("heap slope: {free:.1}° without rolling resistance, {resisted:.1}° with μ_r = 0.4");
    assert!(
        resisted > free + 2.0,
        "μ_r = 0.4 gives {resisted:.1}° against {free:.1}° without"
    );
}

/// A disk of unit mass and diameter at rest on a floor inclined by `degrees` (downhill
/// towards +x), g = 1, μ_r = `MU_R`: its speed along the slope at t = 1 and t = 2; None
/// on the GPU path without an adapter.
fn disk_on_an_incline(path: Path, degrees: f64) -> Option<[f64; 2]> {
    let (s, c) = degrees.to_radians().sin_cos();
    // Resting on the floor with the overlap of its weight's normal part, m g cos θ / k_n.
    let h = 0.5 - c / 1.0e4;
    let disk = json!({ "position": [s * h, c * h], "diameter": 1.0 });
    let mut v = scene_value(
        spring_dashpot(),
        json!([{ "kind": "list", "material": "m", "particles": [disk] }]),
    );
    v["walls"] = json!([{ "from": [-50.0 * c, 50.0 * s], "to": [50.0 * c, -50.0 * s] }]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(DT);
    v["rolling"] = json!({ "mu_r": MU_R });
    let mut e = engine(path, "disk_on_an_incline", sim(&v))?;
    let mut speed = || {
        e.advance((1.0 / DT).round() as u64).unwrap();
        let sim = e.sim().unwrap();
        let u = sim.particles.velocity(0, sim.dt());
        u[0] * c - u[1] * s
    };
    Some([speed(), speed()])
}

#[test]
fn on_an_incline_a_disk_rolls_down_above_the_threshold_and_creeps_below_it() {
    // Above tan θ = μ_r (10°) the disk rolls down at a = (2/3) g (sin θ − μ_r cos θ)
    // (the torque's full size, μ_r R m g cos θ). Below it (3°) the constant-torque model
    // cannot hold it: the torque, limited near rest to AT_REST I ω / dt, balances the
    // weight's m g R sin θ at ω = m g R sin θ dt / (AT_REST I), so the disk creeps
    // down at v = ω R (src/law/rolling.rs). Measured on both paths (GPU: lavapipe):
    // the acceleration and the creep both 2e-4 below these.
    let at_rest = talus::law::rolling::AT_REST;
    for path in PATHS {
        let Some([v1, v2]) = disk_on_an_incline(path, 10.0) else {
            continue;
        };
        let (s, c) = 10f64.to_radians().sin_cos();
        let a = 2.0 / 3.0 * (s - MU_R * c);
        eprintln!("{path:?}, 10°: acceleration {} against {a}", v2 - v1);
        assert!(
            ((v2 - v1) / a - 1.0).abs() < 1e-3,
            "{path:?}: {} against {a}",
            v2 - v1
        );
        let [_, creep] = disk_on_an_incline(path, 3.0).unwrap();
        let (m, r, inertia) = (1.0, 0.5, 0.125);
        let expected = m * r * 3f64.to_radians().sin() * DT / (at_rest * inertia) * r;
        eprintln!("{path:?}, 3°: creeps at {creep:e} against {expected:e}");
        assert!(
            (creep / expected - 1.0).abs() < 1e-2,
            "{path:?}: {creep} against {expected}"
        );
    }
}

#[test]
fn a_stage_may_add_rolling_resistance() {
    // Pour the default heap without it, then go on with μ_r = 0.3 (`--from`): the stage
    // runs under the new scene (its scene.json has it), and ends elsewhere than the same
    // stage without it.
    let dir = tmp("rolling", "stage");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let (pour, with, without) = (dir.join("pour"), dir.join("with"), dir.join("without"));
    let (code, _, err) = talus(["run", "-q", "--set", "stop.time=10", "--out", &s(&pour)]);
    assert_eq!(code, 0, "{err}");
    let stage = |out: &std::path::Path, mu_r: &str| {
        let set = format!("rolling={{\"mu_r\": {mu_r}}}");
        let (code, _, err) = talus([
            "run",
            "-q",
            "--from",
            &s(&pour),
            "--set",
            "stop.time=14",
            "--set",
            &set,
            "--out",
            &s(out),
        ]);
        assert_eq!(code, 0, "{err}");
        // The final state's spins (not the provenance, which names the command).
        let snapshot = talus::io::snapshot::read(&out.join("final.json")).unwrap();
        snapshot.f64("particles.omega").expect("spins").to_vec()
    };
    let (a, b) = (stage(&with, "0.3"), stage(&without, "0"));
    let scene: Value =
        serde_json::from_str(&std::fs::read_to_string(with.join("scene.json")).unwrap()).unwrap();
    assert_eq!(scene["rolling"]["mu_r"], 0.3);
    assert_ne!(a, b, "the rolling torque changed nothing");
}

#[test]
fn talus_check_names_rolling_resistance_and_moving_walls() {
    let scene = |name: &str| format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    let out = talus_ok(["check", &scene("rolling_heap.json")]);
    assert!(
        out.contains("rolling resistance") && out.contains("μ_r = 0.3"),
        "{out}"
    );
    let out = talus_ok(["check", &scene("belt.json")]);
    assert!(out.contains("walls[0].velocity"), "{out}");
    assert!(!out.contains("rolling resistance"), "{out}");
}
