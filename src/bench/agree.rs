//! The GPU path against the CPU path on the benchmark workloads at full size (issue 38:
//! `talus agree`, the agreement phase of `scripts/gpu-check`): one scene run the same
//! number of steps on both paths, then positions, pair forces and contact counts
//! compared, each against a stated tolerance.
//!
//! The workloads are dense and start at rest with neighbours exactly touching, so for a
//! few hundred steps they are not chaotic: the paths part only by the GPU's f32 forces
//! and velocities (relative ~6e-8) carried through the steps. Which of the exactly
//! touching pairs count as contacts is decided by rounding, so forces are compared pair
//! by pair over the union of both contact lists, a missing contact counting as zero.

use super::BenchError;
use crate::gpu::GpuSimulation;
use crate::scene::Scene;
use crate::sim::Simulation;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// What counts as agreement after a run of both paths.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Tolerance {
    /// Largest position difference of a particle, in diameters.
    pub position: f64,
    /// Worst normal-force difference of a pair, in units of the CPU's mean normal force.
    pub normal_force: f64,
    /// The mean of the pairs' normal-force differences, in the same unit.
    pub typical_normal_force: f64,
    /// Relative difference of the sum of the contacts' vertical forces (the weight the
    /// contacts carry).
    pub vertical_sum: f64,
}

/// The tolerances of `talus agree` for disks: SPEC 3's 1e-3 of the mean force for the
/// worst pair, ten times tighter for the typical pair and the weight carried, 1e-5 d for
/// positions. Measured on lavapipe after 300 steps (stop 47, benches/RESULTS.md):
/// 10⁵ disks at 3.0e-7 d, 1.7e-4 worst, 8.6e-7 in the vertical sum.
pub const DISKS: Tolerance = Tolerance {
    position: 1e-5,
    normal_force: 1e-3,
    typical_normal_force: 1e-4,
    vertical_sum: 1e-4,
};

/// The tolerances for the polygon pile. Its faces start exactly touching, where the
/// GPU's corners (whole position units) are right to 1e-3 only from A/l ≈ 2e-6 d
/// (docs/GUIDE.md, "Precision"), and the 60° pile slumps a little, stick–slip deciding which
/// faces slide: one pair in a thousand parts from its twin by a few per cent of the mean
/// force while the typical pair and the weight carried stay within SPEC 3's 1e-3.
/// Measured on lavapipe after 300 steps: 3·10⁴ 12-gons at 6.9e-5 d, 6.1e-2 worst,
/// 1.8e-4 typical, 8.7e-6 in the vertical sum (3000: 7.5e-5 d, 4.4e-2, 4.0e-4, 2.5e-5).
pub const POLYGONS: Tolerance = Tolerance {
    position: 5e-4,
    normal_force: 0.2,
    typical_normal_force: 1e-3,
    vertical_sum: 1e-3,
};

/// Rods (paper 004's stiff law, rows pressed 2e-3 d into each other at the start, so
/// they ring): no tolerance is claimed yet, their comparison is reported only.
pub const RODS: Option<Tolerance> = None;

/// One workload on both paths.
#[derive(Clone, Debug, Serialize)]
pub struct Agreement {
    pub workload: String,
    /// The GPU path's adapter.
    pub adapter: String,
    pub particles: usize,
    pub steps: u64,
    /// Wall time of each path's steps (the GPU's includes its upload and download).
    pub cpu_seconds: f64,
    pub gpu_seconds: f64,
    pub position_difference: f64,
    pub normal_force_difference: f64,
    pub typical_normal_force_difference: f64,
    pub vertical_sum_difference: f64,
    pub contacts_cpu: usize,
    pub contacts_gpu: usize,
    /// None where no tolerance is claimed (rods): reported, not judged.
    pub tolerance: Option<Tolerance>,
    pub passed: bool,
}

/// Runs `scene` for `steps` steps on the CPU path (this process's threads) and on the
/// GPU path, and compares the two end states. `d`: the particles' diameter.
pub fn agree(
    workload: &str,
    scene: &Scene,
    steps: u64,
    d: f64,
    tolerance: Option<Tolerance>,
) -> Result<Agreement, BenchError> {
    let invalid = |source| BenchError::Scene {
        workload: workload.into(),
        source,
    };
    let t = Instant::now();
    let mut gpu = GpuSimulation::new(Simulation::new(scene.clone()).map_err(invalid)?)?;
    gpu.advance(steps)?;
    let adapter = gpu.adapter_name().to_string();
    let g = gpu.download();
    let gpu_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut cpu = Simulation::new(scene.clone()).map_err(invalid)?;
    for _ in 0..steps {
        cpu.step()?;
    }
    let cpu_seconds = t.elapsed().as_secs_f64();
    let position_difference = max_position_difference(g, &cpu, d);
    let forces = pair_force_difference(g, &cpu);
    let passed = tolerance.is_none_or(|t| {
        position_difference <= t.position
            && forces.worst <= t.normal_force
            && forces.typical <= t.typical_normal_force
            && forces.vertical_sum <= t.vertical_sum
    });
    Ok(Agreement {
        workload: workload.into(),
        adapter,
        particles: cpu.particles.active_count(),
        steps,
        cpu_seconds,
        gpu_seconds,
        position_difference,
        normal_force_difference: forces.worst,
        typical_normal_force_difference: forces.typical,
        vertical_sum_difference: forces.vertical_sum,
        contacts_cpu: forces.contacts_b,
        contacts_gpu: forces.contacts_a,
        tolerance,
        passed,
    })
}

/// `talus agree`'s answer: every workload's agreement, and those that could not run.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub cpu: String,
    /// Threads of the CPU path.
    pub threads: usize,
    pub results: Vec<Agreement>,
    pub failures: Vec<super::Failure>,
}

/// Runs every workload (`super::workloads`) on both paths for `steps` steps;
/// `log` receives one line per workload. A workload that cannot run (too large for the
/// adapter, a divergence) is listed in `failures` and the rest go on.
pub fn run(
    sizes: &[usize],
    polygon_sizes: &[usize],
    rod_sizes: &[usize],
    steps: u64,
    log: &mut dyn FnMut(String),
) -> Result<Report, BenchError> {
    let mut results = Vec::new();
    let mut failures = Vec::new();
    for (name, text) in super::workloads(sizes, polygon_sizes, rod_sizes, false) {
        let scene = crate::scene::parse(&text, &[]).map_err(|source| BenchError::Scene {
            workload: name.clone(),
            source,
        })?;
        let tolerance = if name.starts_with("packing") {
            Some(DISKS)
        } else if name.starts_with("polygon") {
            Some(POLYGONS)
        } else {
            RODS
        };
        // Every workload's grains are one unit wide.
        match agree(&name, &scene, steps, 1.0, tolerance) {
            Ok(a) => {
                let limit = |f: fn(&Tolerance) -> f64| {
                    a.tolerance
                        .as_ref()
                        .map_or(String::new(), |t| format!(" (≤ {:.0e})", f(t)))
                };
                log(format!(
                    "{:>18} {:>7} particles, {} steps: positions {:.2e} d{}, normal forces {:.2e} of the mean at worst{}, {:.2e} typically{}, vertical sum {:.2e}{}, contacts {} CPU / {} GPU: {}",
                    a.workload,
                    a.particles,
                    a.steps,
                    a.position_difference,
                    limit(|t| t.position),
                    a.normal_force_difference,
                    limit(|t| t.normal_force),
                    a.typical_normal_force_difference,
                    limit(|t| t.typical_normal_force),
                    a.vertical_sum_difference,
                    limit(|t| t.vertical_sum),
                    a.contacts_cpu,
                    a.contacts_gpu,
                    match (a.tolerance, a.passed) {
                        (None, _) => "reported (no tolerance claimed)",
                        (_, true) => "agree",
                        (_, false) => "DISAGREE",
                    }
                ));
                results.push(a);
            }
            Err(e) => {
                log(format!("{name:>18} failed: {e}"));
                failures.push(super::Failure {
                    workload: name,
                    backend: "gpu and cpu".into(),
                    error: e.to_string(),
                });
            }
        }
    }
    Ok(Report {
        cpu: super::cpu_name(),
        threads: rayon::current_num_threads(),
        results,
        failures,
    })
}

/// Largest position difference of the particles both states have (active in both), in
/// units of `d`; NaN when a position is not finite.
pub fn max_position_difference(a: &Simulation, b: &Simulation, d: f64) -> f64 {
    let n = a.particles.len().min(b.particles.len());
    (0..n)
        .filter(|&i| a.particles.active[i] && b.particles.active[i])
        .map(|i| {
            let (p, q) = (a.particles.position(i), b.particles.position(i));
            (p[0] - q[0]).abs().max((p[1] - q[1]).abs()) / d
        })
        .fold(0.0_f64, |m, x| {
            if x.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(x)
            }
        })
}

/// Two states' contacts compared pair by pair (`pair_force_difference`).
#[derive(Clone, Copy, Debug)]
pub struct ForceDifference {
    /// Worst normal-force difference of a pair over the union of both contact lists (a
    /// missing contact counts as zero force), in units of b's mean normal force.
    pub worst: f64,
    /// The mean of those differences over the union, in the same unit: the typical pair.
    pub typical: f64,
    /// Relative difference of the sums of the contacts' vertical forces.
    pub vertical_sum: f64,
    pub contacts_a: usize,
    pub contacts_b: usize,
}

/// The recorded contacts of `a` against those of `b` (the reference), pair by pair.
pub fn pair_force_difference(a: &Simulation, b: &Simulation) -> ForceDifference {
    let forces = |s: &Simulation| -> BTreeMap<(u32, u32), f64> {
        s.pairs
            .iter()
            .zip(&s.contacts)
            .map(|(p, c)| ((p.i, p.j), c.f_n))
            .collect()
    };
    let (fa, fb) = (forces(a), forces(b));
    let mean = fb.values().sum::<f64>() / fb.len() as f64;
    let union: std::collections::BTreeSet<_> = fa.keys().chain(fb.keys()).collect();
    let differences = || {
        (union.iter()).map(|k| (fa.get(k).unwrap_or(&0.0) - fb.get(k).unwrap_or(&0.0)).abs() / mean)
    };
    let worst = differences().fold(0.0_f64, |m, x| {
        if x.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(x)
        }
    });
    let typical = differences().sum::<f64>() / union.len().max(1) as f64;
    let total = |s: &Simulation| s.contacts.iter().map(|c| c.force[1]).sum::<f64>();
    let (ta, tb) = (total(a), total(b));
    ForceDifference {
        worst,
        typical,
        vertical_sum: (ta - tb).abs() / tb.abs(),
        contacts_a: fa.len(),
        contacts_b: fb.len(),
    }
}
