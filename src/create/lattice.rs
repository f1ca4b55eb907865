//! Triangular-lattice piles, paper 000 sec. 4 and Fig. 2.
//!
//! Row M holds L_M = L − 3M disks (30° pile) or L − M (60°), centred on the same line;
//! the number of rows is H = ⌊(L − 1)/3⌋ + 1 or H = L, so N(30°) = H (L − 3(H − 1)/2)
//! (1717 for L = 100). All rows use the bottom-row spacing a = d0 (1 + c); rows are
//! stacked so that neighbours in adjacent rows just touch, h = sqrt(d0² − a²/4). For
//! c < 0 neighbours within a row then overlap by |c| d0 at the start (the paper gives
//! zero initial overlaps only for c ≥ 0; its squeezed rows need some).

use crate::rng::Rng;
use crate::scene::LatticePile;
use crate::state::NewParticle;

/// Number of rows H for a pile with L disks at the bottom.
pub fn rows(slope: f64, bottom_row: u32) -> u32 {
    if slope == 30.0 {
        (bottom_row - 1) / 3 + 1
    } else {
        bottom_row
    }
}

/// Disks in row M.
pub fn row_length(slope: f64, bottom_row: u32, m: u32) -> u32 {
    if slope == 30.0 {
        bottom_row - 3 * m
    } else {
        bottom_row - m
    }
}

pub fn pile(p: &LatticePile, material: u32, rng: &mut Rng) -> Vec<NewParticle> {
    let d0 = p.diameter;
    let a = d0 * (1.0 + p.spacing_c);
    let h = (d0 * d0 - 0.25 * a * a).sqrt();
    let mut out = Vec::new();
    for m in 0..rows(p.slope, p.bottom_row) {
        let n = row_length(p.slope, p.bottom_row, m);
        let fixed = m == 0 && p.fixed_bottom;
        for k in 0..n {
            let x = p.center_x + (k as f64 - 0.5 * (n - 1) as f64) * a;
            let z = p.base_z + 0.5 * d0 + m as f64 * h;
            // Size disorder only for mobile disks (paper 000 sec. 4.4).
            let diameter = if fixed || p.size_disorder == 0.0 {
                d0
            } else {
                d0 * (1.0 + rng.range(-0.5 * p.size_disorder, 0.5 * p.size_disorder))
            };
            // Polygons are turned by π/C: for C divisible by 6 flat faces, not corners,
            // face the six lattice neighbours.
            let (radius, corners) = super::regular_shape(p.polygon.as_ref(), diameter, true);
            out.push(NewParticle {
                position: [x, z],
                theta: 0.0,
                velocity: [0.0; 2],
                omega: 0.0,
                radius,
                fixed,
                fixed_rotation: false,
                material,
                corners,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(slope: f64, l: u32) -> LatticePile {
        LatticePile {
            material: "m".into(),
            slope,
            bottom_row: l,
            diameter: 1.0,
            spacing_c: 0.0,
            size_disorder: 0.0,
            fixed_bottom: true,
            center_x: 0.0,
            base_z: 0.0,
            polygon: None,
        }
    }

    #[test]
    fn paper_particle_counts() {
        let mut rng = Rng::new(0);
        assert_eq!(pile(&spec(30.0, 100), 0, &mut rng).len(), 1717); // paper 000 sec. 4
        assert_eq!(pile(&spec(30.0, 7), 0, &mut rng).len(), 7 + 4 + 1); // Fig. 2, L0 = 7
        assert_eq!(pile(&spec(60.0, 10), 0, &mut rng).len(), 55); // H (L + 1)/2
    }

    #[test]
    fn neighbours_touch_without_overlap_for_c_zero() {
        let mut rng = Rng::new(0);
        let disks = pile(&spec(30.0, 10), 0, &mut rng);
        let mut min = f64::MAX;
        for (i, a) in disks.iter().enumerate() {
            for b in &disks[i + 1..] {
                let d = ((a.position[0] - b.position[0]).powi(2)
                    + (a.position[1] - b.position[1]).powi(2))
                .sqrt();
                min = min.min(d);
            }
        }
        assert!((min - 1.0).abs() < 1e-12, "closest pair at {min}");
    }
}
