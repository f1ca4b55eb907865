//! Each GPU kernel against its CPU twin on random inputs (issue 3). The GPU works in
//! f32, the CPU in f64; integer stages (cell list, prefix sum, contact lists, spring
//! table) must agree exactly, float stages within the tolerances stated at each test.

mod common;

use serde_json::json;
use std::collections::BTreeMap;
use talus::base::rng::Rng;
use talus::cpu::cell_list::{CellList, Grid, prefix_sum};
use talus::cpu::contacts::{Pair, find_contacts};
use talus::cpu::forces::{contact_forces, reduce_forces};
use talus::cpu::orientation::{RotatedCorners, rotate_corners};
use talus::gpu::layout::control::REBUILD;
use talus::gpu::layout::{Entry, MAX_CONTACTS};
use talus::gpu::modules::Kernel;
use talus::gpu::{GpuSimulation, REBUILD_STAGES, workgroups};

/// `n` disks of diameter 0.8–1.2 on a jittered lattice in a box with walls, some
/// overlapping, with random velocities and spins; every 7th one fixed.
fn random_scene(n: usize, law: serde_json::Value, seed: u64) -> serde_json::Value {
    let mut rng = Rng::new(seed);
    let cols = (n as f64).sqrt().ceil() as usize;
    let list: Vec<_> = (0..n)
        .map(|k| {
            let (c, r) = ((k % cols) as f64, (k / cols) as f64);
            json!({
                "position": [c * 1.0 + rng.range(-0.1, 0.1) + 0.7, r * 1.0 + rng.range(-0.1, 0.1) + 0.7],
                "theta": rng.range(-4.0, 4.0),
                "diameter": rng.range(0.8, 1.2),
                "velocity": [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)],
                "omega": rng.range(-2.0, 2.0),
                "fixed": k % 7 == 3
            })
        })
        .collect();
    let w = cols as f64 + 1.5;
    let polygons = law["law"] == "overlap_area";
    let mut block = json!({ "kind": "list", "material": "m", "particles": list });
    if polygons {
        block["polygon"] = json!({ "corners": 7 });
    }
    let mut v = common::scene_value(law, json!([block]));
    v["dt"] = json!(2e-4);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["domain"] = json!({ "x": [-3.0, w + 3.0], "z": [-3.0, w + 3.0] });
    // Random placement gives deep overlaps; the divergence check must not halt the kernels.
    v["limits"] = json!({
        "max_overlap": if polygons { 10.0 } else { 0.9 },
        "initial_overlap": 1e9
    });
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [w, 0.0] }, { "from": [0.0, 0.0], "to": [0.0, w] },
                        { "from": [w, 0.0], "to": [w, w] }]);
    v
}

/// `random_scene` of heptagons with every third particle a disk instead.
fn mixed_scene(n: usize, seed: u64) -> serde_json::Value {
    let mut v = random_scene(n, polygons(), seed);
    let all = v["particles"][0]["particles"].as_array().unwrap().clone();
    let (disks, polys): (Vec<_>, Vec<_>) =
        all.into_iter().enumerate().partition(|(k, _)| k % 3 == 0);
    let strip =
        |l: Vec<(usize, serde_json::Value)>| l.into_iter().map(|(_, p)| p).collect::<Vec<_>>();
    v["particles"] = json!([
        { "kind": "list", "material": "m", "particles": strip(polys), "polygon": { "corners": 7 } },
        { "kind": "list", "material": "m", "particles": strip(disks) }
    ]);
    v
}

fn spring_dashpot() -> serde_json::Value {
    json!({ "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 5.0, "k_t": 500.0, "gamma_t": 1.0, "mu": 0.5 })
}

/// Heptagons with the overlap-area law (paper 000 sec. 2.2).
fn polygons() -> serde_json::Value {
    json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 })
}

fn continuous() -> serde_json::Value {
    json!({ "law": "continuous", "n": 36.0, "r0": 1.2, "mu": 0.5 })
}

/// The CPU grid the GPU uses: the same origin, and the cell size rounded up to f32.
fn gpu_grid(g: &GpuSimulation) -> Grid {
    let mut grid = g.grid.clone();
    grid.cell_size = g.params.cell_size as f64;
    grid
}

fn setup(test: &str, v: &serde_json::Value) -> Option<GpuSimulation> {
    let gpu = common::gpu(test)?;
    Some(GpuSimulation::with_gpu(common::sim(v), gpu).expect("uploads"))
}

/// Runs the cell list and find_contacts on the GPU (a rebuild of the neighbour lists);
/// returns the candidates in list order.
fn gpu_candidates(g: &mut GpuSimulation) -> Vec<Pair> {
    let mut ks = GpuSimulation::CELL_LIST.to_vec();
    ks.push(Kernel::FindContacts);
    g.run_kernels(&ks);
    let n = g.live() as usize;
    let count = g.read_u32("contact_count", n);
    let js = g.read_u32("contact_j", n * MAX_CONTACTS as usize);
    let mut pairs = Vec::new();
    for i in 0..n {
        for k in 0..count[i] as usize {
            pairs.push(Pair {
                i: i as u32,
                j: js[i * MAX_CONTACTS as usize + k],
            });
        }
    }
    pairs
}

/// The slots (i · MAX_CONTACTS + k) of the candidates that touched at the last
/// contact_forces, in list order.
fn touching_slots(g: &GpuSimulation) -> Vec<usize> {
    let n = g.live() as usize;
    let m = MAX_CONTACTS as usize;
    let count = g.read_u32("contact_count", n);
    let touching = g.read_u32("touching", n * m);
    (0..n)
        .flat_map(|i| (0..count[i] as usize).map(move |k| i * m + k))
        .filter(|&s| touching[s] != 0)
        .collect()
}

/// The GPU's contacts: the candidates of a rebuild that touch at the evaluation.
fn gpu_pairs(g: &mut GpuSimulation) -> Vec<Pair> {
    gpu_candidates(g);
    g.run_kernels(&[Kernel::GatherHistory, Kernel::ContactForces]);
    let m = MAX_CONTACTS as usize;
    let js = g.read_u32("contact_j", g.live() as usize * m);
    let slots = touching_slots(g);
    slots
        .into_iter()
        .map(|s| Pair {
            i: (s / m) as u32,
            j: js[s],
        })
        .collect()
}

#[test]
fn cell_list_matches_the_cpu() {
    let Some(mut g) = setup(
        "cell_list_matches_the_cpu",
        &random_scene(500, spring_dashpot(), 1),
    ) else {
        return;
    };
    g.run_kernels(&GpuSimulation::CELL_LIST);
    let host = g.download().clone();
    let grid = gpu_grid(&g);
    let mut cpu = CellList::default();
    cpu.build(&grid, &host.particles.q[0], &host.particles.active);
    let n = host.particles.len();
    let cells = grid.cell_count();
    assert_eq!(
        g.read_u32("cell_of", n),
        cpu.cell_of,
        "cell of each particle"
    );
    assert_eq!(g.read_u32("cell_count", cells), cpu.count, "histogram");
    assert_eq!(
        g.read_u32("cell_start", cells),
        cpu.start,
        "exclusive prefix sum"
    );
    // Within a cell the GPU order comes from atomics; as sets the cells must agree.
    let mut sorted = g.read_u32("sorted", n);
    for c in 0..cells {
        let (a, b) = (
            cpu.start[c] as usize,
            (cpu.start[c] + cpu.count[c]) as usize,
        );
        sorted[a..b].sort_unstable();
    }
    assert_eq!(sorted, cpu.sorted, "scatter");
}

#[test]
fn prefix_sum_matches_the_cpu_on_all_three_levels() {
    // A domain of 333 × 333 cells (of 2.4 d: the largest diameter's cells doubled to
    // hold the neighbour lists' skin): 110 889 counts, several level-1 and level-2
    // blocks. 20 000 particles, so that the grid stays dense (a grid with more than four
    // times its ~2 buckets per particle is hashed).
    let mut v = random_scene(20_000, spring_dashpot(), 2);
    v["domain"] = json!({ "x": [-3.0, 797.0], "z": [-3.0, 797.0] });
    let Some(mut g) = setup("prefix_sum_matches_the_cpu_on_all_three_levels", &v) else {
        return;
    };
    let cells = g.params.cells as usize;
    assert_eq!(cells, (g.params.nx * g.params.nz) as usize, "a dense grid");
    assert!(g.params.scan_blocks2 > 1, "the test must reach level 2");
    let mut rng = Rng::new(5);
    let counts: Vec<u32> = (0..cells).map(|_| (rng.uniform() * 4.0) as u32).collect();
    g.upload_cell_counts(&counts);
    g.run_kernels(&[
        Kernel::ScanLevel0,
        Kernel::ScanLevel1,
        Kernel::ScanLevel2,
        Kernel::ScanAdd1,
        Kernel::ScanAdd0,
    ]);
    let mut expect = Vec::new();
    prefix_sum(&counts, &mut expect);
    assert_eq!(g.read_u32("cell_start", cells), expect);
}

#[test]
fn find_contacts_matches_the_cpu_for_both_laws() {
    for (name, law) in [
        ("spring_dashpot", spring_dashpot()),
        ("continuous", continuous()),
        ("polygons", polygons()),
        ("mixed", json!("mixed")),
    ] {
        let scene = if law == "mixed" {
            mixed_scene(600, 3)
        } else {
            random_scene(600, law, 3)
        };
        let Some(mut g) = setup("find_contacts_matches_the_cpu", &scene) else {
            return;
        };
        let pairs = gpu_pairs(&mut g);
        let host = g.download().clone();
        let grid = gpu_grid(&g);
        let mut cells = CellList::default();
        cells.build(&grid, &host.particles.q[0], &host.particles.active);
        let mut shapes = RotatedCorners::default();
        rotate_corners(&host.particles, &mut shapes);
        let mut cpu = Vec::new();
        find_contacts(
            &grid,
            &cells,
            &host.particles,
            &shapes,
            &host.walls,
            host.law.range_factor(),
            &mut cpu,
        );
        // Heptagons inscribed in the disks' circles touch less often.
        let dense = if name == "polygons" || name == "mixed" {
            300
        } else {
            500
        };
        assert!(
            cpu.len() > dense,
            "{name}: a dense packing ({} contacts)",
            cpu.len()
        );
        assert_eq!(pairs, cpu, "{name}: same contacts in the same order");
    }
}

/// The CPU's contact forces and updated histories for the given pairs of `host`.
fn cpu_contact_forces(
    host: &talus::sim::Simulation,
    pairs: &[Pair],
    history: &[f64],
) -> (Vec<talus::cpu::forces::ContactForce>, Vec<f64>) {
    let (mut cpu, mut hist_out) = (Vec::new(), Vec::new());
    let mut shapes = RotatedCorners::default();
    rotate_corners(&host.particles, &mut shapes);
    contact_forces(
        &host.particles,
        &shapes,
        &host.walls,
        &host.wall_velocity,
        &host.law,
        &host.rolling,
        host.dt(),
        pairs,
        history,
        &mut cpu,
        &mut hist_out,
    );
    (cpu, hist_out)
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

#[test]
fn contact_forces_and_reduction_match_the_cpu() {
    // f32 against f64: geometry carries ~1e-7 of a diameter, and the overlaps here are
    // 1e-2..1e-1 of a diameter, so forces agree to ~1e-5 of the largest contact force;
    // 1e-4 leaves room for the velocity terms and the 6-10 term sums.
    for (name, law) in [
        ("spring_dashpot", spring_dashpot()),
        ("continuous", continuous()),
        ("polygons", polygons()),
        ("mixed", json!("mixed")),
    ] {
        let scene = if law == "mixed" {
            mixed_scene(400, 4)
        } else {
            random_scene(400, law, 4)
        };
        let Some(mut g) = setup("contact_forces_match_the_cpu", &scene) else {
            return;
        };
        let pairs = gpu_pairs(&mut g);
        // Give every contact a previous history so the tangential laws are exercised.
        let mut rng = Rng::new(9);
        let entries: Vec<Entry> = pairs
            .iter()
            .map(|p| Entry {
                i: p.i,
                j: p.j,
                value: rng.range(-2e-3, 2e-3) as f32,
                _pad: 0,
            })
            .collect();
        // The table is read at a rebuild: the contacts' slots get their springs, the
        // other candidates' 0.
        g.upload_springs(&entries);
        g.run_kernels(&[Kernel::GatherHistory]);
        let n = g.live() as usize;
        let slots = touching_slots(&g);
        let hist_in = g.read_f32("hist_in", n * MAX_CONTACTS as usize);
        for (k_global, &slot) in slots.iter().enumerate() {
            assert_eq!(
                hist_in[slot], entries[k_global].value,
                "{name}: gathered history"
            );
        }
        let listed = g.read_u32("contact_count", n).iter().sum::<u32>() as usize;
        let zeros = hist_in.iter().filter(|h| **h == 0.0).count();
        assert!(
            zeros + slots.len() >= listed,
            "{name}: other candidates start at 0"
        );
        g.run_kernels(&[Kernel::ContactForces, Kernel::ReduceForces]);
        assert_eq!(touching_slots(&g), slots, "{name}: the same contacts");
        let host = g.download().clone();
        let history: Vec<f64> = entries.iter().map(|e| e.value as f64).collect();
        let (cpu, hist_out) = cpu_contact_forces(&host, &pairs, &history);
        let scale = cpu.iter().map(|c| c.f_n.abs()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        let out = g.read_contact_out(n * MAX_CONTACTS as usize);
        // The history is updated in the slot.
        let gpu_hist = g.read_f32("hist_in", n * MAX_CONTACTS as usize);
        let mut worst: f64 = 0.0;
        let hscale = hist_out.iter().map(|h| h.abs()).fold(1e-12, f64::max);
        for (k_global, &slot) in slots.iter().enumerate() {
            {
                let o = out[slot];
                let c = cpu[k_global];
                worst = worst
                    .max(rel(o.ft[0] as f64, c.force[0], scale))
                    .max(rel(o.ft[1] as f64, c.force[1], scale))
                    .max(rel(o.info[0] as f64, c.f_n, scale))
                    .max(rel(o.info[1] as f64, c.f_t, scale));
                let dh = rel(gpu_hist[slot] as f64, hist_out[k_global], hscale);
                assert!(
                    dh < 1e-4,
                    "{name}: history of contact {k_global} {:?} differs by {dh:.2e}: gpu {} cpu {} (in {}), gpu out {:?} cpu {:?}",
                    pairs[k_global],
                    gpu_hist[slot],
                    hist_out[k_global],
                    history[k_global],
                    o,
                    c
                );
            }
        }
        assert!(
            worst < 1e-4,
            "{name}: forces differ by {worst:.2e} of the largest"
        );
        let mut f = Vec::new();
        reduce_forces(&host.particles, &pairs, &cpu, &mut f);
        let gf = g.read_forces(n);
        let tscale = scale * 1.2;
        for i in 0..n {
            for d in 0..3 {
                let s = if d == 2 { tscale } else { scale };
                let e = rel(gf[i][d] as f64, f[i][d], s);
                assert!(
                    e < 1e-4,
                    "{name}: reduced force {d} of particle {i} differs by {e:.2e}"
                );
            }
        }
    }
}

#[test]
fn spring_table_survives_contact_churn() {
    // 300 particles, random contact lists that persist (80 %), open and close each step;
    // the GPU table must give back exactly the value stored for every persisting pair
    // and 0 for every new one, never losing or duplicating a spring.
    let Some(mut g) = setup(
        "spring_table_survives_contact_churn",
        &random_scene(300, spring_dashpot(), 6),
    ) else {
        return;
    };
    let n = g.live() as usize;
    let m = MAX_CONTACTS as usize;
    let mut rng = Rng::new(11);
    let mut reference: BTreeMap<(u32, u32), f32> = BTreeMap::new();
    for step in 0..40 {
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
        for &(i, j) in reference.keys() {
            if rng.uniform() < 0.8 {
                lists[i as usize].push(j);
            }
        }
        for _ in 0..200 {
            let i = (rng.uniform() * (n - 1) as f64) as usize;
            let j = (i + 1 + (rng.uniform() * 30.0) as usize).min(n - 1) as u32;
            lists[i].push(if rng.uniform() < 0.1 {
                0xFFFF_0000 + (rng.uniform() * 3.0) as u32
            } else {
                j
            });
        }
        let (mut count, mut js, mut values) = (vec![0u32; n], vec![0u32; n * m], vec![0f32; n * m]);
        let mut next = BTreeMap::new();
        for (i, l) in lists.iter_mut().enumerate() {
            l.sort_unstable();
            l.dedup();
            l.truncate(m);
            count[i] = l.len() as u32;
            for (k, &j) in l.iter().enumerate() {
                js[i * m + k] = j;
                let v = (step * 1000 + i * 16 + k) as f32;
                values[i * m + k] = v;
                next.insert((i as u32, j), v);
            }
        }
        // A rebuild: the new lists take their springs from the table...
        g.upload_contacts(&count, &js, &vec![0.0; n * m]);
        g.run_kernels(&[Kernel::GatherHistory]);
        let hist = g.read_f32("hist_in", n * m);
        for i in 0..n {
            for k in 0..count[i] as usize {
                let j = js[i * m + k];
                let want = reference.get(&(i as u32, j)).copied().unwrap_or(0.0);
                assert_eq!(hist[i * m + k], want, "step {step}: pair ({i}, {j})");
            }
        }
        // ...which the next rebuild fills from these lists' springs.
        g.upload_contacts(&count, &js, &values);
        g.set_list_flags(REBUILD);
        g.run_kernels(&[Kernel::ClearTable, Kernel::StoreHistory]);
        let stored = g.download().springs.len();
        assert_eq!(
            stored,
            next.len(),
            "step {step}: no lost or duplicated springs"
        );
        reference = next;
    }
}

#[test]
fn one_step_of_each_integrator_matches_the_cpu() {
    // A whole step (predict, contacts, forces, correct, boundaries) from the same f32
    // state. Positions move by ~v dt = 2e-4 per step; f32 offsets carry 6e-8 of a cell,
    // so positions agree to 1e-6 and scaled velocities q1 to 1e-3 of their size.
    for integrator in ["gear5", "leapfrog"] {
        let mut v = random_scene(300, spring_dashpot(), 7);
        v["integrator"] = json!(integrator);
        let Some(mut g) = setup("one_step_of_each_integrator_matches_the_cpu", &v) else {
            return;
        };
        // Start both from the f32-rounded state.
        let mut cpu = g.download().clone();
        g.advance(1).expect("no divergence");
        cpu.step().expect("no divergence");
        let host = g.download();
        let q1_scale = cpu.particles.q[1]
            .iter()
            .map(|q| q[0].abs().max(q[1].abs()))
            .fold(0.0, f64::max);
        for i in 0..cpu.particles.len() {
            let (a, b) = (host.particles.q[0][i], cpu.particles.q[0][i]);
            for d in 0..3 {
                // Orientations come back from the device in [-π, π).
                let mut diff = a[d] - b[d];
                if d == 2 {
                    diff = (diff + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI;
                }
                assert!(
                    diff.abs() < 1e-6,
                    "{integrator}: q0[{d}] of {i}: {} vs {}",
                    a[d],
                    b[d]
                );
            }
            let (a, b) = (host.particles.q[1][i], cpu.particles.q[1][i]);
            for d in 0..2 {
                assert!(
                    rel(a[d], b[d], q1_scale) < 1e-3,
                    "{integrator}: q1[{d}] of {i}: {} vs {}",
                    a[d],
                    b[d]
                );
            }
        }
    }
}

#[test]
fn corner_rotation_matches_the_host_twin_bit_for_bit() {
    // orientation.wgsl rotates polygon corners with Q31 sin and cos in integers; its
    // host twin (src/gpu/orientation.rs, itself checked against f64 to 2e-9) must give
    // the very same integers on the device.
    use common::wgsl::{COMMON, ORIENTATION, POSITION, run_wgsl_fn};
    use talus::gpu::orientation::{rotate_units, turn_sin_cos};
    let n = 8192usize;
    let mut rng = Rng::new(17);
    let input: Vec<[i32; 4]> = (0..n)
        .map(|k| {
            // Random turns, and the quarter-turn boundaries with their neighbours.
            let turn = if k < 64 {
                ((k as u32 / 16) << 30).wrapping_add([0, 1, u32::MAX, 0x1FFF_FFFF][k % 4])
            } else {
                (rng.uniform() * 4_294_967_296.0) as u32
            };
            let c = |r: &mut Rng| (r.range(-1.0, 1.0) * 5.3e8) as i32;
            [turn as i32, c(&mut rng), c(&mut rng), 0]
        })
        .collect();
    let words: Vec<[u32; 4]> = input.iter().map(|x| x.map(|v| v as u32)).collect();
    let body = "
    let x = bitcast<vec4<i32>>(wgsl_arg(k, 0u));
    let sc = turn_sin_cos(bitcast<u32>(x.x));
    wgsl_put(k, 0u, bitcast<vec4<u32>>(vec4<i32>(sc, rotate_units(x.yz, sc))));";
    let Some(out) = run_wgsl_fn(
        "corner_rotation_matches_the_host_twin",
        &[COMMON, POSITION, ORIENTATION],
        &talus::gpu::layout::Params::default(),
        (1, 1),
        body,
        &words,
    ) else {
        return;
    };
    let got: Vec<[i32; 4]> = out.iter().map(|w| w.map(|v| v as i32)).collect();
    let mut differ = 0;
    for (x, g) in input.iter().zip(&got) {
        let sc = turn_sin_cos(x[0] as u32);
        let w = rotate_units([x[1], x[2]], sc);
        if [sc[0], sc[1], w[0], w[1]] != *g {
            differ += 1;
            if differ < 5 {
                eprintln!("turn {:#x}: device {g:?}, host {sc:?} {w:?}", x[0] as u32);
            }
        }
    }
    assert_eq!(
        differ, 0,
        "{differ} of {n} rotations differ from the host twin"
    );
}

/// Pairs of polygons at rest, each pair just touching and then pushed together by a
/// gap of 1e-6..1e-3 d along the line of centres; half of them face to face (regular
/// 12-gons at equal orientation, along a face normal), half at random orientations
/// (heptagons). Returns the simulation with the pairs (2k, 2k + 1).
fn touching_pairs(pairs: usize, seed: u64) -> talus::sim::Simulation {
    use talus::overlap::polygon_polygon;
    use talus::shape::world;
    let mut rng = Rng::new(seed);
    let mut blocks = Vec::new();
    for (corners, diameter) in [(12, 1.0), (7, 1.1)] {
        let list: Vec<_> = (0..pairs)
            .flat_map(|k| {
                let x = 3.0 * k as f64;
                let z = if corners == 7 { 5.0 } else { 2.0 };
                [
                    json!({ "position": [x, z], "diameter": diameter }),
                    json!({ "position": [x, z + 2.0], "diameter": diameter }),
                ]
            })
            .collect();
        blocks.push(json!({ "kind": "list", "material": "m", "particles": list,
                            "polygon": { "corners": corners } }));
    }
    let mut v = common::scene_value(polygons(), json!(blocks));
    v["contact"]["k_n"] = json!(1.0e7);
    v["dt"] = json!(1e-5);
    v["domain"] = json!({ "x": [-3.0, 3.0 * pairs as f64 + 5.0], "z": [-2.0, 8.0] });
    let mut sim = common::sim(&v);
    let p = &mut sim.particles;
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for k in 0..p.len() / 2 {
        let (i, j) = (2 * k, 2 * k + 1);
        let face = p.shape[i].len() == 12;
        // Every fourth face-to-face pair axis-aligned, as on a lattice.
        let ti = if face && k % 4 == 0 {
            0.0
        } else {
            rng.range(-3.2, 3.2)
        };
        let tj = if face { ti } else { rng.range(-3.2, 3.2) };
        world(&p.shape[i], [0.0, 0.0], ti, &mut a);
        let u = if face {
            // Outward normal of p's edge 0.
            let e = [a[1][0] - a[0][0], a[1][1] - a[0][1]];
            let l = e[0].hypot(e[1]);
            [e[1] / l, -e[0] / l]
        } else {
            let t = rng.range(0.0, std::f64::consts::TAU);
            [t.cos(), t.sin()]
        };
        let ci = p.q[0][i];
        let touch = |s: f64, b: &mut Vec<[f64; 2]>| {
            world(&p.shape[j], [s * u[0], s * u[1]], tj, b);
            polygon_polygon(
                &a,
                &common::relative(b, [s * u[0], s * u[1]]),
                [-s * u[0], -s * u[1]],
            )
            .is_some()
        };
        let (mut lo, mut hi) = (0.0, 2.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if touch(mid, &mut b) {
                lo = mid
            } else {
                hi = mid
            }
        }
        // Face to face A/l is the gap; corner first it grows as the gap squared.
        let gap = if face {
            10f64.powf(rng.range(-6.0, -3.0))
        } else {
            10f64.powf(rng.range(-3.0, -1.5))
        };
        let s = lo - gap;
        p.q[0][i] = [ci[0], ci[1], ti];
        p.q[0][j] = [ci[0] + s * u[0], ci[1] + s * u[1], tj];
    }
    sim
}

/// A contact with its A/l (or overlap) on the GPU and on the CPU path.
type Compared = (Pair, f64, f64);

/// Each contact the GPU finds in `sim`, compared at the same state; None without an
/// adapter.
fn gpu_and_cpu_overlaps(
    test: &str,
    sim: talus::sim::Simulation,
) -> Option<(talus::sim::Simulation, Vec<Compared>)> {
    let gpu = common::gpu(test)?;
    let mut g = GpuSimulation::with_gpu(sim, gpu).expect("uploads");
    let pairs = gpu_pairs(&mut g);
    let host = g.download().clone();
    let n = host.particles.len();
    let (cpu, _) = cpu_contact_forces(&host, &pairs, &vec![0.0; pairs.len()]);
    let out = g.read_contact_out(n * MAX_CONTACTS as usize);
    let rows = touching_slots(&g)
        .into_iter()
        .enumerate()
        .map(|(k, slot)| (pairs[k], out[slot].info[2] as f64, cpu[k].overlap))
        .collect();
    Some((host, rows))
}

#[test]
fn polygon_overlaps_are_exact_down_to_1e_6_d() {
    // SPEC 3: overlaps of resting contacts right to 1e-3 relative. Polygon overlaps of
    // 1e-7..1e-3 d (A/l), face to face and corner first: the GPU's exact area
    // (polygon.wgsl `exact_area`) against the f64 CPU path.
    let Some((host, rows)) =
        gpu_and_cpu_overlaps("polygon_overlaps_are_exact", touching_pairs(40, 21))
    else {
        return;
    };
    let pairs: Vec<Pair> = rows.iter().map(|r| r.0).collect();
    // Worst error beyond 1e-3 relative, in d (= 1 here).
    let (mut worst_face, mut worst_random, mut smallest) = (0.0f64, 0.0f64, f64::MAX);
    for &(p, gpu, cpu) in &rows {
        let e = (gpu - cpu).abs() - 1e-3 * cpu;
        smallest = smallest.min(cpu);
        if host.particles.shape[p.i as usize].len() == 12 {
            worst_face = worst_face.max(e);
        } else {
            worst_random = worst_random.max(e);
        }
    }
    eprintln!(
        "A/l beyond 1e-3 relative: face to face {worst_face:.2e} d, corner first {worst_random:.2e} d; smallest A/l {smallest:.2e} d"
    );
    assert_eq!(
        pairs.len(),
        80,
        "every pair touches, and only its own partner"
    );
    // Corners are whole position units (~1e-9 d) on the GPU and f64 on the CPU: the two
    // shapes differ by up to a unit, and a sliver's A/l with them (measured 2e-9 d).
    // SPEC 3's 1e-3 thus holds from A/l = 5e-6 d up.
    assert!(
        worst_face < 5e-9 && worst_random < 5e-9,
        "A/l off by more than 1e-3 relative + 5e-9 d: {worst_face:.2e}, {worst_random:.2e}"
    );
}

#[test]
fn deep_polygon_overlaps_with_many_crossings_agree_with_the_cpu() {
    // polygon.wgsl keeps the exact (u, w) of four crossings in registers; a deeper
    // overlap (two 12-gons nearly on top of each other cross up to 24 times) takes the
    // f32 area of its edges' parts inside each other instead. Pairs of 12-gons and of
    // heptagons with centres 0.02-0.8 d apart, at random orientations, and heptagons
    // with a disk 0.05-0.6 d from their centre (the polygon-disk branch for deep
    // overlaps, which finds its crossings again for each pair of edges): A/l, the
    // normal and the arm agree with the f64 CPU path.
    let mut rng = Rng::new(29);
    let n = 40;
    let mut blocks = Vec::new();
    for (corners, diameter) in [(12, 1.0), (7, 1.1)] {
        let list: Vec<_> = (0..n)
            .flat_map(|k| {
                let (x, z) = (3.0 * k as f64, if corners == 7 { 5.0 } else { 2.0 });
                let s = rng.range(0.02, 0.8);
                let t = rng.range(0.0, std::f64::consts::TAU);
                [
                    json!({ "position": [x, z], "diameter": diameter,
                            "theta": rng.range(-3.2, 3.2) }),
                    json!({ "position": [x + s * t.cos(), z + s * t.sin()],
                            "diameter": diameter, "theta": rng.range(-3.2, 3.2) }),
                ]
            })
            .collect();
        blocks.push(json!({ "kind": "list", "material": "m", "particles": list,
                            "polygon": { "corners": corners } }));
    }
    // Heptagon k (id 4n + k) and disk k (id 5n + k).
    let (mut heptagons, mut disks) = (Vec::new(), Vec::new());
    for k in 0..n {
        let (x, z) = (3.0 * k as f64, 8.0);
        let s = rng.range(0.05, 0.6);
        let t = rng.range(0.0, std::f64::consts::TAU);
        heptagons
            .push(json!({ "position": [x, z], "diameter": 1.1, "theta": rng.range(-3.2, 3.2) }));
        disks.push(json!({ "position": [x + s * t.cos(), z + s * t.sin()],
                           "diameter": rng.range(0.5, 1.2) }));
    }
    blocks.push(
        json!({ "kind": "list", "material": "m", "particles": heptagons,
                        "polygon": { "corners": 7 } }),
    );
    blocks.push(json!({ "kind": "list", "material": "m", "particles": disks }));
    let mut v = common::scene_value(polygons(), json!(blocks));
    v["domain"] = json!({ "x": [-3.0, 3.0 * n as f64 + 5.0], "z": [-2.0, 11.0] });
    v["limits"] = json!({ "max_overlap": 1e9, "initial_overlap": 1e300 });
    let Some(gpu) = common::gpu("deep_polygon_overlaps") else {
        return;
    };
    let mut g = GpuSimulation::with_gpu(common::sim(&v), gpu).expect("uploads");
    let pairs = gpu_pairs(&mut g);
    let host = g.download().clone();
    let m = host.particles.len();
    let (cpu, _) = cpu_contact_forces(&host, &pairs, &vec![0.0; pairs.len()]);
    let out = g.read_contact_out(m * MAX_CONTACTS as usize);
    let slots = touching_slots(&g);
    assert_eq!(
        pairs.len(),
        3 * n,
        "every pair overlaps, and only its own partner"
    );
    let (mut worst_delta, mut worst_disk) = (0.0f64, 0.0f64);
    let (mut worst_n, mut worst_arm) = (0.0f64, 0.0f64);
    for (k, &slot) in slots.iter().enumerate() {
        let (o, c) = (&out[slot], &cpu[k]);
        let delta = (o.info[2] as f64 - c.overlap).abs() / c.overlap;
        if k < 2 * n {
            worst_delta = worst_delta.max(delta);
        } else if c.overlap < 100.0 {
            // Polygon-disk, deep: the general formula in f32 (polygon.wgsl), to ~3e-4;
            // beyond A/l = 100 d the force point is on a centre, and the arm's floor
            // (1e-6 of the pair's size on the GPU, 1e-9 on the CPU) sets A/l.
            worst_disk = worst_disk.max(delta);
        }
        worst_n = worst_n.max((o.geo[0] as f64 - c.n[0]).hypot(o.geo[1] as f64 - c.n[1]));
        worst_arm = worst_arm.max((o.geo[2] as f64 - c.arm[0]).hypot(o.geo[3] as f64 - c.arm[1]));
    }
    eprintln!(
        "A/l {worst_delta:.2e} relative (polygon-disk {worst_disk:.2e}), normal {worst_n:.2e}, arm {worst_arm:.2e} d"
    );
    assert!(
        worst_delta < 1e-4,
        "A/l differs by {worst_delta:.2e} relative"
    );
    assert!(
        worst_disk < 1e-3,
        "polygon-disk A/l differs by {worst_disk:.2e} relative"
    );
    assert!(
        worst_n < 1e-3 && worst_arm < 1e-3,
        "normal {worst_n:.2e}, arm {worst_arm:.2e} d"
    );
}

/// Touching pairs with disks under the overlap-area law: a regular 12-gon and a disk
/// along a face normal, an irregular heptagon and a disk from a random direction (corner
/// first, mostly), two disks; each pushed together by a random gap. And disks resting on
/// the floor by a random overlap. Pairs are (2k, 2k + 1); the floor disks come last.
fn touching_mixed(pairs: usize, seed: u64) -> talus::sim::Simulation {
    use talus::overlap::polygon_disk;
    use talus::shape::world;
    let mut rng = Rng::new(seed);
    let mut blocks = Vec::new();
    let kinds = [(Some(12), 1.0), (Some(7), 1.1), (None, 1.0)];
    for k in 0..3 * pairs {
        let (corners, d) = kinds[k % 3];
        let x = 5.0 * k as f64;
        let mut first = json!({ "kind": "list", "material": "m",
            "particles": [{ "position": [x, 2.0], "diameter": d }] });
        if let Some(c) = corners {
            first["polygon"] = json!({ "corners": c, "irregular": c == 7 });
        }
        blocks.push(first);
        let dj = rng.range(0.7, 1.3);
        blocks.push(json!({ "kind": "list", "material": "m",
            "particles": [{ "position": [x, 4.0], "diameter": dj }] }));
    }
    for k in 0..pairs {
        blocks.push(json!({ "kind": "list", "material": "m",
            "particles": [{ "position": [5.0 * k as f64, 7.0], "diameter": rng.range(0.7, 1.3) }] }));
    }
    let mut v = common::scene_value(polygons(), json!(blocks));
    v["contact"]["k_n"] = json!(1.0e7);
    v["dt"] = json!(1e-5);
    let w = 15.0 * pairs as f64 + 5.0;
    v["domain"] = json!({ "x": [-3.0, w], "z": [-2.0, 10.0] });
    v["walls"] = json!([{ "from": [-3.0, 6.0], "to": [w, 6.0] }]);
    let mut sim = common::sim(&v);
    let p = &mut sim.particles;
    let mut a = Vec::new();
    for k in 0..3 * pairs {
        let (i, j) = (2 * k, 2 * k + 1);
        let ti = rng.range(-3.2, 3.2);
        let rj = p.radius[j];
        let ci = p.q[0][i];
        let u = match k % 3 {
            0 => {
                world(&p.shape[i], [0.0, 0.0], ti, &mut a);
                let e = [a[1][0] - a[0][0], a[1][1] - a[0][1]];
                let l = e[0].hypot(e[1]);
                [e[1] / l, -e[0] / l]
            }
            _ => {
                let t = rng.range(0.0, std::f64::consts::TAU);
                [t.cos(), t.sin()]
            }
        };
        let touch = |s: f64, a: &mut Vec<[f64; 2]>| match k % 3 {
            2 => s < p.radius[i] + rj,
            _ => {
                world(&p.shape[i], [0.0, 0.0], ti, a);
                polygon_disk(a, [-s * u[0], -s * u[1]], rj, true).is_some()
            }
        };
        let (mut lo, mut hi) = (0.0, 3.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if touch(mid, &mut a) {
                lo = mid
            } else {
                hi = mid
            }
        }
        // A face or a disk: A/l grows as the gap; a corner into a disk as its square.
        let gap = if k % 3 == 1 {
            10f64.powf(rng.range(-3.0, -1.5))
        } else {
            10f64.powf(rng.range(-6.0, -3.0))
        };
        let s = lo - gap;
        p.q[0][i] = [ci[0], ci[1], ti];
        p.q[0][j] = [ci[0] + s * u[0], ci[1] + s * u[1], 0.0];
    }
    for k in 0..pairs {
        let f = 6 * pairs + k;
        let gap = 10f64.powf(rng.range(-6.0, -3.0));
        p.q[0][f][1] = 6.0 + p.radius[f] - gap;
    }
    sim
}

#[test]
fn disk_overlaps_under_the_area_law_are_exact_down_to_1e_6_d() {
    // Mixed scenes (SPEC 2.3): polygon-disk, disk-disk and disk-wall area contacts at
    // k^n = 1e7 and A/l from ~1e-6 d: the GPU's exact-depth forms (polygon.wgsl, "Disks
    // under the overlap-area law") against the f64 CPU path.
    let Some((_, rows)) =
        gpu_and_cpu_overlaps("disk_overlaps_under_the_area_law", touching_mixed(12, 5))
    else {
        return;
    };
    let names = [
        "polygon face-disk",
        "polygon corner-disk",
        "disk-disk",
        "disk-wall",
    ];
    let mut worst = [0.0f64; 4];
    let mut seen = [0usize; 4];
    for &(p, gpu, cpu) in &rows {
        let kind = if p.is_wall() {
            3
        } else {
            (p.i as usize / 2) % 3
        };
        let e = (gpu - cpu).abs() - 1e-3 * cpu;
        worst[kind] = worst[kind].max(e);
        seen[kind] += 1;
    }
    for k in 0..4 {
        eprintln!(
            "{}: {} contacts, A/l beyond 1e-3 relative {:.2e} d",
            names[k], seen[k], worst[k]
        );
    }
    assert_eq!(
        seen,
        [12, 12, 12, 12],
        "every pair touches, and only its own partner"
    );
    for k in 0..4 {
        assert!(
            worst[k] < 5e-9,
            "{}: A/l off by {:.2e} d beyond 1e-3",
            names[k],
            worst[k]
        );
    }
}

#[test]
fn degenerate_polygon_contacts_vary_continuously_on_the_gpu() {
    // The sweeps of tests/polygons.rs (a corner through a face, parallel faces turning
    // through 0 and sliding past each other's ends, spike against spike), 400 steps
    // each, every step a separate pair of unit squares in one scene: the GPU force is
    // finite, continuous along each sweep, and the CPU's to 1e-3 of the sweep's largest.
    use std::f64::consts::FRAC_PI_4;
    use talus::overlap::polygon_polygon;
    let n = 400;
    // A configuration: the upper square's centre and the two orientations.
    type Config = fn(f64) -> ([f64; 2], f64, f64);
    let sweeps: [(&str, Config); 4] = [
        ("corner", |s| {
            (
                [0.0, 0.5 + 0.5 * 2f64.sqrt() + 0.01 - 0.06 * s],
                FRAC_PI_4,
                0.0,
            )
        }),
        ("parallel", |s| ([0.2, 1.0 - 1e-3], (s - 0.5) * 2e-3, 0.0)),
        ("sliding", |s| ([0.9 + 0.2 * s, 1.0 - 1e-3], 0.0, 0.0)),
        ("spikes", |s| {
            ([(s - 0.5) * 0.02, 2f64.sqrt() - 0.01], FRAC_PI_4, FRAC_PI_4)
        }),
    ];
    // Particle 2k: the moving square (i), 2k + 1: the one below it (j). List squares
    // have a corner at 0; the sweeps' squares have their faces along the axes.
    let mut list = Vec::new();
    for (m, (_, config)) in sweeps.iter().enumerate() {
        for k in 0..=n {
            let (cj, ti, tj) = config(k as f64 / n as f64);
            let x = 4.0 * (m * (n + 1) + k) as f64;
            list.push(json!({ "position": [x + cj[0], 2.0 + cj[1]], "diameter": 2f64.sqrt(), "theta": ti + FRAC_PI_4 }));
            list.push(
                json!({ "position": [x, 2.0], "diameter": 2f64.sqrt(), "theta": tj + FRAC_PI_4 }),
            );
        }
    }
    let w = 4.0 * (4 * (n + 1)) as f64 + 4.0;
    let mut v = common::scene_value(
        polygons(),
        json!([{ "kind": "list", "material": "m", "particles": list, "polygon": { "corners": 4 } }]),
    );
    v["domain"] = json!({ "x": [-4.0, w], "z": [-1.0, 6.0] });
    let sim = common::sim(&v);
    let Some(gpu) = common::gpu("degenerate_polygon_contacts_vary_continuously") else {
        return;
    };
    let mut g = GpuSimulation::with_gpu(sim, gpu).expect("uploads");
    let pairs = gpu_pairs(&mut g);
    g.run_kernels(&[Kernel::GatherHistory, Kernel::ContactForces]);
    let host = g.download().clone();
    let count = g.read_u32("contact_count", host.particles.len());
    let out = g.read_contact_out(host.particles.len() * MAX_CONTACTS as usize);
    let k_n = 2000.0;
    let mut shapes = RotatedCorners::default();
    rotate_corners(&host.particles, &mut shapes);
    assert!(
        pairs.iter().all(|p| p.j == p.i + 1 && p.i % 2 == 0),
        "only partners touch"
    );
    for (m, (name, _)) in sweeps.iter().enumerate() {
        let (mut gpu_f, mut cpu_f) = (Vec::new(), Vec::new());
        for k in 0..=n {
            let i = 2 * (m * (n + 1) + k);
            let f = if count[i] > 0 {
                let o = out[i * MAX_CONTACTS as usize];
                [o.ft[0] as f64 / k_n, o.ft[1] as f64 / k_n]
            } else {
                [0.0, 0.0]
            };
            assert!(
                f[0].is_finite() && f[1].is_finite(),
                "{name}: step {k} not finite"
            );
            gpu_f.push(f);
            let d = talus::state::offset(&host.particles, i, i + 1);
            cpu_f.push(match polygon_polygon(shapes.of(i), shapes.of(i + 1), d) {
                Some(c) => [c.area / c.l * c.n[0], c.area / c.l * c.n[1]],
                None => [0.0, 0.0],
            });
        }
        let scale = cpu_f.iter().map(|f| f[0].hypot(f[1])).fold(0.0, f64::max);
        let jump = gpu_f
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .fold(0.0, f64::max)
            / scale;
        let diff = gpu_f
            .iter()
            .zip(&cpu_f)
            .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
            .fold(0.0, f64::max)
            / scale;
        eprintln!("{name}: largest step {jump:.2e}, GPU vs CPU {diff:.2e} of the largest force");
        assert!(scale > 0.0, "{name}: in contact");
        assert!(
            jump < 0.05,
            "{name}: the GPU force jumps by {jump:.2e} of its size"
        );
        assert!(diff < 1e-3, "{name}: GPU and CPU differ by {diff:.2e}");
    }
}

#[test]
fn clears_cover_everything_from_any_number_of_workgroups() {
    // One dispatch holds at most 65535 workgroups; the clears of the cells and of the
    // spring table loop over the rest (grid-stride), here from a single workgroup.
    let Some(mut g) = setup(
        "clears_cover_everything_from_any_number_of_workgroups",
        &random_scene(300, spring_dashpot(), 8),
    ) else {
        return;
    };
    let cells = g.params.cells as usize;
    assert!(
        cells > 64 && g.params.table_mask as usize + 1 > 64,
        "more than one workgroup's worth"
    );
    g.upload_cell_counts(&vec![7; cells]);
    g.set_list_flags(REBUILD);
    g.run_kernel_with_groups(Kernel::ClearCells, 1);
    assert!(
        g.read_u32("cell_count", cells).iter().all(|&c| c == 0),
        "every cell cleared"
    );
    // A table full of springs, cleared by one workgroup.
    let entries: Vec<Entry> = (0..200u32)
        .map(|k| Entry {
            i: k,
            j: k + 1,
            value: 1.0,
            _pad: 0,
        })
        .collect();
    g.upload_springs(&entries);
    g.set_list_flags(REBUILD);
    let slots = g.params.table_mask as usize + 1;
    let keys = |g: &GpuSimulation| -> usize {
        let words = g.read_u32("table", 4 * slots);
        words.chunks(4).filter(|e| e[0] != u32::MAX).count()
    };
    assert_eq!(keys(&g), entries.len(), "the springs are in");
    g.run_kernel_with_groups(Kernel::ClearTable, 1);
    assert_eq!(keys(&g), 0, "every slot of the table cleared");
}

#[test]
fn rebuild_stages_run_workgroups_only_at_a_rebuild() {
    // Issue 14 item 2: the rebuild stages are dispatched indirectly every step, with the
    // workgroups `plan_rebuild` gives them: all of them at a rebuild, none between.
    let Some(mut g) = setup(
        "rebuild_stages_run_workgroups_only_at_a_rebuild",
        &random_scene(300, spring_dashpot(), 9),
    ) else {
        return;
    };
    let stages = REBUILD_STAGES.len();
    let this_step = |g: &GpuSimulation| -> Vec<u32> {
        let words = g.read_u32("dispatch_args", 8 * stages);
        (words[4 * stages..].chunks(4))
            .map(|a| {
                assert_eq!(a[1..3], [1, 1], "one-dimensional dispatches");
                a[0]
            })
            .collect()
    };
    let full: Vec<u32> = (REBUILD_STAGES.iter())
        .map(|&k| workgroups(&g.params, k) as u32)
        .collect();
    assert!(full.iter().all(|&x| x >= 1));
    // The upload asks for a rebuild: the first step runs every stage.
    g.advance(1).expect("runs");
    assert_eq!((g.rebuilds(), this_step(&g)), (1, full.clone()));
    // One step moves every disk by far less than skin/2: no rebuild, no workgroups.
    g.advance(1).expect("runs");
    assert_eq!((g.rebuilds(), this_step(&g)), (1, vec![0; stages]));
    // A rebuild asked for (as an insertion or a removal asks) runs them again.
    g.set_list_flags(REBUILD);
    g.advance(1).expect("runs");
    assert_eq!((g.rebuilds(), this_step(&g)), (2, full));
}

#[test]
fn profiled_steps_time_every_dispatch_and_change_nothing() {
    // `talus bench --kernels` (src/gpu/profile.rs): a timestamp after every dispatch of
    // a run of steps. The run must be the same run, bit for bit, and each dispatch must
    // be charged once.
    let test = "profiled_steps_time_every_dispatch_and_change_nothing";
    let mut v = random_scene(300, spring_dashpot(), 11);
    // Fast enough that the lists are rebuilt within the run (the rebuild stages then
    // do work in some steps and none in the others).
    for p in v["particles"][0]["particles"].as_array_mut().unwrap() {
        p["velocity"] = json!([
            5.0 * p["velocity"][0].as_f64().unwrap(),
            5.0 * p["velocity"][1].as_f64().unwrap()
        ]);
    }
    let (Some(mut a), Some(mut b)) = (setup(test, &v), setup(test, &v)) else {
        return;
    };
    a.advance(5).unwrap();
    b.advance(5).unwrap();
    if !a.can_profile() {
        let e = a.profile(10).unwrap_err().to_string();
        assert!(e.contains("timestamp"), "{e}");
        eprintln!(
            "{test}: {} has no timestamps inside passes; only the refusal checked",
            a.adapter_name()
        );
        return;
    }
    let steps = 150;
    let c0 = a.counters();
    let t = a.profile(steps).unwrap();
    let c = a.counters();
    b.advance(steps).unwrap();
    assert_eq!(a.step(), b.step());
    assert_eq!(a.positions(), b.positions(), "timestamps changed the run");
    assert!(
        c.rebuilds > c0.rebuilds,
        "the scene should rebuild its lists within {steps} steps"
    );
    assert_eq!(t.steps, steps);
    let dispatched = (c.direct + c.indirect - c0.direct - c0.indirect) as f64;
    let charged: f64 = t.kernels.iter().map(|k| k.dispatches_per_step).sum::<f64>() * steps as f64;
    assert!(
        (charged - dispatched).abs() < 1e-9,
        "{charged} charged, {dispatched} dispatched"
    );
    let per_step = |name: &str| {
        (t.kernels.iter().find(|k| k.kernel == name))
            .unwrap_or_else(|| panic!("{name} not timed: {t:?}"))
            .dispatches_per_step
    };
    // Every step: the rebuild stages (empty or not), the clock; the contact forces with
    // the outputs only at the last step; Gear predicts at the first only and runs ahead
    // after that.
    for k in REBUILD_STAGES
        .iter()
        .chain([&Kernel::AdvanceClock, &Kernel::PlanRebuild])
    {
        assert_eq!(per_step(&format!("{k:?}")), 1.0, "{k:?}");
    }
    assert_eq!(per_step("ContactForces") * steps as f64, 1.0);
    assert_eq!(
        per_step("ContactForcesOnly") * steps as f64,
        (steps - 1) as f64
    );
    assert_eq!(per_step("Predict") * steps as f64, 1.0);
    let sum: f64 = t.kernels.iter().map(|k| k.microseconds_per_step).sum();
    assert!(t.microseconds_per_step > 0.0 && (sum - t.microseconds_per_step).abs() < 1e-6);
    assert!(
        t.kernels
            .windows(2)
            .all(|w| w[0].microseconds_per_step >= w[1].microseconds_per_step)
    );
}
