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
//! This module is the shape and its mass properties; the sub-contacts are
//! `overlap::spheropolygon`, their springs `cpu::springs::SubSprings`, a pair's force
//! under paper 004's law (`law::hertz_cohesive`) `cpu::forces::rods::pair_force`.

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
pub(crate) fn edge_iter(n: usize) -> impl Iterator<Item = (usize, usize)> {
    let count = match n {
        0 | 1 => 0,
        2 => 1,
        _ => n,
    };
    (0..count).map(move |k| (k, (k + 1) % n))
}

pub(crate) fn edges(n: usize) -> Vec<(usize, usize)> {
    edge_iter(n).collect()
}

/// The point of segment a–b closest to p, and its parameter t ∈ [0, 1] along a → b.
pub(crate) fn closest_on_segment(p: P2, a: P2, b: P2) -> (P2, f64) {
    let e = sub(b, a);
    let l2 = dot(e, e);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), e) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ([a[0] + t * e[0], a[1] + t * e[1]], t)
}

pub(crate) fn inside_convex(v: &[P2], p: P2) -> bool {
    let n = v.len();
    (0..n).all(|k| cross(sub(v[(k + 1) % n], v[k]), sub(p, v[k])) >= 0.0)
}

pub(crate) fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

pub(crate) fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

pub(crate) fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

pub(crate) fn norm(a: P2) -> f64 {
    a[0].hypot(a[1])
}

pub(crate) fn rotate(a: P2, angle: f64) -> P2 {
    let (s, c) = angle.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

#[cfg(test)]
impl Spheropolygon {
    /// A random core of one to six corners with a random sweep (tests).
    pub(crate) fn random(rng: &mut crate::base::rng::Rng) -> Spheropolygon {
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
