//! The sub-contacts of two spheropolygons (paper 004 sec. 2, after Alonso-Marroquín,
//! its refs. 10 and 11): vertex–edge pairs of the two cores closer than the sweeps, each
//! its own contact point with overlap δ = r_i + r_j − distance(vertex, edge) and its own
//! tangential spring (`SubContact::key`).

use crate::shape::P2;
use crate::shape::spheropolygon::{closest_on_segment, cross, dot, edge_iter, norm, sub};

/// One contact point of a pair of spheropolygons, seen from particle i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubContact {
    /// Which features touch, the same from step to step while they do (the tangential
    /// spring's key within the pair): `VERTEX_I` | vertex of i << 8 | edge of j, or
    /// `VERTEX_J` | vertex of j << 8 | edge of i (the vertex projects inside the edge),
    /// or `VERTICES` | vertex of i << 8 | vertex of j (it projects onto an end).
    pub key: u32,
    /// Overlap r_i + r_j − distance between the cores' features (negative in a gap).
    pub delta: f64,
    /// Unit normal from j to i.
    pub n: P2,
    /// The contact point relative to i's centre: the middle of the overlap along n.
    pub arm: P2,
}

/// The sub-contacts of a pair, inline up to four (what a rod pair has at most; a pair of cores with more corners may spill): no heap
/// allocation per pair and step.
pub type SubList = smallvec::SmallVec<[SubContact; 4]>;

pub const VERTEX_I: u32 = 0;

pub const VERTEX_J: u32 = 1 << 16;

pub const VERTICES: u32 = 2 << 16;

/// The sub-contacts of spheropolygons i and j whose surfaces are less than `gap` apart
/// (0, or a cohesion range): `p` and `q` their cores turned to their orientations,
/// relative to their centres, `d` = r_i − r_j. Vertex–edge pairs of both sides; a pair
/// where the vertex projects onto an end of the edge is the pair of vertices, listed
/// once however many edges lead to it. A polygon core's vertex counts only on the outer
/// side of an edge (the cores do not overlap: that would be an overlap of more than the
/// whole sweep, a diverging state).
pub fn sub_contacts(
    (p, rp): (&[P2], f64),
    (q, rq): (&[P2], f64),
    d: P2,
    gap: f64,
    out: &mut SubList,
) {
    out.clear();
    let reach = rp + rq + gap;
    // Most candidates of a neighbour list do not touch: beyond their circumscribed
    // circles about the centres (the cores' farthest corners plus the sweeps) no
    // sub-contact can be in range.
    let far = |c: &[P2]| {
        c.iter()
            .map(|v| v[0] * v[0] + v[1] * v[1])
            .fold(0.0, f64::max)
            .sqrt()
    };
    let circles = far(p) + far(q) + reach;
    if d[0] * d[0] + d[1] * d[1] >= circles * circles {
        return;
    }
    // j's corners relative to i's centre.
    let qi: smallvec::SmallVec<[P2; 16]> = q.iter().map(|c| sub(*c, d)).collect();
    // Vertices of one side against the edges of the other; `flip`: the vertex is j's.
    let pairs = |verts: &[P2], cores: &[P2], flip: bool, out: &mut SubList| {
        for (a, e) in edge_iter(cores.len()).enumerate() {
            let (ea, eb) = (cores[e.0], cores[e.1]);
            for (k, &v) in verts.iter().enumerate() {
                let edge = sub(eb, ea);
                if cores.len() >= 3 && cross(edge, sub(v, ea)) > 0.0 {
                    continue;
                }
                let (c, t) = closest_on_segment(v, ea, eb);
                let gap_v = sub(v, c);
                let dist = norm(gap_v);
                if dist >= reach || dist.is_nan() {
                    continue;
                }
                let key = if t > 0.0 && t < 1.0 {
                    let kind = if flip { VERTEX_J } else { VERTEX_I };
                    kind | (k as u32) << 8 | a as u32
                } else {
                    let end = if t <= 0.0 { e.0 } else { e.1 };
                    let (vi, vj) = if flip { (end, k) } else { (k, end) };
                    VERTICES | (vi as u32) << 8 | vj as u32
                };
                if key & VERTICES != 0 && out.iter().any(|s| s.key == key) {
                    continue;
                }
                // The normal from the edge's side to the vertex's side, then from j to i.
                let mut n = if dist > 0.0 {
                    [gap_v[0] / dist, gap_v[1] / dist]
                } else {
                    // The vertex on the edge: the edge's normal toward the vertex's centre.
                    let l = norm(edge);
                    let m = [edge[1] / l, -edge[0] / l];
                    let centre = if flip { sub([0.0, 0.0], d) } else { [0.0, 0.0] };
                    if dot(m, sub(centre, c)) < 0.0 {
                        [-m[0], -m[1]]
                    } else {
                        m
                    }
                };
                let (r_vertex, r_edge) = if flip { (rq, rp) } else { (rp, rq) };
                // The middle of the overlap: between the two surfaces along n.
                let s_edge = [c[0] + r_edge * n[0], c[1] + r_edge * n[1]];
                let s_vertex = [v[0] - r_vertex * n[0], v[1] - r_vertex * n[1]];
                let arm = [
                    0.5 * (s_edge[0] + s_vertex[0]),
                    0.5 * (s_edge[1] + s_vertex[1]),
                ];
                if flip {
                    n = [-n[0], -n[1]];
                }
                out.push(SubContact {
                    key,
                    delta: rp + rq - dist,
                    n,
                    arm,
                });
            }
        }
    };
    if p.len() == 1 && qi.len() == 1 {
        // Two disks: the one pair of vertices.
        vertices(p[0], qi[0], (rp, rq), reach, out);
        return;
    }
    pairs(p, &qi, false, out);
    pairs(&qi, p, true, out);
}

/// The contact of two point cores (disks) at a and b, relative to i's centre.
fn vertices(a: P2, b: P2, (rp, rq): (f64, f64), reach: f64, out: &mut SubList) {
    let gap = sub(a, b);
    let dist = norm(gap);
    if dist >= reach || dist.is_nan() {
        return;
    }
    let n = if dist > 0.0 {
        [gap[0] / dist, gap[1] / dist]
    } else {
        [0.0, 1.0]
    };
    let (si, sj) = (
        [a[0] - rp * n[0], a[1] - rp * n[1]],
        [b[0] + rq * n[0], b[1] + rq * n[1]],
    );
    out.push(SubContact {
        key: VERTICES,
        delta: rp + rq - dist,
        n,
        arm: [0.5 * (si[0] + sj[0]), 0.5 * (si[1] + sj[1])],
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;
    use crate::shape::spheropolygon::{Spheropolygon, edges, inside_convex};
    use std::f64::consts::PI;

    #[test]
    fn parallel_rods_touch_at_two_points_with_equal_overlaps() {
        let rod = Spheropolygon::rod(5.0, 1.0);
        // j lies under i, shifted by 1 along the rods, overlapping by 0.01.
        let d = [-1.0, 0.99];
        let mut out = SubList::new();
        sub_contacts((&rod.core, 0.5), (&rod.core, 0.5), d, 0.0, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for c in &out {
            assert!((c.delta - 0.01).abs() < 1e-12);
            assert!((c.n[0]).abs() < 1e-15 && (c.n[1] - 1.0).abs() < 1e-15);
            assert!((c.arm[1] + 0.495).abs() < 1e-12);
        }
        // At the two ends of the stretch where they overlap: j spans x ∈ [−1, 3] in i's
        // frame, i [−2, 2]: j's end at x = −1 and i's end at x = 2.
        let mut xs: Vec<f64> = out.iter().map(|c| c.arm[0]).collect();
        xs.sort_by(f64::total_cmp);
        assert!(
            (xs[0] + 1.0).abs() < 1e-12 && (xs[1] - 2.0).abs() < 1e-12,
            "{xs:?}"
        );
    }

    #[test]
    fn a_rods_end_on_anothers_side_touches_once_and_end_to_end_once() {
        let rod = Spheropolygon::rod(3.0, 1.0);
        let mut out = SubList::new();
        // A T: j upright below i's middle, its top end 0.98 below i's axis.
        let upright = Spheropolygon {
            core: vec![[0.0, -1.0], [0.0, 1.0]],
            radius: 0.5,
        };
        sub_contacts(
            (&rod.core, 0.5),
            (&upright.core, 0.5),
            [0.0, 1.98],
            0.0,
            &mut out,
        );
        assert_eq!(out.len(), 1, "{out:?}");
        assert!((out[0].delta - 0.02).abs() < 1e-12);
        // End to end along x: the two ends' vertices, once.
        sub_contacts(
            (&rod.core, 0.5),
            (&rod.core, 0.5),
            [2.99, 0.0],
            0.0,
            &mut out,
        );
        assert_eq!(out.len(), 1, "{out:?}");
        assert_eq!(out[0].key & VERTICES, VERTICES);
        assert!((out[0].delta - 0.01).abs() < 1e-12 && (out[0].n[0] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn the_nearest_sub_contact_is_the_distance_between_the_cores() {
        // Random convex cores at random offsets: the deepest sub-contact's overlap is
        // r_i + r_j minus the distance between the cores, found by sampling both cores'
        // boundaries densely; swapping i and j gives the same contacts, mirrored.
        let mut rng = Rng::new(7);
        let mut checked = 0;
        for _ in 0..200 {
            let (s, t) = (
                Spheropolygon::random(&mut rng),
                Spheropolygon::random(&mut rng),
            );
            let reach = s.circumradius() + t.circumradius();
            let angle = rng.uniform() * 2.0 * PI;
            let dist = reach * (0.3 + 0.8 * rng.uniform());
            let d = [dist * angle.cos(), dist * angle.sin()];
            // Separated cores only (overlapping cores are a diverged state).
            let qi: Vec<P2> = t.core.iter().map(|c| sub(*c, d)).collect();
            let sample = |v: &[P2]| -> Vec<P2> {
                let mut pts = v.to_vec();
                for (a, b) in edges(v.len()) {
                    for k in 1..800 {
                        let f = k as f64 / 800.0;
                        pts.push([
                            v[a][0] + f * (v[b][0] - v[a][0]),
                            v[a][1] + f * (v[b][1] - v[a][1]),
                        ]);
                    }
                }
                pts
            };
            let (ps, qs) = (sample(&s.core), sample(&qi));
            if ps
                .iter()
                .any(|&x| t.core.len() >= 3 && inside_convex(&qi, x))
                || qs
                    .iter()
                    .any(|&x| s.core.len() >= 3 && inside_convex(&s.core, x))
            {
                continue;
            }
            let brute = (ps.iter())
                .flat_map(|a| qs.iter().map(move |b| norm(sub(*a, *b))))
                .fold(f64::INFINITY, f64::min);
            let mut out = SubList::new();
            sub_contacts((&s.core, s.radius), (&t.core, t.radius), d, 0.0, &mut out);
            let deepest = out
                .iter()
                .map(|c| c.delta)
                .fold(f64::NEG_INFINITY, f64::max);
            let expected = s.radius + t.radius - brute;
            if expected > 1e-3 {
                assert!(!out.is_empty(), "a contact at overlap {expected}");
                // Sampling finds the distance to within a 1/800 of an edge.
                assert!(
                    (deepest - expected).abs() < 6e-3,
                    "{deepest} against {expected}"
                );
                checked += 1;
            } else if expected < -1e-3 {
                assert!(out.is_empty(), "no contact at gap {}", -expected);
            }
            // Swapped: the same overlaps, normals and world points mirrored.
            let mut swapped = SubList::new();
            sub_contacts(
                (&t.core, t.radius),
                (&s.core, s.radius),
                [-d[0], -d[1]],
                0.0,
                &mut swapped,
            );
            assert_eq!(swapped.len(), out.len());
            for c in &out {
                let world = c.arm;
                let twin = swapped.iter().find(|o| {
                    let w = [o.arm[0] - d[0], o.arm[1] - d[1]];
                    norm(sub(w, world)) < 1e-9
                });
                let twin = twin.unwrap_or_else(|| panic!("no mirror of {c:?} in {swapped:?}"));
                assert!((twin.delta - c.delta).abs() < 1e-12);
                assert!(norm([twin.n[0] + c.n[0], twin.n[1] + c.n[1]]) < 1e-12);
            }
        }
        assert!(checked > 20, "only {checked} touching pairs");
    }
}
