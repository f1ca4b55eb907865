//! Same scene and seed → bitwise-identical snapshots; a run resumed from a checkpoint is
//! bitwise identical to the uninterrupted run (SPEC 3). Failures name the column and the
//! first differing index. Damaged checkpoints and killed runs: tests/hostile.rs.

mod common;
use std::path::Path;
use talus::io::snapshot::{self, Column};
use talus::run::{RunOptions, run};
use talus::scene;
use talus::sim::Simulation;

/// The default heap, shortened: a point source pouring onto a bumpy row with friction.
fn small_heap(extra: &[&str]) -> talus::scene::Scene {
    let mut o: Vec<String> = vec![
        "stop.time=30".into(),
        "stop.kinetic_fraction=null".into(),
        "particles[1].count=120".into(),
        "particles[1].rate=10".into(),
        "output.snapshot_every=7.5".into(),
        "output.checkpoint_every=15".into(),
    ];
    o.extend(extra.iter().map(|s| s.to_string()));
    scene::parse(scene::DEFAULT_SCENE, &o).expect("valid scene")
}

/// Runs `sim` to its end on `path` into `dir`; false on the GPU path without an adapter.
fn run_to(path: common::Path, dir: &Path, sim: Simulation) -> bool {
    let test = "same_seed_gives_bitwise_identical_snapshots";
    let Some(mut e) = common::engine(path, test, sim) else {
        return false;
    };
    run(
        &mut e,
        &RunOptions {
            out: dir.to_path_buf(),
            quiet: true,
            ..Default::default()
        },
    )
    .expect("run succeeds");
    true
}

fn assert_same_snapshot(a: &Path, b: &Path) {
    let (sa, sb) = (snapshot::read(a).unwrap(), snapshot::read(b).unwrap());
    if a.ends_with("final.json") {
        assert!(
            sa.meta.particles > 150 && sa.meta.contacts > 150,
            "a non-trivial state: {:?}",
            sa.meta.contacts
        );
    }
    assert_eq!(sa.meta.step, sb.meta.step);
    for (name, ca) in &sa.columns {
        let cb = &sb.columns[name];
        let first_diff = match (ca, cb) {
            (Column::F64(x), Column::F64(y)) => x
                .iter()
                .zip(y)
                .position(|(p, q)| p.to_bits() != q.to_bits())
                .or((x.len() != y.len()).then_some(0)),
            (Column::U32(x), Column::U32(y)) => x
                .iter()
                .zip(y)
                .position(|(p, q)| p != q)
                .or((x.len() != y.len()).then_some(0)),
            (Column::U8(x), Column::U8(y)) => x
                .iter()
                .zip(y)
                .position(|(p, q)| p != q)
                .or((x.len() != y.len()).then_some(0)),
            _ => Some(0),
        };
        assert_eq!(
            first_diff, None,
            "column {name} differs at index {first_diff:?}"
        );
    }
}

#[test]
fn same_seed_gives_bitwise_identical_snapshots() {
    for path in common::PATHS {
        let tmp = common::tmp("det", &format!("{path:?}"));
        let (a, b, c) = (tmp.join("a"), tmp.join("b"), tmp.join("c"));
        if !run_to(path, &a, Simulation::new(small_heap(&[])).unwrap()) {
            continue;
        }
        run_to(path, &b, Simulation::new(small_heap(&[])).unwrap());
        for step in [3750, 7500, 11250, 15000] {
            let name = format!("snapshots/snap_{step:010}.json");
            assert_same_snapshot(&a.join(&name), &b.join(&name));
        }
        assert_same_snapshot(&a.join("final.json"), &b.join("final.json"));
        // A different seed must give a different heap (the test can fail).
        run_to(path, &c, Simulation::new(small_heap(&["seed=2"])).unwrap());
        let (fa, fc) = (
            snapshot::read(&a.join("final.json")).unwrap(),
            snapshot::read(&c.join("final.json")).unwrap(),
        );
        assert_ne!(fa.f64("particles.x"), fc.f64("particles.x"), "{path:?}");
        std::fs::remove_dir_all(&tmp).ok();
    }
}

#[test]
fn resume_from_checkpoint_is_bitwise_identical() {
    // Resumed at t = 15 (step 7500), with the heap still forming, to t = 30.
    for path in common::PATHS {
        let test = "resume_from_checkpoint_is_bitwise_identical";
        let check = |c: &talus::io::checkpoint::Checkpoint| {
            let springs = c.sim.springs.len();
            assert!(springs > 0, "the checkpoint carries tangential springs");
        };
        let Some(mut e) =
            common::assert_resumes_bitwise(path, test, &small_heap(&[]), 15000, 7500, check)
        else {
            continue;
        };
        let s = e.sim().unwrap();
        let (n, c) = (s.particles.active_count(), s.contacts.len());
        assert!(
            n > 150 && c > 150,
            "a non-trivial state: {n} particles, {c} contacts"
        );
    }
}

/// Irregular heptagons from a point source (with a pending candidate most of the time)
/// and a layered block beside it: the shapes, the drawn-but-unplaced particle and the
/// layers' progress all travel through the checkpoint.
fn polygon_scene(layered: bool) -> talus::scene::Scene {
    let mut v = serde_json::json!({
        "name": "polygon-resume", "dt": 0.002, "seed": 5,
        "stop": { "time": 30.0 },
        "gravity": { "g": [0.0, -1.0] },
        "domain": { "x": [-30.0, 30.0], "z": [-1.0, 20.0] },
        "materials": { "m": { "density": 1.2732395447351628 } },
        "contact": { "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 },
        "walls": [{ "from": [-30.0, 0.0], "to": [30.0, 0.0] }],
        "particles": [
            { "kind": "point_source", "material": "m", "position": [-8.0, 10.0], "spread": 1.0,
              "rate": 5.0, "count": 120, "velocity": [0.0, -6.0],
              "polygon": { "corners": 7, "axes": [{ "uniform": [0.8, 1.2] }, { "uniform": [0.8, 1.2] }],
                           "irregular": true } },
            { "kind": "layered", "material": "m", "center_x": 10.0, "base_width": 14.0, "slope": 30.0,
              "interval": 2.0, "gap": 0.3, "diameter": 1.0, "polygon": { "corners": 5, "irregular": true } }
        ],
        "output": { "snapshot_every": 10.0, "checkpoint_every": 10.0 }
    });
    if !layered {
        v["particles"].as_array_mut().unwrap().pop();
    }
    scene::parse(&v.to_string(), &[]).expect("valid scene")
}

#[test]
fn polygon_runs_resume_bitwise() {
    let check = |c: &talus::io::checkpoint::Checkpoint| {
        let p = &c.sim.particles;
        let shapes = p.shape.iter().all(|c| c.len() == 7 || c.len() == 5);
        assert!(shapes, "the checkpoint carries the polygons");
        assert!(p.len() > 40, "particles poured: {}", p.len());
    };
    for path in common::PATHS {
        // The GPU path does not take point sources beside layered blocks yet: it resumes
        // the pour alone.
        let scene = polygon_scene(path == common::Path::Cpu);
        let test = "polygon_runs_resume_bitwise";
        common::assert_resumes_bitwise(path, test, &scene, 15000, 5000, check);
    }
}

/// Throughput counts the moving particles only, as other DEM codes do (issue 20: a
/// pour's fixed base row flattered it): 10 fixed disks under 3 moving ones make
/// particle-steps/s × wall seconds = 3 × steps, on both paths.
#[test]
fn throughput_counts_moving_particles_only() {
    use serde_json::json;
    let mut v = common::scene_value(
        json!({ "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0 }),
        json!([
            { "kind": "row", "material": "m", "count": 10, "diameter": 1.0, "spacing": 1.0, "start": [0.0, 0.5] },
            { "kind": "list", "material": "m", "particles": [
                { "position": [2.0, 1.6], "diameter": 1.0 },
                { "position": [4.0, 1.6], "diameter": 1.0 },
                { "position": [6.0, 1.6], "diameter": 1.0 }
            ] }
        ]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(0.002);
    v["stop"] = json!({ "time": 2.0 });
    for path in common::PATHS {
        let Some(mut e) = common::engine(path, "throughput", common::sim(&v)) else {
            continue;
        };
        let dir =
            std::env::temp_dir().join(format!("talus-throughput-{}-{path:?}", std::process::id()));
        let s = run(
            &mut e,
            &RunOptions {
                out: dir.clone(),
                quiet: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!((s.particles, s.mobile, s.steps), (13, 3, 1000), "{path:?}");
        let counted = s.particle_steps_per_second * s.wall_seconds;
        assert!(
            (counted - 3000.0).abs() < 1e-6 * 3000.0,
            "{path:?}: {counted} particle-steps counted, 3 moving particles × 1000 steps"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
