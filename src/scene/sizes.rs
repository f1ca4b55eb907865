//! What a scene's particles measure, read from its creation blocks before any particle
//! exists: the largest reach (for the cell list), the smallest and largest sizes, the
//! smallest area, typical masses, each block's material.

use super::{Creation, PolygonSpec, Scene, Size};
use std::sync::Mutex;

/// Largest reach (diameter of the circumscribed circle) any creation block can produce:
/// what the cell list needs.
pub fn max_diameter(scene: &Scene) -> f64 {
    scene
        .particles
        .iter()
        .map(|c| reach_bounds(c).1)
        .fold(0.0, f64::max)
}

/// The polygon spec of a block, if it makes polygons.
pub fn polygon_of(c: &Creation) -> Option<&PolygonSpec> {
    match c {
        Creation::LatticePile(p) => p.polygon.as_ref(),
        Creation::Row(r) => r.polygon.as_ref(),
        Creation::PointSource(s) => s.polygon.as_ref(),
        Creation::Layered(s) => s.polygon.as_ref(),
        Creation::List(l) => l.polygon.as_ref(),
    }
}

/// Size bounds of particles drawn from `diameter` or `polygon.axes` (sources, layers).
fn drawn_size_bounds(diameter: Option<&Size>, polygon: Option<&PolygonSpec>) -> (f64, f64) {
    match (polygon.and_then(|p| p.axes.as_ref()), diameter) {
        (Some([a, b]), _) => {
            let (a, b) = (a.bounds(), b.bounds());
            (a.0.min(b.0), a.1.max(b.1))
        }
        (None, Some(d)) => d.bounds(),
        (None, None) => (0.0, 0.0),
    }
}

/// The largest circumscribed diameter of particles drawn from `diameter` or
/// `polygon.axes`: for polygons on ellipses of independent axes the largest over the
/// corners of the axes' ranges and the start angle, sampled finely, plus 2 % (the
/// centroid of an irregular polygon is off the ellipse's centre).
pub fn reach_bound_of(diameter: Option<&Size>, polygon: Option<&PolygonSpec>) -> f64 {
    let Some((p, [a, b])) = polygon.and_then(|p| p.axes.as_ref().map(|x| (p, x))) else {
        return drawn_size_bounds(diameter, polygon).1;
    };
    let (a, b) = (a.bounds(), b.bounds());
    // Sampling takes about a millisecond and layered blocks ask every step: remember
    // each polygon family's bound.
    static KNOWN: Mutex<Vec<([u64; 5], f64)>> = Mutex::new(Vec::new());
    let key = [
        p.corners as u64,
        a.0.to_bits(),
        a.1.to_bits(),
        b.0.to_bits(),
        b.1.to_bits(),
    ];
    let mut known = KNOWN.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&(_, reach)) = known.iter().find(|(k, _)| *k == key) {
        return reach;
    }
    let mut reach: f64 = 0.0;
    for (x, z) in [(a.0, b.0), (a.0, b.1), (a.1, b.0), (a.1, b.1)] {
        for k in 0..256 {
            let start = std::f64::consts::TAU / p.corners.max(1) as f64 * k as f64 / 256.0;
            let v = crate::shape::ellipse_polygon(p.corners, x, z, start);
            reach = reach.max(2.0 * crate::shape::circumradius(&v));
        }
    }
    known.push((key, 1.02 * reach));
    1.02 * reach
}

/// Smallest and largest full axes (or diameters) of a block's particles.
pub(super) fn size_bounds(c: &Creation) -> (f64, f64) {
    match c {
        Creation::LatticePile(p) => (
            p.diameter * (1.0 - 0.5 * p.size_disorder),
            p.diameter * (1.0 + 0.5 * p.size_disorder),
        ),
        Creation::Row(r) => (r.diameter, r.diameter),
        Creation::PointSource(s) => drawn_size_bounds(s.diameter.as_ref(), s.polygon.as_ref()),
        Creation::Layered(s) => drawn_size_bounds(s.diameter.as_ref(), s.polygon.as_ref()),
        Creation::List(l) => l.particles.iter().fold((f64::MAX, 0.0), |(lo, hi), p| {
            (lo.min(p.diameter), hi.max(p.diameter))
        }),
    }
}

/// Diameter of the circumscribed circle, bounded over the block's sizes: a disk's
/// diameter; a regular polygon's circle (on a lattice, the face-to-face diameter over
/// cos(π/C)); drawn polygons as [`reach_bound_of`].
fn reach_bounds(c: &Creation) -> (f64, f64) {
    let (lo, hi) = size_bounds(c);
    match (c, polygon_of(c)) {
        (Creation::PointSource(s), Some(_)) => {
            (lo, reach_bound_of(s.diameter.as_ref(), s.polygon.as_ref()))
        }
        (Creation::Layered(s), Some(_)) => {
            (lo, reach_bound_of(s.diameter.as_ref(), s.polygon.as_ref()))
        }
        (Creation::LatticePile(_) | Creation::Row(_), Some(p)) => {
            (lo, hi / (std::f64::consts::PI / p.corners as f64).cos())
        }
        // A rod's circle is its length, `aspect` widths.
        (Creation::List(l), None) if l.rod.is_some() => {
            (lo, hi * l.rod.as_ref().map_or(1.0, |r| r.aspect.max(1.0)))
        }
        (Creation::PointSource(s), None) if s.rod.is_some() => {
            (lo, hi * s.rod.as_ref().map_or(1.0, |r| r.aspect.max(1.0)))
        }
        _ => (lo, hi),
    }
}

/// Area of the smallest particle of a block: a disk, a rod of width w and aspect d (a
/// stadium, w² (d − 1 + π/4)), or a polygon on an ellipse with axes (a, b), which is the
/// affine image of a regular polygon: (a b / 4)(C/2) sin(2π/C).
pub(super) fn smallest_area(c: &Creation) -> f64 {
    let (lo, _) = size_bounds(c);
    let rod = match c {
        Creation::List(l) => l.rod.as_ref(),
        Creation::PointSource(s) => s.rod.as_ref(),
        _ => None,
    };
    if let Some(r) = rod {
        return lo * lo * ((r.aspect - 1.0).max(0.0) + 0.25 * std::f64::consts::PI);
    }
    match polygon_of(c) {
        None => std::f64::consts::PI * 0.25 * lo * lo,
        Some(p) => {
            let n = p.corners as f64;
            0.25 * lo * lo * 0.5 * n * (std::f64::consts::TAU / n).sin()
        }
    }
}

/// About how many particles a block creates, and the key that says so: computed from
/// the block's numbers without creating anything.
pub(super) fn estimated_particles(c: &Creation) -> (f64, &'static str) {
    match c {
        Creation::LatticePile(p) => {
            let l = p.bottom_row as f64;
            (0.5 * l * (l + 1.0), "bottom_row")
        }
        Creation::Row(r) => (r.count as f64, "count"),
        Creation::PointSource(s) => (s.count as f64, "count"),
        Creation::List(l) => (l.particles.len() as f64, "particles"),
        Creation::Layered(s) => {
            let lo = size_bounds(c).0.max(f64::MIN_POSITIVE);
            let rows = super::rows::max_rows(s) as f64;
            (rows * (s.base_width / lo + 1.0), "base_width")
        }
    }
}

/// The area of the smallest particle the scene's blocks create (∞ without blocks).
pub fn smallest_particle_area(scene: &Scene) -> f64 {
    (scene.particles.iter())
        .map(smallest_area)
        .fold(f64::INFINITY, f64::min)
}

/// Each material's typical particle mass (None for a material no block creates): the
/// mass of a disk of the middle diameter of each block's range, averaged over the
/// material's blocks (`talus check`'s contact table).
pub fn typical_masses(scene: &Scene) -> Vec<Option<f64>> {
    (scene.materials.iter())
        .map(|(name, m)| {
            let masses: Vec<f64> = (scene.particles.iter())
                .filter(|c| material_of(c) == name)
                .map(|c| {
                    let (lo, hi) = size_bounds(c);
                    let d = 0.5 * (lo + hi);
                    m.density * std::f64::consts::FRAC_PI_4 * d * d * m.thickness
                })
                .collect();
            (!masses.is_empty()).then(|| masses.iter().sum::<f64>() / masses.len() as f64)
        })
        .collect()
}

pub fn material_of(c: &Creation) -> &str {
    match c {
        Creation::LatticePile(p) => &p.material,
        Creation::Row(r) => &r.material,
        Creation::PointSource(s) => &s.material,
        Creation::Layered(s) => &s.material,
        Creation::List(l) => &l.material,
    }
}
