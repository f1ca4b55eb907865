//! The CPU path's neighbour lists and threads change only its speed (issue 13): the same
//! scene gives bitwise the same state for any skin (a list rebuilt every step, the
//! default, a large one) and for 1, 2 and 3 threads. Pours with friction (grains land,
//! slide and roll, contacts open and close between rebuilds) of disks and heptagons,
//! and a settled packing.

mod common;

use serde_json::json;
use talus::sim::Simulation;

/// 60 grains with friction poured onto a floor between walls; `skin` as given.
fn pour(polygons: bool, skin: Option<f64>) -> serde_json::Value {
    let mut source = json!({ "kind": "point_source", "material": "m", "position": [0.0, 6.0],
        "spread": 4.0, "rate": 10.0, "count": 60, "velocity": [0.5, -4.0],
        "diameter": { "uniform": [0.8, 1.2] } });
    let law = if polygons {
        source["polygon"] = json!({ "corners": 7, "irregular": true,
            "axes": [{ "uniform": [0.8, 1.2] }, { "uniform": [0.8, 1.2] }] });
        source.as_object_mut().unwrap().remove("diameter");
        json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.3, "mu": 0.5 })
    } else {
        json!({ "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 5.0, "k_t": 571.4,
                "gamma_t": 1.0, "mu": 0.5 })
    };
    let mut v = common::scene_value(law, json!([source]));
    v["dt"] = json!(0.002);
    v["integrator"] = json!(if polygons { "leapfrog" } else { "gear5" });
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["domain"] = json!({ "x": [-12.0, 12.0], "z": [-2.0, 14.0] });
    v["walls"] = json!([{ "from": [-8.0, 0.0], "to": [8.0, 0.0] },
                        { "from": [-8.0, 0.0], "to": [-8.0, 8.0] },
                        { "from": [8.0, 0.0], "to": [8.0, 8.0] }]);
    if let Some(s) = skin {
        v["skin"] = json!(s);
    }
    v
}

fn run(v: &serde_json::Value, steps: usize) -> Simulation {
    let mut s = common::sim(v);
    for _ in 0..steps {
        s.step().unwrap();
    }
    s
}

/// Bitwise equality of two states and their contacts, naming the first difference.
fn assert_same(a: &Simulation, b: &Simulation, what: &str) {
    assert_same_state(a, b, what);
    assert_eq!(a.pairs, b.pairs, "{what}: contacts");
}

/// Bitwise equality of two states (particles, removals, springs).
fn assert_same_state(a: &Simulation, b: &Simulation, what: &str) {
    assert_eq!(
        a.particles.len(),
        b.particles.len(),
        "{what}: particle count"
    );
    for k in 0..6 {
        for (i, (x, y)) in a.particles.q[k].iter().zip(&b.particles.q[k]).enumerate() {
            assert!(
                x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits()),
                "{what}: particle {i}, value q{k}: {x:?} vs {y:?}"
            );
        }
    }
    assert_eq!(
        a.particles.active, b.particles.active,
        "{what}: active particles"
    );
    assert_eq!(
        (a.lost, a.step),
        (b.lost, b.step),
        "{what}: lost particles, step"
    );
    assert_eq!(a.spring_table(), b.spring_table(), "{what}: springs");
}

/// f run on a pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn results_do_not_depend_on_the_skin() {
    // History lives in the candidates' slots between rebuilds and moves with its pair at
    // a rebuild: against a list rebuilt every step (skin 0), the default skin and a large
    // one (fewer rebuilds, more candidates) give bitwise the same pours.
    for polygons in [false, true] {
        let steps = 8000;
        let every = run(&pour(polygons, Some(0.0)), steps);
        let springs = every.spring_table().len();
        assert!(springs > 60, "the pour has {springs} springs");
        let mut rebuilds = vec![every.neighbours.rebuilds];
        for skin in [None, Some(1.0)] {
            let s = run(&pour(polygons, skin), steps);
            assert_same(&every, &s, &format!("polygons {polygons}, skin {skin:?}"));
            rebuilds.push(s.neighbours.rebuilds);
        }
        eprintln!(
            "polygons {polygons}: {springs} springs; rebuilds with skin 0, default, 1: {rebuilds:?}"
        );
        assert!(
            rebuilds[0] > rebuilds[1] && rebuilds[1] > rebuilds[2],
            "rebuilds {rebuilds:?}"
        );
    }
}

#[test]
fn results_do_not_depend_on_the_polygon_hints() {
    // Each polygon candidate keeps a hint of what its last step found (apart by an edge,
    // or resting along a chain of corners: src/overlap/hint.rs) that only saves work.
    // With hints and with every evaluation starting from none, the heptagon pour (grains
    // landing, sliding, turning) and the lattice pile of 12-gons (faces pressed and faces
    // touching to rounding) give bitwise the same runs; and the hints are used.
    let pile =
        common::parse(&serde_json::from_str(&talus::bench::polygon_pile_scene(300)).unwrap());
    let scenes = [
        ("heptagon pour", pour(true, None), 4000),
        ("lattice pile", serde_json::to_value(pile).unwrap(), 400),
    ];
    for (name, v, steps) in scenes {
        let with = run(&v, steps);
        let mut cold = common::sim(&v);
        cold.use_hints = false;
        for _ in 0..steps {
            cold.step().unwrap();
        }
        assert_same(&with, &cold, &format!("{name}, hints against none"));
        let (known, pairs) = (with.neighbours.hints.known(), with.neighbours.pairs.len());
        eprintln!("{name}: {known} of {pairs} candidates with a hint");
        assert!(
            known > pairs / 3,
            "{name}: {known} of {pairs} candidates with a hint"
        );
        assert!(
            with.pairs.len() > 50,
            "{name}: {} contacts",
            with.pairs.len()
        );
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    // Every stage split over the threads even for these small scenes.
    talus::base::parallel::set_min_parallel(1);
    let packing = common::parse(&serde_json::from_str(&talus::bench::packing_scene(600)).unwrap());
    let scenes = [
        ("disk pour", pour(false, None), 3000),
        ("heptagon pour", pour(true, None), 3000),
        ("packing", serde_json::to_value(packing).unwrap(), 300),
    ];
    for (name, v, steps) in scenes {
        let on = |threads: usize| on_threads(threads, || run(&v, steps));
        let one = on(1);
        for threads in [2, 3] {
            assert_same(&one, &on(threads), &format!("{name}, {threads} threads"));
        }
    }
}

#[test]
fn a_domain_a_hundred_thousand_diameters_square_runs() {
    // Issue 13: the cell search was a dense grid over the whole domain (10¹⁰ cells here:
    // the run aborted on memory). The neighbour list sorts the particles by cell instead,
    // in memory and time proportional to the particles: the pour lands as in a tight box.
    let mut huge = pour(false, None);
    huge["domain"] = json!({ "x": [-5e4, 5e4], "z": [-5e4, 5e4] });
    let tight = pour(false, None);
    let (a, b) = (run(&huge, 6000), run(&tight, 6000));
    assert!(a.pairs.len() > 40, "{} contacts", a.pairs.len());
    assert_same(&a, &b, "the same pour in a huge domain");
}

#[test]
fn results_do_not_depend_on_the_memory_order() {
    // Issue 13 item 4: `advance` sorts the particles in memory by cell at every rebuild
    // and puts them back in id order when it returns. Pours insert particles in time
    // order, which is no order in space: against plain steps (memory = id order), the
    // same pours and the packing give bitwise the same states, ids, contacts and springs,
    // also when the advances end between rebuilds, and on several threads.
    talus::base::parallel::set_min_parallel(1);
    let packing = common::parse(&serde_json::from_str(&talus::bench::packing_scene(600)).unwrap());
    // The pours are sorted at many rebuilds; the settled packing, created in rows, at
    // the first advance only.
    let scenes = [
        ("disk pour", pour(false, None), 3000, 10),
        ("heptagon pour", pour(true, None), 3000, 10),
        ("packing", serde_json::to_value(packing).unwrap(), 300, 1),
    ];
    for (name, v, steps, reorders) in scenes {
        let plain = run(&v, steps);
        assert_eq!(plain.reorders, 0, "plain steps keep the id order");
        for threads in [1, 2] {
            let sorted = on_threads(threads, || {
                let mut s = common::sim(&v);
                let mut done = 0;
                // Advances of uneven lengths: some end right after a reorder.
                for chunk in [1, 7, 100, 256].into_iter().cycle() {
                    let k = chunk.min(steps - done);
                    s.advance(k as u64).unwrap();
                    done += k;
                    if done == steps {
                        break;
                    }
                }
                s
            });
            assert!(
                sorted.reorders >= reorders,
                "{name}: only {} rebuilds changed the memory order",
                sorted.reorders
            );
            assert_same(
                &plain,
                &sorted,
                &format!("{name}, sorted by cell, {threads} threads"),
            );
            assert_eq!(plain.contacts, sorted.contacts, "{name}: contact forces");
        }
    }
}

#[test]
fn an_advance_is_its_steps_through_insertions_escapes_and_a_divergence() {
    // `advance` corrects each step and predicts the next in one pass when another step
    // follows and no insertion is due then (Gear). A pour onto a short floor, with some
    // grains thrown off its edge out of the domain, and the same pour diverging: bitwise
    // the states, removals, errors and error steps of plain steps.
    let mut v = pour(false, None);
    v["walls"] = json!([{ "from": [-3.0, 0.0], "to": [3.0, 0.0] }]);
    v["particles"][0]["velocity"] = json!([3.0, -6.0]);
    v["particles"][0]["count"] = json!(30);
    let steps = 6000;
    let plain = run(&v, steps);
    assert!(
        plain.lost >= 10,
        "only {} grains left the domain",
        plain.lost
    );
    for threads in [1, 2] {
        let advanced = on_threads(threads, || {
            let mut s = common::sim(&v);
            for chunk in [3, 50, 999, 64, 4884] {
                s.advance(chunk).unwrap();
            }
            s
        });
        assert_same(
            &plain,
            &advanced,
            &format!("pour off a floor, {threads} threads"),
        );
    }
    // A bound on the overlap that the landing grains break.
    v["limits"] = json!({ "max_overlap": 0.002 });
    let mut plain = common::sim(&v);
    let error = (0..steps)
        .find_map(|_| plain.step().err())
        .expect("the pour diverges");
    let mut advanced = common::sim(&v);
    let same = advanced
        .advance(steps as u64)
        .expect_err("the advance diverges");
    assert_eq!(same.to_string(), error.to_string());
    // (A diverging step inside an advance does not list its contacts.)
    assert_same_state(&plain, &advanced, "a diverging pour");
}
