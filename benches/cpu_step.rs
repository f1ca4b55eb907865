//! Particle-steps per second of the CPU reference path on settled disk packings.
//! `cargo bench --bench cpu_step` prints one JSON line per workload. With CI=true the
//! workloads are small (a smoke run, not a measurement).
//!
//! Workloads: a 30° lattice pile (spring-dashpot, frictionless) of about 10³ disks and a
//! settled point-source heap (spring-dashpot with friction), each stepped from rest.

use std::time::Instant;
use talus::scene;
use talus::sim::Simulation;

fn measure(name: &str, mut sim: Simulation, steps: u64) {
    // warm up the buffers
    for _ in 0..10 {
        sim.step().expect("bench scene runs");
    }
    let n = sim.particles.active_count() as u64;
    let t = Instant::now();
    for _ in 0..steps {
        sim.step().expect("bench scene runs");
    }
    let secs = t.elapsed().as_secs_f64();
    println!(
        "{{\"workload\": \"{name}\", \"backend\": \"cpu\", \"shape\": \"disk\", \"particles\": {n}, \"contacts\": {}, \"steps\": {steps}, \"seconds\": {secs:.4}, \"particle_steps_per_second\": {:.4e}}}",
        sim.pairs.len(),
        (n * steps) as f64 / secs
    );
}

fn main() {
    let small = std::env::var("CI").is_ok_and(|v| v == "true");
    let steps = if small { 50 } else { 2000 };
    for l in if small { vec![31] } else { vec![31, 100] } {
        let s = scene::parse(
            &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/r1_pile.json"))
                .unwrap(),
            &[
                format!("particles[0].bottom_row={l}"),
                "gravity.ramp_time=0".into(),
            ],
        )
        .expect("scene");
        measure(
            &format!("lattice-pile-L{l}"),
            Simulation::new(s).unwrap(),
            steps,
        );
    }
    // A poured heap, run until all particles are in, then measured.
    let s = scene::parse(
        scene::DEFAULT_SCENE,
        &[
            "particles[1].count=400".into(),
            "particles[1].rate=40".into(),
        ],
    )
    .unwrap();
    let mut sim = Simulation::new(s).unwrap();
    let pour = if small { 2000 } else { 30_000 };
    for _ in 0..pour {
        sim.step().unwrap();
    }
    measure("poured-heap", sim, steps);
}
