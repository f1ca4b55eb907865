//! The bitwise-resume check (SPEC 3), written once for every scene and both paths
//! (issue 42 item 4).

use super::{Path, engine};
use talus::checkpoint::{self, Checkpoint};
use talus::gpu::{DeviceState, GpuSimulation};
use talus::run::Engine;
use talus::scene::Scene;
use talus::sim::Simulation;

/// Runs `scene` on `path` for `total` steps uninterrupted; runs it again to `split`,
/// writes a checkpoint file through the real encoder, reads it back (it must hold
/// exactly the state written), hands it to `check`, resumes it on the same path in a
/// fresh engine (a fresh device context on the GPU) and runs on to `total`: the two end
/// states must be bitwise the same (`assert_same_state`). Returns the uninterrupted
/// run, for checks of its end state; None when the GPU path is skipped (no adapter,
/// without TALUS_REQUIRE_GPU=1).
pub fn assert_resumes_bitwise(
    path: Path,
    test: &str,
    scene: &Scene,
    total: u64,
    split: u64,
    check: impl Fn(&Checkpoint),
) -> Option<Engine> {
    let fresh = || engine(path, test, Simulation::new(scene.clone()).expect("builds"));
    let mut straight = fresh()?;
    straight.advance(total).expect("the uninterrupted run runs");
    let mut half = fresh().expect("a second engine");
    half.advance(split).expect("the run to the checkpoint runs");
    let file =
        std::env::temp_dir().join(format!("talus-{test}-{path:?}-{}.ckpt", std::process::id()));
    let (sim, device) = half.checkpoint_state().expect("the state reads back");
    checkpoint::write(sim, device, &file).expect("the checkpoint is written");
    let loaded = checkpoint::read(&file, &[]).expect("the checkpoint loads");
    std::fs::remove_file(&file).ok();
    assert_eq!(
        loaded.sim.step, split,
        "{test} on {path:?}: checkpoint step"
    );
    let written = exact_state(&mut half);
    let read = match (path, &loaded.device) {
        (Path::Cpu, None) => sim_fields(&loaded.sim),
        (Path::Gpu, Some(d)) => device_fields(d),
        (_, d) => panic!(
            "{test} on {path:?}: a checkpoint {} the device state",
            if d.is_some() { "carries" } else { "lacks" }
        ),
    };
    same(
        &written,
        &read,
        &format!("{test} on {path:?}: the checkpoint read back"),
    );
    check(&loaded);
    let mut resumed = match path {
        Path::Cpu => Engine::cpu(loaded.sim),
        Path::Gpu => {
            let gpu = super::gpu(test).expect("a second device context");
            Engine::Gpu(Box::new(
                GpuSimulation::resume_with_gpu(loaded, gpu).expect("resumes"),
            ))
        }
    };
    resumed
        .advance(total - split)
        .expect("the resumed run runs");
    assert_same_state(
        &mut straight,
        &mut resumed,
        &format!(
            "{test} on {path:?}: resumed at step {split} against uninterrupted, at step {total}"
        ),
    );
    Some(straight)
}

/// Two engines' exact states are the same bit for bit: on the CPU the f64 state (Gear
/// values, particle properties, sources, generator) and the springs; on the GPU the
/// device state. A failure names the first field and index that differ.
pub fn assert_same_state(a: &mut Engine, b: &mut Engine, what: &str) {
    same(&exact_state(a), &exact_state(b), what);
}

type Fields = Vec<(String, Vec<String>)>;

/// An engine's exact state, field by field, each element as its Debug text (which tells
/// every f64 and f32 apart, -0 from 0 included).
fn exact_state(e: &mut Engine) -> Fields {
    match e {
        Engine::Cpu(s) => sim_fields(s),
        Engine::Gpu(g) => device_fields(&g.device_state()),
    }
}

fn column<T: std::fmt::Debug>(name: &str, v: impl IntoIterator<Item = T>) -> (String, Vec<String>) {
    (
        name.to_string(),
        v.into_iter().map(|x| format!("{x:?}")).collect(),
    )
}

fn sim_fields(s: &Simulation) -> Fields {
    let p = &s.particles;
    let springs = s.spring_table();
    let mut table: Vec<_> = springs.entries().collect();
    table.sort_by_key(|e| e.0);
    let mut f = vec![
        column("step", [s.step]),
        column("lost", [s.lost]),
        column("rng", [&s.rng]),
        column("sources", &s.sources),
    ];
    f.extend((0..p.q.len()).map(|k| column(&format!("Gear value q{k}"), &p.q[k])));
    f.extend([
        column("radius", &p.radius),
        column("mass", &p.mass),
        column("inertia", &p.inertia),
        column("fixed", &p.fixed),
        column("active", &p.active),
        column("material", &p.material),
        column("shape", &p.shape),
        column("sweep", &p.sweep),
        column("copy", &p.copy),
        column("springs", table),
        column("sub-contact springs", &springs.sub),
    ]);
    f
}

fn device_fields(d: &DeviceState) -> Fields {
    vec![
        column("device states", &d.states),
        column("device props", &d.props),
        column("device springs", &d.springs),
        column("device sub-contact springs", &d.sub),
    ]
}

fn same(a: &Fields, b: &Fields, what: &str) {
    for ((name, x), (_, y)) in a.iter().zip(b) {
        if let Some(i) = (0..x.len().max(y.len())).find(|&i| x.get(i) != y.get(i)) {
            panic!(
                "{what}: {name} differs first at index {i} (lengths {} and {}):\n  {:?}\n  {:?}",
                x.len(),
                y.len(),
                x.get(i),
                y.get(i)
            );
        }
    }
}

/// A `check`: the checkpoint of rods in contact carries sub-contact springs (a GPU run's
/// in its device section).
pub fn carries_sub_springs(c: &Checkpoint) {
    let any = match &c.device {
        Some(d) => d.sub.iter().any(|s| s.key[0] != u32::MAX),
        None => !c.sim.springs.sub.is_empty(),
    };
    assert!(any, "the checkpoint carries sub-contact springs");
}
