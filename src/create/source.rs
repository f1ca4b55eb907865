//! Point sources (paper 001 sec. II, paper 000 sec. 5.3): particle k of a source appears
//! at t = start + k/rate at the outlet, x uniform within ±spread, with the initial
//! velocity. If the spot is taken, the same drawn particle waits for a later step. Each
//! source draws from its own random stream, so candidate k of a source is fixed by the
//! seed alone: only *when* it is placed depends on the state. The GPU path relies on
//! this to draw the candidates on the host ahead of time ([`upcoming`]).

use crate::rng::Rng;
use crate::scene::PointSource;
use crate::state::{NewDisk, Particles};

/// At most this many particles of one source are placed in one step (the GPU's
/// `INSERT_WINDOW`; both paths use it so that they insert on the same steps).
pub const MAX_PER_STEP: u32 = 4;

/// Progress of one source; part of the checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceState {
    pub inserted: u32,
    /// A particle drawn but not yet placed: (x, diameter).
    pub pending: Option<[f64; 2]>,
    /// The source's own random stream.
    pub rng: Rng,
}

impl SourceState {
    /// The state of source number `index` (in scene order) of a run seeded with `seed`.
    pub fn new(seed: u64, index: usize) -> Self {
        let mut mix = Rng::new(seed ^ (index as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03));
        Self {
            inserted: 0,
            pending: None,
            rng: Rng::new(mix.next_u64()),
        }
    }

    pub fn done(&self, spec: &PointSource) -> bool {
        self.inserted >= spec.count
    }
}

/// The candidates (x, diameter) a source will place next, in order: the pending one,
/// then fresh draws, up to the source's count.
pub fn upcoming(spec: &PointSource, state: &SourceState) -> Vec<[f64; 2]> {
    let left = spec.count.saturating_sub(state.inserted) as usize;
    let mut rng = state.rng.clone();
    let mut out: Vec<[f64; 2]> = state.pending.into_iter().collect();
    while out.len() < left {
        out.push(draw(spec, &mut rng));
    }
    out.truncate(left);
    out
}

/// The state after `placed` more particles of `upcoming(spec, state)` are placed (and
/// none is pending).
pub fn advanced(spec: &PointSource, state: &SourceState, placed: u32) -> SourceState {
    let mut s = state.clone();
    for _ in 0..placed {
        match s.pending.take() {
            Some(_) => {}
            None => {
                draw(spec, &mut s.rng);
            }
        }
        s.inserted += 1;
    }
    s
}

/// The first step whose time step·dt reaches `t` (the test `t_step >= t` of [`emit`]).
pub fn due_step(t: f64, dt: f64) -> u64 {
    let mut s = (t / dt).ceil().max(0.0) as u64;
    while s > 0 && (s - 1) as f64 * dt >= t {
        s -= 1;
    }
    while (s as f64 * dt) < t {
        s += 1;
    }
    s
}

/// Time at which particle k of a source is due.
pub fn due_time(spec: &PointSource, k: u32) -> f64 {
    spec.start_time + k as f64 / spec.rate
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
) -> Vec<NewDisk> {
    let mut out = Vec::new();
    while !state.done(spec)
        && t >= due_time(spec, state.inserted)
        && (out.len() as u32) < MAX_PER_STEP
    {
        let [x, d] = match state.pending.take() {
            Some(p) => p,
            None => draw(spec, &mut state.rng),
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
