//! Disks under the overlap-area law (SPEC 2.3, for mixed scenes): a polygon against a
//! disk, two disks, a disk against a wall.

use super::clip::{Clip, MAX_CLIP};

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
use super::{AreaContact, dot, norm, reduced_arm, sub, unit_or_up};
use crate::base::geometry::{WallSegment, cross};
use crate::shape::{MAX_CORNERS, P2};

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
