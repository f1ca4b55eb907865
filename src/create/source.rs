//! Point sources (paper 001 sec. II, paper 000 sec. 5.3): particle k of a source appears
//! at t = start + k/rate at the outlet, x uniform within ±spread, with the initial
//! velocity. If the spot is taken, the same drawn particle waits for a later step. Each
//! source draws from its own random stream, so candidate k of a source is fixed by the
//! seed alone: only *when* it is placed depends on the state. The GPU path relies on
//! this to draw the candidates on the host ahead of time ([`upcoming`]).

use crate::base::rng::Rng;
use crate::scene::{PointSource, Size};
use crate::state::{NewParticle, Particles};

/// At most this many particles of one source are placed in one step (the GPU's
/// `INSERT_WINDOW`; both paths use it so that they insert on the same steps).
pub const MAX_PER_STEP: u32 = 4;

/// Progress of one source; part of the checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceState {
    pub inserted: u32,
    /// A particle drawn but not yet placed.
    pub pending: Option<Drawn>,
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

/// One particle as drawn by a source: its outlet x, the ellipse's full axes (a, b; a
/// disk's diameter twice), the start angle φ0 of the corners on the ellipse and the
/// orientation θ (both 0 for disks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drawn {
    pub x: f64,
    pub axes: [f64; 2],
    pub start: f64,
    pub theta: f64,
    /// A rod's random velocity added to the source's (`velocity_spread`; zero for the
    /// other shapes, so checkpoints, which rod runs do not write yet, need not hold it).
    pub kick: [f64; 2],
}

/// The candidates a source will place next, in order: the pending one, then fresh
/// draws, up to the source's count.
pub fn upcoming(spec: &PointSource, state: &SourceState) -> Vec<Drawn> {
    let left = spec.count.saturating_sub(state.inserted) as usize;
    let mut rng = state.rng.clone();
    let mut out: Vec<Drawn> = state.pending.into_iter().collect();
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

/// How far point source `source` of copy `copy` got by time t (the run's summary, and a
/// warning when it waits): it placed `inserted` of its `count`. `waiting_since` is the
/// time its next particle fell due, when that was a step or more before t and the
/// particle is still not placed: its spot at the outlet, `next_at`, has been taken at
/// every step since (a pile grown up to the outlet, a grain stuck there).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SourceProgress {
    pub copy: u32,
    pub source: usize,
    pub count: u32,
    pub inserted: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub waiting_since: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub next_at: Option<[f64; 2]>,
}

pub fn progress(
    spec: &PointSource,
    state: &SourceState,
    (copy, source): (u32, usize),
    t: f64,
    dt: f64,
) -> SourceProgress {
    let due = due_time(spec, state.inserted);
    let waiting = !state.done(spec) && due <= t - dt;
    let next = (state.pending).unwrap_or_else(|| draw(spec, &mut state.rng.clone()));
    SourceProgress {
        copy,
        source,
        count: spec.count,
        inserted: state.inserted,
        waiting_since: waiting.then_some(due),
        next_at: waiting.then_some([next.x, spec.position[1]]),
    }
}

/// A source has waited long enough to say so: ten of its intervals and a hundred steps.
pub fn stalled(p: &SourceProgress, spec: &PointSource, t: f64, dt: f64) -> bool {
    p.waiting_since
        .is_some_and(|since| t - since >= (10.0 / spec.rate).max(100.0 * dt))
}

/// Whether the source tries to insert at time t (`emit` is a no-op otherwise).
pub fn due(spec: &PointSource, state: &SourceState, t: f64) -> bool {
    !state.done(spec) && t >= due_time(spec, state.inserted)
}

fn size(s: &Size, rng: &mut Rng) -> f64 {
    let (lo, hi) = s.bounds();
    if lo == hi { lo } else { rng.range(lo, hi) }
}

/// Draws the next particle of a source, always in the same order: x, the size (one
/// diameter, or the two axes), then for polygons φ0 (if irregular) and θ, uniform in
/// [0, 2π/C) and [0, 2π).
/// Rods: then θ uniform in [0, 2π), and the random velocity's speed (uniform in
/// [0, velocity_spread)) and direction.
fn draw(spec: &PointSource, rng: &mut Rng) -> Drawn {
    let x = spec.position[0] + rng.range(-spec.spread, spec.spread);
    let mut d = draw_shape(x, spec.diameter.as_ref(), spec.polygon.as_ref(), rng);
    if spec.rod.is_some() {
        d.theta = rng.range(0.0, std::f64::consts::TAU);
        let speed = rng.range(0.0, spec.velocity_spread);
        let (s, c) = rng.range(0.0, std::f64::consts::TAU).sin_cos();
        d.kick = [speed * c, speed * s];
    }
    d
}

/// The size and shape part of [`draw`] (also used by layered construction).
pub fn draw_shape(
    x: f64,
    diameter: Option<&Size>,
    polygon: Option<&crate::scene::PolygonSpec>,
    rng: &mut Rng,
) -> Drawn {
    let axes = match (polygon, diameter) {
        (
            Some(crate::scene::PolygonSpec {
                axes: Some([a, b]), ..
            }),
            _,
        ) => {
            let a = size(a, rng);
            [a, size(b, rng)]
        }
        (_, Some(d)) => {
            let d = size(d, rng);
            [d, d]
        }
        (_, None) => unreachable!("validated: a point source has a diameter or polygon axes"),
    };
    let (mut start, mut theta) = (0.0, 0.0);
    if let Some(p) = polygon {
        if p.irregular {
            start = rng.range(0.0, std::f64::consts::TAU / p.corners as f64);
        }
        theta = rng.range(0.0, std::f64::consts::TAU);
    }
    Drawn {
        x,
        axes,
        start,
        theta,
        kick: [0.0; 2],
    }
}

/// The particle a drawn candidate becomes (at the outlet, not yet placed).
pub fn particle(spec: &PointSource, c: &Drawn, material: u32) -> NewParticle {
    let velocity = [spec.velocity[0] + c.kick[0], spec.velocity[1] + c.kick[1]];
    let mut p = particle_at(
        spec.polygon.as_ref(),
        c,
        [c.x, spec.position[1]],
        velocity,
        material,
    );
    if let Some(rod) = &spec.rod {
        // Paper 004's rod: width the drawn diameter, length `aspect` widths.
        let s = crate::shape::spheropolygon::Spheropolygon::rod(rod.aspect, c.axes[0]);
        p.radius = s.circumradius();
        p.sweep = s.radius;
        p.corners = s.core;
    }
    p
}

/// The particle a drawn candidate becomes at `position`.
pub fn particle_at(
    polygon: Option<&crate::scene::PolygonSpec>,
    c: &Drawn,
    position: [f64; 2],
    velocity: [f64; 2],
    material: u32,
) -> NewParticle {
    let (radius, corners) = super::shape_of(polygon, c.axes[0], c.axes[1], c.start);
    NewParticle {
        position,
        theta: c.theta,
        velocity,
        omega: 0.0,
        radius,
        fixed: false,
        fixed_rotation: false,
        material,
        corners,
        sweep: 0.0,
    }
}

/// Whether a disk at `p` with radius `r` would touch an active particle of copy `copy`.
fn is_free(particles: &Particles, p: [f64; 2], r: f64, copy: u32) -> bool {
    (0..particles.len()).all(|j| {
        if !particles.present_in(j, copy) {
            return true;
        }
        let q = particles.position(j);
        let dx = crate::state::nearest_image(p[0] - q[0], particles.period_x);
        let dz = p[1] - q[1];
        let s = r + particles.radius[j];
        dx * dx + dz * dz >= s * s
    })
}

/// The disks that source `spec` of copy `copy` places at time `t`; at most those due
/// by then, where no particle of that copy is in the way.
pub fn emit(
    spec: &PointSource,
    state: &mut SourceState,
    t: f64,
    material: u32,
    particles: &Particles,
    copy: u32,
) -> Vec<NewParticle> {
    let mut out = Vec::new();
    while due(spec, state, t) && (out.len() as u32) < MAX_PER_STEP {
        let drawn = match state.pending.take() {
            Some(p) => p,
            None => draw(spec, &mut state.rng),
        };
        let new = particle(spec, &drawn, material);
        let pos = new.position;
        // The spot is free when the circumscribed circles do not touch.
        let fresh_ok = out.iter().all(|o: &NewParticle| {
            let dx = crate::state::nearest_image(o.position[0] - pos[0], particles.period_x);
            let dz = o.position[1] - pos[1];
            dx * dx + dz * dz >= (o.radius + new.radius).powi(2)
        });
        if !(fresh_ok && is_free(particles, pos, new.radius, copy)) {
            state.pending = Some(drawn);
            break;
        }
        out.push(new);
        state.inserted += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A source of 5 particles at 2 a second from t = 0.
    fn spec() -> PointSource {
        let text = serde_json::json!({
            "name": "s", "dt": 0.001, "stop": { "time": 10.0 }, "gravity": { "g": [0.0, -1.0] },
            "domain": { "x": [-5.0, 5.0], "z": [-1.0, 10.0] },
            "materials": { "m": { "density": 1.0 } },
            "contact": { "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0, "mu": 0.5 },
            "particles": [{ "kind": "point_source", "material": "m", "position": [0.0, 5.0],
                            "spread": 1.0, "rate": 2.0, "count": 5, "diameter": 1.0 }]
        })
        .to_string();
        let scene = crate::scene::parse(&text, &[]).unwrap();
        match &scene.particles[0] {
            crate::scene::Creation::PointSource(s) => s.clone(),
            _ => unreachable!("a point source"),
        }
    }

    #[test]
    fn a_source_waits_once_its_next_particle_is_past_due_and_stalls_after_ten_intervals() {
        let (spec, dt) = (spec(), 0.01);
        let mut st = SourceState::new(1, 0);
        st.inserted = 2; // the next is due at t = 1
        let at = |st: &SourceState, t: f64| progress(&spec, st, (0, 0), t, dt);
        // Due this step: not tried yet, so not waiting.
        assert_eq!(at(&st, 1.0).waiting_since, None);
        let p = at(&st, 1.0 + 2.0 * dt);
        assert_eq!(p.waiting_since, Some(1.0));
        let x = p.next_at.unwrap()[0];
        assert!(
            (-1.0..=1.0).contains(&x) && p.next_at.unwrap()[1] == 5.0,
            "{p:?}"
        );
        assert!(!stalled(&p, &spec, 1.0 + 2.0 * dt, dt));
        // Ten intervals (5 time units) later it has stalled.
        assert!(!stalled(&at(&st, 5.9), &spec, 5.9, dt));
        assert!(stalled(&at(&st, 6.1), &spec, 6.1, dt));
        // The candidate it waits for is the one `emit` would place next.
        assert_eq!(upcoming(&spec, &st)[0].x, x);
        st.inserted = 5;
        assert_eq!(at(&st, 100.0).waiting_since, None);
    }
}
