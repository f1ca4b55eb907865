//! Contact geometry of disks and walls: normal, overlap, contact point (SPEC 2.1).
//!
//! Pure functions, one per pair of shapes (polygons: src/overlap/), in a frame at the
//! first particle's centre: positions enter only as offsets (issue 18).

/// A fixed wall: the segment from `a` to `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallSegment {
    pub a: [f64; 2],
    pub b: [f64; 2],
}

/// The geometry of one contact, seen from particle 1, in a frame at particle 1's centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Geometry {
    /// Unit normal pointing from 2 to 1.
    pub n: [f64; 2],
    /// Overlap δ (negative for a gap).
    pub delta: f64,
    /// Centre distance and mean diameter for the continuous laws (mirror disk for walls).
    pub r: f64,
    pub sigma: f64,
    /// Contact point relative to particle 1's centre (its branch vector): on the line of
    /// centres, δ/2 inside particle 1's rim.
    pub arm: [f64; 2],
}

/// Tangent t = (−n_z, n_x): n rotated by +90°.
#[inline]
pub fn tangent(n: [f64; 2]) -> [f64; 2] {
    [-n[1], n[0]]
}

/// 2D cross product a × b (the z component).
#[inline]
pub fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// ω ẑ × l.
#[inline]
pub fn spin_velocity(omega: f64, l: [f64; 2]) -> [f64; 2] {
    [-omega * l[1], omega * l[0]]
}

/// A wall seen from the point c: its end points relative to c. Contacts with walls are
/// computed in this frame, never from absolute coordinates (issue 18).
#[inline]
pub fn wall_from(w: &WallSegment, c: [f64; 2]) -> WallSegment {
    WallSegment {
        a: [w.a[0] - c[0], w.a[1] - c[1]],
        b: [w.b[0] - c[0], w.b[1] - c[1]],
    }
}

/// Two disks whose centres are d = r1 − r2 apart: δ = (d1 + d2)/2 − |d| (paper 000 sec. 2.1).
#[inline]
pub fn disk_disk(d: [f64; 2], r1: f64, r2: f64) -> Geometry {
    let r = (d[0] * d[0] + d[1] * d[1]).sqrt();
    // Coincident centres: any direction is as good; pick +z so the force stays finite.
    let n = if r > 0.0 {
        [d[0] / r, d[1] / r]
    } else {
        [0.0, 1.0]
    };
    let sigma = r1 + r2;
    let delta = sigma - r;
    let arm = r1 - 0.5 * delta;
    Geometry {
        n,
        delta,
        r,
        sigma,
        arm: [-n[0] * arm, -n[1] * arm],
    }
}

/// A disk and a wall segment `w` given relative to the disk's centre ([`wall_from`]):
/// δ = R − distance to the closest point of the segment. The continuous laws see the
/// mirror disk behind the wall: r = 2·distance, σ = 2R.
#[inline]
pub fn disk_wall(radius: f64, w: &WallSegment) -> Geometry {
    let ab = [w.b[0] - w.a[0], w.b[1] - w.a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s = if len2 > 0.0 {
        ((-w.a[0] * ab[0] - w.a[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    // The centre minus the closest point.
    let d = [-(w.a[0] + s * ab[0]), -(w.a[1] + s * ab[1])];
    let dist = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let n = if dist > 0.0 {
        [d[0] / dist, d[1] / dist]
    } else {
        let l = len2.sqrt().max(f64::MIN_POSITIVE);
        [-ab[1] / l, ab[0] / l]
    };
    let delta = radius - dist;
    let arm = radius - 0.5 * delta;
    Geometry {
        n,
        delta,
        r: 2.0 * dist,
        sigma: 2.0 * radius,
        arm: [-n[0] * arm, -n[1] * arm],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disk_disk_overlap_normal_and_point() {
        let g = disk_disk([1.9, 0.0], 1.0, 1.0);
        assert!((g.delta - 0.1).abs() < 1e-15);
        assert_eq!(g.n, [1.0, 0.0]);
        assert!((g.arm[0] + 0.95).abs() < 1e-15 && g.arm[1] == 0.0);
    }

    #[test]
    fn disk_wall_uses_closest_point_and_ends() {
        let w = WallSegment {
            a: [0.0, 0.0],
            b: [10.0, 0.0],
        };
        let g = disk_wall(0.5, &wall_from(&w, [3.0, 0.4]));
        assert!((g.delta - 0.1).abs() < 1e-15);
        assert_eq!(g.n, [0.0, 1.0]);
        assert!((g.r - 0.8).abs() < 1e-15 && g.sigma == 1.0);
        assert!(g.arm[0] == 0.0 && (g.arm[1] + 0.45).abs() < 1e-15);
        // beyond the end: distance to the corner
        let g = disk_wall(0.6, &wall_from(&w, [-0.3, 0.4]));
        assert!((g.delta - 0.1).abs() < 1e-15);
        assert!((g.n[0] + 0.6).abs() < 1e-15);
    }
}
