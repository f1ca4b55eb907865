//! The contact network: coordination numbers (all grains, without rattlers, without
//! rattlers and surface grains) and the distribution of normal force magnitudes.

use super::input::{Grain, Touch};

/// Contacts per grain (a wall contact counts for its grain).
pub fn contact_counts(grains: &[Grain], touches: &[Touch]) -> Vec<usize> {
    let mut c = vec![0; grains.len()];
    for t in touches {
        c[t.a] += 1;
        if let Some(b) = t.b {
            c[b] += 1;
        }
    }
    c
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Coordination {
    /// Mean contacts per mobile grain.
    pub all: f64,
    /// Over mobile grains that are not rattlers, counting contacts between such grains
    /// and with walls and fixed grains.
    pub without_rattlers: f64,
    /// As `without_rattlers`, leaving out the free-surface grains too.
    pub interior: f64,
    pub rattlers: usize,
    /// A rattler has fewer contacts than this: 2 with friction, 3 without (one pass).
    pub rattler_below: usize,
    pub mobile: usize,
}

pub fn coordination(
    grains: &[Grain],
    touches: &[Touch],
    counts: &[usize],
    surface: &[bool],
    frictionless: bool,
) -> (Coordination, Vec<bool>) {
    let below = if frictionless { 3 } else { 2 };
    let rattler: Vec<bool> = grains
        .iter()
        .zip(counts)
        .map(|(g, &c)| !g.fixed && c < below)
        .collect();
    let mobile: Vec<usize> = (0..grains.len()).filter(|&k| !grains[k].fixed).collect();
    let mean = |keep: &dyn Fn(usize) -> bool, c: &[usize]| {
        let ks: Vec<usize> = mobile.iter().copied().filter(|&k| keep(k)).collect();
        if ks.is_empty() {
            return f64::NAN;
        }
        ks.iter().map(|&k| c[k]).sum::<usize>() as f64 / ks.len() as f64
    };
    // Contacts not involving a rattler.
    let mut firm = vec![0; grains.len()];
    for t in touches {
        let b_ok = t.b.is_none_or(|b| !rattler[b]);
        if !rattler[t.a] && b_ok {
            firm[t.a] += 1;
            if let Some(b) = t.b {
                firm[b] += 1;
            }
        }
    }
    let c = Coordination {
        all: mean(&|_| true, counts),
        without_rattlers: mean(&|k| !rattler[k], &firm),
        interior: mean(&|k| !rattler[k] && !surface[k], &firm),
        rattlers: rattler.iter().filter(|&&r| r).count(),
        rattler_below: below,
        mobile: mobile.len(),
    };
    (c, rattler)
}

/// P(f/⟨f⟩) of the grain–grain normal forces, as a probability density over bins of
/// `bin` (in units of the mean), and the mean.
pub fn force_distribution(touches: &[Touch], bin: f64) -> (Vec<(f64, f64)>, f64, f64) {
    let f: Vec<f64> = touches
        .iter()
        .filter(|t| t.b.is_some() && t.normal_force > 0.0)
        .map(|t| t.normal_force)
        .collect();
    if f.is_empty() {
        return (Vec::new(), 0.0, 0.0);
    }
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    let max = f.iter().copied().fold(0.0, f64::max);
    let bins = ((max / mean) / bin).floor() as usize + 1;
    let mut h = vec![0usize; bins];
    for v in &f {
        h[((v / mean / bin).floor() as usize).min(bins - 1)] += 1;
    }
    let n = f.len() as f64;
    (
        h.iter()
            .enumerate()
            .map(|(k, &c)| ((k as f64 + 0.5) * bin, c as f64 / (n * bin)))
            .collect(),
        mean,
        max,
    )
}
