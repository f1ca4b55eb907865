//! Overlap-area contact geometry (paper 000 sec. 2.2, SPEC 2.3): what the overlap-area
//! law needs of a pair, one query per file.
//!
//! - `polygon.rs`: two convex polygons, each one's facing edges cut by the other's
//!   half-planes (the twin of shaders/polygon.wgsl), and `hint.rs`: what a pair's last
//!   step proves about this one (apart, or resting along a chain), checked first on the
//!   CPU path; the area floor below which an overlap is no contact.
//! - `wall.rs`: a polygon against a wall segment, by clipping (`clip.rs`).
//! - `disk.rs`: a polygon, a disk or a wall against a disk, from overlap depths that do
//!   not cancel.
//!
//! Two polygons touch when their outlines intersect. The overlap polygon's area A
//! measures the deformation. The two crossing points of the outlines define the
//! intersection line: the normal is perpendicular to it, the tangent along it, and the
//! force acts at its midpoint S. Degenerate overlaps fall back to quantities that stay
//! finite and vary continuously with the area, which then is small: fewer than two
//! crossings (one polygon inside the other) or a vanishing chord take S at the mean of
//! the overlap's corners and n along the line of centres; more than two crossings
//! (nearly parallel edges) take the two that are farthest apart, which spans the thin
//! overlap along its length.
//!
//! **Frames (issue 18).** Every function works in a frame at particle i's centre: its
//! corners relative to its centre (`shape::rotate`), the other particle through the
//! offset d = r_i − r_j, a wall through its end points relative to r_i
//! (`geometry::wall_from`). Absolute world coordinates never enter: on coordinates of
//! size X, the crossings would carry X ε and the shoelace area X² ε, which at X = 100 d
//! is more than a resting overlap's whole area. Areas are summed about a point of the
//! overlap's own outline, so a sliver 1e-6 d deep keeps ~1e-10 of relative precision.
//! The results are in the same frame: `arm` is the force point relative to r_i.

mod clip;
mod disk;
mod hint;
mod outline;
mod polygon;
pub mod spheropolygon;
mod wall;

pub use clip::{END_A_LINE, END_B_LINE, MAX_CLIP, Q_LINE, WALL_LINE};
pub use disk::{disk_disk_area, disk_wall_area, polygon_disk, segment_area, x_minus_sin};
pub use hint::{Chain, Hint, Seen, THICKNESS_FLOOR};
pub use outline::Outline;
pub use polygon::{polygon_polygon, polygon_polygon_hinted, polygon_polygon_of};
pub use wall::polygon_wall;

use crate::shape::P2;

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

pub(crate) fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

pub(crate) fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

pub(crate) fn norm(a: P2) -> f64 {
    dot(a, a).sqrt()
}

/// Mean of the corners: the fallback force point. Unlike the area centroid it needs no
/// division by a vanishing area, so a degenerate overlap keeps S inside it.
pub(crate) fn corner_mean(v: &[P2]) -> P2 {
    let n = v.len() as f64;
    let s = v.iter().fold([0.0, 0.0], |a, x| [a[0] + x[0], a[1] + x[1]]);
    [s[0] / n, s[1] / n]
}

/// A polygon pair's length scale for its tolerances: |d|₁ + r_p + r_q (the 1-norm: a
/// scale needs no square root).
#[inline(always)]
pub(crate) fn pair_scale(p: &Outline, q: &Outline, d: P2) -> f64 {
    d[0].abs() + d[1].abs() + p.reach + q.reach
}

/// l = 1/(1/l_i + 1/l_j), with a floor so that a force point on a centre (a diverging
/// overlap) gives a large but finite force.
pub(crate) fn reduced_arm(li: f64, lj: f64, scale: f64) -> f64 {
    let floor = 1e-9 * scale;
    let (li, lj) = (li.max(floor), lj.max(floor));
    li * lj / (li + lj)
}

/// The unit vector along d, or +z for d = 0.
pub(crate) fn unit_or_up(d: P2) -> P2 {
    let l = norm(d);
    if l > 0.0 {
        [d[0] / l, d[1] / l]
    } else {
        [0.0, 1.0]
    }
}

/// The overlap area of polygons p (corners relative to r_i) and q (relative to r_j),
/// d = r_i − r_j: the contact test of the broad phase's survivors (0 below the floor).
pub fn overlap_area(p: &[P2], q: &[P2], d: P2) -> f64 {
    polygon_polygon(p, q, d).map_or(0.0, |c| c.area)
}
