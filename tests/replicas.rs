//! Copies of a scene in one simulation (`replicas`, issue 17 item 4): copy c is bitwise
//! the run of seed `seed + c` alone on the same path (CPU, and GPU on whatever adapter
//! there is), through pouring, layer-by-layer construction, polygons, a checkpoint and
//! the run folder's outputs; copies never touch.

mod common;

use serde_json::json;
use talus::scene::{self, Scene};
use talus::sim::Simulation;

/// The default heap cut short: a fixed row and a source of 60 disks, no settling rule.
fn pour(extra: &[&str]) -> Scene {
    let mut o: Vec<String> = [
        "stop.time=12",
        "particles[1].count=60",
        "particles[1].rate=10",
        "stop.kinetic_fraction=null",
    ]
    .map(String::from)
    .to_vec();
    o.extend(extra.iter().map(|s| s.to_string()));
    scene::parse(scene::DEFAULT_SCENE, &o).unwrap()
}

/// Steps the scene with copies and, alone, each copy's scene the same number of steps
/// on `path`, and requires every copy to be bitwise its lone run: particles, contacts,
/// lost particles. None when the path has no adapter (the GPU, skipped with a message).
fn copies_match_lone_runs(path: common::Path, scene: Scene, steps: u64) -> Option<()> {
    let k = scene.replicas;
    assert!(k > 1);
    let mut e = common::engine(
        path,
        "copies of a scene",
        Simulation::new(scene.clone()).unwrap(),
    )?;
    e.advance(steps).unwrap();
    let sim = e.sim().unwrap();
    for c in 0..k {
        let copy = sim.replica(c).unwrap();
        let mut alone = scene.clone();
        alone.replicas = 1;
        alone.seed = scene.seed + c as u64;
        let mut lone = common::engine(
            path,
            "a copy alone",
            Simulation::new(alone.clone()).unwrap(),
        )?;
        lone.advance(steps).unwrap();
        let lone = lone.sim().unwrap();
        assert_eq!(copy.scene.seed, alone.seed);
        assert!(copy.particles.len() > 2, "copy {c} is empty");
        assert_eq!(
            copy.particles.len(),
            lone.particles.len(),
            "copy {c}: particle count"
        );
        for g in 0..copy.particles.q.len() {
            let bits = |s: &Simulation| -> Vec<u64> {
                s.particles.q[g]
                    .iter()
                    .flatten()
                    .map(|v| v.to_bits())
                    .collect()
            };
            assert!(
                bits(&copy) == bits(lone),
                "copy {c}: Gear value {g} differs"
            );
        }
        assert_eq!(copy.particles, lone.particles, "copy {c}: particles");
        assert_eq!(copy.pairs, lone.pairs, "copy {c}: contact pairs");
        assert_eq!(copy.contacts, lone.contacts, "copy {c}: contact forces");
        assert_eq!(copy.lost, lone.lost, "copy {c}: lost");
        assert_eq!(copy.energies().kinetic(), lone.energies().kinetic());
    }
    // The copies are not the same heap (different seeds).
    let (a, b) = (sim.replica(0).unwrap(), sim.replica(1).unwrap());
    assert_ne!(a.particles.q[0], b.particles.q[0]);
    Some(())
}

#[test]
fn each_copy_of_a_pour_is_the_run_of_its_seed_alone() {
    // Several copies of a pour in one simulation; each lies exactly where the others'
    // grains are, so any contact between copies would show.
    for path in common::PATHS {
        copies_match_lone_runs(path, pour(&["replicas=3"]), 6000);
    }
}

#[test]
fn each_copy_of_a_layered_polygon_pile_is_its_run_alone() {
    // Rows laid on the pile measured under each (copy by copy), irregular polygons
    // drawn from each copy's stream.
    let mut v = common::layered_pile(true);
    v["particles"][0]
        .as_object_mut()
        .unwrap()
        .remove("row_height");
    v["particles"][0]["polygon"] = json!({ "corners": 7, "irregular": true });
    v["stop"] = json!({ "time": 8.0 });
    v["seed"] = json!(5);
    v["replicas"] = json!(2);
    v["integrator"] = json!("leapfrog");
    for path in common::PATHS {
        copies_match_lone_runs(path, common::parse(&v), 3000);
    }
}

#[test]
fn copies_survive_a_checkpoint() {
    let check = |c: &talus::io::checkpoint::Checkpoint| assert!(c.sim.particles.copy.contains(&1));
    for path in common::PATHS {
        let test = "copies_survive_a_checkpoint";
        common::assert_resumes_bitwise(path, test, &pour(&["replicas=2"]), 3000, 2000, check);
    }
    let path = std::env::temp_dir().join(format!("talus-replicas-{}.bin", std::process::id()));
    // A copy that is not one of the scene's is a damaged checkpoint.
    let mut one = pour(&[]);
    one.replicas = 2;
    let mut sim = Simulation::new(one).unwrap();
    sim.advance(10).unwrap();
    sim.scene.replicas = 1;
    talus::io::checkpoint::write(&sim, None, &path).unwrap();
    assert!(talus::io::checkpoint::read(&path, &[]).is_err());
    std::fs::remove_file(&path).ok();
}

#[test]
fn replicas_are_checked() {
    for bad in ["replicas=0", "replicas=5000", "replicas=-1", "replicas=1.5"] {
        let e = scene::parse(scene::DEFAULT_SCENE, &[bad.into()])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("replicas"), "{bad}: {e}");
    }
    // The estimate counts every copy.
    let e = scene::parse(
        scene::DEFAULT_SCENE,
        &["replicas=4000".into(), "particles[1].count=6000".into()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("limits.max_particles"), "{e}");
}

#[test]
fn a_run_with_copies_writes_each_as_a_run_of_its_own() {
    let dir = std::env::temp_dir().join(format!("talus-replicas-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let run = |out: &std::path::Path, set: &[&str]| {
        let mut c = common::command(["--threads", "2", "run", "-q", "--backend", "cpu", "--out"]);
        c.arg(out);
        for s in [
            "stop.time=8",
            "particles[1].count=40",
            "particles[1].rate=10",
            "stop.kinetic_fraction=null",
        ]
        .iter()
        .chain(set)
        {
            c.args(["--set", s]);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&dir.join("copies3"), &["replicas=3", "seed=7"]);
    for c in 0..3u32 {
        let lone = dir.join(format!("seed{}", 7 + c));
        run(&lone, &[&format!("seed={}", 7 + c)]);
        let copy = dir.join("copies3/copies").join(format!("copy_{c:04}"));
        for f in ["final.bin", "final.json", "scene.json"] {
            assert!(
                common::output_without_provenance(&copy.join(f))
                    == common::output_without_provenance(&lone.join(f)),
                "copy {c}: {f} differs from the run of its seed alone"
            );
        }
        // Measured and drawn like a run.
        assert!(copy.join("analysis/summary.json").is_file());
        assert!(copy.join("pictures/grains.png").is_file());
    }
    // The whole state's snapshots say which copy each particle is.
    let meta = std::fs::read_to_string(dir.join("copies3/final.json")).unwrap();
    assert!(meta.contains("\"copy\""), "no copy column");
    std::fs::remove_dir_all(&dir).ok();
}
