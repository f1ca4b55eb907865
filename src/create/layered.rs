//! Layer-by-layer construction (paper 000 sec. 5.4.2, the "layered sequence"): rows of
//! particles dropped smoothly, from less than a particle diameter above the surface,
//! each row narrower than the last so that the pile grows with a chosen outline.
//!
//! Row k appears at t = start + k · interval with width w_k = w_0 − 2 k h / tan(slope),
//! h = (√3/2) d_max the height of a close-packed row of the largest particles. It holds
//! n = ⌊w_k / d_max⌋ particles, evenly spaced (at least d_max apart, so the new ones never
//! touch each other); each is placed `gap` · d_max above the highest particle within d_max
//! of it horizontally (or the floor), so it never starts inside another. Particles are
//! drawn as by a point source, from the block's own random stream; the progress (rows
//! placed) and the stream live in a [`SourceState`], so checkpoints carry them.

use super::source::{SourceState, draw_shape, particle_at};
use crate::scene::Layered;
use crate::state::{NewParticle, Particles};

/// d_max: the largest particle's reach (circumscribed diameter).
pub fn largest(spec: &Layered) -> f64 {
    crate::scene::reach_bound_of(spec.diameter.as_ref(), spec.polygon.as_ref())
}

fn row_height(spec: &Layered) -> f64 {
    0.5 * 3f64.sqrt() * largest(spec)
}

/// Width of row k.
pub fn row_width(spec: &Layered, k: u32) -> f64 {
    spec.base_width - 2.0 * k as f64 * row_height(spec) / spec.slope.to_radians().tan()
}

/// Number of rows: until a row would be narrower than one particle.
pub fn row_count(spec: &Layered) -> u32 {
    let d = largest(spec);
    (0..100_000)
        .take_while(|&k| row_width(spec, k) >= d)
        .count() as u32
}

/// Number of particles in row k (evenly spaced, at least d_max apart).
pub fn row_size(spec: &Layered, k: u32) -> usize {
    (row_width(spec, k) / largest(spec)).floor().max(1.0) as usize
}

/// Top of the material within `reach` of x (the floor where there is none).
fn surface(spec: &Layered, particles: &Particles, x: f64, reach: f64) -> f64 {
    (0..particles.len())
        .filter(|&j| particles.active[j])
        .filter(|&j| (particles.q[0][j][0] - x).abs() < reach)
        .map(|j| particles.q[0][j][1] + particles.radius[j])
        .fold(spec.base_z, f64::max)
}

/// The particles of the rows due by time t (at most one row per call).
pub fn emit(
    spec: &Layered,
    state: &mut SourceState,
    t: f64,
    material: u32,
    particles: &Particles,
) -> Vec<NewParticle> {
    let k = state.inserted;
    // Time first: `row_count` samples the polygon family for its reach (milliseconds),
    // and this runs every step.
    if t < spec.start_time + k as f64 * spec.interval || k >= row_count(spec) {
        return Vec::new();
    }
    let d = largest(spec);
    let w = row_width(spec, k);
    let n = row_size(spec, k);
    let spacing = w / n as f64;
    let mut out = Vec::with_capacity(n);
    for m in 0..n {
        let x = spec.center_x - 0.5 * w + (m as f64 + 0.5) * spacing;
        let drawn = draw_shape(
            x,
            spec.diameter.as_ref(),
            spec.polygon.as_ref(),
            &mut state.rng,
        );
        let z = surface(spec, particles, x, d) + 0.5 * d + spec.gap * d;
        out.push(particle_at(
            spec.polygon.as_ref(),
            &drawn,
            [x, z],
            [0.0, 0.0],
            material,
        ));
    }
    state.inserted += 1;
    out
}
