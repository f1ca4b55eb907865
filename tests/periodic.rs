//! A domain periodic in x (scene `domain.periodic_x`, issue 43 item 2), on both paths: a
//! particle crossing the seam, a contact across it equal to one in the middle, a layer
//! dragged by a moving wall through the seam, the GPU against the CPU, the stress of a
//! contact across it, and the refusals.

mod common;
use common::*;
use serde_json::{Value, json};
use talus::analyze::input::{Grain, Touch};
use talus::analyze::stress::moments;

const MU: f64 = 0.5;
const L: f64 = 12.0;

fn spring_dashpot() -> Value {
    json!({ "law": "spring_dashpot", "k_n": 1.0e4, "gamma_n": 20.0, "k_t": 2.0e3,
            "gamma_t": 10.0, "mu": MU })
}

/// A scene of the disks `disks` in the periodic domain [0, L] × [0, 20], no gravity.
fn periodic(disks: Value) -> Value {
    let mut v = scene_value(
        spring_dashpot(),
        json!([{ "kind": "list", "material": "m", "particles": disks }]),
    );
    v["domain"] = json!({ "x": [0.0, L], "z": [0.0, 20.0], "periodic_x": true });
    v["dt"] = json!(1e-3);
    v
}

#[test]
fn a_particle_crossing_the_seam_comes_back_through_the_other_side() {
    // Two free disks, one leaving through each side, at 1 and −1.5 per time unit: after
    // 2 time units they are where x0 + v t lands modulo L, both still in the run.
    // Measured: 3e-13 (CPU), 3.6e-7 (GPU, lavapipe: f32 velocities).
    let disks = json!([
        { "position": [11.5, 5.0], "diameter": 1.0, "velocity": [1.0, 0.0] },
        { "position": [0.5, 10.0], "diameter": 1.0, "velocity": [-1.5, 0.0] }
    ]);
    for path in PATHS {
        let Some(mut e) = engine(path, "periodic_crossing", sim(&periodic(disks.clone()))) else {
            continue;
        };
        e.advance(2000).unwrap();
        let s = e.sim().unwrap();
        let p = &s.particles;
        assert!(
            p.active[0] && p.active[1],
            "{path:?}: a particle was lost at the seam"
        );
        assert_eq!(s.lost, 0);
        let (a, b) = (p.position(0)[0], p.position(1)[0]);
        eprintln!("{path:?}: after the seam at {a}, {b}");
        let tol = if path == Path::Cpu { 1e-9 } else { 1e-5 };
        assert!((a - 1.5).abs() < tol, "{path:?}: {a} against 1.5");
        assert!((b - 9.5).abs() < tol, "{path:?}: {b} against 9.5");
    }
}

/// Two disks colliding obliquely (with spins, so friction and rolling act), centred at
/// `x`: the first at x − 0.55, the second at x + 0.55 (taken modulo L), with a vertical
/// offset of 0.3; the state after the collision, relative to the first disk. None on
/// the GPU path without an adapter.
fn collision(path: Path, x: f64) -> Option<Vec<[f64; 5]>> {
    let at = |u: f64| u.rem_euclid(L);
    let disks = json!([
        { "position": [at(x - 0.55), 5.0], "diameter": 1.0, "velocity": [0.5, 0.0],
          "omega": 1.0 },
        { "position": [at(x + 0.55), 5.3], "diameter": 1.0, "velocity": [-0.5, 0.0],
          "omega": -2.0 }
    ]);
    let mut e = engine(path, "periodic_collision", sim(&periodic(disks)))?;
    e.advance(1500).unwrap();
    let s = e.sim().unwrap();
    let p = &s.particles;
    let x0 = p.position(0);
    Some(
        (0..2)
            .map(|i| {
                let (q, v) = (p.position(i), p.velocity(i, s.dt()));
                let dx = talus::state::nearest_image(q[0] - x0[0], L);
                [dx, q[1] - x0[1], v[0], v[1], v[2]]
            })
            .collect(),
    )
}

fn largest_difference(a: &[[f64; 5]], b: &[[f64; 5]]) -> f64 {
    (a.iter().flatten())
        .zip(b.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_contact_across_the_seam_equals_one_in_the_middle() {
    // The same collision in the middle of the domain and astride the seam: the relative
    // positions and the velocities agree to rounding (on the CPU positions differ by L,
    // so their differences round differently, and the stiff contact carries that on:
    // measured 5e-12; on the GPU, lavapipe, 1.4e-5: the two start from positions
    // rounded to its fixed point in two ways, and f32 carries that on, as far as the
    // GPU's collision lies from the CPU's, 1.3e-5).
    let cpu = collision(Path::Cpu, 6.0).unwrap();
    let touched = (cpu[0][2] - 0.5).abs() > 0.1;
    assert!(touched, "the disks did not collide: {cpu:?}");
    for path in PATHS {
        let (Some(middle), Some(seam)) = (collision(path, 6.0), collision(path, 0.0)) else {
            continue;
        };
        let worst = largest_difference(&middle, &seam);
        eprintln!("{path:?}: middle {middle:?}\n  seam {seam:?}\n  largest difference {worst:e}");
        let tol = if path == Path::Cpu { 1e-10 } else { 1e-4 };
        assert!(
            worst < tol,
            "{path:?}: across the seam the contact differs by {worst:e}"
        );
        let off = largest_difference(&seam, &cpu);
        eprintln!("{path:?} against the CPU in the middle: {off:e}");
        assert!(off < 1e-4, "{path:?}: {off:e} off the CPU");
    }
}

/// A layer of 5 rows of 12 disks (d = 0.98, a triangular lattice that the period closes)
/// on a floor moving at `belt` along x, g = 1 down.
fn dragged_layer(belt: f64) -> Value {
    let mut disks = Vec::new();
    for row in 0..5 {
        for k in 0..12 {
            let x = 0.5 + k as f64 + 0.5 * (row % 2) as f64;
            disks.push(json!({ "position": [x, 0.49 + 0.87 * row as f64], "diameter": 0.98 }));
        }
    }
    let mut v = periodic(json!(disks));
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [L, 0.0], "velocity": [belt, 0.0] }]);
    v
}

#[test]
fn a_periodic_layer_is_sheared_by_a_moving_wall_through_the_seam() {
    // The floor moves at 100, far faster than any grain can reach in 8 time units, so
    // every floor contact slides and pushes at μ f_n: with no side walls (the period
    // closes the layer) the layer's momentum then obeys P_x = μ ∫ N dt = μ (P_z + M g t)
    // exactly, the floor's normal force N read off P_z = ∫ (N − M g) dt. The rows drag
    // each other, so the bottom row runs ahead of the top one (a sheared layer), and
    // by t = 8 the layer has moved more than a period: grains cross the seam, none is
    // lost. Measured on the CPU: P_x within 4e-7 of it at t = 2, then a constant 4.2e-3
    // off (3e-5; one event between t = 2 and 4); at t = 1 the bottom row at 2.66, the
    // top at 0.28; 87 crossings. The GPU (lavapipe): within 1e-7 of it throughout, the
    // same rows at t = 1, 85 crossings.
    for path in PATHS {
        let Some(mut e) = engine(path, "periodic_layer", sim(&dragged_layer(100.0))) else {
            continue;
        };
        let s = e.sim().unwrap();
        let n = s.particles.len();
        let dt = s.dt();
        let mass: f64 = s.particles.mass.iter().sum();
        let mut wraps = 0;
        let mut last: Vec<f64> = (0..n).map(|i| s.particles.position(i)[0]).collect();
        let momentum = |s: &talus::sim::Simulation| {
            let p = &s.particles;
            (0..n).fold([0.0, 0.0], |acc, i| {
                let v = p.velocity(i, dt);
                [acc[0] + p.mass[i] * v[0], acc[1] + p.mass[i] * v[1]]
            })
        };
        for k in 1..=80 {
            e.advance(100).unwrap();
            let s = e.sim().unwrap();
            for (i, x) in last.iter_mut().enumerate() {
                let now = s.particles.position(i)[0];
                if now < *x - 0.5 * L {
                    wraps += 1;
                }
                *x = now;
            }
            if k % 20 == 0 {
                let t = k as f64 * 0.1;
                let [px, pz] = momentum(s);
                let expected = MU * (pz + mass * t);
                eprintln!("{path:?}, t = {t}: P_x {px:.6} against μ (P_z + M g t) = {expected:.6}");
                let tol = if path == Path::Cpu { 1e-4 } else { 1e-3 };
                assert!(
                    (px / expected - 1.0).abs() < tol,
                    "{path:?}, t = {t}: P_x = {px} against {expected}"
                );
            }
            if k == 10 {
                // The rows' mean speeds, bottom to top.
                let p = &s.particles;
                let row =
                    |r: usize| (0..12).map(|k| p.velocity(r * 12 + k, dt)[0]).sum::<f64>() / 12.0;
                let (bottom, top) = (row(0), row(4));
                eprintln!("{path:?}, t = 1: bottom row at {bottom:.4}, top row at {top:.4}");
                assert!(
                    bottom > top + 0.05,
                    "{path:?}: no shear: bottom {bottom}, top {top}"
                );
            }
        }
        let s = e.sim().unwrap();
        eprintln!("{path:?}: {wraps} crossings of the seam");
        assert!(
            wraps >= n,
            "{path:?}: only {wraps} crossings of the seam for {n} grains"
        );
        assert_eq!(s.lost, 0, "{path:?}: grains lost");
        assert!(s.particles.active.iter().all(|&a| a));
    }
}

/// The force on the grains from each wall (summed over its contacts) at the state's
/// step.
fn wall_forces(s: &talus::sim::Simulation, walls: usize) -> Vec<[f64; 2]> {
    let mut f = vec![[0.0; 2]; walls];
    for (p, c) in s.pairs.iter().zip(&s.contacts) {
        if p.is_wall() {
            let w = (p.j - talus::cpu::contacts::WALL_BASE) as usize;
            f[w] = [f[w][0] + c.force[0], f[w][1] + c.force[1]];
        }
    }
    f
}

/// What a layer between a still floor and a top wall moving along x at `u` does from
/// t = 1 to 3 (see `a_periodic_layer_is_dragged_by_a_moving_top_wall`): its momentum's
/// change ΔP_x, the walls' x impulse over the same steps (trapezoid) and the size of
/// their impulses, the top wall's impulse, and the rows' mean speeds at t = 3; None on
/// the GPU path without an adapter. Checks Coulomb at both walls at every step.
fn couette(path: Path, u: f64) -> Option<([f64; 4], Vec<f64>)> {
    // Five rows of 12 disks (d = 0.98) in each other's hollows, sqrt(0.98² − 0.5²)
    // apart, the top wall 1e-2 into the top row.
    let rise = (0.98f64 * 0.98 - 0.25).sqrt();
    let top = 0.49 + rise * 4.0 + 0.49 - 1e-2;
    let mut disks = Vec::new();
    for row in 0..5 {
        for k in 0..12 {
            let x = 0.5 + k as f64 + 0.5 * (row % 2) as f64;
            disks.push(json!({ "position": [x, 0.49 + rise * row as f64], "diameter": 0.98 }));
        }
    }
    let mut v = dragged_layer(0.0);
    v["particles"][0]["particles"] = json!(disks);
    v["walls"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "from": [0.0, top], "to": [L, top], "velocity": [u, 0.0] }));
    let mut e = engine(path, "periodic_couette", sim(&v))?;
    let dt = e.sim().unwrap().dt();
    let momentum = |s: &talus::sim::Simulation| {
        let p = &s.particles;
        (0..p.len())
            .map(|i| p.mass[i] * p.velocity(i, dt)[0])
            .sum::<f64>()
    };
    e.advance(1000).unwrap();
    let s = e.sim().unwrap();
    let p1 = momentum(s);
    let mut last = wall_forces(s, 2);
    let (mut impulse, mut size, mut top_x) = (0.0, 0.0, 0.0);
    for _ in 0..2000 {
        e.advance(1).unwrap();
        let s = e.sim().unwrap();
        let f = wall_forces(s, 2);
        for (w, [fx, fz]) in f.iter().enumerate() {
            // Each contact |f_t| ≤ μ f_n, its normal along z: so does the sum.
            assert!(
                fx.abs() <= MU * fz.abs() * (1.0 + 1e-6) + 1e-9,
                "{path:?}, wall {w} at step {}: F_x {fx} beyond μ |F_z| = {}",
                s.step,
                MU * fz.abs()
            );
        }
        let x = |f: &[[f64; 2]]| [f[0][0] + f[1][0], f[0][0].abs() + f[1][0].abs(), f[1][0]];
        let (now, before) = (x(&f), x(&last));
        impulse += 0.5 * (now[0] + before[0]) * dt;
        size += 0.5 * (now[1] + before[1]) * dt;
        top_x += 0.5 * (now[2] + before[2]) * dt;
        last = f;
    }
    let s = e.sim().unwrap();
    assert_eq!(s.lost, 0, "{path:?}: grains lost");
    let p = &s.particles;
    let row = |r: usize| (0..12).map(|k| p.velocity(r * 12 + k, dt)[0]).sum::<f64>() / 12.0;
    Some((
        [momentum(s) - p1, impulse, size, top_x],
        (0..5).map(row).collect(),
    ))
}

#[test]
fn a_periodic_layer_is_dragged_by_a_moving_top_wall() {
    // Plane Couette: a layer between a still floor and a top wall at a fixed height
    // pressing on it, whose surface moves at U = 1 along x. With no side walls (the
    // period closes the layer) only the two walls push it along x, so its momentum
    // obeys dP_x/dt = F_top + F_floor: integrated step by step from t = 1 to 3 it gives
    // ΔP_x to 1e-3 of the impulses' size. Coulomb holds at each wall (|F_x| ≤ μ |F_z|,
    // summed over its contacts, every step); the top wall drags the layer forward, and
    // the layer stays slower than it. With the top wall still, the layer stays at rest.
    // Measured on the CPU: the balance to 2e-6 of the impulses (ΔP_x 11.98 of 220.8),
    // the top wall's impulse 6.5, the rows at 0.60–0.63 at t = 3 (the lattice rolls
    // along as a plug, its rows spinning, rather than shearing); the GPU (lavapipe):
    // the balance to 2e-6 as well and the rows within 2e-4 of the CPU's.
    let mut cpu: Option<Vec<f64>> = None;
    for path in PATHS {
        let Some(([change, impulse, size, top_x], rows)) = couette(path, 1.0) else {
            continue;
        };
        eprintln!(
            "{path:?}: ΔP_x {change:.6} against the walls' impulse {impulse:.6} (of {size:.3}); the top wall's {top_x:.4}; rows at t = 3, floor to top: {rows:.4?}"
        );
        assert!(
            (change - impulse).abs() < 1e-3 * size,
            "{path:?}: ΔP_x {change} against the walls' impulse {impulse}"
        );
        assert!(
            top_x > 0.1 && change > 0.1,
            "{path:?}: the top wall's impulse {top_x}, ΔP_x {change}"
        );
        assert!(
            rows.iter().all(|&r| r > 0.0 && r < 1.0),
            "{path:?}: rows {rows:?} not between the floor and the wall"
        );
        match &cpu {
            None => cpu = Some(rows),
            Some(c) => {
                let off = rows
                    .iter()
                    .zip(c)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(off < 1e-2, "GPU rows {rows:?} against CPU {c:?}");
            }
        }
    }
    let (still, rows) = couette(Path::Cpu, 0.0).unwrap();
    eprintln!("top wall still: ΔP_x {:.2e}, rows {rows:?}", still[0]);
    assert!(
        still[0].abs() < 1e-6 && rows.iter().all(|r| r.abs() < 1e-6),
        "with the top wall still the layer moves: {still:?}, {rows:?}"
    );
}

#[test]
fn polygons_touch_across_the_seam_alike_on_both_paths() {
    // Two rows of pentagons on a floor moving at 2 along x, so that they are dragged
    // through the seam and touch across it (overlap-area law): the GPU's positions stay
    // within f32 reach of the CPU's (nearest image). Measured on lavapipe: 4.5e-6 after
    // 3000 steps, 3 pentagons having crossed the seam.
    let mut grains = Vec::new();
    for row in 0..2 {
        for k in 0..11 {
            let x = 0.55 + 1.05 * k as f64 + 0.5 * row as f64;
            grains.push(json!({ "position": [x, 0.45 + 0.95 * row as f64], "diameter": 1.0 }));
        }
    }
    let mut v = scene_value(
        json!({ "law": "overlap_area", "k_n": 1e4, "eta_n": 0.5, "mu": 0.5 }),
        json!([{ "kind": "list", "material": "m", "polygon": { "corners": 5 },
                 "particles": grains }]),
    );
    v["domain"] = json!({ "x": [0.0, L], "z": [0.0, 20.0], "periodic_x": true });
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(1e-3);
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [L, 0.0], "velocity": [2.0, 0.0] }]);
    let run = |path: Path| {
        let mut e = engine(path, "periodic_polygons", sim(&v))?;
        e.advance(3000).unwrap();
        Some(e.sim().unwrap().clone())
    };
    let cpu = run(Path::Cpu).unwrap();
    assert_eq!(cpu.lost, 0);
    // Dragged forwards, those that crossed the seam now lie left of where they started.
    let crossed = (0..grains.len())
        .filter(|&i| cpu.particles.position(i)[0] < grains[i]["position"][0].as_f64().unwrap())
        .count();
    eprintln!("CPU: {crossed} pentagons crossed the seam");
    assert!(crossed > 0, "no pentagon crossed the seam");
    let Some(gpu) = run(Path::Gpu) else {
        return;
    };
    assert_eq!(gpu.lost, 0);
    let worst = (0..cpu.particles.len())
        .map(|i| {
            let (a, b) = (cpu.particles.position(i), gpu.particles.position(i));
            talus::state::nearest_image(a[0] - b[0], L).hypot(a[1] - b[1])
        })
        .fold(0.0, f64::max);
    eprintln!("GPU against CPU: {worst:e}");
    assert!(worst < 1e-3, "GPU {worst:e} off the CPU");
}

#[test]
fn the_stress_of_a_contact_across_the_seam_is_that_of_one_in_the_middle() {
    // Two grains pressed together along x, once astride the seam (the contact point on
    // the first grain's side) and once in the middle: the same moments.
    let grain = |x: f64| Grain {
        x,
        z: 1.0,
        radius: 0.5,
        mass: 1.0,
        area: 0.785,
        ..Default::default()
    };
    let touch = |p: f64| Touch {
        a: 0,
        b: Some(1),
        force: [-2.0, 0.5],
        normal_force: 2.0,
        point: [p, 1.0],
    };
    let middle = moments(&[grain(6.45), grain(5.55)], &[touch(6.0)], L);
    let seam = moments(&[grain(0.45), grain(11.55)], &[touch(0.0)], L);
    for (a, b) in middle.iter().zip(&seam) {
        assert!(
            (a.xx - b.xx).abs() < 1e-12 && (a.xz - b.xz).abs() < 1e-12,
            "{a:?} against {b:?}"
        );
        assert!((a.zx - b.zx).abs() < 1e-12 && (a.zz - b.zz).abs() < 1e-12);
    }
    // Without the period the image grain's branch vector would be 11.55 long.
    let flat = moments(&[grain(0.45), grain(11.55)], &[touch(0.0)], 0.0);
    assert!((flat[1].xx - middle[1].xx).abs() > 1.0);
}

#[test]
fn periodic_domains_are_refused_where_they_do_not_fit() {
    // Narrower than three neighbour cells: refused naming domain.x.
    let mut v = periodic(json!([{ "position": [1.0, 5.0], "diameter": 1.0 }]));
    v["domain"]["x"] = json!([0.0, 3.0]);
    let text = talus::scene::parse(&v.to_string(), &[])
        .expect_err("refused")
        .to_string();
    assert!(
        text.contains("domain.x") && text.contains("periodic"),
        "{text}"
    );
    // The key goes with the domain; elsewhere it is an unknown key.
    let mut v = periodic(json!([{ "position": [1.0, 5.0], "diameter": 1.0 }]));
    v["periodic_x"] = json!(true);
    let text = talus::scene::parse(&v.to_string(), &[])
        .expect_err("refused")
        .to_string();
    assert!(text.contains("periodic_x"), "{text}");
}

#[test]
fn talus_check_names_a_periodic_domain() {
    let scene = format!("{}/scenes/periodic_chute.json", env!("CARGO_MANIFEST_DIR"));
    let out = talus_ok(["check", &scene]);
    assert!(
        out.contains("periodic in x") && out.contains("period 40"),
        "{out}"
    );
    let out = talus_ok([
        "check",
        &format!("{}/scenes/belt.json", env!("CARGO_MANIFEST_DIR")),
    ]);
    assert!(!out.contains("periodic"), "{out}");
}

#[test]
fn outputs_draw_contacts_across_the_seam_to_the_nearest_image() {
    // The layer at rest on a still floor through `talus run`: its rows settle onto each
    // other, across the seam too (the odd rows' last grain sits at x = L ≡ 0); every
    // contact line in contacts.vtp joins a grain to its partner's image beside it
    // (shorter than two diameters), none spans the domain; the pictures are drawn.
    let dir = tmp("periodic", "outputs");
    let scene = dir.join("layer.json");
    std::fs::create_dir_all(&dir).unwrap();
    let mut v = dragged_layer(0.0);
    v["stop"] = json!({ "time": 3.0 });
    v["output"] = json!({ "checkpoint_every": 0 });
    std::fs::write(&scene, v.to_string()).unwrap();
    let out = dir.join("run");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    talus_ok([
        "run",
        "-q",
        "--backend",
        "cpu",
        &s(&scene),
        "--out",
        &s(&out),
    ]);
    let vtp = common::vtp::read(&out.join("pictures").join("contacts.vtp"));
    let points = vtp.get("Points", "Points");
    let lines = points.len() / 6;
    let longest = (0..lines)
        .map(|k| {
            let (a, b) = (&points[6 * k..6 * k + 3], &points[6 * k + 3..6 * k + 6]);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .fold(0.0, f64::max);
    eprintln!("{lines} contact lines, the longest {longest}");
    assert!(lines > 100, "{lines} contacts");
    assert!(
        longest < 2.0,
        "a contact line of {longest} spans the domain"
    );
    for f in ["grains.png", "forces.png", "stress_crosses.png"] {
        assert!(out.join("pictures").join(f).is_file(), "{f}");
    }
}
