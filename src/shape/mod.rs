//! Convex polygon shapes (paper 000 sec. 2.2, SPEC 1): corners on an ellipse, and the
//! mass properties of the actual polygon.
//!
//! A shape is its list of corners in the body frame, counter-clockwise, with the
//! polygon's centroid at the origin; a disk has no corners. The world position of
//! corner k of particle i is r_i + R(θ_i) v_k. The contact geometry never forms that sum:
//! it works with the rotated corners R(θ_i) v_k and the offset between the two centres
//! (`crate::overlap`), so a contact is computed the same anywhere in the domain.

pub mod spheropolygon;

/// A point or vector in the plane.
pub type P2 = [f64; 2];

/// Fewest and most corners a polygon may have.
pub const MIN_CORNERS: u32 = 3;
pub const MAX_CORNERS: u32 = 16;

/// C corners on the ellipse with full axes a (along x) and b (along z), at angles
/// φ0 + 2πk/C (paper 000 sec. 5.4: irregular polygons by a random start φ0), shifted so
/// that the polygon's centroid is the origin.
pub fn ellipse_polygon(corners: u32, a: f64, b: f64, start: f64) -> Vec<P2> {
    let c = corners as usize;
    let mut v: Vec<P2> = (0..c)
        .map(|k| {
            let phi = start + std::f64::consts::TAU * k as f64 / c as f64;
            [0.5 * a * phi.cos(), 0.5 * b * phi.sin()]
        })
        .collect();
    let m = centroid(&v);
    for p in &mut v {
        p[0] -= m[0];
        p[1] -= m[1];
    }
    v
}

/// Signed area (positive for counter-clockwise corners): the shoelace formula about the
/// first corner, i.e. a fan of triangles from it. About the polygon's own corner, not
/// the frame's origin: on coordinates of size X the plain shoelace formula cancels
/// products of size X², losing X² ε of area (at X = 1000 d more than a resting
/// overlap's whole area; issue 18).
pub fn area(v: &[P2]) -> f64 {
    let Some(&o) = v.first() else {
        return 0.0;
    };
    let rel = |p: P2| [p[0] - o[0], p[1] - o[1]];
    v.windows(2)
        .skip(1)
        .map(|w| {
            let (p, q) = (rel(w[0]), rel(w[1]));
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        * 0.5
}

/// Centroid of the polygon's area.
pub fn centroid(v: &[P2]) -> P2 {
    let n = v.len();
    let (mut cx, mut cz, mut a2) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (p, q) = (v[k], v[(k + 1) % n]);
        let w = p[0] * q[1] - q[0] * p[1];
        a2 += w;
        cx += (p[0] + q[0]) * w;
        cz += (p[1] + q[1]) * w;
    }
    if a2 == 0.0 {
        return [0.0, 0.0];
    }
    [cx / (3.0 * a2), cz / (3.0 * a2)]
}

/// Polar second moment of area about the origin, ∫ |r|² dA (I = ρ · thickness · this).
pub fn polar_moment(v: &[P2]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|k| {
            let (p, q) = (v[k], v[(k + 1) % n]);
            let w = p[0] * q[1] - q[0] * p[1];
            w * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0] + p[1] * p[1] + p[1] * q[1] + q[1] * q[1])
        })
        .sum::<f64>()
        / 12.0
}

/// Radius of the smallest circle about the centroid that holds the polygon: the
/// particle's reach in the broad phase.
pub fn circumradius(v: &[P2]) -> f64 {
    v.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max)
}

/// Corners in the world frame: r + R(θ) v (for pictures and files; contacts use
/// [`rotate`] and offsets between centres).
pub fn world(v: &[P2], r: P2, theta: f64, out: &mut Vec<P2>) {
    rotate(v, theta, out);
    for p in out.iter_mut() {
        *p = [r[0] + p[0], r[1] + p[1]];
    }
}

/// Corners turned to the orientation θ about the centre: R(θ) v.
pub fn rotate(v: &[P2], theta: f64, out: &mut Vec<P2>) {
    let (s, c) = theta.sin_cos();
    out.clear();
    out.extend(v.iter().map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1]]));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_mass_properties() {
        // A square of side 2 (corners on the circle of diameter 2√2).
        let v = ellipse_polygon(4, 8f64.sqrt(), 8f64.sqrt(), std::f64::consts::FRAC_PI_4);
        assert!((area(&v) - 4.0).abs() < 1e-12);
        // ∫ r² dA of a square of side s about its centre: s⁴/6.
        assert!((polar_moment(&v) - 16.0 / 6.0).abs() < 1e-12);
        assert!((circumradius(&v) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn irregular_polygon_has_its_centroid_at_the_origin() {
        let v = ellipse_polygon(7, 2.0, 1.3, 0.37);
        let c = centroid(&v);
        assert!(c[0].abs() < 1e-14 && c[1].abs() < 1e-14);
        assert!(area(&v) > 0.0, "counter-clockwise");
        // Many corners approach the ellipse: area → π a b / 4.
        let e = ellipse_polygon(16, 2.0, 1.3, 0.0);
        let ellipse = std::f64::consts::PI * 2.0 * 1.3 / 4.0;
        assert!(area(&e) < ellipse && area(&e) > 0.97 * ellipse);
    }

    #[test]
    fn area_does_not_depend_on_where_the_polygon_is() {
        // A sliver 2⁻²⁰ ≈ 1e-6 thin and 1 long, far from the origin: the plain shoelace formula would
        // lose ~X² ε = 1e-8 of area at X = 1e4, 1 % of it; about a corner it is exact.
        let sliver = |x: f64| {
            [
                [x, x],
                [x + 1.0, x],
                [x + 1.0, x + 9.5367431640625e-7],
                [x, x + 9.5367431640625e-7],
            ]
        };
        for x in [0.0, 1e2, 1e4, 1e8] {
            assert_eq!(area(&sliver(x)), 9.5367431640625e-7, "at {x}");
        }
    }
}
