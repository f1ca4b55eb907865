//! Overlap-area contact geometry of convex polygons (paper 000 sec. 2.2, SPEC 2.3).
//!
//! Two polygons touch when their outlines intersect. The overlap polygon is computed
//! exactly by convex clipping (Sutherland–Hodgman); its area A measures the
//! deformation. The two crossing points of the outlines define the intersection line:
//! the normal is perpendicular to it, the tangent along it, and the force acts at its
//! midpoint S. Degenerate overlaps fall back to quantities that stay finite and vary
//! continuously with the area, which then is small: fewer than two crossings (one
//! polygon inside the other) or a vanishing chord take S at the mean of the overlap's
//! corners and n along the line of centres; more than two crossings (nearly parallel
//! edges) take the two that are farthest apart, which spans the thin overlap along its
//! length.
//!
//! **Frames (issue 18).** Every function works in a frame at particle i's centre: its
//! corners relative to its centre (`shape::rotate`), the other particle through the
//! offset d = r_i − r_j, a wall through its end points relative to r_i
//! (`geometry::wall_from`). Absolute world coordinates never enter: on coordinates of
//! size X, the crossings would carry X ε and the shoelace area X² ε, which at X = 100 d
//! is more than a resting overlap's whole area. The area is then summed about the
//! overlap's own first corner (`shape::area`), so a sliver 1e-6 d deep keeps ~1e-10 of
//! relative precision. The results are in the same frame: `arm` is the force point
//! relative to r_i. The clipping follows `shaders/polygon.wgsl` step for step: each
//! corner of the clipped polygon remembers the line its outgoing edge lies on.

use crate::geometry::{WallSegment, cross};
use crate::shape::{MAX_CORNERS, P2};
use std::cell::RefCell;

/// Most corners an overlap polygon can have: each clipping half-plane adds at most one.
pub const MAX_CLIP: usize = 2 * MAX_CORNERS as usize + 4;

/// Line ids of the clipping: edge m of p (corner m to m + 1) is m, edge m of q is
/// `Q_LINE + m`; then a wall's line and the lines across its two ends (as in
/// polygon.wgsl).
pub const Q_LINE: u32 = MAX_CORNERS;
pub const WALL_LINE: u32 = 2 * MAX_CORNERS;
pub const END_A_LINE: u32 = WALL_LINE + 1;
pub const END_B_LINE: u32 = WALL_LINE + 2;

/// A convex polygon being clipped, on the stack (the overlap is computed for every
/// contact every step; no allocation): its corners and, for each, the line of its
/// outgoing edge (corner k to k + 1).
#[derive(Clone, Copy, Debug)]
pub struct Clip {
    pub n: usize,
    pub v: [P2; MAX_CLIP],
    pub line: [u32; MAX_CLIP],
}

impl Default for Clip {
    fn default() -> Self {
        Self {
            n: 0,
            v: [[0.0; 2]; MAX_CLIP],
            line: [0; MAX_CLIP],
        }
    }
}

thread_local! {
    /// Scratch polygons for the clipping, one set per thread: the overlap of every
    /// contact is computed every step, and zeroing fresh 36-corner buffers each time
    /// cost as much as the clipping itself.
    static SCRATCH: RefCell<[Clip; 3]> = RefCell::new([Clip::default(); 3]);
}

/// Runs f with this thread's scratch polygons.
fn with_scratch<R>(f: impl FnOnce(&mut [Clip; 3]) -> R) -> R {
    SCRATCH.with(|s| f(&mut s.borrow_mut()))
}

impl Clip {
    /// Becomes a polygon's outline: edge k on line `first_line + k`.
    fn set_outline(&mut self, p: &[P2], first_line: u32) {
        self.n = 0;
        for (k, x) in p.iter().enumerate() {
            self.push(*x, first_line + k as u32);
        }
    }

    pub fn corners(&self) -> &[P2] {
        &self.v[..self.n]
    }

    /// The lines of the edges into and out of corner k.
    fn lines_at(&self, k: usize) -> (u32, u32) {
        let before = if k == 0 { self.n - 1 } else { k - 1 };
        (self.line[before], self.line[k])
    }

    fn push(&mut self, x: P2, line: u32) {
        self.v[self.n] = x;
        self.line[self.n] = line;
        self.n += 1;
    }
}

/// The geometry of one area contact, seen from particle i, in a frame at its centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AreaContact {
    /// Overlap area A.
    pub area: f64,
    /// Unit normal from j to i, perpendicular to the intersection line.
    pub n: P2,
    /// Force point S relative to r_i: the midpoint of the intersection line.
    pub arm: P2,
    /// Length L of the intersection line (0 in the degenerate fallback).
    pub chord: f64,
    /// l = 1/(1/l_i + 1/l_j), l_i = |S − r_i| (paper 000 eq. 6); l_i alone for a wall.
    pub l: f64,
}

fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn norm(a: P2) -> f64 {
    dot(a, a).sqrt()
}

/// One Sutherland–Hodgman step (`clip_lines` in polygon.wgsl): the part of `src` in
/// the half-plane {x : (x − a)·m ≥ 0}, whose boundary is line `id`. Leaving the
/// half-plane the outline follows the clip line, entering it the edge it was on.
fn clip_lines(src: &Clip, a: P2, m: P2, id: u32, dst: &mut Clip) {
    dst.n = 0;
    let n = src.n;
    if n == 0 {
        return;
    }
    let side = |x: P2| dot(sub(x, a), m);
    // Edge e runs from corner e to the next, the last back to the first (no modulo: an
    // integer division for every corner of every clip cost more than the clip). Each
    // corner's side is computed once and carried to the next edge (the kernel computes
    // it twice; the values are the same).
    let first = side(src.v[0]);
    let mut dx = first;
    for e in 0..n {
        let x = src.v[e];
        let (y, dy) = if e + 1 == n {
            (src.v[0], first)
        } else {
            (src.v[e + 1], side(src.v[e + 1]))
        };
        if dx >= 0.0 {
            dst.push(x, src.line[e]);
        }
        if (dx >= 0.0) != (dy >= 0.0) {
            let t = dx / (dx - dy);
            let at = [x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])];
            dst.push(at, if dx >= 0.0 { id } else { src.line[e] });
        }
        dx = dy;
    }
}

/// Where a corner of the overlap polygon comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Origin {
    /// A corner of p inside q (two of p's edges meet).
    P,
    /// A corner of q inside p (two of q's edge lines meet).
    Q,
    /// An edge of p crosses an edge of q: a crossing point of the outlines.
    Crossing,
}

fn origin_of(line_in: u32, line_out: u32) -> Origin {
    match (line_in < Q_LINE, line_out < Q_LINE) {
        (true, true) => Origin::P,
        (false, false) => Origin::Q,
        _ => Origin::Crossing,
    }
}

/// Particle j's corners (relative to r_j) in i's frame, d = r_i − r_j, into `out`.
fn in_frame_of_i(q: &[P2], d: P2, out: &mut Clip) {
    out.n = q.len();
    for (o, x) in out.v.iter_mut().zip(q) {
        *o = sub(*x, d);
    }
}

/// The overlap polygon: p (centred on the origin) clipped by the edges of q, both
/// convex and counter-clockwise in i's frame (q's centre at −d). The lines of the
/// clipped polygon's edges tell where each of its corners comes from; the crossings come
/// out of the clipping, with no extra search.
/// Returns which of the two scratch polygons `buf` holds the result.
fn clip_by(p: &[P2], q: &[P2], d: P2, buf: [&mut Clip; 2]) -> usize {
    clip_in_order::<true>(p, q, d, buf)
}

/// `clip_by`; `SKIP`: skip the edges that cannot cut the corners left after the first
/// two clips (what `clip_by` does; without, every edge near p's circle is clipped, which
/// the tests compare with).
fn clip_in_order<const SKIP: bool>(p: &[P2], q: &[P2], d: P2, buf: [&mut Clip; 2]) -> usize {
    let [x, y] = buf;
    x.set_outline(p, 0);
    let mut cur = 0;
    // p lies in the circle of radius r about its centre: an edge line of q that keeps
    // the whole circle inside clips nothing, one that keeps it all outside leaves no
    // overlap. Only the few edges near the contact are clipped.
    let r = p.iter().map(|v| dot(*v, *v)).fold(0.0, f64::max).sqrt();
    // The edges are clipped from the corner of q that points most towards p (the
    // largest q_k·d): its two edges cut p down to the few corners near the contact
    // first, and the later clips treat those few instead of all of p.
    let nq = q.len();
    let first = (0..nq).fold(0, |best, k| {
        if dot(q[k], d) > dot(q[best], d) {
            k
        } else {
            best
        }
    });
    let first = if first == 0 { nq - 1 } else { first - 1 };
    // After the first two clips, the few corners left lie in a small circle (centre c,
    // radius rho): an edge whose half-plane holds all of it with room for rounding
    // (relative 1e-6, and 1e-12 of r, far beyond the rounding of a corner's side in
    // `clip_lines`) leaves every corner where it is, exactly as clipping by it would: the
    // clip is skipped, bitwise the same.
    let mut cap: Option<(P2, f64)> = None;
    for e in 0..nq {
        let (src, dst) = if cur == 0 {
            (&*x, &mut *y)
        } else {
            (&*y, &mut *x)
        };
        if src.n == 0 {
            break;
        }
        if SKIP && e == 2 {
            let (c, rho2) = bounding_circle(src.corners());
            cap = Some((c, rho2.sqrt() * (1.0 + 1e-6) + 1e-12 * r));
        }
        let k = if first + e >= nq {
            first + e - nq
        } else {
            first + e
        };
        let (a, b) = (q[k], q[if k + 1 == nq { 0 } else { k + 1 }]);
        let m = [-(b[1] - a[1]), b[0] - a[0]];
        let centre = -dot(a, m);
        match circle_side(centre, r, m) {
            Side::Inside => continue,
            Side::Outside => {
                // No overlap: the result is an empty polygon.
                dst.n = 0;
                cur = 1 - cur;
                break;
            }
            Side::Across => {}
        }
        if let Some((c, rho)) = cap {
            let side = dot(sub(c, a), m);
            if side > 0.0 && side * side > rho * rho * dot(m, m) {
                continue;
            }
        }
        clip_lines(src, a, m, Q_LINE + k as u32, dst);
        cur = 1 - cur;
    }
    cur
}

/// A circle holding every corner: their mean, and the largest squared distance from it.
fn bounding_circle(v: &[P2]) -> (P2, f64) {
    let c = corner_mean(v);
    let rho2 = v
        .iter()
        .map(|x| dot(sub(*x, c), sub(*x, c)))
        .fold(0.0, f64::max);
    (c, rho2)
}

/// Where the circle of radius r about the origin lies with respect to the line
/// {x : (x − a)·m = 0}, given `centre` = −a·m (the origin's side, times |m|).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Side {
    Inside,
    Outside,
    Across,
}

/// The test is centre ≥ r|m| (inside), centre ≤ −r|m| (outside). Its square root is
/// taken only where squares cannot tell: far from the boundary the squares decide with
/// room for their rounding (1e-9), and near it the same rounded r|m| as always decides,
/// so the decision never changes with the shortcut.
#[inline]
fn circle_side(centre: f64, r: f64, m: P2) -> Side {
    let (c2, r2) = (centre * centre, r * r * dot(m, m));
    // (Squares of lengths below 1e-140 lose bits to underflow: no shortcut there.)
    if r2.is_nan() || r2 <= 1e-280 {
        return circle_side_exact(centre, r, m);
    }
    if c2 < r2 * (1.0 - 1e-9) {
        return Side::Across;
    }
    if c2 > r2 * (1.0 + 1e-9) {
        return if centre > 0.0 {
            Side::Inside
        } else {
            Side::Outside
        };
    }
    circle_side_exact(centre, r, m)
}

fn circle_side_exact(centre: f64, r: f64, m: P2) -> Side {
    let reach = r * norm(m);
    if centre >= reach {
        Side::Inside
    } else if centre <= -reach {
        Side::Outside
    } else {
        Side::Across
    }
}

/// The overlap area of polygons p (corners relative to r_i) and q (relative to r_j),
/// d = r_i − r_j: the contact test of the broad phase's survivors, by the same clipping
/// as [`polygon_polygon`].
pub fn overlap_area(p: &[P2], q: &[P2], d: P2) -> f64 {
    with_scratch(|buf| {
        let [x, y, qi] = buf;
        in_frame_of_i(q, d, qi);
        let o = if clip_by(p, qi.corners(), d, [&mut *x, &mut *y]) == 0 {
            x
        } else {
            y
        };
        if o.n < 3 {
            return 0.0;
        }
        crate::shape::area(o.corners())
    })
}

/// Mean of the corners: the fallback force point. Unlike the area centroid it needs no
/// division by a vanishing area, so a degenerate overlap keeps S inside it.
fn corner_mean(v: &[P2]) -> P2 {
    let n = v.len() as f64;
    let s = v.iter().fold([0.0, 0.0], |a, x| [a[0] + x[0], a[1] + x[1]]);
    [s[0] / n, s[1] / n]
}

/// The two points farthest apart.
fn farthest_pair(points: &[P2]) -> (P2, P2) {
    let mut best = (points[0], points[1], -1.0);
    for a in 0..points.len() {
        for b in a + 1..points.len() {
            let d = norm(sub(points[a], points[b]));
            if d > best.2 {
                best = (points[a], points[b], d);
            }
        }
    }
    (best.0, best.1)
}

/// l = 1/(1/l_i + 1/l_j), with a floor so that a force point on a centre (a diverging
/// overlap) gives a large but finite force.
fn reduced_arm(li: f64, lj: f64, scale: f64) -> f64 {
    let floor = 1e-9 * scale;
    let (li, lj) = (li.max(floor), lj.max(floor));
    li * lj / (li + lj)
}

/// The unit vector along d, or +z for d = 0.
fn unit_or_up(d: P2) -> P2 {
    let l = norm(d);
    if l > 0.0 {
        [d[0] / l, d[1] / l]
    } else {
        [0.0, 1.0]
    }
}

/// Area contact of polygon p (particle i) with polygon q (particle j): corners relative
/// to their own centres, both convex and counter-clockwise, d = r_i − r_j. None when
/// the outlines do not overlap.
pub fn polygon_polygon(p: &[P2], q: &[P2], d: P2) -> Option<AreaContact> {
    with_scratch(|buf| {
        // The third scratch polygon holds q in i's frame for the clipping, then the
        // crossings.
        let [x, y, qi] = buf;
        in_frame_of_i(q, d, qi);
        let k = clip_by(p, qi.corners(), d, [&mut *x, &mut *y]);
        overlap_contact(if k == 0 { x } else { y }, qi, p, q, d)
    })
}

/// The contact of the overlap polygon `clip` of p and q (d = r_i − r_j); `crossed` is
/// scratch space.
fn overlap_contact(
    clip: &Clip,
    crossed: &mut Clip,
    p: &[P2],
    q: &[P2],
    d: P2,
) -> Option<AreaContact> {
    if clip.n < 3 {
        return None;
    }
    let overlap = clip.corners();
    let area = crate::shape::area(overlap);
    if area <= 0.0 {
        return None;
    }
    let origin = |k: usize| {
        let (lin, lout) = clip.lines_at(k);
        origin_of(lin, lout)
    };
    crossed.n = 0;
    for (k, x) in overlap.iter().enumerate() {
        if origin(k) == Origin::Crossing {
            crossed.push(*x, 0);
        }
    }
    let xs = crossed.corners();
    let scale = norm(d) + norm(p[0]) + norm(q[0]);
    let along_centres = unit_or_up(d);
    let (n, point, chord) = if xs.len() >= 2 {
        let (a, b) = farthest_pair(xs);
        let chord = norm(sub(b, a));
        if chord > 1e-12 * scale {
            let t = [(b[0] - a[0]) / chord, (b[1] - a[1]) / chord];
            let mut n = [-t[1], t[0]];
            let s = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            // Corners of i inside j lie on j's side of the line, corners of j inside i
            // on i's side; n points from j to i.
            let side: f64 = overlap
                .iter()
                .enumerate()
                .map(|(k, x)| match origin(k) {
                    Origin::P => dot(n, sub(*x, s)),
                    Origin::Q => -dot(n, sub(*x, s)),
                    Origin::Crossing => 0.0,
                })
                .sum();
            if side > 0.0 || (side == 0.0 && dot(n, d) < 0.0) {
                n = [-n[0], -n[1]];
            }
            (n, s, chord)
        } else {
            (along_centres, corner_mean(overlap), 0.0)
        }
    } else {
        (along_centres, corner_mean(overlap), 0.0)
    };
    // S − r_j = S + d.
    let l = reduced_arm(norm(point), norm([point[0] + d[0], point[1] + d[1]]), scale);
    Some(AreaContact {
        area,
        n,
        arm: point,
        chord,
        l,
    })
}

/// Area contact of polygon p (corners relative to its centre) with a wall segment given
/// relative to the same centre (`geometry::wall_from`): the part of p beyond the wall's
/// line (seen from the centre) and between its end points. The intersection line is
/// the stretch of the wall's line inside p: the overlap corners on the wall's line, known
/// from the clipping (not by a tolerance). n is the wall's normal towards the centre;
/// l = l_i (a wall is infinitely large).
pub fn polygon_wall(p: &[P2], w: &WallSegment) -> Option<AreaContact> {
    let ab = sub(w.b, w.a);
    let len = norm(ab);
    if len == 0.0 {
        return None;
    }
    let mut m = [-ab[1] / len, ab[0] / len];
    if dot(m, w.a) > 0.0 {
        m = [-m[0], -m[1]];
    }
    with_scratch(|buf| {
        let [cur, next, _] = buf;
        cur.set_outline(p, 0);
        clip_lines(cur, w.a, [-m[0], -m[1]], WALL_LINE, next);
        clip_lines(next, w.a, ab, END_A_LINE, cur);
        clip_lines(cur, w.b, [-ab[0], -ab[1]], END_B_LINE, next);
        wall_contact(next, p, w, m)
    })
}

/// The contact of the part `clip` of p beyond the wall w (m: its normal towards the
/// centre).
fn wall_contact(clip: &Clip, p: &[P2], w: &WallSegment, m: P2) -> Option<AreaContact> {
    if clip.n < 3 {
        return None;
    }
    let (ab, len) = (sub(w.b, w.a), norm(sub(w.b, w.a)));
    let area = crate::shape::area(clip.corners());
    if area <= 0.0 {
        return None;
    }
    // Overlap corners on the wall's line (the crossings, or a wall end inside p), along
    // the wall from the foot of the centre, not from an end point that may be far.
    let t = [ab[0] / len, ab[1] / len];
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for k in 0..clip.n {
        let (lin, lout) = clip.lines_at(k);
        if lin == WALL_LINE || lout == WALL_LINE {
            let s = dot(clip.v[k], t);
            lo = lo.min(s);
            hi = hi.max(s);
        }
    }
    let (point, chord) = if hi > lo {
        let (dist, mid) = (-dot(m, w.a), 0.5 * (lo + hi));
        (
            [-dist * m[0] + mid * t[0], -dist * m[1] + mid * t[1]],
            hi - lo,
        )
    } else {
        (corner_mean(clip.corners()), 0.0)
    };
    let scale = len + norm(p[0]);
    let l = norm(point).max(1e-9 * scale);
    Some(AreaContact {
        area,
        n: m,
        arm: point,
        chord,
        l,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn relative(v: &[P2], c: P2) -> Vec<P2> {
        v.iter().map(|x| sub(*x, c)).collect()
    }

    /// The contact of two polygons given in world coordinates, and its force point there.
    fn world_pp(p: &[P2], ci: P2, q: &[P2], cj: P2) -> Option<(AreaContact, P2)> {
        polygon_polygon(&relative(p, ci), &relative(q, cj), sub(ci, cj))
            .map(|g| (g, [ci[0] + g.arm[0], ci[1] + g.arm[1]]))
    }

    fn world_pw(p: &[P2], ci: P2, w: &WallSegment) -> Option<(AreaContact, P2)> {
        polygon_wall(&relative(p, ci), &crate::geometry::wall_from(w, ci))
            .map(|g| (g, [ci[0] + g.arm[0], ci[1] + g.arm[1]]))
    }

    fn square(c: P2, half: f64) -> Vec<P2> {
        vec![
            [c[0] - half, c[1] - half],
            [c[0] + half, c[1] - half],
            [c[0] + half, c[1] + half],
            [c[0] - half, c[1] + half],
        ]
    }

    #[test]
    fn two_unit_squares_offset() {
        // Unit squares, j at the origin, i shifted by (0.9, 0.3): overlap 0.1 × 0.7.
        let (ci, cj) = ([0.9, 0.3], [0.0, 0.0]);
        let (g, point) = world_pp(&square(ci, 0.5), ci, &square(cj, 0.5), cj).unwrap();
        assert!((g.area - 0.07).abs() < 1e-14);
        // Crossings at (0.4, 0.5) (i's left edge, j's top) and (0.5, -0.2) (j's right
        // edge, i's bottom): the line joins them.
        let t = [0.1, -0.7];
        let tn = norm(t);
        assert!((dot(g.n, [t[0] / tn, t[1] / tn])).abs() < 1e-14, "n ⊥ line");
        assert!(g.n[0] > 0.0, "n points from j to i");
        assert!((point[0] - 0.45).abs() < 1e-14 && (point[1] - 0.15).abs() < 1e-14);
        assert!((g.chord - tn).abs() < 1e-14);
        let (li, lj) = (norm(sub(point, ci)), norm(sub(point, cj)));
        assert!((g.l - li * lj / (li + lj)).abs() < 1e-15);
    }

    #[test]
    fn a_triangle_corner_in_a_square() {
        // Triangle with its apex (0, -0.1) pushed 0.1 into the top of a unit square whose
        // top edge is z = 0: overlap is the triangle below z = 0.
        let tri = vec![[0.0, -0.1], [1.0, 1.0], [-1.0, 1.0]];
        let ci = [0.0, 0.6333333333333333];
        let sq = vec![[-2.0, -1.0], [2.0, -1.0], [2.0, 0.0], [-2.0, 0.0]];
        let cj = [0.0, -0.5];
        let (g, point) = world_pp(&tri, ci, &sq, cj).unwrap();
        // Sides through the apex have slope 1.1: the crossings are at x = ±0.1/1.1.
        let half = 0.1 / 1.1;
        assert!((g.area - half * 0.1).abs() < 1e-15);
        assert!((g.n[0]).abs() < 1e-15 && (g.n[1] - 1.0).abs() < 1e-15);
        assert!(point[0].abs() < 1e-15 && point[1].abs() < 1e-15);
        assert!((g.chord - 2.0 * half).abs() < 1e-15);
    }

    #[test]
    fn rotated_square_on_a_square() {
        // A unit square turned by 45° standing on its corner 0.1 deep in the top face.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let ci = [0.0, h - 0.1];
        let diamond = vec![[0.0, -0.1], [h, ci[1]], [0.0, ci[1] + h], [-h, ci[1]]];
        let cj = [0.0, -0.5];
        let (g, _) = world_pp(&diamond, ci, &square(cj, 0.5), cj).unwrap();
        assert!(
            (g.area - 0.01).abs() < 1e-15,
            "a right triangle of legs 0.1√2"
        );
        assert!((g.n[1] - 1.0).abs() < 1e-15);
        assert!((g.chord - 0.2).abs() < 1e-15);
    }

    #[test]
    fn separated_and_touching_polygons_have_no_contact() {
        let (ci, cj) = ([1.5, 0.0], [0.0, 0.0]);
        assert!(world_pp(&square(ci, 0.5), ci, &square(cj, 0.5), cj).is_none());
        let ci = [1.0, 0.0];
        assert!(world_pp(&square(ci, 0.5), ci, &square(cj, 0.5), cj).is_none());
    }

    #[test]
    fn square_on_a_floor() {
        let w = WallSegment {
            a: [-5.0, 0.0],
            b: [5.0, 0.0],
        };
        let ci = [0.3, 0.45];
        let (g, point) = world_pw(&square(ci, 0.5), ci, &w).unwrap();
        assert!((g.area - 0.05).abs() < 1e-15);
        assert_eq!(g.n, [0.0, 1.0]);
        assert!((point[0] - 0.3).abs() < 1e-15 && point[1] == 0.0);
        assert!((g.chord - 1.0).abs() < 1e-15 && (g.l - 0.45).abs() < 1e-15);
        // Beyond the wall's end only the part above the segment counts.
        let ci = [5.3, 0.45];
        let (g, point) = world_pw(&square(ci, 0.5), ci, &w).unwrap();
        assert!((g.area - 0.01).abs() < 1e-15);
        assert!((g.chord - 0.2).abs() < 1e-15 && (point[0] - 4.9).abs() < 1e-15);
    }
}

// ---- Disks under the overlap-area law (SPEC 2.3 for mixed scenes) ----
//
// The twins of polygon.wgsl's forms, step for step. A small overlap is built from an
// overlap depth that does not cancel: a circular segment of known sagitta, a lens of
// two segments, the triangle a corner cuts off plus a segment. General formulas (a
// sum of signed triangles and sectors about the disk's centre, each of size r²) would
// lose r² ε of area, 1e-4 of a corner 1e-6 d deep. Only a polygon–disk overlap that is
// none of these (a deep one) takes the general formula.

/// x − sin x, by its series where it cancels (relative error ~1e-16).
pub fn x_minus_sin(x: f64) -> f64 {
    if x > 1.0 {
        return x - x.sin();
    }
    // x³/3! − x⁵/5! + …: the terms up to x¹⁹/19! reach f64's precision at x = 1.
    let x2 = x * x;
    let mut term = x * x2 / 6.0;
    let mut sum = term;
    for k in 2..=9 {
        term *= -x2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        sum += term;
    }
    sum
}

/// Area of the circular segment of radius r beyond a chord at depth e (the sagitta):
/// r²/2 (x − sin x) with x = 4 asin(sqrt(e / 2r)) the central angle.
pub fn segment_area(r: f64, e: f64) -> f64 {
    let y = (e / (2.0 * r)).clamp(0.0, 1.0).sqrt();
    0.5 * r * r * x_minus_sin(4.0 * y.asin())
}

/// Signed area of the triangle (0, a, b) inside the circle of radius r about the origin:
/// the segment ab is split where it crosses the circle; pieces inside add their triangle,
/// pieces outside the circular sector they subtend.
fn triangle_in_circle(a: P2, b: P2, r: f64) -> f64 {
    let d = sub(b, a);
    let (qa, qb, qc) = (dot(d, d), 2.0 * dot(a, d), dot(a, a) - r * r);
    let mut ts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa > 0.0 && disc > 0.0 {
        let s = disc.sqrt();
        for t in [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)] {
            if t > 0.0 && t < 1.0 {
                ts[n] = t;
                n += 1;
            }
        }
    }
    ts[n] = 1.0;
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    ts[..=n]
        .windows(2)
        .map(|w| {
            let (p, q) = (at(w[0]), at(w[1]));
            let m = at(0.5 * (w[0] + w[1]));
            let c = p[0] * q[1] - p[1] * q[0];
            if dot(m, m) <= r * r {
                0.5 * c
            } else {
                0.5 * r * r * c.atan2(dot(p, q))
            }
        })
        .sum()
}

/// Points where the circle of radius r about the origin crosses the outline of
/// polygon p (half-open edges).
fn circle_crossings(p: &[P2], r: f64, out: &mut Clip) {
    out.n = 0;
    let n = p.len();
    for k in 0..n {
        let (a, b) = (p[k], p[(k + 1) % n]);
        let d = sub(b, a);
        let (qa, qb, qc) = (dot(d, d), 2.0 * dot(a, d), dot(a, a) - r * r);
        let disc = qb * qb - 4.0 * qa * qc;
        if qa == 0.0 || disc < 0.0 {
            continue;
        }
        let s = disc.sqrt();
        for t in [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)] {
            if (0.0..1.0).contains(&t) && out.n < MAX_CLIP {
                out.push([a[0] + t * d[0], a[1] + t * d[1]], k as u32);
            }
        }
    }
}

/// An overlap's area, chord, force point and the unit vector from the polygon's side
/// to the disk's, in the disk's frame.
type DiskOverlap = (f64, f64, P2, P2);

/// A sliver under one face a–b (corners relative to the polygon's centre c; nothing
/// else of the polygon in the circle): the segment beyond the face's line, whose depth
/// is the radius less the centre's distance from the line. None: no overlap.
fn face_segment(a: &P2, b: &P2, c: P2, r: f64) -> Option<DiskOverlap> {
    let t = unit_or_up(sub(*b, *a));
    let nout = [t[1], -t[0]]; // out of the polygon, towards the disk
    // The face's distance from the disk's centre, from the polygon's own corner (not
    // from c + a, which would round at the size of c).
    let delta = r + dot(c, nout) + dot(*a, nout);
    if delta <= 0.0 {
        return None;
    }
    let chord = 2.0 * (delta * (2.0 * r - delta)).max(0.0).sqrt();
    let point = [-(r - delta) * nout[0], -(r - delta) * nout[1]];
    Some((segment_area(r, delta), chord, point, nout))
}

/// A run of corners inside the circle (one or more in a row, `mask`) and no other edge
/// cut: the polygon from the crossing on the edge into the run, along the run, to the
/// crossing on the edge out of it, plus the minor segment beyond the chord between the
/// two crossings. Everything from the run's own corners (the crossings from the end
/// corners' depths, the polygon's area about its first crossing), so a small overlap
/// keeps its relative precision (the general formula loses r² ε). None when the run is
/// not one (the corners inside are not in a row) or the disk's centre lies beyond the
/// chord (the rest of the disk is then a major segment): the general formula.
fn corner_cap(v: &[P2], p: &[P2], mask: u32, r: f64) -> Option<DiskOverlap> {
    let np = p.len();
    let inside = |m: usize| mask & (1 << (m % np)) != 0;
    // The run starts at `first` (inside, its predecessor outside) and ends at `last`.
    let first = (0..np).find(|&m| inside(m) && !inside(m + np - 1))?;
    let count = (0..np).take_while(|&k| inside(first + k)).count();
    if count != mask.count_ones() as usize {
        return None;
    }
    let last = (first + count - 1) % np;
    // How far along u from corner x the edge leaves the circle: s² + 2 b s − k = 0 with
    // k = r² − |x|² from the corner's depth, without cancelling.
    let reach = |x: P2, u: P2| {
        let depth = r - norm(x);
        let (k, b) = (depth * (2.0 * r - depth), dot(x, u));
        let root = (b * b + k).sqrt();
        if b > 0.0 { k / (b + root) } else { root - b }
    };
    let u1 = unit_or_up(sub(p[(first + np - 1) % np], p[first]));
    let u2 = unit_or_up(sub(p[(last + 1) % np], p[last]));
    let (s1, s2) = (reach(v[first], u1), reach(v[last], u2));
    // Relative to the first crossing x1 = v_first + s1 u1: corner m at p_m − p_first − s1 u1.
    let from_x1 = |m: usize| sub(sub(p[m], p[first]), [s1 * u1[0], s1 * u1[1]]);
    let x21 = {
        let e = from_x1(last);
        [e[0] + s2 * u2[0], e[1] + s2 * u2[1]]
    };
    let mut twice_area = 0.0;
    let mut prev = from_x1(first);
    for k in 1..count {
        let next = from_x1((first + k) % np);
        twice_area += cross(prev, next);
        prev = next;
    }
    twice_area += cross(prev, x21);
    let chord = norm(x21);
    let x1 = [v[first][0] + s1 * u1[0], v[first][1] + s1 * u1[1]];
    let point = [x1[0] + 0.5 * x21[0], x1[1] + 0.5 * x21[1]];
    let t = [x21[0] / chord.max(1e-300), x21[1] / chord.max(1e-300)];
    let nn = [-t[1], t[0]];
    let (centre_side, corner_side) = (-dot(nn, point), dot(nn, sub(v[first], point)));
    if centre_side * corner_side < 0.0 {
        return None;
    }
    let half = 0.5 * chord;
    let sagitta = half * half / (r + (r * r - half * half).max(0.0).sqrt());
    let area = 0.5 * twice_area.abs() + segment_area(r, sagitta);
    let towards = if centre_side + corner_side > 0.0 {
        nn
    } else {
        [-nn[0], -nn[1]]
    };
    Some((area, chord, point, towards))
}

/// Deep or unusual overlaps: the general formula (triangles and sectors about the
/// disk's centre), the force point between the two crossings of the outlines farthest
/// apart. `mask`: the corners inside the circle. None: no overlap.
fn deep_overlap(v: &[P2], c: P2, r: f64, mask: u32) -> Option<DiskOverlap> {
    let np = v.len();
    let area: f64 = (0..np)
        .map(|k| triangle_in_circle(v[k], v[(k + 1) % np], r))
        .sum();
    if area <= 0.0 {
        return None;
    }
    let mut crossed = Clip::default();
    circle_crossings(v, r, &mut crossed);
    let xs = crossed.corners();
    let (mut towards, mut point, mut chord) = (unit_or_up([-c[0], -c[1]]), [0.0, 0.0], 0.0);
    if xs.len() >= 2 {
        let (a, b) = farthest_pair(xs);
        let d = norm(sub(b, a));
        if d > 1e-12 * r {
            let t = [(b[0] - a[0]) / d, (b[1] - a[1]) / d];
            point = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            chord = d;
            towards = [-t[1], t[0]];
            // The disk's side: its centre and the polygon's corners inside it.
            let side = dot(towards, [-point[0], -point[1]])
                + (0..np)
                    .filter(|m| mask & (1 << m) != 0)
                    .map(|m| dot(towards, sub(v[m], point)))
                    .sum::<f64>();
            if side < 0.0 {
                towards = [-towards[0], -towards[1]];
            }
        }
    }
    Some((area, chord, point, towards))
}

/// Area contact of polygon p and a disk of radius r, in a frame at the disk's centre:
/// `c` is the polygon's centre relative to the disk's (so p's corners in this frame are
/// c + p). `polygon_is_i` says which of the two is particle i (n points from j to i);
/// the result is in the frame of i's centre, as everywhere. The kernel twin is
/// `polygon_disk_ij` in polygon.wgsl, with the same three cases.
pub fn polygon_disk(p: &[P2], c: P2, r: f64, polygon_is_i: bool) -> Option<AreaContact> {
    let np = p.len();
    let mut v = [[0.0; 2]; MAX_CORNERS as usize];
    for (x, y) in v.iter_mut().zip(p) {
        *x = [c[0] + y[0], c[1] + y[1]];
    }
    let v = &v[..np];
    // Corners inside the circle, by their depth r − |v|.
    let (mut inside, mut mask) = (0, 0u32);
    for (m, x) in v.iter().enumerate() {
        if r - norm(*x) > 0.0 {
            inside += 1;
            mask |= 1 << m;
        }
    }
    // Edges with both ends outside that the circle cuts (`cut` of them with the disk's
    // centre on their outer side), and whether the centre is inside the polygon. With
    // no corner inside, no edge cut and the centre outside there is no overlap.
    let (mut cut, mut cut_any, mut edge, mut centre_inside) = (0, 0, 0, true);
    for m in 0..np {
        let m2 = (m + 1) % np;
        let (a, ab) = (v[m], sub(v[m2], v[m]));
        let outside = cross(ab, [-a[0], -a[1]]) < 0.0;
        if outside {
            centre_inside = false;
        }
        let t = -dot(a, ab) / dot(ab, ab);
        let f = [a[0] + t * ab[0], a[1] + t * ab[1]];
        let ends_out = mask & ((1 << m) | (1 << m2)) == 0;
        if ends_out && t > 0.0 && t < 1.0 && dot(f, f) < r * r {
            cut_any += 1;
            if outside {
                cut += 1;
                edge = m;
            }
        }
    }
    if inside == 0 && cut == 0 && !centre_inside {
        return None;
    }
    let (area, chord, point, towards_disk) = if inside == 0 && cut == 1 && cut_any == 1 {
        face_segment(&p[edge], &p[(edge + 1) % np], c, r)?
    } else if let Some(cap) = (inside > 0 && cut_any == 0)
        .then(|| corner_cap(v, p, mask, r))
        .flatten()
    {
        cap
    } else {
        deep_overlap(v, c, r, mask)?
    };
    if area <= 0.0 {
        return None;
    }
    let n = if polygon_is_i {
        [-towards_disk[0], -towards_disk[1]]
    } else {
        towards_disk
    };
    let scale = norm(c) + 2.0 * r;
    let l = reduced_arm(norm(sub(point, c)), norm(point), scale);
    // From the disk's frame to i's.
    let arm = if polygon_is_i { sub(point, c) } else { point };
    Some(AreaContact {
        area,
        n,
        arm,
        chord,
        l,
    })
}

/// Area contact of two disks whose centres are d = r_i − r_j apart: the lens between
/// them, of two segments whose sagittas come from the overlap δ = r_i + r_j − |d|; the
/// chord through the circles' crossings, n along the line of centres.
pub fn disk_disk_area(d: P2, ri: f64, rj: f64) -> Option<AreaContact> {
    let dist = norm(d);
    if dist >= ri + rj {
        return None;
    }
    let n = unit_or_up(d);
    if dist <= (ri - rj).abs() {
        // One inside the other: the smaller disk's area, at its centre.
        let area = std::f64::consts::PI * ri.min(rj).powi(2);
        let arm = if ri < rj { [0.0, 0.0] } else { [-d[0], -d[1]] };
        let l = reduced_arm(norm(arm), norm([arm[0] + d[0], arm[1] + d[1]]), ri + rj);
        return Some(AreaContact {
            area,
            n,
            arm,
            chord: 0.0,
            l,
        });
    }
    // The chord lies a_i = r_i − e_i from i's centre and a_j = r_j − e_j from j's.
    let delta = ri + rj - dist;
    let ei = delta * (rj + dist - ri) / (2.0 * dist);
    let ej = delta * (ri + dist - rj) / (2.0 * dist);
    let area = segment_area(ri, ei) + segment_area(rj, ej);
    let chord = 2.0 * (ej * (2.0 * rj - ej)).max(0.0).sqrt();
    let arm = [-n[0] * (ri - ei), -n[1] * (ri - ei)];
    let l = reduced_arm(ri - ei, rj - ej, ri + rj);
    Some(AreaContact {
        area,
        n,
        arm,
        chord,
        l,
    })
}

/// Area contact of a disk of radius r and a wall segment given relative to the disk's
/// centre (`geometry::wall_from`): the circular segment beyond the wall's line; where
/// the chord reaches past an end of the wall only the part over the wall counts (its
/// area scaled by that fraction of the chord, an approximation at the ends).
pub fn disk_wall_area(r: f64, w: &WallSegment) -> Option<AreaContact> {
    let ab = sub(w.b, w.a);
    let len = norm(ab);
    if len == 0.0 {
        return None;
    }
    let t = [ab[0] / len, ab[1] / len];
    let mut m = [-t[1], t[0]];
    // The centre's distance from the wall's line, on its side.
    let mut dist = -dot(m, w.a);
    if dist < 0.0 {
        m = [-m[0], -m[1]];
        dist = -dist;
    }
    let delta = r - dist;
    if delta <= 0.0 {
        return None;
    }
    let h = (delta * (2.0 * r - delta)).sqrt();
    // The chord's ends relative to the foot of the centre, cut at the wall's ends (not
    // s ± h, which far along a long wall would round at the size of s).
    let s = -dot(w.a, t);
    let (lo, hi) = ((-h).max(-s), h.min(len - s));
    if hi <= lo {
        return None;
    }
    let area = segment_area(r, delta) * (hi - lo) / (2.0 * h);
    let mid = 0.5 * (lo + hi);
    let arm = [-dist * m[0] + mid * t[0], -dist * m[1] + mid * t[1]];
    let l = norm(arm).max(1e-9 * r);
    Some(AreaContact {
        area,
        n: m,
        arm,
        chord: hi - lo,
        l,
    })
}

#[cfg(test)]
mod disk_tests {
    use super::*;

    #[test]
    fn skipping_the_edges_that_cannot_cut_changes_no_bit() {
        // `clip_by` skips the edges whose half-plane holds the few corners left after
        // its first two clips; clipping by them anyway must give the same polygon, bit
        // for bit: random pairs of irregular polygons (3–12 corners), from overlaps of
        // 1e-9 of the size to deep ones, anywhere around each other.
        let mut rng = crate::rng::Rng::new(7);
        let (mut compared, mut skipped_some) = (0, false);
        for _ in 0..20_000 {
            let shape = |rng: &mut crate::rng::Rng| {
                let corners = 3 + (rng.uniform() * 10.0) as u32;
                let (a, b) = (rng.range(0.5, 1.5), rng.range(0.5, 1.5));
                let body = crate::shape::ellipse_polygon(corners, a, b, rng.range(0.0, 1.0));
                let mut v = Vec::new();
                crate::shape::rotate(&body, rng.range(0.0, 6.3), &mut v);
                v
            };
            let (p, q) = (shape(&mut rng), shape(&mut rng));
            let rp = p.iter().map(|v| norm(*v)).fold(0.0, f64::max);
            let rq = q.iter().map(|v| norm(*v)).fold(0.0, f64::max);
            let angle = rng.range(0.0, 6.3);
            let dir = [angle.cos(), angle.sin()];
            let at = |dist: f64| -> (P2, Vec<P2>) {
                let d = [dist * dir[0], dist * dir[1]];
                (d, q.iter().map(|v| sub(*v, d)).collect())
            };
            let overlaps = |dist: f64| {
                let (d, qi) = at(dist);
                let (mut a, mut b) = (Clip::default(), Clip::default());
                let k = clip_in_order::<false>(&p, &qi, d, [&mut a, &mut b]);
                [&a, &b][k].n >= 3
            };
            // The distance at which they touch along this direction, by bisection; then
            // an overlap from 1e-9 of it to deep.
            let (mut lo, mut hi) = (0.0, rp + rq);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if overlaps(mid) { lo = mid } else { hi = mid }
            }
            let (d, qi) = at(lo * (1.0 - 10f64.powf(rng.range(-9.0, -0.3))));
            let (mut a, mut b) = (Clip::default(), Clip::default());
            let (mut c, mut e) = (Clip::default(), Clip::default());
            let k = clip_in_order::<true>(&p, &qi, d, [&mut a, &mut b]);
            let m = clip_in_order::<false>(&p, &qi, d, [&mut c, &mut e]);
            let (x, y) = ([&a, &b][k], [&c, &e][m]);
            assert_eq!(x.n, y.n, "corner count");
            for j in 0..x.n {
                assert_eq!(x.line[j], y.line[j], "line of corner {j}");
                assert_eq!(x.v[j][0].to_bits(), y.v[j][0].to_bits(), "corner {j}");
                assert_eq!(x.v[j][1].to_bits(), y.v[j][1].to_bits(), "corner {j}");
            }
            compared += (x.n >= 3) as usize;
            skipped_some |= k != m;
        }
        assert!(compared > 5_000, "only {compared} overlaps");
        assert!(skipped_some, "some clips were skipped");
    }

    #[test]
    fn x_minus_sin_and_segments_match_their_closed_forms() {
        // Small x against the series' leading terms (the next is below 1e-17 relative),
        // larger x against the direct difference.
        for x in [1e-6f64, 1e-3, 0.01] {
            let series = x * x * x / 6.0 * (1.0 - x * x / 20.0 + x.powi(4) / 840.0);
            assert!((x_minus_sin(x) / series - 1.0).abs() < 1e-14, "{x}");
        }
        for x in [0.05, 0.1, 0.5, 0.999, 1.0, 1.5, 3.0] {
            assert!((x_minus_sin(x) / (x - x.sin()) - 1.0).abs() < 1e-11, "{x}");
        }
        // A half disk: the chord through the centre.
        let r = 0.7;
        assert!((segment_area(r, r) - 0.5 * std::f64::consts::PI * r * r).abs() < 1e-15);
        // A shallow segment: 4/3 sqrt(2r) e^{3/2} (1 − 3e/(20 r) + O(e²)).
        let e = 1e-8f64;
        let approx = 4.0 / 3.0 * (2.0 * r).sqrt() * e.powf(1.5) * (1.0 - 3.0 * e / (20.0 * r));
        assert!((segment_area(r, e) / approx - 1.0).abs() < 1e-12);
    }
}
