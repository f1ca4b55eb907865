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

use crate::geometry::{WallSegment, cross};
use crate::shape::{MAX_CORNERS, P2};

/// Most corners an overlap polygon can have: each clipping half-plane adds at most one.
pub const MAX_CLIP: usize = 2 * MAX_CORNERS as usize + 4;

/// A convex polygon of at most [`MAX_CLIP`] corners, held on the stack (the overlap is
/// computed for every contact every step; no allocation).
#[derive(Clone, Copy, Debug)]
pub struct Poly {
    pub n: usize,
    pub v: [P2; MAX_CLIP],
}

impl Default for Poly {
    fn default() -> Self {
        Self {
            n: 0,
            v: [[0.0; 2]; MAX_CLIP],
        }
    }
}

impl Poly {
    pub fn from_slice(p: &[P2]) -> Self {
        let mut out = Self::default();
        out.v[..p.len()].copy_from_slice(p);
        out.n = p.len();
        out
    }

    pub fn corners(&self) -> &[P2] {
        &self.v[..self.n]
    }

    fn push(&mut self, x: P2) {
        self.v[self.n] = x;
        self.n += 1;
    }
}

/// The geometry of one area contact, seen from particle i.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AreaContact {
    /// Overlap area A.
    pub area: f64,
    /// Unit normal from j to i, perpendicular to the intersection line.
    pub n: P2,
    /// Force point S: the midpoint of the intersection line.
    pub point: P2,
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

/// One Sutherland–Hodgman step: the part of the convex polygon `poly` in the half-plane
/// {x : (x − a)·m ≥ 0}.
pub fn clip_half_plane(poly: &[P2], a: P2, m: P2, out: &mut Poly) {
    out.n = 0;
    let n = poly.len();
    for k in 0..n {
        let (p, q) = (poly[k], poly[(k + 1) % n]);
        let (dp, dq) = (dot(sub(p, a), m), dot(sub(q, a), m));
        if dp >= 0.0 {
            out.push(p);
        }
        if (dp >= 0.0) != (dq >= 0.0) {
            let t = dp / (dp - dq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
}

/// The overlap polygon of two convex, counter-clockwise polygons: p clipped by every
/// edge of q (p's centre ci speeds it up; see `tagged_intersection`).
pub fn intersection(p: &[P2], ci: P2, q: &[P2]) -> Poly {
    tagged_intersection(p, ci, q).poly
}

/// Whether two convex polygons overlap with positive area (the contact test of the
/// broad phase's survivors; the same clipping as [`polygon_polygon`]).
pub fn overlap_area(p: &[P2], ci: P2, q: &[P2]) -> f64 {
    let o = intersection(p, ci, q);
    if o.n < 3 {
        return 0.0;
    }
    crate::shape::area(o.corners())
}

/// Where a corner of the overlap polygon comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Origin {
    /// A corner of p inside q.
    P,
    /// A corner of q inside p (two of q's edge lines meet).
    Q,
    /// An edge of p crosses an edge of q: a crossing point of the outlines.
    Crossing,
}

/// The overlap polygon with the origin of each corner: p clipped by every edge of q,
/// remembering for each edge of the clipped polygon whether it lies on p's outline. A
/// new corner on such an edge is a crossing of the outlines; one on an edge of q's
/// lines is a corner of q. The crossings come out of the clipping, with no extra search.
struct Tagged {
    poly: Poly,
    origin: [Origin; MAX_CLIP],
    on_p: [bool; MAX_CLIP],
}

impl Tagged {
    fn push(&mut self, x: P2, origin: Origin, on_p: bool) {
        let n = self.poly.n;
        self.poly.v[n] = x;
        self.origin[n] = origin;
        self.on_p[n] = on_p;
        self.poly.n += 1;
    }
}

fn tagged_intersection(p: &[P2], ci: P2, q: &[P2]) -> Tagged {
    let empty = || Tagged {
        poly: Poly::default(),
        origin: [Origin::P; MAX_CLIP],
        on_p: [true; MAX_CLIP],
    };
    let mut buf = [empty(), empty()];
    buf[0].poly = Poly::from_slice(p);
    let mut cur = 0;
    // p lies in the circle of radius r about ci: an edge line of q that keeps the whole
    // circle inside clips nothing, one that keeps it all outside leaves no overlap. Only
    // the few edges near the contact are clipped.
    let r = p
        .iter()
        .map(|v| dot(sub(*v, ci), sub(*v, ci)))
        .fold(0.0, f64::max)
        .sqrt();
    let nq = q.len();
    for k in 0..nq {
        let (a, b) = (q[k], q[(k + 1) % nq]);
        let m = [-(b[1] - a[1]), b[0] - a[0]];
        let reach = r * norm(m);
        let centre = dot(sub(ci, a), m);
        if centre >= reach {
            continue;
        }
        if centre <= -reach {
            buf[cur].poly.n = 0;
            break;
        }
        let (src, dst) = if cur == 0 {
            let (x, y) = buf.split_at_mut(1);
            (&x[0], &mut y[0])
        } else {
            let (x, y) = buf.split_at_mut(1);
            (&y[0], &mut x[0])
        };
        dst.poly.n = 0;
        let n = src.poly.n;
        for e in 0..n {
            let (x, y) = (src.poly.v[e], src.poly.v[(e + 1) % n]);
            let (dx, dy) = (dot(sub(x, a), m), dot(sub(y, a), m));
            let on_p = src.on_p[e];
            if dx >= 0.0 {
                dst.push(x, src.origin[e], on_p);
            }
            if (dx >= 0.0) != (dy >= 0.0) {
                let t = dx / (dx - dy);
                let at = [x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])];
                let origin = if on_p { Origin::Crossing } else { Origin::Q };
                // Leaving the half-plane the polygon follows q's line; entering it, the
                // edge it was on.
                dst.push(at, origin, if dx >= 0.0 { false } else { on_p });
            }
        }
        cur = 1 - cur;
        if buf[cur].poly.n == 0 {
            break;
        }
    }
    let [a, b] = buf;
    if cur == 0 { a } else { b }
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

/// Area contact of polygon p (particle i, centre ci) with polygon q (particle j, centre
/// cj), both convex and counter-clockwise in world coordinates; None when the outlines
/// do not overlap.
pub fn polygon_polygon(p: &[P2], ci: P2, q: &[P2], cj: P2) -> Option<AreaContact> {
    let tagged = tagged_intersection(p, ci, q);
    if tagged.poly.n < 3 {
        return None;
    }
    let overlap = tagged.poly.corners();
    let area = crate::shape::area(overlap);
    if area <= 0.0 {
        return None;
    }
    let mut crossed = Poly::default();
    for (k, x) in overlap.iter().enumerate() {
        if tagged.origin[k] == Origin::Crossing {
            crossed.push(*x);
        }
    }
    let xs = crossed.corners();
    let scale = norm(sub(ci, cj)) + norm(sub(p[0], ci)) + norm(sub(q[0], cj));
    let centres = sub(ci, cj);
    let along_centres = if norm(centres) > 0.0 {
        [centres[0] / norm(centres), centres[1] / norm(centres)]
    } else {
        [0.0, 1.0]
    };
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
                .map(|(k, x)| match tagged.origin[k] {
                    Origin::P => dot(n, sub(*x, s)),
                    Origin::Q => -dot(n, sub(*x, s)),
                    Origin::Crossing => 0.0,
                })
                .sum();
            if side > 0.0 || (side == 0.0 && dot(n, centres) < 0.0) {
                n = [-n[0], -n[1]];
            }
            (n, s, chord)
        } else {
            (along_centres, corner_mean(overlap), 0.0)
        }
    } else {
        (along_centres, corner_mean(overlap), 0.0)
    };
    let l = reduced_arm(norm(sub(point, ci)), norm(sub(point, cj)), scale);
    Some(AreaContact {
        area,
        n,
        point,
        chord,
        l,
    })
}

/// Area contact of polygon p (centre ci) with a wall segment: the part of p beyond the
/// wall's line (seen from the centre) and between its end points. The intersection line
/// is the stretch of the wall's line inside p; n is the wall's normal towards the centre;
/// l = l_i (a wall is infinitely large).
pub fn polygon_wall(p: &[P2], ci: P2, w: &WallSegment) -> Option<AreaContact> {
    let ab = sub(w.b, w.a);
    let len = norm(ab);
    if len == 0.0 {
        return None;
    }
    let mut m = [-ab[1] / len, ab[0] / len];
    if dot(m, sub(ci, w.a)) < 0.0 {
        m = [-m[0], -m[1]];
    }
    let mut cur = Poly::default();
    let mut next = Poly::default();
    clip_half_plane(p, w.a, [-m[0], -m[1]], &mut cur);
    clip_half_plane(cur.corners(), w.a, ab, &mut next);
    clip_half_plane(next.corners(), w.b, [-ab[0], -ab[1]], &mut cur);
    if cur.n < 3 {
        return None;
    }
    let cur = cur.corners();
    let area = crate::shape::area(cur);
    if area <= 0.0 {
        return None;
    }
    // Overlap corners on the wall's line: the crossing points (or a wall end inside p).
    let scale = len + norm(sub(p[0], ci));
    let on_line = |x: &P2| dot(sub(*x, w.a), m).abs() <= 1e-12 * scale;
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for x in cur.iter().filter(|x| on_line(x)) {
        let s = dot(sub(*x, w.a), ab) / len;
        lo = lo.min(s);
        hi = hi.max(s);
    }
    let (point, chord) = if hi > lo {
        let s = 0.5 * (lo + hi) / len;
        ([w.a[0] + s * ab[0], w.a[1] + s * ab[1]], hi - lo)
    } else {
        (corner_mean(cur), 0.0)
    };
    let l = norm(sub(point, ci)).max(1e-9 * scale);
    Some(AreaContact {
        area,
        n: m,
        point,
        chord,
        l,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let g = polygon_polygon(&square(ci, 0.5), ci, &square(cj, 0.5), cj).unwrap();
        assert!((g.area - 0.07).abs() < 1e-14);
        // Crossings at (0.4, 0.5) (i's left edge, j's top) and (0.5, -0.2) (j's right
        // edge, i's bottom): the line joins them.
        let t = [0.1, -0.7];
        let tn = norm(t);
        assert!((dot(g.n, [t[0] / tn, t[1] / tn])).abs() < 1e-14, "n ⊥ line");
        assert!(g.n[0] > 0.0, "n points from j to i");
        assert!((g.point[0] - 0.45).abs() < 1e-14 && (g.point[1] - 0.15).abs() < 1e-14);
        assert!((g.chord - tn).abs() < 1e-14);
        let (li, lj) = (norm(sub(g.point, ci)), norm(sub(g.point, cj)));
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
        let g = polygon_polygon(&tri, ci, &sq, cj).unwrap();
        // Sides through the apex have slope 1.1: the crossings are at x = ±0.1/1.1.
        let half = 0.1 / 1.1;
        assert!((g.area - half * 0.1).abs() < 1e-15);
        assert!((g.n[0]).abs() < 1e-15 && (g.n[1] - 1.0).abs() < 1e-15);
        assert!(g.point[0].abs() < 1e-15 && g.point[1].abs() < 1e-15);
        assert!((g.chord - 2.0 * half).abs() < 1e-15);
    }

    #[test]
    fn rotated_square_on_a_square() {
        // A unit square turned by 45° standing on its corner 0.1 deep in the top face.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let ci = [0.0, h - 0.1];
        let diamond = vec![[0.0, -0.1], [h, ci[1]], [0.0, ci[1] + h], [-h, ci[1]]];
        let cj = [0.0, -0.5];
        let g = polygon_polygon(&diamond, ci, &square(cj, 0.5), cj).unwrap();
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
        assert!(polygon_polygon(&square(ci, 0.5), ci, &square(cj, 0.5), cj).is_none());
        let ci = [1.0, 0.0];
        assert!(polygon_polygon(&square(ci, 0.5), ci, &square(cj, 0.5), cj).is_none());
    }

    #[test]
    fn square_on_a_floor() {
        let w = WallSegment {
            a: [-5.0, 0.0],
            b: [5.0, 0.0],
        };
        let ci = [0.3, 0.45];
        let g = polygon_wall(&square(ci, 0.5), ci, &w).unwrap();
        assert!((g.area - 0.05).abs() < 1e-15);
        assert_eq!(g.n, [0.0, 1.0]);
        assert!((g.point[0] - 0.3).abs() < 1e-15 && g.point[1] == 0.0);
        assert!((g.chord - 1.0).abs() < 1e-15 && (g.l - 0.45).abs() < 1e-15);
        // Beyond the wall's end only the part above the segment counts.
        let ci = [5.3, 0.45];
        let g = polygon_wall(&square(ci, 0.5), ci, &w).unwrap();
        assert!((g.area - 0.01).abs() < 1e-15);
        assert!((g.chord - 0.2).abs() < 1e-15 && (g.point[0] - 4.9).abs() < 1e-15);
    }
}

// ---- Disks under the overlap-area law (SPEC 2.3 for mixed scenes; the kernel twins are
// in polygon.wgsl, built from exact depths) ----

/// Signed area of the triangle (0, a, b) inside the circle of radius r about the origin:
/// the segment ab is split where it crosses the circle; pieces inside add their triangle,
/// pieces outside the circular sector they subtend.
fn triangle_in_circle(a: P2, b: P2, r: f64) -> f64 {
    let d = sub(b, a);
    let (qa, qb, qc) = (dot(d, d), 2.0 * dot(a, d), dot(a, a) - r * r);
    let mut ts = vec![0.0];
    let disc = qb * qb - 4.0 * qa * qc;
    if qa > 0.0 && disc > 0.0 {
        let s = disc.sqrt();
        for t in [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)] {
            if t > 0.0 && t < 1.0 {
                ts.push(t);
            }
        }
    }
    ts.push(1.0);
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    ts.windows(2)
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

/// Points where the circle (c, r) crosses the outline of polygon p (half-open edges).
fn circle_crossings(p: &[P2], c: P2, r: f64, out: &mut Poly) {
    out.n = 0;
    let n = p.len();
    for k in 0..n {
        let (a, b) = (sub(p[k], c), sub(p[(k + 1) % n], c));
        let d = sub(b, a);
        let (qa, qb, qc) = (dot(d, d), 2.0 * dot(a, d), dot(a, a) - r * r);
        let disc = qb * qb - 4.0 * qa * qc;
        if qa == 0.0 || disc < 0.0 {
            continue;
        }
        let s = disc.sqrt();
        for t in [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)] {
            if (0.0..1.0).contains(&t) && out.n < MAX_CLIP {
                out.push([c[0] + a[0] + t * d[0], c[1] + a[1] + t * d[1]]);
            }
        }
    }
}

/// Area contact of polygon p (centre cp) and the disk (c, r); `polygon_is_i` says which
/// of the two is particle i (n points from j to i). The force point is the midpoint of
/// the two crossings farthest apart; corners of the polygon inside the disk and the
/// disk's centre lie on the disk's side of that line.
pub fn polygon_disk(p: &[P2], cp: P2, c: P2, r: f64, polygon_is_i: bool) -> Option<AreaContact> {
    let n = p.len();
    // No corner inside the circle, no edge cut by it and the centre outside the polygon:
    // no overlap (the sum below would give round-off instead of zero). As in the kernel.
    let inside = |v: P2| dot(sub(v, c), sub(v, c)) < r * r;
    let (mut cut, mut centre_inside) = (false, true);
    for k in 0..n {
        let (a, ab) = (p[k], sub(p[(k + 1) % n], p[k]));
        if cross(ab, sub(c, a)) < 0.0 {
            centre_inside = false;
        }
        let t = dot(sub(c, a), ab) / dot(ab, ab);
        let f = [a[0] + t * ab[0], a[1] + t * ab[1]];
        cut |= t > 0.0 && t < 1.0 && inside(f);
    }
    if !cut && !centre_inside && !p.iter().any(|&v| inside(v)) {
        return None;
    }
    let area: f64 = (0..n)
        .map(|k| triangle_in_circle(sub(p[k], c), sub(p[(k + 1) % n], c), r))
        .sum();
    if area <= 0.0 {
        return None;
    }
    let mut crossed = Poly::default();
    circle_crossings(p, c, r, &mut crossed);
    let xs = crossed.corners();
    let scale = norm(sub(cp, c)) + r + norm(sub(p[0], cp));
    let (ci, cj) = if polygon_is_i { (cp, c) } else { (c, cp) };
    let centres = sub(ci, cj);
    let along = if norm(centres) > 0.0 {
        [centres[0] / norm(centres), centres[1] / norm(centres)]
    } else {
        [0.0, 1.0]
    };
    let (mut n_vec, point, chord) = if xs.len() >= 2 {
        let (a, b) = farthest_pair(xs);
        let chord = norm(sub(b, a));
        if chord > 1e-12 * scale {
            let t = [(b[0] - a[0]) / chord, (b[1] - a[1]) / chord];
            (
                [-t[1], t[0]],
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
                chord,
            )
        } else {
            (along, c, 0.0)
        }
    } else {
        (along, c, 0.0)
    };
    if chord > 0.0 {
        // Score the disk's side: its centre and the polygon's corners inside it.
        let disk_side: f64 = dot(n_vec, sub(c, point))
            + p.iter()
                .filter(|v| dot(sub(**v, c), sub(**v, c)) < r * r)
                .map(|v| dot(n_vec, sub(*v, point)))
                .sum::<f64>();
        // n must point from j to i: away from the disk when the polygon is i.
        let towards_disk = disk_side > 0.0;
        if towards_disk == polygon_is_i {
            n_vec = [-n_vec[0], -n_vec[1]];
        }
    }
    let l = reduced_arm(norm(sub(point, ci)), norm(sub(point, cj)), scale);
    Some(AreaContact {
        area,
        n: n_vec,
        point,
        chord,
        l,
    })
}

/// Area contact of two disks: the lens between them, the chord through the circles'
/// crossings, n along the line of centres.
pub fn disk_disk_area(ci: P2, ri: f64, cj: P2, rj: f64) -> Option<AreaContact> {
    let dv = sub(ci, cj);
    let d = norm(dv);
    if d >= ri + rj {
        return None;
    }
    let n = if d > 0.0 {
        [dv[0] / d, dv[1] / d]
    } else {
        [0.0, 1.0]
    };
    if d <= (ri - rj).abs() {
        // One inside the other: the smaller disk's area, at its centre.
        let (small, cs) = if ri < rj { (ri, ci) } else { (rj, cj) };
        let area = std::f64::consts::PI * small * small;
        let l = reduced_arm(norm(sub(cs, ci)), norm(sub(cs, cj)), ri + rj);
        return Some(AreaContact {
            area,
            n,
            point: cs,
            chord: 0.0,
            l,
        });
    }
    // Distances of the chord from each centre along the line of centres.
    let a_j = (d * d + rj * rj - ri * ri) / (2.0 * d);
    let a_i = d - a_j;
    let h = (rj * rj - a_j * a_j).max(0.0).sqrt();
    // Circular segment beyond a chord at distance a from the centre of a circle r.
    let segment = |r: f64, a: f64| {
        let theta = h.atan2(a);
        r * r * (theta - theta.sin() * theta.cos())
    };
    let area = segment(ri, a_i) + segment(rj, a_j);
    let point = [cj[0] + n[0] * a_j, cj[1] + n[1] * a_j];
    let l = reduced_arm(a_i.abs(), a_j.abs(), ri + rj);
    Some(AreaContact {
        area,
        n,
        point,
        chord: 2.0 * h,
        l,
    })
}

/// Area contact of a disk and a wall segment: the circular segment beyond the wall's
/// line; where the chord reaches past an end of the wall only the part over the wall
/// counts (its area scaled by that fraction of the chord, an approximation at the ends).
pub fn disk_wall_area(c: P2, r: f64, w: &WallSegment) -> Option<AreaContact> {
    let ab = sub(w.b, w.a);
    let len = norm(ab);
    if len == 0.0 {
        return None;
    }
    let t = [ab[0] / len, ab[1] / len];
    let mut m = [-t[1], t[0]];
    let mut dist = dot(m, sub(c, w.a));
    if dist < 0.0 {
        m = [-m[0], -m[1]];
        dist = -dist;
    }
    if dist >= r {
        return None;
    }
    let h = (r * r - dist * dist).sqrt();
    let s = dot(sub(c, w.a), t);
    let (lo, hi) = ((s - h).max(0.0), (s + h).min(len));
    if hi <= lo {
        return None;
    }
    let theta = h.atan2(dist);
    let full = r * r * (theta - theta.sin() * theta.cos());
    let area = full * (hi - lo) / (2.0 * h);
    let mid = 0.5 * (lo + hi);
    let point = [w.a[0] + mid * t[0], w.a[1] + mid * t[1]];
    let l = norm(sub(point, c)).max(1e-9 * r);
    Some(AreaContact {
        area,
        n: m,
        point,
        chord: hi - lo,
        l,
    })
}
