//! What a polygon pair's contact at the last step proves about this step's (issue 37
//! items 2 and 3): a hint kept per candidate that decides only how much work the
//! overlap takes, never what it comes to.
//!
//! Most candidates of a pile are one of two kinds, step after step:
//! - **apart**, with an edge of one polygon whose line has every corner of the other
//!   beyond it (a separating axis, as Box2D's and Bullet's caches keep): checking it
//!   again is one side test per corner (`separated_by`);
//! - **resting**, their outlines crossing twice: p enters q through q's edge f_in on
//!   its own edge e_in and leaves it through q's edge f_out on e_out, and the overlap's
//!   outline is the crossing in, p's corners e_in + 1 … e_out, the crossing out, q's
//!   corners f_out + 1 … f_in (a `Chain`).
//!
//! A chain is checked in a few tests (`certify`): both crossings are proper crossings of
//! the two edges named, in the right sense, and every corner of the chains lies inside
//! the other polygon (in one triangle of its fan about its centre, found from the
//! crossing's edge). That proves it is the overlap's outline: the part of p's outline
//! from the crossing in to the crossing out lies in q and leaves it at both ends, so it
//! is a whole arc of p's outline inside q, as q's chain is of q's inside p, and the two
//! arcs close up; the outline of the overlap, convex, is a single closed curve of such
//! arcs, so it is those two. Every test keeps a margin far beyond its rounding, so a
//! chain that passes is the one an exact computation would find, and the one
//! `edges_inside` finds; the contact is then computed from the chain alone
//! (`assemble`), by the same arithmetic whichever way the chain was found. So the
//! result is the same, bit for bit, with a hint, with a stale one or with none: a run
//! resumed from a checkpoint (which keeps no hints) stays bitwise the same as one that
//! went on.

use super::outline::{Outline, along, chord_frame};
use super::{AreaContact, dot, norm, pair_scale, reduced_arm, sub, unit_or_up};
use crate::base::geometry::cross;
use crate::shape::P2;

/// A candidate's hint: nothing known (0), apart by an edge of p or of q (with the
/// corner of the other that reached deepest towards it), or a chain. Two bits of kind,
/// then four bits per edge or corner number.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Hint(pub u32);

/// A pair's overlap outline when they rest on each other (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chain {
    pub e_in: usize,
    pub f_in: usize,
    pub e_out: usize,
    pub f_out: usize,
}

/// What a hint says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seen {
    Nothing,
    /// Apart: the line of edge `edge` of p (`of_q` false) or of q has the other polygon
    /// wholly beyond it; `corner`: the other's corner that reached farthest towards it.
    Apart {
        of_q: bool,
        edge: usize,
        corner: usize,
    },
    Resting(Chain),
}

impl Hint {
    pub const NONE: Hint = Hint(0);

    pub fn apart(of_q: bool, edge: usize, corner: usize) -> Hint {
        Hint((1 + of_q as u32) | ((edge as u32) << 2) | (corner as u32) << 6)
    }

    pub fn resting(c: Chain) -> Hint {
        let n = |e: usize, k: u32| (e as u32) << (2 + 4 * k);
        Hint(3 | n(c.e_in, 0) | n(c.f_in, 1) | n(c.e_out, 2) | n(c.f_out, 3))
    }

    #[inline(always)]
    pub fn seen(self) -> Seen {
        let n = |k: u32| ((self.0 >> (2 + 4 * k)) & 15) as usize;
        match self.0 & 3 {
            0 => Seen::Nothing,
            1 | 2 => Seen::Apart {
                of_q: self.0 & 3 == 2,
                edge: n(0),
                corner: n(1),
            },
            _ => Seen::Resting(Chain {
                e_in: n(0),
                f_in: n(1),
                e_out: n(2),
                f_out: n(3),
            }),
        }
    }
}

/// How far beyond its rounding a sign must be to count, per unit of the pair's scale
/// and of the line's normal (1-norms): a side value (x − a)·m carries a few ε of
/// |x − a| |m|, and every |x − a| of the pair is below its scale (`room`), so this is
/// ~45 ε of the largest such value.
const MARGIN: f64 = 1e-14;

/// The thinnest overlap that makes a contact, relative to the two polygons'
/// circumscribed radii together: an overlap of area A whose outline spans D (the
/// diagonal of its corners' bounding box) is a contact when A > THICKNESS_FLOOR (r_p +
/// r_q) D. Thinner, it is at the level of the corners' rounding (polygons resting face
/// to face on a lattice touch within 1e-16 of a diameter, or not at all: slivers the
/// whole face long and 10⁻¹⁶ thick), and its force, k_n A/l ≈ 10⁻¹³ k_n r L/l, is far
/// below any a pile resolves. A corner pushed 10⁻⁸ d into a face is a contact (its
/// overlap is as thick as it is deep). The floor lets a pair that touches only to
/// rounding be proved apart in one test.
pub const THICKNESS_FLOOR: f64 = 1e-13;

fn norm1(a: P2) -> f64 {
    a[0].abs() + a[1].abs()
}

/// The margin of a side value against a line of normal m, per `MARGIN`: any two points
/// of the pair lie within |d|₁ + √2 (r_p + r_q) of each other.
#[inline(always)]
fn room(p: &Outline, q: &Outline, m: P2) -> f64 {
    let d = sub(p.base, q.base);
    MARGIN * (norm1(d) + 1.5 * (p.reach + q.reach)) * norm1(m)
}

/// Whether the line of edge k of `a` has every corner of `b` beyond it, or short of it
/// by less than what keeps their overlap under the floor: they are apart (a separating
/// axis). The overlap then lies in a strip of a along its edge k, no deeper than the
/// corners reach into it, and a convex region no wider than w has A ≤ w D. So a depth
/// of 0.9 `THICKNESS_FLOOR` (r_a + r_b) (times |m| ≥ |m|₁/√2 in side units) keeps it
/// below the floor.
///
/// Only the corner of b that reaches farthest along the normal is tested: b is convex,
/// so its corners' reach along any direction rises to one top and falls again around
/// the outline (strictly: corners on an ellipse never line up), and a corner that
/// reaches as far as both its neighbours is that top. It is climbed to from `corner`,
/// last step's, which is left at the top.
pub fn separated_by(a: &Outline, k: usize, b: &Outline, corner: &mut usize) -> bool {
    let (x, m) = (a.at(k), a.normal(k));
    let depth = 0.9 * THICKNESS_FLOOR * (a.reach + b.reach);
    let allowed = 0.7 * depth * norm1(m) - room(a, b, m);
    // (v + base − x)·m = v·m + (base − x)·m: the corners as stored, one product each.
    let limit = allowed - dot(sub(b.base, x), m);
    let n = b.v.len();
    let reach = |j: usize| dot(b.v[j], m);
    let mut s = if *corner < n { *corner } else { 0 };
    let mut top = reach(s);
    for _ in 0..n {
        let (next, prev) = (b.next_corner(s), if s == 0 { n - 1 } else { s - 1 });
        let (rn, rp) = (reach(next), reach(prev));
        if rn > top {
            (s, top) = (next, rn);
        } else if rp > top {
            (s, top) = (prev, rp);
        } else {
            break;
        }
    }
    *corner = s;
    top < limit
}

/// Whether an overlap of this area, whose outline's corners lie in the box [lo, hi], is
/// too thin to make a contact (`THICKNESS_FLOOR`).
/// Compared in squares (area ≥ 0 here; no square root on the step's hottest path): a
/// NaN area is below it, as before.
#[inline(always)]
pub fn below_floor(p: &Outline, q: &Outline, area: f64, (lo, hi): (P2, P2)) -> bool {
    let e = sub(hi, lo);
    let floor = THICKNESS_FLOOR * (p.reach + q.reach);
    !(area > 0.0 && area * area > floor * floor * dot(e, e))
}

/// The box [lo, hi] grown to hold x.
#[inline(always)]
pub fn hold(b: &mut (P2, P2), x: P2) {
    b.0 = [b.0[0].min(x[0]), b.0[1].min(x[1])];
    b.1 = [b.1[0].max(x[0]), b.1[1].max(x[1])];
}

/// An empty box.
pub const NO_BOX: (P2, P2) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);

/// The first edge of `edges` (a mask) of `a` whose line separates it from `b`, and the
/// corner of b that reaches deepest towards it.
pub fn separating_edge(a: &Outline, edges: u32, b: &Outline) -> Option<(usize, usize)> {
    super::outline::bits(edges).find_map(|k| {
        let mut corner = 0;
        separated_by(a, k, b, &mut corner).then_some((k, corner))
    })
}

/// Whether p's edge e and q's edge f cross properly, p entering q there (`entering`) or
/// leaving it, each sign clear of `room` (per unit |m|₁); and the crossing's parameters
/// along p's edge and along q's edge, and the crossing itself.
#[inline(always)]
fn crossing(
    p: &Outline,
    e: usize,
    q: &Outline,
    f: usize,
    entering: bool,
    room: f64,
) -> Option<(f64, [f64; 2], P2)> {
    let (x, y) = (p.at(e), p.at(p.next_corner(e)));
    let (a, b) = (q.at(f), q.at(q.next_corner(f)));
    let (pe, qe) = (sub(y, x), sub(b, a));
    // Inward normals of the two edges, as `Outline::normal` (from the corners as stored:
    // the base cancels).
    let (mq, mp) = (q.normal(f), p.normal(e));
    let (xa, ya, bx) = (sub(x, a), sub(y, a), sub(b, x));
    let (dx, dy) = (dot(xa, mq), dot(ya, mq));
    let (da, db) = (-dot(xa, mp), dot(bx, mp));
    let (rq, rp) = (room * norm1(qe), room * norm1(pe));
    // p entering q: x outside q's line, y inside; there q leaves p: a inside p's line,
    // b outside. Leaving, all the other way round.
    let sign = if entering { 1.0 } else { -1.0 };
    let proper = sign * dx < -rq && sign * dy > rq && sign * da > rp && sign * db < -rp;
    if !proper {
        return None;
    }
    let t = dx / (dx - dy);
    // The parameter along q's edge matters only when both crossings lie on one edge of
    // q (`chain_length`): its division is left to the caller.
    Some((t, [da, db], along(x, y, t)))
}

/// The parameter along q's edge of a crossing from its side values [da, db].
#[inline(always)]
fn parameter([da, db]: [f64; 2]) -> f64 {
    da / (da - db)
}

/// How many corners a chain of `a` takes from the crossing on edge `from` to the one on
/// edge `to` (corners from + 1 … to), `t_from` and `t_to` the crossings' parameters
/// along their edges: on one edge, none if the first comes first, else all of them.
/// None when the two are too close to tell.
fn chain_length(n: usize, from: usize, to: usize, t_from: f64, t_to: f64) -> Option<usize> {
    if from != to {
        return Some(if to > from { to - from } else { to + n - from });
    }
    if (t_to - t_from).abs() <= 1e-9 {
        return None;
    }
    Some(if t_from < t_to { 0 } else { n })
}

/// Whether the point v (in the contact's frame) lies inside `a` by the margin `room`
/// (per unit |m|₁), in the triangle of a's fan about its centre between corners k and
/// k + 1, starting from sector `k` and moving to a neighbouring one where v lies beyond
/// its rays (a few moves at most).
#[inline(always)]
fn in_fan(a: &Outline, v: P2, k: &mut usize, room: f64) -> bool {
    let n = a.v.len();
    let r = sub(v, a.base);
    for _ in 0..4 {
        let next = a.next_corner(*k);
        let (c0, c1) = (a.v[*k], a.v[next]);
        if cross(c0, r) < 0.0 {
            *k = if *k == 0 { n - 1 } else { *k - 1 };
        } else if cross(r, c1) < 0.0 {
            *k = next;
        } else {
            // Inside edge k's line (v − corner k, from the centre's frame).
            let m = [-(c1[1] - c0[1]), c1[0] - c0[0]];
            return dot(sub(r, c0), m) > room * norm1(m);
        }
    }
    false
}

/// The contact of p and q resting on each other along the chain c, if c is their
/// overlap's outline (module doc): Some(the contact, or None below the floor); None if
/// the chain does not hold, or is too close to call. The outline is the crossing in,
/// p's run of corners, the crossing out, q's run; its area the fan of triangles from
/// the crossing in (each within the overlap: no cancellation). The normal is
/// perpendicular to the line through the crossings, the force point its midpoint, as
/// `polygon_polygon_of` for any overlap. The same arithmetic whether the chain came
/// from a hint or from `edges_inside`.
pub fn rest(p: &Outline, q: &Outline, d: P2, c: Chain) -> Option<Option<AreaContact>> {
    let (np, nq) = (p.v.len(), q.v.len());
    if c.e_in.max(c.e_out) >= np || c.f_in.max(c.f_out) >= nq {
        return None;
    }
    let room = room(p, q, [1.0, 0.0]);
    let (t_in, r_in, x_in) = crossing(p, c.e_in, q, c.f_in, true, room)?;
    let (t_out, r_out, x_out) = crossing(p, c.e_out, q, c.f_out, false, room)?;
    let lp = chain_length(np, c.e_in, c.e_out, t_in, t_out)?;
    // q's run goes from the crossing out (q entering p) to the crossing in.
    let lq = if c.f_out == c.f_in {
        chain_length(nq, c.f_out, c.f_in, parameter(r_out), parameter(r_in))?
    } else {
        chain_length(nq, c.f_out, c.f_in, 0.0, 0.0)?
    };
    let (mut area2, mut prev) = (0.0, x_in);
    let mut span = NO_BOX;
    hold(&mut span, x_in);
    hold(&mut span, x_out);
    // p's corners: inside q, in its fan from the crossing in's edge.
    let (mut p_sum, mut k, mut e) = ([0.0; 2], c.f_in, c.e_in);
    for _ in 0..lp {
        e = p.next_corner(e);
        let v = p.at(e);
        if !in_fan(q, v, &mut k, room) {
            return None;
        }
        p_sum = [p_sum[0] + v[0], p_sum[1] + v[1]];
        hold(&mut span, v);
        area2 += cross(sub(prev, x_in), sub(v, x_in));
        prev = v;
    }
    area2 += cross(sub(prev, x_in), sub(x_out, x_in));
    prev = x_out;
    // q's corners: inside p, in its fan from the crossing out's edge.
    let (mut q_sum, mut k, mut f) = ([0.0; 2], c.e_out, c.f_out);
    for _ in 0..lq {
        f = q.next_corner(f);
        let v = q.at(f);
        if !in_fan(p, v, &mut k, room) {
            return None;
        }
        q_sum = [q_sum[0] + v[0], q_sum[1] + v[1]];
        hold(&mut span, v);
        area2 += cross(sub(prev, x_in), sub(v, x_in));
        prev = v;
    }
    let area = 0.5 * area2;
    if below_floor(p, q, area, span) {
        return Some(None);
    }
    let scale = pair_scale(p, q, d);
    let (np, nq) = (lp as f64, lq as f64);
    let (n, point, chord) = match chord_frame(x_in, x_out, (p_sum, np), (q_sum, nq), d, scale) {
        Some(frame) => frame,
        None => {
            // A vanishing chord: n along the centres, S at the mean of the outline's
            // corners.
            let k = (lp + lq + 2) as f64;
            let s = [
                (p_sum[0] + q_sum[0] + x_in[0] + x_out[0]) / k,
                (p_sum[1] + q_sum[1] + x_in[1] + x_out[1]) / k,
            ];
            (unit_or_up(d), s, 0.0)
        }
    };
    // S − r_j = S + d.
    let l = reduced_arm(norm(point), norm([point[0] + d[0], point[1] + d[1]]), scale);
    Some(Some(AreaContact {
        area,
        n,
        arm: point,
        chord,
        l,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hint_says_what_it_was_made_of() {
        assert_eq!(Hint::NONE.seen(), Seen::Nothing);
        for (of_q, edge, corner) in [(false, 0, 15), (true, 15, 0), (false, 9, 4)] {
            assert_eq!(
                Hint::apart(of_q, edge, corner).seen(),
                Seen::Apart { of_q, edge, corner }
            );
        }
        let c = Chain {
            e_in: 15,
            f_in: 0,
            e_out: 3,
            f_out: 14,
        };
        assert_eq!(Hint::resting(c).seen(), Seen::Resting(c));
    }
}
