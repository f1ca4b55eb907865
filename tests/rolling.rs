//! Rolling resistance at disk contacts (scene `rolling`, src/law/rolling.rs; issue 43
//! item 1): the constant directional torque and the elastic–plastic spring–dashpot of
//! Ai et al. (2011), on both paths.

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
fn rolling_disk(
    path: Path,
    v0: f64,
    t_end: f64,
    rolling: Value,
) -> Option<([f64; 2], [f64; 2], f64)> {
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
    v["rolling"] = rolling;
    let mut e = engine(path, "rolling_disk", sim(&v))?;
    let steps = |t: f64| (t / DT).round() as u64;
    let speed = |e: &mut talus::run::Engine| {
        let s = e.sim().unwrap();
        s.particles.velocity(0, s.dt())[0]
    };
    let x = |e: &mut talus::run::Engine| e.sim().unwrap().particles.position(0)[0];
    e.advance(steps(1.0)).unwrap();
    let (v1, x1) = (speed(&mut e), x(&mut e));
    e.advance(steps(2.0)).unwrap();
    let v3 = speed(&mut e);
    e.advance(steps(t_end - 3.0)).unwrap();
    Some(([v1, v3], [x1, x(&mut e)], speed(&mut e)))
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
        let cdt = json!({ "model": "constant_torque", "mu_r": MU_R });
        let Some(([v1, v3], [_, x], v_end)) = rolling_disk(path, v0, v0 / a + 2.0, cdt) else {
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
/// (contact law in its material form: restitution 0.5), with the constant torque at
/// `mu_r` (none at 0).
fn heap(seed: u64, mu_r: f64) -> Value {
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
    v
}

fn heap_slope(seed: u64, mu_r: f64) -> f64 {
    heap_slope_of(heap(seed, mu_r))
}

/// The slope of a `heap` at t = 100: the triangle of its height H and area A (grains'
/// area / 0.82), tan θ = H² / A.
fn heap_slope_of(v: Value) -> f64 {
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
    let v = incline(degrees, json!({ "mu_r": MU_R }));
    let (s, c) = degrees.to_radians().sin_cos();
    let mut e = engine(path, "disk_on_an_incline", sim(&v))?;
    let mut speed = || {
        e.advance((1.0 / DT).round() as u64).unwrap();
        let sim = e.sim().unwrap();
        let u = sim.particles.velocity(0, sim.dt());
        u[0] * c - u[1] * s
    };
    Some([speed(), speed()])
}

/// The scene of `disk_on_an_incline` with the rolling block `rolling`.
fn incline(degrees: f64, rolling: Value) -> Value {
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
    v["rolling"] = rolling;
    v
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

// The elastic–plastic spring–dashpot (model C of Ai et al. 2011).

/// The rolling spring's block: μ_r = `MU_R`, the default stiffness 2.25 μ_r² k_n and
/// damping η_r = 0.3.
fn spring_model() -> Value {
    json!({ "model": "spring_dashpot", "mu_r": MU_R })
}

#[test]
fn with_a_rolling_spring_a_rolling_disk_stops_within_the_analytic_distance() {
    // While it rolls the spring slips at its limit μ_r R m g, the constant torque's
    // deceleration (2/3) μ_r g, so from t = 1 (at speed v1) the disk stops after
    // 3 v1² / (4 μ_r g). Not from the start: as the spring winds up from nothing (two
    // steps here) its dashpot C_r ω acts, far above the limit at this spin (Ai et al.
    // damp only a spring below its limit), and takes 0.6 % of the speed. Having stopped,
    // the spring unwinds, rolling the disk back by at most R μ_r m g / (k_roll R²) =
    // 4.4e-4 (3e-4 of the distance), damped. Measured on both paths (GPU: lavapipe): the
    // stop 3.8e-4 short on both, at rest (speed 3e-9) four time units later.
    let v0 = 0.5;
    let a = 2.0 / 3.0 * MU_R;
    let mut cpu = None;
    for path in PATHS {
        let t_end = v0 / a + 4.0;
        let Some(([v1, v3], [x1, x], v_end)) = rolling_disk(path, v0, t_end, spring_model()) else {
            continue;
        };
        let decel = (v1 - v3) / 2.0;
        let s = 3.0 * v1 * v1 / (4.0 * MU_R);
        eprintln!(
            "{path:?}: deceleration {decel}, stopped {} after t = 1 (speed {v_end:e}); analytic {a}, {s}",
            x - x1
        );
        assert!(
            (decel / a - 1.0).abs() < 2e-4,
            "{path:?}: deceleration {decel} against (2/3) μ_r g = {a}"
        );
        assert!(
            ((x - x1) / s - 1.0).abs() < 1e-3,
            "{path:?}: stopped {} after t = 1 against 3 v1² / (4 μ_r g) = {s}",
            x - x1
        );
        assert!(v_end.abs() < 1e-6, "{path:?}: still moving at {v_end}");
        match cpu {
            None => cpu = Some((decel, x)),
            Some((c1, c2)) => assert!(
                (decel / c1 - 1.0).abs() < 1e-4 && (x / c2 - 1.0).abs() < 1e-4,
                "GPU {decel}, {x} against CPU {c1}, {c2}"
            ),
        }
    }
}

#[test]
fn a_rolling_spring_holds_a_disk_on_an_incline_below_the_threshold() {
    // At 3° (below tan θ = μ_r) the spring winds up to M = f R_c with f = m g sin θ the
    // friction that holds the disk (R_c = R − δ/2 the contact's arm), and stays there:
    // the disk turns by θ_r = M / (k_roll R²) and its centre moves down the slope by
    // R_c θ_r plus the tangential spring's stretch f / k_t, then stands still, where the
    // constant torque creeps on (the test above). Measured on both paths (GPU: lavapipe):
    // the displacement 5e-6 (CPU) and 2.3e-5 (GPU) off, then still within 2e-4 of it and
    // a speed below 1.1e-8.
    let degrees: f64 = 3.0;
    let (sn, cs) = degrees.to_radians().sin_cos();
    let k_roll = 2.25 * MU_R * MU_R * 1.0e4;
    let f = sn;
    let r_c = 0.5 - 0.5 * cs / 1.0e4;
    let expected = r_c * (f * r_c / (k_roll * 0.25)) + f / 2.0e3;
    for path in PATHS {
        let v = incline(degrees, spring_model());
        let Some(mut e) = engine(path, "rolling_spring_incline", sim(&v)) else {
            continue;
        };
        let along = |e: &mut talus::run::Engine| {
            let s = e.sim().unwrap();
            let (p, u) = (s.particles.position(0), s.particles.velocity(0, s.dt()));
            (p[0] * cs - p[1] * sn, u[0] * cs - u[1] * sn)
        };
        let x0 = along(&mut e).0;
        e.advance((4.0 / DT) as u64).unwrap();
        let (x4, _) = along(&mut e);
        e.advance((4.0 / DT) as u64).unwrap();
        let (x8, v8) = along(&mut e);
        eprintln!(
            "{path:?}: moved {:e} by t = 4 (expected {expected:e}), {:e} more by t = 8, speed {v8:e}",
            x4 - x0,
            x8 - x4
        );
        assert!(
            ((x4 - x0) / expected - 1.0).abs() < 1e-3,
            "{path:?}: moved {} against {expected}",
            x4 - x0
        );
        assert!(
            (x8 - x4).abs() < 1e-3 * expected && v8.abs() < 1e-7,
            "{path:?}: still moving: {} from t = 4 to 8, speed {v8}",
            x8 - x4
        );
    }
}

#[test]
fn gpu_rolling_springs_agree_with_the_cpu_and_resume_bitwise() {
    // The spinning rows under the spring model: the GPU path within f32 rounding of the
    // CPU path, the springs making a difference against the constant torque; then a
    // small pour with rolling springs resumes bitwise from a checkpoint on both paths,
    // the checkpoint carrying them.
    // 1000 steps: the spring switches between holding (damped) and slipping (not) at
    // its limit, and at 2000 steps one contact's switch a step apart in f32 has parted
    // the paths by 1.3e-5 d (measured on lavapipe; 2.3e-8 d at 1000).
    let steps = 1000;
    let mut rows = spinning_rows(0.0);
    rows["rolling"] = spring_model();
    let run = |path: Path, v: &Value| {
        let mut e = engine(path, "gpu_rolling_springs_agree", sim(v))?;
        e.advance(steps).unwrap();
        Some(e.sim().unwrap().clone())
    };
    let cpu = run(Path::Cpu, &rows).unwrap();
    let cdt = run(Path::Cpu, &spinning_rows(MU_R)).unwrap();
    let (fx, fw) = differences(&cpu, &cdt);
    eprintln!("spring against constant torque: {fx:.2e} d, {fw:.2e} in ω");
    assert!(fx > 1e-3 && fw > 0.1, "the spring changed nothing");
    if let Some(gpu) = run(Path::Gpu, &rows) {
        let (dx, dw) = differences(&gpu, &cpu);
        eprintln!("GPU against CPU: {dx:.2e} d, {dw:.2e} in ω");
        assert!(
            dx < 1e-6 && dw < 1e-4,
            "GPU {dx:.2e} d, {dw:.2e} in ω off the CPU"
        );
    }
    let mut pour = heap(1, 0.3);
    pour["rolling"] =
        json!({ "model": "spring_dashpot", "mu_r": 0.3, "stiffness": 1.0e3, "damping": 0.1 });
    pour["particles"][1]["count"] = json!(60);
    let scene = parse(&pour);
    for path in PATHS {
        let test = "rolling_springs_resume_bitwise";
        assert_resumes_bitwise(path, test, &scene, 6000, 2500, carries_sub_springs);
    }
}

#[test]
fn a_heap_stands_steeper_with_rolling_springs() {
    // The heap of `a_heap_stands_steeper_with_rolling_resistance` under the spring model
    // at μ_r = 0.4, four seeds. Measured: 24.2° (k_roll = 10³, η_r = 0.1) against 15.5°
    // without. With the dashpot stronger, Gear pumps energy into it and the heap slumps
    // (η_r = 0.3: 17.9°; k_roll = 3·10³, η_r = 0.3: 14.1°): the scene's check warns
    // there and not here.
    let spring = |k_roll: f64, eta_r: f64| json!({ "model": "spring_dashpot", "mu_r": 0.4, "stiffness": k_roll, "damping": eta_r });
    let with = |seed: u64, rolling: Value| {
        let mut v = heap(seed, 0.0);
        v["rolling"] = rolling;
        v
    };
    let warned = |rolling: Value| {
        let w = talus::scene::warnings(&parse(&with(1, rolling)));
        w.iter().any(|w| w.contains("rolling dashpots"))
    };
    assert!(!warned(spring(1.0e3, 0.1)), "a stable dashpot warned about");
    assert!(
        warned(spring(3.0e3, 0.3)),
        "no warning for a dashpot that slumps the heap"
    );
    let mean = |rolling: Option<Value>| {
        (1..=4)
            .map(|seed| match &rolling {
                Some(r) => heap_slope_of(with(seed, r.clone())),
                None => heap_slope(seed, 0.0),
            })
            .sum::<f64>()
            / 4.0
    };
    let (free, held) = (mean(None), mean(Some(spring(1.0e3, 0.1))));
    eprintln!("heap slope: {free:.1}° without rolling resistance, {held:.1}° with rolling springs");
    assert!(
        held > free + 4.0,
        "rolling springs give {held:.1}° against {free:.1}° without"
    );
}

#[test]
fn rolling_springs_are_refused_where_they_cannot_be_built() {
    let disk = json!([{ "kind": "list", "material": "m",
                        "particles": [{ "position": [0.0, 0.5], "diameter": 1.0 }] }]);
    let refused = |contact: Value, rolling: Value| {
        let mut v = scene_value(contact, disk.clone());
        v["rolling"] = rolling;
        v["gravity"] = json!({ "g": [0.0, -1.0] });
        v["dt"] = json!(DT);
        talus::scene::parse(&v.to_string(), &[])
            .err()
            .map(|e| e.to_string())
    };
    // A spring's keys under the constant torque.
    let text =
        refused(spring_dashpot(), json!({ "mu_r": 0.1, "stiffness": 100.0 })).expect("refused");
    assert!(
        text.contains("rolling.stiffness") && text.contains("spring_dashpot"),
        "{text}"
    );
    // No one k_n to take the default from (the continuous law).
    let continuous = json!({ "law": "hooke_equivalent", "n": 36.0, "r0": 1.2, "mu": MU });
    let text = refused(continuous.clone(), spring_model()).expect("refused");
    assert!(
        text.contains("rolling.stiffness") && text.contains("required"),
        "{text}"
    );
    let mut given = spring_model();
    given["stiffness"] = json!(10.0);
    assert_eq!(
        refused(continuous, given),
        None,
        "a given stiffness is taken"
    );
    // Too stiff for the time step, and a negative damping.
    let text = refused(
        spring_dashpot(),
        json!({ "model": "spring_dashpot", "mu_r": 0.1, "stiffness": 1.0e9 }),
    )
    .expect("refused");
    assert!(
        text.contains("rolling.stiffness") && text.contains("dt"),
        "{text}"
    );
    let text = refused(
        spring_dashpot(),
        json!({ "model": "spring_dashpot", "mu_r": 0.1, "damping": -1.0 }),
    )
    .expect("refused");
    assert!(text.contains("rolling.damping"), "{text}");
}

// Rolling resistance per pair of materials (`rolling.pairs`).

/// Two disks of unit mass and diameter, of materials "m" and "rough", rolling without
/// slip along one floor at `v0` 50 d apart, g = 1, under `rolling`: for each, its
/// position and speed at t = 1 and at `t_end`; None on the GPU path without an adapter.
fn two_rolling_disks(
    path: Path,
    v0: f64,
    t_end: f64,
    rolling: Value,
) -> Option<[[[f64; 2]; 2]; 2]> {
    let disk = |x: f64| {
        json!({ "position": [x, 0.5 - 1e-4], "diameter": 1.0,
                "velocity": [v0, 0.0], "omega": -2.0 * v0 })
    };
    let mut v = scene_value(
        spring_dashpot(),
        json!([{ "kind": "list", "material": "m", "particles": [disk(0.0)] },
               { "kind": "list", "material": "rough", "particles": [disk(50.0)] }]),
    );
    v["materials"]["rough"] = v["materials"]["m"].clone();
    v["walls"] = json!([{ "from": [-100.0, 0.0], "to": [100.0, 0.0] }]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(DT);
    v["rolling"] = rolling;
    let mut e = engine(path, "two_rolling_disks", sim(&v))?;
    // Particle ids follow the creators: "m" first.
    let at = |e: &mut talus::run::Engine| {
        let s = e.sim().unwrap();
        let one = |i: usize| {
            [
                s.particles.position(i)[0],
                s.particles.velocity(i, s.dt())[0],
            ]
        };
        [one(0), one(1)]
    };
    e.advance((1.0 / DT).round() as u64).unwrap();
    let early = at(&mut e);
    e.advance(((t_end - 1.0) / DT).round() as u64).unwrap();
    let late = at(&mut e);
    Some([[early[0], late[0]], [early[1], late[1]]])
}

#[test]
fn each_pair_of_materials_takes_its_own_rolling_resistance() {
    // The disk of "m" takes the block's μ_r = 0.1 against the floor, the disk of
    // "rough" its pair's 0.2 (rough–walls): from t = 1 (speed v1) each stops after its
    // own 3 v1² / (4 μ_r g), under both models, on both paths (from t = 1: the spring
    // winding up takes a little speed first; see
    // `with_a_rolling_spring_a_rolling_disk_stops_within_the_analytic_distance`).
    // Measured (GPU: lavapipe): the constant torque 5e-5 and 1.4e-4 of the distances
    // short, the spring 3.8e-4 and 6.1e-4; the GPU within 3e-7 d of the CPU.
    let v0 = 0.5;
    let pairs = json!([{ "materials": ["rough", "walls"], "mu_r": 2.0 * MU_R }]);
    for model in ["constant_torque", "spring_dashpot"] {
        let rolling = json!({ "model": model, "mu_r": MU_R, "pairs": pairs });
        let mut cpu: Option<[f64; 2]> = None;
        for path in PATHS {
            let t_end = v0 / (2.0 / 3.0 * MU_R) + 4.0;
            let Some(disks) = two_rolling_disks(path, v0, t_end, rolling.clone()) else {
                continue;
            };
            let mut stops = [0.0; 2];
            for (k, mu_r) in [MU_R, 2.0 * MU_R].into_iter().enumerate() {
                let [[x1, v1], [x, v]] = disks[k];
                let s = 3.0 * v1 * v1 / (4.0 * mu_r);
                eprintln!(
                    "{model}, {path:?}: disk {k} stopped {} after t = 1 (speed {v:e}) against {s}",
                    x - x1
                );
                assert!(
                    ((x - x1) / s - 1.0).abs() < 1e-3,
                    "{model}, {path:?}: disk {k} stopped {} after t = 1 against 3 v1² / (4 μ_r g) = {s}",
                    x - x1
                );
                assert!(
                    v.abs() < 1e-6,
                    "{model}, {path:?}: disk {k} still moving at {v}"
                );
                stops[k] = x;
            }
            match cpu {
                None => cpu = Some(stops),
                Some(c) => assert!(
                    (stops[0] - c[0]).abs() < 1e-4 && (stops[1] - c[1]).abs() < 1e-4,
                    "{model}: GPU stops {stops:?} against CPU {c:?}"
                ),
            }
        }
    }
}

/// The spinning rows with every other disk of material "b", rolling springs of
/// μ_r = `MU_R` between "m" and "m" (the block), 0.3 between "m" and "b" and none
/// between "b" and the floor.
fn spinning_rows_of_two_materials() -> Value {
    let mut v = spinning_rows(0.0);
    v["materials"]["b"] = v["materials"]["m"].clone();
    let list = v["particles"][0]["particles"].as_array().unwrap().clone();
    let (even, odd): (Vec<_>, Vec<_>) = list.into_iter().enumerate().partition(|(k, _)| k % 2 == 0);
    let strip = |l: Vec<(usize, Value)>| l.into_iter().map(|(_, p)| p).collect::<Vec<_>>();
    v["particles"] = json!([{ "kind": "list", "material": "m", "particles": strip(even) },
                            { "kind": "list", "material": "b", "particles": strip(odd) }]);
    v["rolling"] = json!({ "model": "spring_dashpot", "mu_r": MU_R, "pairs": [
        { "materials": ["m", "b"], "mu_r": 0.3 },
        { "materials": ["walls", "b"], "mu_r": 0.0 }] });
    v
}

#[test]
fn gpu_rolling_resistance_per_pair_agrees_with_the_cpu() {
    // 1000 steps of the rows of two materials: the GPU path within f32 rounding of the
    // CPU path (measured 2.1e-8 d and 6.8e-7 in ω, lavapipe), while the same rows with
    // the block's values for every pair end far from both (1.6e-2 d, 0.26 in ω): the
    // pairs' values are what the two paths agree on.
    let steps = 1000;
    let run = |path: Path, v: &Value| {
        let mut e = engine(path, "gpu_rolling_per_pair", sim(v))?;
        e.advance(steps).unwrap();
        Some(e.sim().unwrap().clone())
    };
    let rows = spinning_rows_of_two_materials();
    let cpu = run(Path::Cpu, &rows).unwrap();
    let mut uniform = rows.clone();
    uniform["rolling"] = spring_model();
    let (fx, fw) = differences(&cpu, &run(Path::Cpu, &uniform).unwrap());
    eprintln!("per pair against one value: {fx:.2e} d, {fw:.2e} in ω");
    assert!(fx > 1e-3 && fw > 0.1, "the pairs changed nothing");
    let Some(gpu) = run(Path::Gpu, &rows) else {
        return;
    };
    let (dx, dw) = differences(&gpu, &cpu);
    eprintln!("GPU against CPU: {dx:.2e} d, {dw:.2e} in ω");
    assert!(
        dx < 1e-6 && dw < 1e-4,
        "GPU {dx:.2e} d, {dw:.2e} in ω off the CPU"
    );
}

#[test]
fn rolling_pairs_are_refused_where_they_are_wrong_and_named_by_check() {
    let mut rows = spinning_rows_of_two_materials();
    rows["dt"] = json!(DT);
    let refused = |pairs: Value, model: &str| {
        let mut v = rows.clone();
        v["rolling"] = json!({ "model": model, "mu_r": MU_R, "pairs": pairs });
        talus::scene::parse(&v.to_string(), &[])
            .err()
            .map(|e| e.to_string())
    };
    let spring = "spring_dashpot";
    for (pairs, model, key, reason) in [
        (
            json!([{ "materials": ["m", "c"], "mu_r": 0.2 }]),
            spring,
            "rolling.pairs[0].materials",
            "unknown material \"c\"",
        ),
        (
            json!([{ "materials": ["walls", "walls"], "mu_r": 0.2 }]),
            spring,
            "rolling.pairs[0].materials",
            "walls",
        ),
        (
            json!([{ "materials": ["m", "b"] }, { "materials": ["b", "m"] }]),
            spring,
            "rolling.pairs[1].materials",
            "twice",
        ),
        (
            json!([{ "materials": ["m", "b"], "mu_r": -1.0 }]),
            spring,
            "rolling.pairs[0].mu_r",
            "",
        ),
        (
            json!([{ "materials": ["m", "b"], "stiffness": 1.0e9 }]),
            spring,
            "rolling.pairs[0].stiffness",
            "dt",
        ),
        (
            json!([{ "materials": ["m", "b"], "damping": 0.5 }]),
            "constant_torque",
            "rolling.pairs[0].damping",
            "spring_dashpot",
        ),
        (
            json!([{ "materials": ["m", "b"], "shape": 1 }]),
            spring,
            "shape",
            "",
        ),
    ] {
        let text = refused(pairs.clone(), model).unwrap_or_else(|| panic!("{pairs} accepted"));
        assert!(
            text.contains(key) && text.contains(reason),
            "{pairs}: {text}"
        );
    }
    assert_eq!(
        refused(json!([{ "materials": ["m", "b"], "mu_r": 0.2 }]), spring),
        None
    );
    // `talus check` names every pair's values.
    let dir = tmp("rolling", "pairs_check");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rows.json");
    std::fs::write(&path, rows.to_string()).unwrap();
    let out = talus_ok(["check", path.to_str().unwrap()]);
    assert!(
        out.contains("rolling.pairs")
            && out.contains("b–m: μ_r = 0.3")
            && out.contains("b–walls: none"),
        "{out}"
    );
}
