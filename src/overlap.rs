//! Overlap-area contact geometry of convex polygons (paper 000 sec. 2.2, SPEC 2.3).
//!
//! Two polygons touch when their outlines intersect. The overlap polygon is computed
//! exactly by convex clipping (Sutherland–Hodgman); its area A measures the
//! deformation. The two crossing points of the outlines define the intersection line:
//! the normal is perpendicular to it, the tangent along it, and the force acts at its
//! midpoint S. Degenerate overlaps fall back to quantities that stay finite and vary
//! continuously with the area, which then is small: fewer than two crossings (one
//! polygon inside the other) or a vanishing chord take S at the overlap's centroid and
//! n along the line of centres; more than two crossings (nearly parallel edges) take
//! the two that are farthest apart, which spans the thin overlap along its length.

use crate::geometry::{WallSegment, cross};
use crate::shape::{P2, centroid};

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
    a[0].hypot(a[1])
}

/// One Sutherland–Hodgman step: the part of the convex polygon `poly` in the half-plane
/// {x : (x − a)·m ≥ 0}.
pub fn clip_half_plane(poly: &[P2], a: P2, m: P2, out: &mut Vec<P2>) {
    out.clear();
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
/// edge of q.
pub fn intersection(p: &[P2], q: &[P2]) -> Vec<P2> {
    let mut cur = p.to_vec();
    let mut next = Vec::with_capacity(p.len() + q.len());
    let n = q.len();
    for k in 0..n {
        let (a, b) = (q[k], q[(k + 1) % n]);
        // Inward normal of a counter-clockwise edge: the edge turned by +90°.
        clip_half_plane(&cur, a, [-(b[1] - a[1]), b[0] - a[0]], &mut next);
        std::mem::swap(&mut cur, &mut next);
        if cur.is_empty() {
            break;
        }
    }
    cur
}

/// Crossing points of the two outlines: intersections of an edge of p with an edge of q.
/// Parameters are half-open, [0, 1) on both edges, so a crossing through a corner is
/// found once.
pub fn crossings(p: &[P2], q: &[P2], out: &mut Vec<P2>) {
    out.clear();
    let (np, nq) = (p.len(), q.len());
    for a in 0..np {
        let (p0, d) = (p[a], sub(p[(a + 1) % np], p[a]));
        for b in 0..nq {
            let (q0, e) = (q[b], sub(q[(b + 1) % nq], q[b]));
            let den = cross(d, e);
            if den == 0.0 {
                continue; // parallel edges: their end points are found on the neighbours
            }
            let w = sub(q0, p0);
            let t = cross(w, e) / den;
            let s = cross(w, d) / den;
            if (0.0..1.0).contains(&t) && (0.0..1.0).contains(&s) {
                out.push([p0[0] + t * d[0], p0[1] + t * d[1]]);
            }
        }
    }
}

/// Whether x lies inside the convex, counter-clockwise polygon q (boundary excluded).
fn strictly_inside(x: P2, q: &[P2]) -> bool {
    let n = q.len();
    (0..n).all(|k| cross(sub(q[(k + 1) % n], q[k]), sub(x, q[k])) > 0.0)
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
    let overlap = intersection(p, q);
    if overlap.len() < 3 {
        return None;
    }
    let area = crate::shape::area(&overlap);
    if area <= 0.0 {
        return None;
    }
    let mut xs = Vec::with_capacity(4);
    crossings(p, q, &mut xs);
    let scale = norm(sub(ci, cj)) + norm(sub(p[0], ci)) + norm(sub(q[0], cj));
    let centres = sub(ci, cj);
    let along_centres = if norm(centres) > 0.0 {
        [centres[0] / norm(centres), centres[1] / norm(centres)]
    } else {
        [0.0, 1.0]
    };
    let (n, point, chord) = if xs.len() >= 2 {
        let (a, b) = farthest_pair(&xs);
        let chord = norm(sub(b, a));
        if chord > 1e-12 * scale {
            let t = [(b[0] - a[0]) / chord, (b[1] - a[1]) / chord];
            let mut n = [-t[1], t[0]];
            let s = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            // Corners of i inside j lie on j's side of the line, corners of j inside i
            // on i's side; n points from j to i.
            let side: f64 = p
                .iter()
                .filter(|v| strictly_inside(**v, q))
                .map(|v| dot(n, sub(*v, s)))
                .sum::<f64>()
                - q.iter()
                    .filter(|w| strictly_inside(**w, p))
                    .map(|w| dot(n, sub(*w, s)))
                    .sum::<f64>();
            if side > 0.0 || (side == 0.0 && dot(n, centres) < 0.0) {
                n = [-n[0], -n[1]];
            }
            (n, s, chord)
        } else {
            (along_centres, centroid(&overlap), 0.0)
        }
    } else {
        (along_centres, centroid(&overlap), 0.0)
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
    let mut cur = Vec::with_capacity(p.len() + 3);
    let mut next = Vec::with_capacity(p.len() + 3);
    clip_half_plane(p, w.a, [-m[0], -m[1]], &mut cur);
    clip_half_plane(&cur, w.a, ab, &mut next);
    clip_half_plane(&next, w.b, [-ab[0], -ab[1]], &mut cur);
    if cur.len() < 3 {
        return None;
    }
    let area = crate::shape::area(&cur);
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
        (centroid(&cur), 0.0)
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
