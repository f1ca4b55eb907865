//! Point sources (paper 001 sec. II, paper 000 sec. 5.3): particle k of a source appears
//! at t = start + k/rate at the outlet, x uniform within ±spread, with the initial
//! velocity. If the spot is taken, the same drawn particle waits for a later step, so the
//! random stream (and with it the run) stays deterministic.

use crate::rng::Rng;
use crate::scene::PointSource;
use crate::state::{NewDisk, Particles};

/// Progress of one source; part of the checkpoint.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceState {
    pub inserted: u32,
    /// A particle drawn but not yet placed: (x, diameter).
    pub pending: Option<[f64; 2]>,
}

impl SourceState {
    pub fn done(&self, spec: &PointSource) -> bool {
        self.inserted >= spec.count
    }
}

/// Draws the next particle of a source: (x, diameter).
fn draw(spec: &PointSource, rng: &mut Rng) -> [f64; 2] {
    let x = spec.position[0] + rng.range(-spec.spread, spec.spread);
    let (lo, hi) = crate::scene::Size::bounds(&spec.diameter);
    let d = if lo == hi { lo } else { rng.range(lo, hi) };
    [x, d]
}

/// Whether a disk at `p` with radius `r` would touch an active particle.
fn is_free(particles: &Particles, p: [f64; 2], r: f64) -> bool {
    (0..particles.len()).all(|j| {
        if !particles.active[j] {
            return true;
        }
        let q = particles.position(j);
        let (dx, dz) = (p[0] - q[0], p[1] - q[1]);
        let s = r + particles.radius[j];
        dx * dx + dz * dz >= s * s
    })
}

/// The disks that source `spec` places at time `t`; at most those due by then.
pub fn emit(
    spec: &PointSource,
    state: &mut SourceState,
    t: f64,
    material: u32,
    particles: &Particles,
    rng: &mut Rng,
) -> Vec<NewDisk> {
    let mut out = Vec::new();
    while !state.done(spec) && t >= spec.start_time + state.inserted as f64 / spec.rate {
        let [x, d] = match state.pending.take() {
            Some(p) => p,
            None => draw(spec, rng),
        };
        let pos = [x, spec.position[1]];
        let fresh_ok = out.iter().all(|o: &NewDisk| {
            let (dx, dz) = (o.position[0] - pos[0], o.position[1] - pos[1]);
            dx * dx + dz * dz >= (o.radius + 0.5 * d).powi(2)
        });
        if !(fresh_ok && is_free(particles, pos, 0.5 * d)) {
            state.pending = Some([x, d]);
            break;
        }
        out.push(NewDisk {
            position: pos,
            theta: 0.0,
            velocity: spec.velocity,
            omega: 0.0,
            radius: 0.5 * d,
            fixed: false,
            fixed_rotation: false,
            material,
        });
        state.inserted += 1;
    }
    out
}
