//! Physics sanity of the input and of the run (issue 16 item 3): particles placed into
//! each other are bad input with their ids, and a particle moving too far in one step
//! (it would tunnel through its neighbours) stops the run on both paths.

mod common;

use common::{PATHS, engine, scene_value};
use serde_json::{Value, json};
use talus::scene;
use talus::sim::{Divergence, Simulation};

fn disks(list: Value) -> Value {
    scene_value(
        json!({ "law": "spring_dashpot", "k_n": 1.0e4 }),
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    )
}

/// What `talus check` does after parsing: the error text of building the simulation.
fn build(v: &Value, overrides: &[&str]) -> Result<Simulation, String> {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let s = scene::parse(&v.to_string(), &overrides).map_err(|e| e.to_string())?;
    Simulation::new(s).map_err(|e| e.to_string())
}

#[test]
fn particles_placed_into_each_other_are_bad_input_with_their_ids() {
    // Unit disks 0.8 apart overlap by 0.2 = 0.4 of the radius; the third is clear.
    let v = disks(json!([
        { "position": [0.0, 0.0], "diameter": 1.0 },
        { "position": [0.8, 0.0], "diameter": 1.0 },
        { "position": [5.0, 0.0], "diameter": 1.0 }
    ]));
    let e = build(&v, &[])
        .err()
        .expect("deep initial overlaps are refused");
    assert!(
        e.contains("limits.initial_overlap") && e.contains("particles 0 and 1 by 0.400"),
        "{e}"
    );
    // A user who means it raises the bound; the overlap is below the run's own guard.
    assert!(build(&v, &["limits.initial_overlap=0.5"]).is_ok());
    // Touching within the tolerance (0.02 of the radius) is a normal start.
    let touching = disks(json!([
        { "position": [0.0, 0.0], "diameter": 1.0 },
        { "position": [0.99, 0.0], "diameter": 1.0 }
    ]));
    assert!(build(&touching, &[]).is_ok());
}

#[test]
fn a_particle_placed_into_a_wall_is_named_with_the_wall() {
    let mut v = disks(json!([
        { "position": [3.0, 0.0], "diameter": 1.0 },
        { "position": [0.0, 0.3], "diameter": 1.0 }
    ]));
    v["walls"] = json!([{ "from": [-5.0, 0.0], "to": [5.0, 0.0] }]);
    let e = build(&v, &[])
        .err()
        .expect("a disk 0.2 into a wall is refused");
    assert!(e.contains("particle 1 and wall 0 by 0.400"), "{e}");
}

#[test]
fn many_overlaps_are_counted_and_the_deepest_listed_first() {
    // Ten pairs, each 0.1 deeper than the last: the report lists five, deepest first.
    let list: Vec<Value> = (0..10)
        .flat_map(|k| {
            let x = 10.0 * k as f64 - 50.0;
            let gap = 0.9 - 0.05 * k as f64;
            [
                json!({ "position": [x, 0.0], "diameter": 1.0 }),
                json!({ "position": [x + gap, 0.0], "diameter": 1.0 }),
            ]
        })
        .collect();
    let e = build(&disks(json!(list)), &[]).err().unwrap();
    assert!(e.contains("particles 18 and 19 by 1.100"), "{e}");
    assert!(e.contains("(10 pairs in all)"), "{e}");
    let first = e.find("18 and 19").unwrap();
    assert!(first < e.find("16 and 17").unwrap(), "deepest first: {e}");
}

/// A disk fired at a row of fixed disks, `per_step` diameters per step.
fn shot_at_a_row(per_step: f64, bound: f64) -> Simulation {
    let mut list: Vec<Value> = (-5..=5)
        .map(|k| json!({ "position": [k as f64, 0.0], "diameter": 1.0, "fixed": true }))
        .collect();
    let dt = 1e-3;
    list.push(json!({
        "position": [0.2, 4.0], "diameter": 1.0, "velocity": [0.0, -per_step / dt]
    }));
    let mut v = scene_value(
        json!({ "law": "spring_dashpot", "k_n": 100.0 }),
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    v["dt"] = json!(dt);
    v["limits"] = json!({ "max_step_displacement": bound });
    build(&v, &[]).expect("the scene is valid")
}

#[test]
fn a_particle_faster_than_the_bound_stops_the_run_on_both_paths() {
    for path in PATHS {
        // Without the guard the disk, 2.5 diameters a step, passes through the row
        // without a single contact: the silent tunnelling the guard is for.
        let Some(mut free) = engine(path, "tunnelling", shot_at_a_row(2.5, 0.0)) else {
            continue;
        };
        free.advance(4).expect("nothing stops it without the guard");
        let z = free.sim().unwrap().particles.position(11)[1];
        assert!(z < -1.0, "{path:?}: the disk went through the row: z = {z}");

        let mut guarded = engine(path, "tunnelling", shot_at_a_row(2.5, 0.5)).unwrap();
        match guarded.advance(4) {
            Err(Divergence::TooFast { id, ratio, limit }) => {
                assert_eq!(id, 11, "{path:?}");
                assert!((ratio - 5.0).abs() < 1e-3, "{path:?}: ratio {ratio}");
                assert_eq!(limit, 0.5);
            }
            other => panic!("{path:?}: expected TooFast, got {other:?}"),
        }
        // Below the bound (0.4 of the radius a step) the guard stays quiet (the contact
        // may still diverge by its overlap: this spring is far too soft for the speed).
        let mut slow = engine(path, "tunnelling", shot_at_a_row(0.2, 0.5)).unwrap();
        let result = slow.advance(30);
        assert!(
            !matches!(result, Err(Divergence::TooFast { .. })),
            "{path:?}: {result:?}"
        );
    }
}

#[test]
fn a_source_whose_outlet_reaches_beyond_the_domain_is_named() {
    let mut v = disks(json!([]));
    v["particles"] = json!([{
        "kind": "point_source", "material": "m", "position": [90.0, 50.0],
        "spread": 20.0, "rate": 10.0, "count": 10, "diameter": 1.0
    }]);
    let e = build(&v, &[])
        .err()
        .expect("an outlet reaching x = 110 is refused");
    assert!(
        e.contains("particles[0].spread") && e.contains("(110, 50)"),
        "{e}"
    );
    v["particles"][0]["spread"] = json!(5.0);
    assert!(build(&v, &[]).is_ok());
}

#[test]
fn a_lost_gpu_stops_the_run_with_an_error_not_a_panic() {
    let sim = shot_at_a_row(0.01, 0.5);
    let Some(mut e) = engine(common::Path::Gpu, "lost device", sim) else {
        return;
    };
    e.advance(10).expect("runs while the device is there");
    let talus::run::Engine::Gpu(g) = &e else {
        unreachable!()
    };
    g.destroy_device_for_test();
    match e.advance(10) {
        Err(Divergence::Device(reason)) => assert!(!reason.is_empty()),
        other => panic!("expected a device failure, got {other:?}"),
    }
    assert!(e.sim().is_err(), "no state is read from a lost device");
    assert!(e.checkpoint_state().is_err());
}
