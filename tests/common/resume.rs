//! The bitwise-resume check (SPEC 3), written once for every scene and both paths
//! (issue 42 item 4).

use super::{Path, engine};
use talus::gpu::{DeviceState, GpuSimulation};
use talus::io::checkpoint::{self, Checkpoint};
use talus::run::Engine;
use talus::sim::Simulation;

/// Runs `scene` on `path` for `total` steps uninterrupted; runs it again to `split`,
/// writes a checkpoint file through the real encoder, reads it back (it must hold
/// exactly the state written), hands it to `check`, resumes it on the same path (on the
/// GPU in a fresh device context) and runs on to `total`: the end states must be bitwise
/// the same. Returns the uninterrupted run; None when the GPU path is skipped.
pub fn assert_resumes_bitwise(
    path: Path,
    test: &str,
    scene: &talus::scene::Scene,
    total: u64,
    split: u64,
    check: impl Fn(&Checkpoint),
) -> Option<Engine> {
    let fresh = || engine(path, test, Simulation::new(scene.clone()).expect("builds"));
    let (mut straight, mut half) = (fresh()?, fresh()?);
    straight.advance(total).expect("the uninterrupted run runs");
    half.advance(split).expect("the run to the checkpoint runs");
    let pid = std::process::id();
    let file = std::env::temp_dir().join(format!("talus-{test}-{path:?}-{pid}.ckpt"));
    let (sim, device) = half.checkpoint_state().expect("the state reads back");
    checkpoint::write(sim, device, &file).expect("the checkpoint is written");
    let loaded = checkpoint::read(&file, &[]).expect("the checkpoint loads");
    std::fs::remove_file(&file).ok();
    let read = match (path, &loaded.device) {
        (Path::Cpu, None) => sim_fields(&loaded.sim),
        (Path::Gpu, Some(d)) => device_fields(d),
        (_, d) => panic!(
            "{test} on {path:?}: device state in the checkpoint: {}",
            d.is_some()
        ),
    };
    let what = format!("{test} on {path:?}: the checkpoint at step {split} read back");
    same(&exact_state(&mut half), &read, &what);
    check(&loaded);
    let mut resumed = match path {
        Path::Cpu => Engine::cpu(loaded.sim),
        Path::Gpu => {
            let gpu = super::gpu(test).expect("a second device context");
            Engine::Gpu(Box::new(
                GpuSimulation::resume_with_gpu(loaded.sim, loaded.device, gpu).expect("resumes"),
            ))
        }
    };
    resumed
        .advance(total - split)
        .expect("the resumed run runs");
    let what = format!("{test} on {path:?}: resumed at step {split} against uninterrupted");
    assert_same_state(&mut straight, &mut resumed, &what);
    Some(straight)
}

/// Two engines' exact states are the same bit for bit: on the CPU the f64 state and the
/// springs, on the GPU the device state. A failure names the first field and index that
/// differ.
pub fn assert_same_state(a: &mut Engine, b: &mut Engine, what: &str) {
    same(&exact_state(a), &exact_state(b), what);
}

/// A state field by field, each element as its Debug text (which tells every f64 and
/// f32 apart, -0 from 0 included).
type Fields = Vec<(&'static str, Vec<String>)>;

macro_rules! fields {
    ($($name:literal: $v:expr),* $(,)?) => {
        vec![$(($name, $v.into_iter().map(|x| format!("{x:?}")).collect())),*]
    };
}

fn exact_state(e: &mut Engine) -> Fields {
    match e {
        Engine::Cpu(s) => sim_fields(s),
        Engine::Gpu(g) => device_fields(&g.device_state()),
    }
}

fn sim_fields(s: &Simulation) -> Fields {
    let (p, springs) = (&s.particles, s.spring_table());
    let mut table: Vec<_> = springs.entries().collect();
    table.sort_by_key(|e| e.0);
    let [q0, q1, q2, q3, q4, q5] = &p.q;
    fields!("step, lost": [s.step, s.lost], "rng": [&s.rng], "sources": &s.sources,
        "Gear q0": q0, "Gear q1": q1, "Gear q2": q2, "Gear q3": q3, "Gear q4": q4, "Gear q5": q5,
        "radius": &p.radius, "mass": &p.mass, "inertia": &p.inertia, "fixed": &p.fixed,
        "active": &p.active, "material": &p.material, "shape": &p.shape, "sweep": &p.sweep,
        "copy": &p.copy, "springs": table, "sub-contact springs": &springs.sub)
}

fn device_fields(d: &DeviceState) -> Fields {
    fields!("device states": &d.states, "device props": &d.props,
        "device springs": &d.springs, "device sub-contact springs": &d.sub)
}

fn same(a: &Fields, b: &Fields, what: &str) {
    for ((name, x), (_, y)) in a.iter().zip(b) {
        if let Some(i) = (0..x.len().max(y.len())).find(|&i| x.get(i) != y.get(i)) {
            let (n, m, u, v) = (x.len(), y.len(), x.get(i), y.get(i));
            panic!("{what}: {name} differs first at [{i}] (of {n} and {m}):\n  {u:?}\n  {v:?}");
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
