//! Spheropolygon rods under paper 004's law on the GPU path against the CPU reference
//! (issue 15 item 4): contact lists exact, forces to 1e-4 of the largest, the
//! sub-contact springs carried alike, a short deposition in agreement, and bitwise
//! resume.

mod common;

use serde_json::{Value, json};
use std::collections::BTreeMap;
use talus::gpu::GpuSimulation;
use talus::rng::Rng;
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
        for c in 0..cols {
            let x = 3.0 + c as f64 * pitch + rng.range(-0.1, 0.1);
            let width = rng.range(0.9, 1.0);
            // Upright rods on top, standing on an end on the rods below them.
            let upright = r + 1 == rows && c % 2 == 1;
            let half = if upright { 2.0 * width } else { 0.5 * width };
            let z = top[c] + half - rng.range(0.002, 0.008);
            top[c] = z + half;
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
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [w, 0.0] },
                        { "from": [0.0, 0.0], "to": [0.0, 20.0] },
                        { "from": [w, 0.0], "to": [w, 20.0] }]);
    v
}

/// Each contact by pair: force (x, z), torque on i, torque about j, overlap.
fn by_pair(s: &Simulation) -> BTreeMap<(u32, u32), [f64; 5]> {
    (s.pairs.iter().zip(&s.contacts))
        .map(|(p, c)| {
            (
                (p.i, p.j),
                [c.force[0], c.force[1], c.torque[0], c.torque[1], c.overlap],
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
    let keys = |m: &BTreeMap<(u32, u32), [f64; 5]>| m.keys().copied().collect::<Vec<_>>();
    assert_eq!(keys(&a), keys(&b), "{test}: the contact lists differ");
    let f_max = b.values().map(|c| c[0].hypot(c[1])).fold(0.0, f64::max);
    let t_max = b.values().map(|c| c[2].abs().max(c[3].abs())).fold(0.0, f64::max);
    let (mut df, mut dt, mut dd) = (0.0f64, 0.0f64, 0.0f64);
    let d_max = b.values().map(|c| c[4].abs()).fold(0.0, f64::max);
    for (k, c) in &b {
        let g = a[k];
        df = df.max((g[0] - c[0]).hypot(g[1] - c[1]) / f_max);
        dt = dt.max((g[2] - c[2]).abs().max((g[3] - c[3]).abs()) / t_max);
        dd = dd.max((g[4] - c[4]).abs() / d_max);
    }
    eprintln!(
        "{test}: {} contacts after {steps} steps; forces {df:.1e}, torques {dt:.1e} of the \
         largest, overlaps {dd:.1e} of the deepest",
        b.len()
    );
    assert!(b.len() >= least, "{test}: the scene is in contact ({})", b.len());
    assert!(df < tol, "{test}: forces differ by {df:.2e} of the largest");
    assert!(dt < tol, "{test}: torques differ by {dt:.2e} of the largest");
    assert!(dd < tol, "{test}: overlaps differ by {dd:.2e} of the deepest");
}

#[test]
fn rod_contacts_match_the_cpu() {
    // One step from a random state: every sub-contact kind (vertex on edge, vertex on
    // vertex, rod on disk, rod on wall interior and wall end), measured 1e-6.
    let v = random_rods(5, 8, 0.0, 1);
    assert_contacts_agree("rod_contacts_match_the_cpu", &v, 1, 1e-4, 45);
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
    assert!(g.rebuilds() >= 5, "the lists were rebuilt ({})", g.rebuilds());
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
    eprintln!("{test}: {} pairs' springs, worst {worst:.1e} of the largest", cs.len());
    assert!(worst < 2e-3, "springs differ by {worst:.2e} of the largest");
}
