//! Whether a contact shows a diverging state (SPEC: a run stops with the step, the
//! particle ids and the last good checkpoint).

use super::ContactForce;
use crate::cpu::contacts::Pair;
use crate::state::Particles;

/// Whether a contact shows a diverging state: a non-finite force, or an overlap beyond
/// `max_overlap` of the smaller radius (limits.max_overlap).
#[inline(always)]
pub fn diverges(particles: &Particles, pair: Pair, c: &ContactForce, max_overlap: f64) -> bool {
    if !(c.force[0].is_finite() && c.force[1].is_finite()) {
        return true;
    }
    // Most contacts are far below the limit: a multiplication (with room for rounding)
    // tells, and only those near it take the division that decides.
    let rmin = smaller_radius(particles, pair);
    c.overlap > 0.999 * max_overlap * rmin && c.overlap / rmin > max_overlap
}

/// The smaller radius of a pair (a wall: the particle's).
#[inline(always)]
pub(super) fn smaller_radius(particles: &Particles, pair: Pair) -> f64 {
    let ri = particles.radius[pair.i as usize];
    if pair.is_wall() {
        ri
    } else {
        ri.min(particles.radius[pair.j as usize])
    }
}

/// A contact's overlap relative to the smaller radius.
pub fn overlap_ratio(particles: &Particles, pair: Pair, c: &ContactForce) -> f64 {
    c.overlap / smaller_radius(particles, pair)
}
