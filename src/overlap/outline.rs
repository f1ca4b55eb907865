//! A polygon as the contact's queries see it (`Outline`: its corners in the frame of the
//! pair, at particle i's centre), and the small steps every polygon query shares: an
//! edge mask's bits, a point along an edge, the contact frame of a chord.

use super::{dot, sub};
use crate::shape::P2;

/// A polygon in the contact's frame, at particle i's centre: its corners relative to its
/// own centre, where that centre lies (`base`: 0 for i, −d for j), and its
/// circumscribed radius (a scale for the tolerances).
#[derive(Clone, Copy, Debug)]
pub struct Outline<'a> {
    pub v: &'a [P2],
    pub base: P2,
    pub reach: f64,
}

impl Outline<'_> {
    /// Corner k in the contact's frame.
    #[inline(always)]
    pub(super) fn at(&self, k: usize) -> P2 {
        let v = self.v[k];
        [v[0] + self.base[0], v[1] + self.base[1]]
    }

    #[inline(always)]
    pub(super) fn next_corner(&self, k: usize) -> usize {
        if k + 1 == self.v.len() { 0 } else { k + 1 }
    }

    /// The inward normal (not of unit length) of edge f, corner f to f + 1: the
    /// half-plane inside it is (x − at(f))·m ≥ 0.
    #[inline(always)]
    pub(super) fn normal(&self, f: usize) -> P2 {
        let (a, b) = (self.v[f], self.v[self.next_corner(f)]);
        [-(b[1] - a[1]), b[0] - a[0]]
    }

    /// Whether the point x lies inside the outline (on an edge counts as inside).
    pub(super) fn contains(&self, x: P2) -> bool {
        (0..self.v.len()).all(|k| dot(sub(x, self.at(k)), self.normal(k)) >= 0.0)
    }
}

/// The bits of a mask, lowest first.
pub(super) fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            k
        })
    })
}

/// x + t (y − x).
#[inline(always)]
pub(super) fn along(x: P2, y: P2, t: f64) -> P2 {
    [x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])]
}

/// The normal, force point and chord of an overlap whose outline crosses from p into q
/// at xa and back at xb (paper 000 sec. 2.2: n perpendicular to the line through the
/// crossings, S at its midpoint, n pointing from j to i), given the sums and counts of
/// p's corners inside q and of q's inside p; None when the chord vanishes (below 10⁻¹²
/// of the pair's `scale`). Which way n points is decided by the unnormalised normal,
/// whose sign is all that matters: the square root and the division that make n a unit
/// vector then run beside that test instead of before it.
#[inline(always)]
pub(super) fn chord_frame(
    xa: P2,
    xb: P2,
    (sum_p, n_p): (P2, f64),
    (sum_q, n_q): (P2, f64),
    d: P2,
    scale: f64,
) -> Option<(P2, P2, f64)> {
    let e = sub(xb, xa);
    let (e2, small) = (dot(e, e), 1e-12 * scale);
    if !(e2 > small * small) {
        return None;
    }
    let m = [-e[1], e[0]];
    let s = [0.5 * (xa[0] + xb[0]), 0.5 * (xa[1] + xb[1])];
    // Corners of i inside j lie on j's side of the line, corners of j inside i on i's
    // side.
    let side = dot(m, [sum_p[0] - n_p * s[0], sum_p[1] - n_p * s[1]])
        - dot(m, [sum_q[0] - n_q * s[0], sum_q[1] - n_q * s[1]]);
    let flip = side > 0.0 || (side == 0.0 && dot(m, d) < 0.0);
    let chord = e2.sqrt();
    let inv = if flip { -1.0 / chord } else { 1.0 / chord };
    Some(([m[0] * inv, m[1] * inv], s, chord))
}
