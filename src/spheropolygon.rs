//! Spheropolygons (paper 004 sec. 2, SPEC 1 and 2.4): a convex core swept by a disk of
//! radius r, i.e. the Minkowski sum of the core and the disk. Paper 004's rods are a
//! segment swept by half their width (a stadium); any convex polygon core works.
//!
//! Two spheropolygons touch where the distance between their cores is below r_i + r_j.
//! Following Alonso-Marroquín's spheropolygons (paper 004 refs. 10, 11), the contact is
//! a set of vertex–edge pairs, each its own contact point with overlap
//! δ = r_i + r_j − distance(vertex, edge) and its own tangential spring (keyed by the
//! pair and the sub-contact, `SubContact::key`). Two parallel rods side by side touch at
//! two points (the ends of the stretch where they overlap), a rod's end on another's
//! side at one.
//!
//! Issue 15, first step: the shape, its mass properties and the sub-contacts. The law
//! (Hertz with cohesion, SPEC 2.4) is `law::hertz_cohesive`; neither is wired into scenes
//! or the GPU path yet (docs/GUIDE.md, "Not done yet").

use crate::shape::P2;
use std::f64::consts::PI;

/// A spheropolygon in its body frame: the core's corners (counter-clockwise; two for a
/// rod's segment, one for a disk) and the sweep radius.
#[derive(Clone, Debug, PartialEq)]
pub struct Spheropolygon {
    pub core: Vec<P2>,
    pub radius: f64,
}

/// Area, first moment and polar second moment about the body frame's origin of a piece.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    area: f64,
    first: P2,
    polar: f64,
}

impl Moments {
    /// A piece of area a with centroid c and polar moment j about c (parallel axes).
    fn piece(a: f64, c: P2, j: f64) -> Self {
        Moments {
            area: a,
            first: [a * c[0], a * c[1]],
            polar: j + a * dot(c, c),
        }
    }

    fn add(&mut self, o: Moments) {
        self.area += o.area;
        self.first = [self.first[0] + o.first[0], self.first[1] + o.first[1]];
        self.polar += o.polar;
    }
}

impl Spheropolygon {
    /// A rod of aspect ratio d (paper 004 sec. 2): length d·w and width w, i.e. a segment
    /// of length (d − 1)·w along x swept by w/2, centred at the origin.
    /// A rod of aspect ratio 1 is a disk (a point core).
    pub fn rod(aspect: f64, width: f64) -> Self {
        let half = 0.5 * (aspect - 1.0) * width;
        let core = if half > 0.0 {
            vec![[-half, 0.0], [half, 0.0]]
        } else {
            vec![[0.0, 0.0]]
        };
        Spheropolygon {
            core,
            radius: 0.5 * width,
        }
    }

    /// The core's edges as (start, end) corner indices: a polygon's n edges, a segment's
    /// one, a point's none.
    pub fn edges(&self) -> Vec<(usize, usize)> {
        edges(self.core.len())
    }

    /// Decomposition of the swept shape: the core polygon, a rectangle of width r
    /// outside each edge and a circular sector at each corner (the exterior angles sum
    /// to 2π). A segment is a polygon of two corners whose two edges (a→b, b→a) face
    /// opposite ways, and a point one whole disk.
    fn moments(&self) -> Moments {
        let (v, r) = (&self.core, self.radius);
        let n = v.len();
        let mut m = Moments::default();
        if n == 1 {
            m.add(Moments::piece(PI * r * r, v[0], 0.5 * PI * r.powi(4)));
            return m;
        }
        if n >= 3 {
            let a = crate::shape::area(v);
            let c = crate::shape::centroid(v);
            m.add(Moments {
                area: a,
                first: [a * c[0], a * c[1]],
                polar: crate::shape::polar_moment(v),
            });
        }
        // The outward normal of edge k (a → b, counter-clockwise: the right-hand side).
        let normal = |k: usize| {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let e = sub(b, a);
            let l = norm(e);
            [e[1] / l, -e[0] / l]
        };
        for k in 0..n {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let l = norm(sub(b, a));
            let nk = normal(k);
            let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let c = [mid[0] + 0.5 * r * nk[0], mid[1] + 0.5 * r * nk[1]];
            let area = l * r;
            m.add(Moments::piece(area, c, area * (l * l + r * r) / 12.0));
            // The sector at corner b, from this edge's normal to the next's.
            let nn = normal((k + 1) % n);
            let mut alpha = cross(nk, nn).atan2(dot(nk, nn));
            if alpha <= 0.0 {
                alpha += 2.0 * PI;
            }
            let sector = 0.5 * alpha * r * r;
            // Its centroid lies on the bisector at 4 r sin(α/2) / (3 α) from the corner.
            let e = 4.0 * r * (0.5 * alpha).sin() / (3.0 * alpha);
            let bis = rotate(nk, 0.5 * alpha);
            let c = [b[0] + e * bis[0], b[1] + e * bis[1]];
            let j_corner = 0.25 * alpha * r.powi(4);
            m.add(Moments::piece(sector, c, j_corner - sector * e * e));
        }
        m
    }

    /// The area of the swept shape.
    pub fn area(&self) -> f64 {
        self.moments().area
    }

    /// The centroid of the swept shape.
    pub fn centroid(&self) -> P2 {
        let m = self.moments();
        [m.first[0] / m.area, m.first[1] / m.area]
    }

    /// Polar second moment of area about the centroid, ∫ |x − c|² dA (the moment of
    /// inertia is ρ · thickness · this).
    pub fn polar_moment(&self) -> f64 {
        let m = self.moments();
        let c = [m.first[0] / m.area, m.first[1] / m.area];
        m.polar - m.area * dot(c, c)
    }

    /// The outline of the swept shape in the body frame, counter-clockwise: the core's
    /// edges pushed out by r, joined by arcs of `per_arc` + 1 points about the corners
    /// (pictures and files; the mass properties are exact, `moments`).
    pub fn outline(&self, per_arc: usize) -> Vec<P2> {
        let (v, r) = (&self.core, self.radius);
        let n = v.len();
        if n == 1 {
            return (0..4 * per_arc)
                .map(|k| {
                    let a = 2.0 * PI * k as f64 / (4 * per_arc) as f64;
                    [v[0][0] + r * a.cos(), v[0][1] + r * a.sin()]
                })
                .collect();
        }
        let normal = |k: usize| {
            let e = sub(v[(k + 1) % n], v[k]);
            let l = norm(e);
            [e[1] / l, -e[0] / l]
        };
        let mut out = Vec::with_capacity(n * (per_arc + 1));
        for k in 0..n {
            let b = v[(k + 1) % n];
            let (nk, nn) = (normal(k), normal((k + 1) % n));
            let mut alpha = cross(nk, nn).atan2(dot(nk, nn));
            if alpha <= 0.0 {
                alpha += 2.0 * PI;
            }
            for m in 0..=per_arc {
                let u = rotate(nk, alpha * m as f64 / per_arc as f64);
                out.push([b[0] + r * u[0], b[1] + r * u[1]]);
            }
        }
        out
    }

    /// The distance from a point to the core (0 inside a polygon core).
    pub fn core_distance(&self, p: P2) -> f64 {
        let v = &self.core;
        if v.len() >= 3 && inside_convex(v, p) {
            return 0.0;
        }
        if v.len() == 1 {
            return norm(sub(p, v[0]));
        }
        (self.edges().into_iter())
            .map(|(a, b)| norm(sub(p, closest_on_segment(p, v[a], v[b]).0)))
            .fold(f64::INFINITY, f64::min)
    }

    /// Radius of the smallest circle about the body frame's origin that holds the shape.
    pub fn circumradius(&self) -> f64 {
        self.core.iter().map(|p| norm(*p)).fold(0.0, f64::max) + self.radius
    }
}

/// The edges of a core of n corners (no allocation: this runs for every pair and step).
fn edge_iter(n: usize) -> impl Iterator<Item = (usize, usize)> {
    let count = match n {
        0 | 1 => 0,
        2 => 1,
        _ => n,
    };
    (0..count).map(move |k| (k, (k + 1) % n))
}

fn edges(n: usize) -> Vec<(usize, usize)> {
    edge_iter(n).collect()
}

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

/// Sub-contact springs a pair keeps at most from one step to the next: a rod pair has
/// at most four sub-contacts (two vertices on each side). Beyond that (polygon cores
/// touching at many points) the shallowest sub-contacts' springs restart every step.
pub const MAX_SUB: usize = 4;

/// One pair's tangential springs, each keyed by its sub-contact (`SubContact::key`):
/// what the neighbour list's slot holds for a spheropolygon pair between steps (SPEC 3:
/// "keyed by the pair and the sub-contact").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SubSprings {
    pub count: usize,
    pub key: [u32; MAX_SUB],
    pub xi: [f64; MAX_SUB],
}

impl SubSprings {
    /// The spring of a sub-contact, 0 for one that was not there at the last step.
    pub fn get(&self, key: u32) -> f64 {
        (0..self.count)
            .find(|&k| self.key[k] == key)
            .map_or(0.0, |k| self.xi[k])
    }

    fn push(&mut self, key: u32, xi: f64) {
        if self.count < MAX_SUB {
            self.key[self.count] = key;
            self.xi[self.count] = xi;
            self.count += 1;
        }
    }
}

/// What a pair of spheropolygons does to its particles this step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairForce {
    /// The total force on i (on j: its opposite).
    pub force: P2,
    /// Torques on i and on j.
    pub torque: [f64; 2],
    /// The updated springs of the sub-contacts in range.
    pub springs: SubSprings,
    /// Each sub-contact in range with its law's output (forces along n and t).
    pub contacts: smallvec::SmallVec<[(SubContact, crate::law::ContactOutput); 4]>,
}

/// The motion of one body: velocity (x, z) and angular velocity.
pub type Motion = [f64; 3];

/// The force between spheropolygons i and j (`p`, `q`: their turned cores and sweep
/// radii; `d` = r_i − r_j; `m12` the reduced mass, the mass of i against a wall, and
/// `mass` the contact's mass scale for the cohesion, `ContactInput::mass`) under
/// paper 004's law, each sub-contact with its own spring from `springs` (SPEC 2.4). A
/// wall is a spheropolygon of sweep radius 0 that does not move.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn pair_force(
    law: &crate::law::hertz_cohesive::HertzCohesive,
    p: (&[P2], f64),
    q: (&[P2], f64),
    d: P2,
    (vi, vj): (Motion, Motion),
    (m12, mass): (f64, f64),
    springs: &SubSprings,
    dt: f64,
) -> PairForce {
    let mut subs = SubList::new();
    sub_contacts(p, q, d, law.d_c, &mut subs);
    // The deepest first: they keep their springs when there are more than MAX_SUB.
    subs.sort_by(|a, b| b.delta.total_cmp(&a.delta).then(a.key.cmp(&b.key)));
    let mut out = PairForce::default();
    for (k, &c) in subs.iter().enumerate() {
        // The contact point relative to each centre, and the velocity of each surface there.
        let (li, lj) = (c.arm, [c.arm[0] + d[0], c.arm[1] + d[1]]);
        let ui = [vi[0] - vi[2] * li[1], vi[1] + vi[2] * li[0]];
        let uj = [vj[0] - vj[2] * lj[1], vj[1] + vj[2] * lj[0]];
        let v12 = sub(ui, uj);
        let t = [-c.n[1], c.n[0]];
        let history = if k < MAX_SUB { springs.get(c.key) } else { 0.0 };
        let input = crate::law::ContactInput {
            delta: c.delta,
            delta_dot: -dot(v12, c.n),
            v_t: dot(v12, t),
            m12,
            mass,
            history,
            dt,
            ..Default::default()
        };
        let r = law.evaluate(&input);
        let f = [r.f_n * c.n[0] + r.f_t * t[0], r.f_n * c.n[1] + r.f_t * t[1]];
        out.force = [out.force[0] + f[0], out.force[1] + f[1]];
        out.torque[0] += cross(li, f);
        out.torque[1] -= cross(lj, f);
        if k < MAX_SUB {
            out.springs.push(c.key, r.history);
        }
        out.contacts.push((c, r));
    }
    out
}

/// The point of segment a–b closest to p, and its parameter t ∈ [0, 1] along a → b.
fn closest_on_segment(p: P2, a: P2, b: P2) -> (P2, f64) {
    let e = sub(b, a);
    let l2 = dot(e, e);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), e) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ([a[0] + t * e[0], a[1] + t * e[1]], t)
}

fn inside_convex(v: &[P2], p: P2) -> bool {
    let n = v.len();
    (0..n).all(|k| cross(sub(v[(k + 1) % n], v[k]), sub(p, v[k])) >= 0.0)
}

fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn norm(a: P2) -> f64 {
    a[0].hypot(a[1])
}

fn rotate(a: P2, angle: f64) -> P2 {
    let (s, c) = angle.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The stadium of paper 004: a rectangle L × 2r and two half disks.
    fn stadium(l: f64, r: f64) -> (f64, f64) {
        let area = 2.0 * r * l + PI * r * r;
        let rect = 2.0 * r * l * (l * l + 4.0 * r * r) / 12.0;
        let half = 0.5 * PI * r * r;
        let e = 4.0 * r / (3.0 * PI);
        let cap = 0.25 * PI * r.powi(4) - half * e * e + half * (0.5 * l + e).powi(2);
        (area, rect + 2.0 * cap)
    }

    #[test]
    fn a_rods_mass_and_inertia_are_the_stadiums() {
        for (aspect, width) in [(2.0, 1.0), (5.0, 1.0), (10.0, 0.3), (1.0, 2.0)] {
            let rod = Spheropolygon::rod(aspect, width);
            let (area, polar) = stadium((aspect - 1.0) * width, 0.5 * width);
            assert!(
                (rod.area() - area).abs() < 1e-12 * area,
                "area, d = {aspect}"
            );
            assert!(
                (rod.polar_moment() - polar).abs() < 1e-12 * polar,
                "inertia, d = {aspect}: {} against {polar}",
                rod.polar_moment()
            );
            let c = rod.centroid();
            assert!(c[0].abs() < 1e-15 && c[1].abs() < 1e-15);
        }
    }

    #[test]
    fn a_polygon_cores_mass_properties_match_a_fine_grid() {
        // A triangle core off the origin, swept by 0.3: the decomposition against the
        // area and moments of the points of a fine grid that lie within r of the core.
        let s = Spheropolygon {
            core: vec![[0.2, -0.1], [1.4, 0.3], [0.5, 1.1]],
            radius: 0.3,
        };
        let h = 2e-3;
        let (mut a, mut fx, mut fz, mut j) = (0.0, 0.0, 0.0, 0.0);
        let mut x = -0.5;
        while x < 2.0 {
            let mut z = -0.8;
            while z < 1.8 {
                if s.core_distance([x, z]) <= s.radius {
                    a += h * h;
                    fx += h * h * x;
                    fz += h * h * z;
                    j += h * h * (x * x + z * z);
                }
                z += h;
            }
            x += h;
        }
        let c = s.centroid();
        assert!(
            (s.area() - a).abs() < 2e-3 * a,
            "area {} against {a}",
            s.area()
        );
        assert!((c[0] - fx / a).abs() < 2e-3 && (c[1] - fz / a).abs() < 2e-3);
        let jc = j - a * ((fx / a).powi(2) + (fz / a).powi(2));
        assert!((s.polar_moment() - jc).abs() < 3e-3 * jc);
    }

    #[test]
    fn the_outline_of_a_rod_is_its_stadium() {
        let rod = Spheropolygon::rod(4.0, 1.0);
        let o = rod.outline(32);
        // Every point lies on the surface, the polygon goes counter-clockwise, and its
        // area approaches the stadium's from below.
        for p in &o {
            assert!((rod.core_distance(*p) - 0.5).abs() < 1e-12);
        }
        let a = crate::shape::area(&o);
        assert!(a > 0.0 && a < rod.area() && a > 0.999 * rod.area(), "{a}");
    }

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

    fn random_shape(rng: &mut Rng) -> Spheropolygon {
        let corners = 1 + (rng.uniform() * 6.0) as usize;
        let core = match corners {
            1 => vec![[0.0, 0.0]],
            2 => {
                let l = 0.2 + 2.0 * rng.uniform();
                let a = rng.uniform() * PI;
                vec![
                    [-0.5 * l * a.cos(), -0.5 * l * a.sin()],
                    [0.5 * l * a.cos(), 0.5 * l * a.sin()],
                ]
            }
            c => {
                let start = rng.uniform() * PI;
                crate::shape::ellipse_polygon(
                    c as u32,
                    0.5 + rng.uniform(),
                    0.5 + rng.uniform(),
                    start,
                )
            }
        };
        Spheropolygon {
            core,
            radius: 0.05 + 0.4 * rng.uniform(),
        }
    }

    #[test]
    fn the_nearest_sub_contact_is_the_distance_between_the_cores() {
        // Random convex cores at random offsets: the deepest sub-contact's overlap is
        // r_i + r_j minus the distance between the cores, found by sampling both cores'
        // boundaries densely; swapping i and j gives the same contacts, mirrored.
        let mut rng = Rng::new(7);
        let mut checked = 0;
        for _ in 0..200 {
            let (s, t) = (random_shape(&mut rng), random_shape(&mut rng));
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

    use crate::law::hertz_cohesive::HertzCohesive;

    #[test]
    fn a_rod_lying_on_a_floor_carries_its_weight_on_two_points() {
        // A rod of mass m on its flat side on a floor (a wall: a segment of sweep 0) at
        // the overlap where each end carries half its weight, k δ^{3/2} = m g / 2.
        let (m, g) = (0.785, 10.0);
        let law = HertzCohesive::paper(g, 0.0, 0.5, 1.0);
        let rod = Spheropolygon::rod(5.0, 1.0);
        let delta = (0.5 * m * g / law.k_n).powf(2.0 / 3.0);
        // The floor's segment relative to the rod's centre: d = r_rod − r_floor with the
        // floor's "centre" at its middle, 0.5 − δ below the rod's axis.
        let floor = [[-10.0, 0.0], [10.0, 0.0]];
        let d = [0.0, 0.5 - delta];
        let f = pair_force(
            &law,
            (&rod.core, 0.5),
            (&floor, 0.0),
            d,
            ([0.0; 3], [0.0; 3]),
            (m, m),
            &SubSprings::default(),
            5e-6,
        );
        assert_eq!(f.contacts.len(), 2);
        assert!((f.force[1] - m * g).abs() < 1e-12 * m * g, "{:?}", f.force);
        assert!(f.force[0].abs() < 1e-15 && f.torque[0].abs() < 1e-12);
        // On its tip (standing upright): one point carries it all.
        let upright = Spheropolygon {
            core: vec![[0.0, -2.0], [0.0, 2.0]],
            radius: 0.5,
        };
        let delta = (m * g / law.k_n).powf(2.0 / 3.0);
        let d = [0.0, 2.5 - delta];
        let f = pair_force(
            &law,
            (&upright.core, 0.5),
            (&floor, 0.0),
            d,
            ([0.0; 3], [0.0; 3]),
            (m, m),
            &SubSprings::default(),
            5e-6,
        );
        assert_eq!(f.contacts.len(), 1);
        assert!((f.force[1] - m * g).abs() < 1e-12 * m * g);
    }

    #[test]
    fn swapping_the_rods_gives_equal_and_opposite_forces() {
        let law = HertzCohesive::paper(10.0, 1e3, 0.4, 1.0);
        let mut rng = Rng::new(3);
        let mut touching = 0;
        for _ in 0..300 {
            let (s, t) = (random_shape(&mut rng), random_shape(&mut rng));
            let reach = s.circumradius() + t.circumradius();
            let angle = rng.uniform() * 2.0 * PI;
            let dist = reach * (0.4 + 0.7 * rng.uniform());
            let d = [dist * angle.cos(), dist * angle.sin()];
            let vi = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let vj = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let none = SubSprings::default();
            let a = pair_force(
                &law,
                (&s.core, s.radius),
                (&t.core, t.radius),
                d,
                (vi, vj),
                (0.5, 1.0),
                &none,
                1e-3,
            );
            let b = pair_force(
                &law,
                (&t.core, t.radius),
                (&s.core, s.radius),
                [-d[0], -d[1]],
                (vj, vi),
                (0.5, 1.0),
                &none,
                1e-3,
            );
            let scale = 1.0 + a.force[0].abs() + a.force[1].abs();
            assert!(
                (a.force[0] + b.force[0]).abs() < 1e-9 * scale
                    && (a.force[1] + b.force[1]).abs() < 1e-9 * scale
            );
            assert!((a.torque[0] - b.torque[1]).abs() < 1e-9 * scale * reach);
            assert!((a.torque[1] - b.torque[0]).abs() < 1e-9 * scale * reach);
            touching += usize::from(!a.contacts.is_empty());
        }
        assert!(touching > 30, "only {touching} pairs in range");
    }

    #[test]
    fn each_sub_contact_keeps_its_own_spring_while_it_lasts() {
        // Rod i slides along rod j below it (parallel, overlapping by 0.001): both
        // sub-contacts' springs grow by v_t dt each step, and when i's end passes j's
        // end the sub-contact there is gone with its spring; a new one starts at 0.
        // No damping and no cap: the springs follow the kinematics alone.
        let law = HertzCohesive {
            mu: 1e6,
            gamma_n: 0.0,
            gamma_t: 0.0,
            ..HertzCohesive::paper(10.0, 0.0, 0.5, 1.0)
        };
        let rod = Spheropolygon::rod(3.0, 1.0);
        let dt = 1e-3;
        let v = 2.0;
        let mut springs = SubSprings::default();
        let mut x = -1.0;
        let mut seen_keys = Vec::new();
        // From x = −1 to 2.5: i's core [x − 1, x + 1] passes over j's [−1, 1].
        for step in 0..1750 {
            let d = [x, 0.999];
            let f = pair_force(
                &law,
                (&rod.core, 0.5),
                (&rod.core, 0.5),
                d,
                ([v, 0.0, 0.0], [0.0; 3]),
                (0.5, 1.0),
                &springs,
                dt,
            );
            for (c, r) in &f.contacts {
                let old = springs.get(c.key);
                let fresh = !(0..springs.count).any(|k| springs.key[k] == c.key);
                // t = (−n_z, n_x): v_t = −v n_z (−v where j lies straight below).
                let step_xi = -v * c.n[1] * dt;
                let expected = match (c.delta > 0.0, fresh) {
                    // In the cohesive range but not touching: no spring.
                    (false, _) => 0.0,
                    (true, true) => step_xi,
                    (true, false) => old + step_xi,
                };
                assert!(
                    (r.history - expected).abs() < 1e-12,
                    "step {step}, key {:x}: {} against {expected}, {c:?}, {r:?}, x = {x}",
                    c.key,
                    r.history
                );
                if !seen_keys.contains(&c.key) {
                    seen_keys.push(c.key);
                }
            }
            springs = f.springs;
            x += v * dt;
        }
        // i passed over j and beyond its right end: each end over the other's side
        // (vertex–edge), and the pairs of ends as they lined up (left ends, right ends,
        // i's left on j's right).
        seen_keys.sort();
        let ends = [0x0, 0x100, 0x10000, 0x10100];
        let lined_up = [VERTICES, VERTICES | 0x1, VERTICES | 0x101];
        assert_eq!(
            seen_keys,
            [&ends[..], &lined_up[..]].concat(),
            "{seen_keys:x?}"
        );
    }
}
