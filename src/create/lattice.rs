//! Triangular-lattice piles, paper 000 sec. 4 and Fig. 2.
//!
//! Row M holds L_M = L − 3M disks (30° pile) or L − M (60°), centred on the same line;
//! the number of rows is H = ⌊(L − 1)/3⌋ + 1 or H = L, so N(30°) = H (L − 3(H − 1)/2)
//! (1717 for L = 100).
//!
//! The paper starts every pile with zero overlaps and zero velocities (sec. 4), and so
//! does this builder, also for a squeezed bottom (c < 0) and for size disorder:
//! - The bottom row is spaced a = d0 (1 + c). A fixed bottom keeps that spacing even
//!   where its disks overlap (fixed disks do not interact).
//! - Every other row is spaced a too, widened between two neighbours where they would
//!   otherwise overlap, and centred. For c ≥ 0 without disorder that is the lattice
//!   itself; for c < 0 the mobile rows keep the spacing d0 and cannot all sit in the
//!   narrower pockets of the bottom, which is what squeezes them (sec. 4.1).
//! - Each disk is dropped at its x onto the rows below (or the floor) and set where it
//!   first touches, without overlap: in the pocket when it is over one, on the higher
//!   neighbour otherwise. Gravity, ramped, then settles the pile gently;
//!   without this, a squeezed or disordered lattice at the papers' stiffness starts with
//!   thousands of weights in its overlaps and explodes.
//!
//! Polygons use their inscribed circles for the spacing and heights: exact for the
//! face-to-face lattice of C = 6, 12, …, approximate otherwise.

use crate::base::rng::Rng;
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
    let mut out = Vec::new();
    // (x, z, diameter) of every disk placed so far.
    let mut placed: Vec<[f64; 3]> = Vec::new();
    for m in 0..rows(p.slope, p.bottom_row) {
        let n = row_length(p.slope, p.bottom_row, m) as usize;
        let fixed = m == 0 && p.fixed_bottom;
        // Size disorder only for mobile disks (paper 000 sec. 4.4).
        let diameters: Vec<f64> = (0..n)
            .map(|_| {
                if fixed || p.size_disorder == 0.0 {
                    d0
                } else {
                    d0 * (1.0 + rng.range(-0.5 * p.size_disorder, 0.5 * p.size_disorder))
                }
            })
            .collect();
        let xs = row_positions(&diameters, a, fixed, p.center_x);
        let row_start = placed.len();
        for (&x, &diameter) in xs.iter().zip(&diameters) {
            let z = rest_height(x, diameter, p.base_z, &placed[..row_start]);
            placed.push([x, z, diameter]);
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
                sweep: 0.0,
            });
        }
    }
    out
}

/// Centres of one row: spacing `a`, widened where two neighbours of a mobile row would
/// overlap, centred on `center`.
fn row_positions(diameters: &[f64], a: f64, fixed: bool, center: f64) -> Vec<f64> {
    let mut xs = Vec::with_capacity(diameters.len());
    let mut x = 0.0;
    for (k, &d) in diameters.iter().enumerate() {
        if k > 0 {
            let touch = 0.5 * (diameters[k - 1] + d);
            x += if fixed { a } else { a.max(touch) };
        }
        xs.push(x);
    }
    let shift = center - 0.5 * (xs[0] + xs[xs.len() - 1]);
    xs.iter().map(|x| x + shift).collect()
}

/// Where a disk of diameter `d` dropped at `x` comes to rest: on the floor `base`, or
/// touching, without overlapping, the highest disk of the rows below within reach.
fn rest_height(x: f64, d: f64, base: f64, below: &[[f64; 3]]) -> f64 {
    below
        .iter()
        .filter_map(|&[xb, zb, db]| {
            let reach = 0.5 * (d + db);
            let dx = x - xb;
            (dx.abs() < reach).then(|| zb + (reach * reach - dx * dx).sqrt())
        })
        .fold(base + 0.5 * d, f64::max)
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

    /// The smallest gap (distance − touching distance) between two disks that are not
    /// both fixed, and the largest gap of a mobile disk to its closest support.
    fn gaps(disks: &[NewParticle]) -> (f64, f64) {
        let mut min = f64::MAX;
        let mut support = vec![f64::MAX; disks.len()];
        for (i, a) in disks.iter().enumerate() {
            for (j, b) in disks.iter().enumerate().skip(i + 1) {
                if a.fixed && b.fixed {
                    continue;
                }
                let d = ((a.position[0] - b.position[0]).powi(2)
                    + (a.position[1] - b.position[1]).powi(2))
                .sqrt();
                let gap = d - (a.radius + b.radius);
                min = min.min(gap);
                // j lies above i in creation order: i can carry j.
                support[j] = support[j].min(gap);
            }
        }
        let worst_support = disks
            .iter()
            .zip(&support)
            .filter(|(d, _)| !d.fixed)
            .map(|(_, &s)| s)
            .fold(0.0, f64::max);
        (min, worst_support)
    }

    #[test]
    fn regular_lattice_is_unchanged_by_the_drop() {
        let mut rng = Rng::new(0);
        let s = spec(30.0, 13);
        let disks = pile(&s, 0, &mut rng);
        let h = (0.75f64).sqrt();
        let mut i = 0;
        for m in 0..rows(30.0, 13) {
            let n = row_length(30.0, 13, m);
            for k in 0..n {
                let want = [k as f64 - 0.5 * (n - 1) as f64, 0.5 + m as f64 * h];
                let got = disks[i].position;
                assert!(
                    (got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12,
                    "row {m} disk {k}: {got:?} against {want:?}"
                );
                i += 1;
            }
        }
    }

    #[test]
    fn squeezed_and_disordered_piles_start_without_overlaps_and_resting() {
        for (c, rd) in [
            (-1.0 / 150.0, 0.0),
            (-1.0 / 750.0, 0.0),
            (1.0 / 15.0, 0.0),
            (0.0, 1.0 / 30.0),
            (-1.0 / 150.0, 1.0 / 30.0),
        ] {
            let mut s = spec(30.0, 22);
            s.spacing_c = c;
            s.size_disorder = rd;
            let disks = pile(&s, 0, &mut Rng::new(3));
            let (min, support) = gaps(&disks);
            assert!(min > -1e-12, "c = {c}, r_d = {rd}: overlap {min}");
            assert!(
                support < 1e-12,
                "c = {c}, r_d = {rd}: a disk floats {support} above its support"
            );
            // The squeezed mobile rows keep the spacing d0; the bottom keeps d0 (1 + c).
            assert!((disks[1].position[0] - disks[0].position[0] - (1.0 + c)).abs() < 1e-12);
            if rd == 0.0 {
                let row1 = &disks[22..22 + 19];
                let spacing = row1[1].position[0] - row1[0].position[0];
                assert!(
                    (spacing - (1.0 + c).max(1.0)).abs() < 1e-12,
                    "row 1 spacing {spacing}"
                );
            }
        }
    }
}
