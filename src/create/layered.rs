//! Layer-by-layer construction (paper 000 sec. 5.4.2, the "layered sequence"): rows of
//! particles dropped smoothly, from less than a particle diameter above the surface,
//! "each new layer less wide than the previous one to arrive at the desired outline".
//!
//! The outline is a triangle of width w_0 (`base_width`) and angle α (`slope`) on the
//! floor. Row k appears at t = start + k · interval. Its particles are placed on a grid
//! d_max apart across the outline, offset by d_max/2 in odd rows so that they fall into
//! the gaps of the row below. A position x is used while the pile there is lower than
//! the outline: while the height H(x) the new particle's centre will have above the
//! first row's centres fits the outline, H(x) ≤ (w_0/2 − |x − c| − d_max/2) tan α.
//! H(x) is measured (the default): the top of the material within d_max/2 of x, less
//! d_max − h with h = (√3/2) d_max, so that close-packed rows of the largest particle
//! give H = k h. Grains that settle into the row below, as irregular polygons do, then
//! get wider rows, and the pile grows to the outline asked for. With `row_height` the
//! rows have a fixed height instead: row k is w_0 − 2 k h / tan α wide and holds
//! ⌊w_k / d_max⌋ evenly spaced particles, whatever the pile does. With `rows` the block
//! stops after that many rows: under an outline steeper than the grains stand, the
//! flanks then take the grains' own slope, not the outline's.
//!
//! Each particle is placed `gap` · d_max above the highest particle within d_max of it
//! horizontally (or the floor), so it never starts inside another. Particles are drawn
//! as by a point source, from the block's own random stream; the progress (rows placed)
//! and the stream live in a [`SourceState`], so checkpoints carry them. A measured pile
//! is finished when neither grid offset has a position left under the outline.

use super::source::{SourceState, draw_shape, particle_at};
use crate::scene::Layered;
use crate::scene::rows::{largest, max_rows, row_width};
use crate::state::{NewParticle, Particles};

/// The most particles row k can hold (for the GPU path's buffers).
pub fn row_capacity(spec: &Layered, k: u32) -> usize {
    if spec.row_height.is_some() {
        row_size(spec, k)
    } else {
        grid(spec, k % 2 == 1).len()
    }
}

/// Number of particles in fixed row k (evenly spaced, at least d_max apart).
pub fn row_size(spec: &Layered, k: u32) -> usize {
    (row_width(spec, k) / largest(spec)).floor().max(1.0) as usize
}

/// The grid positions of a measured row inside the base of the outline: c + m d_max,
/// or c + (m + 1/2) d_max for an odd row.
fn grid(spec: &Layered, odd: bool) -> Vec<f64> {
    let d = largest(spec);
    let reach = 0.5 * spec.base_width - 0.5 * d;
    let offset = if odd { 0.5 } else { 0.0 };
    let m = (reach / d - offset).floor() as i64;
    (-m - 1..=m)
        .map(|m| spec.center_x + (m as f64 + offset) * d)
        .filter(|x| (x - spec.center_x).abs() <= reach)
        .collect()
}

/// Top of the material of copy `copy` within `reach` of x (the floor where there is
/// none).
fn surface(spec: &Layered, particles: &Particles, x: f64, reach: f64, copy: u32) -> f64 {
    (0..particles.len())
        .filter(|&j| particles.present_in(j, copy))
        .filter(|&j| (particles.q[0][j][0] - x).abs() < reach)
        .map(|j| particles.q[0][j][1] + particles.radius[j])
        .fold(spec.base_z, f64::max)
}

/// The positions of measured row k that still lie under the outline.
fn measured_row(spec: &Layered, particles: &Particles, odd: bool, copy: u32) -> Vec<f64> {
    let d = largest(spec);
    let h = 0.5 * 3f64.sqrt() * d;
    let tan = spec.slope.to_radians().tan();
    grid(spec, odd)
        .into_iter()
        .filter(|&x| {
            let top = surface(spec, particles, x, 0.5 * d, copy) - spec.base_z;
            let height = (top - (d - h)).max(0.0);
            height <= (0.5 * spec.base_width - (x - spec.center_x).abs() - 0.5 * d) * tan
        })
        .collect()
}

/// The x of the particles of row k: evenly spaced across the fixed row, or the measured
/// row's grid positions under the outline (the other offset's if none of its own are
/// left; none when the pile is finished).
fn row_positions(spec: &Layered, particles: &Particles, k: u32, copy: u32) -> Vec<f64> {
    if spec.row_height.is_some() {
        let w = row_width(spec, k);
        let n = row_size(spec, k);
        let spacing = w / n as f64;
        return (0..n)
            .map(|m| spec.center_x - 0.5 * w + (m as f64 + 0.5) * spacing)
            .collect();
    }
    let odd = k % 2 == 1;
    let xs = measured_row(spec, particles, odd, copy);
    if xs.is_empty() {
        measured_row(spec, particles, !odd, copy)
    } else {
        xs
    }
}

/// Whether a row is due at time t (`emit` is a no-op otherwise). Time first: `max_rows`
/// samples the polygon family for its reach (milliseconds), and this runs every step.
pub fn due(spec: &Layered, state: &SourceState, t: f64) -> bool {
    let k = state.inserted;
    t >= spec.start_time + k as f64 * spec.interval && k < max_rows(spec)
}

/// The particles of the rows due by time t (at most one row per call), on the pile of
/// copy `copy`.
pub fn emit(
    spec: &Layered,
    state: &mut SourceState,
    t: f64,
    material: u32,
    particles: &Particles,
    copy: u32,
) -> Vec<NewParticle> {
    if !due(spec, state, t) {
        return Vec::new();
    }
    let k = state.inserted;
    let d = largest(spec);
    let xs = row_positions(spec, particles, k, copy);
    if xs.is_empty() {
        // The pile has reached its outline: no more rows.
        state.inserted = max_rows(spec);
        return Vec::new();
    }
    let mut out = Vec::with_capacity(xs.len());
    for x in xs {
        let drawn = draw_shape(
            x,
            spec.diameter.as_ref(),
            spec.polygon.as_ref(),
            &mut state.rng,
        );
        let z = surface(spec, particles, x, d, copy) + 0.5 * d + spec.gap * d;
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
