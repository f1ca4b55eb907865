//! Spheropolygon rods under paper 004's law on the GPU path against the CPU reference
//! (issue 15 item 4): contact lists exact, forces to 1e-4 of the largest, the
//! sub-contact springs carried alike, a short deposition in agreement, and bitwise
//! resume.

mod common;

use serde_json::{Value, json};
use std::collections::BTreeMap;
use talus::base::rng::Rng;
use talus::gpu::GpuSimulation;
use talus::sim::Simulation;

/// `rows` × `cols` rods of aspect 4 and width 0.9–1.0 in rows, turned by up to
/// ±0.003 rad, every other one of the top row upright, with disks between them, random
/// velocities and spins, in a box of three walls: rods touch rods side by side and end
/// to side, disks end on and walls.
fn random_rods(rows: usize, cols: usize, bond: f64, seed: u64) -> Value {
    let mut rng = Rng::new(seed);
    let (mut rods, mut disks) = (Vec::new(), Vec::new());
    let pitch = 5.2;
    // Each column's top: rows rest on each other with overlaps of ~0.005 width.
    let mut top = vec![0.0f64; cols];
    for r in 0..rows {
        for (c, top) in top.iter_mut().enumerate() {
            let x = 3.0 + c as f64 * pitch + rng.range(-0.1, 0.1);
            let width = rng.range(0.9, 1.0);
            // Upright rods on top, standing on an end on the rods below them.
            let upright = r + 1 == rows && c % 2 == 1;
            let half = if upright { 2.0 * width } else { 0.5 * width };
            let z = *top + half - rng.range(0.002, 0.008);
            *top = z + half;
            let theta = if upright {
                std::f64::consts::FRAC_PI_2 + rng.range(-0.1, 0.1)
            } else {
                rng.range(-0.003, 0.003)
            };
            rods.push(json!({
                "position": [x, z],
                "theta": theta,
                "diameter": width,
                "velocity": [rng.range(-0.2, 0.2), rng.range(-0.2, 0.2)],
                "omega": rng.range(-0.3, 0.3),
            }));
            if (r + c) % 3 == 0 && !upright {
                // Against the rod's right end.
                let d = rng.range(0.7, 0.9);
                disks.push(json!({
                    "position": [x + 2.0 * width + 0.5 * d - 0.005, z],
                    "diameter": d,
                    "velocity": [rng.range(-0.5, 0.5), rng.range(-0.5, 0.5)],
                }));
            }
        }
    }
    let w = 6.0 + cols as f64 * pitch;
    let mut v = common::scene_value(
        json!({ "law": "hertz_cohesive", "k_n": 1.0e5, "k_t": 1.0e4, "gamma_n": 30.0,
                "gamma_t": 10.0, "mu": 0.5, "bond": bond, "d_c": 1.0e-4 }),
        json!([
            { "kind": "list", "material": "m", "rod": { "aspect": 4.0 }, "particles": rods },
            { "kind": "list", "material": "m", "particles": disks },
        ]),
    );
    v["dt"] = json!(1e-4);
    v["gravity"] = json!({ "g": [0.0, -10.0] });
    v["domain"] = json!({ "x": [-3.0, w + 3.0], "z": [-3.0, 3.0 + rows as f64 * 1.2 + 6.0] });
    v["limits"] = json!({ "max_overlap": 5.0 });
    let h = rows as f64 * 1.2 + 6.0;
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [w, 0.0] },
                        { "from": [0.0, 0.0], "to": [0.0, h] },
                        { "from": [w, 0.0], "to": [w, h] }]);
    v
}

/// Each contact by pair: force (x, z), torque on i, torque about j, overlap, and the
/// point it is reported at relative to i's centre.
fn by_pair(s: &Simulation) -> BTreeMap<(u32, u32), [f64; 7]> {
    (s.pairs.iter().zip(&s.contacts))
        .map(|(p, c)| {
            (
                (p.i, p.j),
                [
                    c.force[0],
                    c.force[1],
                    c.torque[0],
                    c.torque[1],
                    c.overlap,
                    c.arm[0],
                    c.arm[1],
                ],
            )
        })
        .collect()
}

/// Steps both paths from one state and compares this step's contacts: the lists
/// exactly, forces and torques to `tol` of the largest.
fn assert_contacts_agree(test: &str, v: &Value, steps: u64, tol: f64, least: usize) {
    let Some(gpu) = common::gpu(test) else { return };
    let mut cpu = common::sim(v);
    let mut g = GpuSimulation::with_gpu(common::sim(v), gpu).unwrap();
    g.advance(steps).unwrap();
    (0..steps).for_each(|_| cpu.step().unwrap());
    let gs = g.download();
    let (a, b) = (by_pair(gs), by_pair(&cpu));
    let keys = |m: &BTreeMap<(u32, u32), [f64; 7]>| m.keys().copied().collect::<Vec<_>>();
    assert_eq!(keys(&a), keys(&b), "{test}: the contact lists differ");
    let f_max = b.values().map(|c| c[0].hypot(c[1])).fold(0.0, f64::max);
    let t_max = b
        .values()
        .map(|c| c[2].abs().max(c[3].abs()))
        .fold(0.0, f64::max);
    let (mut df, mut dt, mut dd, mut dp) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let d_max = b.values().map(|c| c[4].abs()).fold(0.0, f64::max);
    for (k, c) in &b {
        let g = a[k];
        df = df.max((g[0] - c[0]).hypot(g[1] - c[1]) / f_max);
        dt = dt.max((g[2] - c[2]).abs().max((g[3] - c[3]).abs()) / t_max);
        dd = dd.max((g[4] - c[4]).abs() / d_max);
        dp = dp.max((g[5] - c[5]).hypot(g[6] - c[6]));
    }
    eprintln!(
        "{test}: {} contacts after {steps} steps; forces {df:.1e}, torques {dt:.1e} of the \
         largest, overlaps {dd:.1e} of the deepest, points {dp:.1e} widths",
        b.len()
    );
    assert!(
        b.len() >= least,
        "{test}: the scene is in contact ({})",
        b.len()
    );
    assert!(df < tol, "{test}: forces differ by {df:.2e} of the largest");
    assert!(
        dt < tol,
        "{test}: torques differ by {dt:.2e} of the largest"
    );
    assert!(
        dd < tol,
        "{test}: overlaps differ by {dd:.2e} of the deepest"
    );
    assert!(dp < tol, "{test}: contact points differ by {dp:.2e} widths");
}

#[test]
fn rod_contacts_match_the_cpu() {
    // One step from a random state: every sub-contact kind (vertex on edge, vertex on
    // vertex, rod on disk, rod on wall interior and wall end), measured 1e-6.
    let v = random_rods(5, 8, 0.0, 1);
    assert_contacts_agree("rod_contacts_match_the_cpu", &v, 1, 1e-4, 45);
}

/// Rods of aspect 10 laid as bricks (each row shifted by half a rod), rows 2·10⁻³ into
/// each other: a packing near 1, where each rod's circumscribed circle (10 widths
/// across, plus the skin) meets ~60 others.
fn brick_rods(rows: usize, cols: usize) -> Value {
    let mut rng = Rng::new(7);
    let len = 10.0;
    let list: Vec<Value> = (0..rows * cols)
        .map(|k| {
            let (r, c) = ((k / cols) as f64, (k % cols) as f64);
            let shift = if (k / cols) % 2 == 1 { 0.5 * len } else { 0.0 };
            json!({ "position": [1.0 + (c + 0.5) * (len + 0.02) + shift, 0.498 + 0.998 * r],
                    "theta": rng.range(-1e-4, 1e-4), "diameter": 1.0 })
        })
        .collect();
    let w = cols as f64 * (len + 0.02) + 0.5 * len + 2.0;
    let mut v = common::scene_value(
        json!({ "law": "hertz_cohesive", "k_n": 1.0e7, "k_t": 1.0e6, "gamma_n": 300.0,
                "gamma_t": 100.0, "mu": 0.5, "bond": 0.0, "d_c": 1.0e-4 }),
        json!([{ "kind": "list", "material": "m", "rod": { "aspect": len }, "particles": list }]),
    );
    v["dt"] = json!(1e-4);
    v["integrator"] = json!("leapfrog");
    v["gravity"] = json!({ "g": [0.0, -10.0] });
    v["domain"] = json!({ "x": [-5.0, w + 5.0], "z": [-5.0, rows as f64 + 10.0] });
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [w, 0.0] }]);
    v
}

#[test]
fn long_rods_in_a_dense_packing_fit_the_gpu_lists() {
    // The lists of rods of aspect 10 hold more than the 16 candidates of disks and
    // polygons (`gpu::list_capacity`); their contacts still match the CPU path's.
    let v = brick_rods(24, 8);
    let cap = talus::gpu::list_capacity(&common::sim(&v));
    assert!(cap >= 48, "list capacity {cap}");
    let cpu = {
        let mut s = common::sim(&v);
        s.step().unwrap();
        s
    };
    // The CPU's most candidates of one particle, as the lower id (walls too) and as the
    // higher: what the GPU's lists must hold.
    let mut per = std::collections::HashMap::new();
    for p in &cpu.neighbours.pairs {
        *per.entry((0, p.i)).or_insert(0u32) += 1;
        if !p.is_wall() {
            *per.entry((1, p.j)).or_insert(0u32) += 1;
        }
    }
    let most = per.values().copied().max().unwrap_or(0);
    eprintln!("aspect 10: up to {most} candidates of one rod, list capacity {cap}");
    assert!(
        most > 16 && most <= cap,
        "{most} candidates against a capacity of {cap}"
    );
    assert_contacts_agree(
        "long_rods_in_a_dense_packing_fit_the_gpu_lists",
        &v,
        1,
        1e-4,
        300,
    );
}

#[test]
fn cohesive_rod_contacts_and_their_springs_match_the_cpu_over_rebuilds() {
    // 400 steps with cohesion (Bo = 50): the lists are rebuilt several times, and the
    // sub-contact springs travel through the pair table on the GPU and through the
    // lists' slots on the CPU.
    let test = "cohesive_rod_contacts_and_their_springs_match_the_cpu_over_rebuilds";
    let mut v = random_rods(4, 6, 50.0, 2);
    // A thin skin: the lists are rebuilt every few dozen steps.
    v["skin"] = json!(0.005);
    assert_contacts_agree(test, &v, 400, 2e-3, 20);
    let Some(gpu) = common::gpu(test) else { return };
    let mut cpu = common::sim(&v);
    let mut g = GpuSimulation::with_gpu(common::sim(&v), gpu).unwrap();
    g.advance(400).unwrap();
    (0..400).for_each(|_| cpu.step().unwrap());
    assert!(
        g.rebuilds() >= 5,
        "the lists were rebuilt ({})",
        g.rebuilds()
    );
    let gs = g.download().spring_table().sub;
    let cs = cpu.spring_table().sub;
    assert_eq!(
        gs.keys().collect::<Vec<_>>(),
        cs.keys().collect::<Vec<_>>(),
        "pairs with sub-contact springs"
    );
    let xi_max = (cs.values())
        .flat_map(|s| s.xi[..s.count].to_vec())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(xi_max > 0.0, "some springs are stretched");
    let mut worst = 0.0f64;
    for (k, c) in &cs {
        let g = &gs[k];
        assert_eq!(g.count, c.count, "sub-contacts of pair {k:x}");
        for m in 0..c.count {
            worst = worst.max((g.get(c.key[m]) - c.xi[m]).abs() / xi_max);
        }
    }
    eprintln!(
        "{test}: {} pairs' springs, worst {worst:.1e} of the largest",
        cs.len()
    );
    assert!(worst < 2e-3, "springs differ by {worst:.2e} of the largest");
}

/// A short box deposition (paper 004's setup, reduced): 16 cohesive rods (d = 3,
/// Bo = 10) poured from a point source with random initial velocities and orientations
/// into a box 20 wide, leapfrog as in R9.
fn rod_deposition() -> talus::scene::Scene {
    let v = json!({
        "name": "rod-deposition", "dt": 2e-4, "integrator": "leapfrog", "seed": 5,
        "stop": { "time": 10.0 },
        "gravity": { "g": [0.0, -10.0] },
        "domain": { "x": [-12.0, 12.0], "z": [-2.0, 20.0] },
        "materials": { "rod": { "density": 1.0 } },
        "contact": { "law": "hertz_cohesive", "k_n": 1.0e5, "k_t": 1.0e4, "gamma_n": 30.0,
                     "gamma_t": 10.0, "mu": 0.5, "bond": 10.0, "d_c": 1.0e-4 },
        "walls": [{ "from": [-10.0, 0.0], "to": [10.0, 0.0] },
                  { "from": [-10.0, 0.0], "to": [-10.0, 15.0] },
                  { "from": [10.0, 0.0], "to": [10.0, 15.0] }],
        "particles": [{ "kind": "point_source", "material": "rod", "rod": { "aspect": 3.0 },
                        "position": [0.0, 10.0], "spread": 8.0, "rate": 8.0, "count": 16,
                        "diameter": 1.0, "velocity": [0.0, -5.0], "velocity_spread": 1.0 }],
        "output": { "checkpoint_every": 0 }
    });
    common::parse(&v)
}

#[test]
fn a_rod_deposition_agrees_with_the_cpu() {
    // Insertions with drawn velocities and orientations, free fall, impacts on the floor
    // and cohesive contacts between rods: both paths step by step, f32 against f64.
    let test = "a_rod_deposition_agrees_with_the_cpu";
    let Some(gpu) = common::gpu(test) else { return };
    let mut g = GpuSimulation::with_gpu(Simulation::new(rod_deposition()).unwrap(), gpu).unwrap();
    let mut cpu = Simulation::new(rod_deposition()).unwrap();
    // Step by step through the insertions and the first impacts (to t = 2 s) ...
    let (mut worst, mut impacts) = (0.0f64, 0);
    for _ in 0..50 {
        g.advance(200).unwrap();
        (0..200).for_each(|_| cpu.step().unwrap());
        let gs = g.download();
        assert_eq!(gs.particles.len(), cpu.particles.len(), "same insertions");
        for i in 0..cpu.particles.len() {
            let (a, b) = (gs.particles.position(i), cpu.particles.position(i));
            worst = worst.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
        impacts = impacts.max(cpu.contacts.len());
    }
    // ... then, as the deposit forms and f32 against f64 parts the two chaotic runs, in
    // their statistics: the rods' centre of mass and the contacts.
    g.advance(5000).unwrap();
    (0..5000).for_each(|_| cpu.step().unwrap());
    let (gs, n) = (g.download(), cpu.particles.len());
    let com = |s: &Simulation| {
        let p = &s.particles;
        let m: f64 = p.mass.iter().sum();
        [0, 1].map(|k| {
            (0..p.len())
                .map(|i| p.mass[i] * p.position(i)[k])
                .sum::<f64>()
                / m
        })
    };
    let (ca, cb) = (com(gs), com(&cpu));
    eprintln!(
        "{test}: {n} rods; to step 10000 (up to {impacts} contacts) positions within {worst:.1e} \
         widths; at step 15000 {} against {} contacts, centre of mass ({:.3}, {:.3}) against \
         ({:.3}, {:.3})",
        gs.contacts.len(),
        cpu.contacts.len(),
        ca[0],
        ca[1],
        cb[0],
        cb[1]
    );
    assert_eq!(n, 16, "every rod was poured");
    assert!(impacts > 3, "rods have reached the floor by step 10000");
    // Measured: 1.1e-5 widths (after the first impacts; 1e-6 before).
    assert!(worst < 1e-4, "positions differ by {worst:.2e} widths");
    assert!(cpu.contacts.len() > 12, "the rods lie in a deposit");
    assert!(
        (ca[0] - cb[0]).abs() < 0.5 && (ca[1] - cb[1]).abs() < 0.2,
        "centre of mass"
    );
    let (a, b) = (gs.contacts.len() as f64, cpu.contacts.len() as f64);
    assert!((a - b).abs() <= 0.2 * b, "contacts");
}

#[test]
fn gpu_rod_runs_resume_bitwise() {
    // The sub-contact springs go through the checkpoint's device section (GPU) or its
    // spring table (CPU), and a pending rod's velocity kick through its source's state.
    let (test, scene) = ("gpu_rod_runs_resume_bitwise", rod_deposition());
    let check = common::carries_sub_springs;
    for path in common::PATHS {
        let Some(e) = common::assert_resumes_bitwise(path, test, &scene, 15000, 7500, check) else {
            continue;
        };
        assert_eq!(e.active_count(), 16, "{path:?}: every rod was poured");
    }
}
