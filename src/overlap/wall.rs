//! A polygon against a wall segment (SPEC 2.3): the part of the polygon beyond the
//! wall's line and between its ends, by clipping (`clip.rs`).

use super::clip::{END_A_LINE, END_B_LINE, WALL_LINE, clip_lines, with_scratch};
use super::{AreaContact, corner_mean, dot, norm, sub};
use crate::base::geometry::WallSegment;
use crate::shape::P2;

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
fn wall_contact(clip: &super::clip::Clip, p: &[P2], w: &WallSegment, m: P2) -> Option<AreaContact> {
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
    use crate::overlap::polygon_polygon;

    fn relative(v: &[P2], c: P2) -> Vec<P2> {
        v.iter().map(|x| sub(*x, c)).collect()
    }

    /// The contact of two polygons given in world coordinates, and its force point there.
    fn world_pp(p: &[P2], ci: P2, q: &[P2], cj: P2) -> Option<(AreaContact, P2)> {
        polygon_polygon(&relative(p, ci), &relative(q, cj), sub(ci, cj))
            .map(|g| (g, [ci[0] + g.arm[0], ci[1] + g.arm[1]]))
    }

    fn world_pw(p: &[P2], ci: P2, w: &WallSegment) -> Option<(AreaContact, P2)> {
        polygon_wall(&relative(p, ci), &crate::base::geometry::wall_from(w, ci))
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
