//! The cell list (counting sort) finds exactly the brute-force contacts (SPEC 3).

use talus::cell_list::{CellList, Grid};
use talus::contacts::{brute_force_contacts, find_contacts};
use talus::geometry::WallSegment;
use talus::rng::Rng;
use talus::shape::{RotatedCorners, circumradius, ellipse_polygon, rotate_corners};
use talus::state::{NewParticle, Particles};

/// A random polydisperse packing: `n` disks (or polygons of 3 to 8 corners on ellipses)
/// with sizes in [0.5, 1.5] in a 30 × 20 box,
/// dense enough that many pairs touch; a few fixed and a few inactive.
fn packing(seed: u64, n: usize, polygons: bool) -> Particles {
    let mut rng = Rng::new(seed);
    let mut p = Particles::default();
    for k in 0..n {
        let position = [rng.range(0.0, 30.0), rng.range(0.0, 20.0)];
        let size = rng.range(0.5, 1.5);
        let (radius, corners) = if polygons {
            let c = 3 + (k % 6) as u32;
            let v = ellipse_polygon(c, size, size * rng.range(0.6, 1.0), rng.range(0.0, 1.0));
            (circumradius(&v), v)
        } else {
            (0.5 * size, Vec::new())
        };
        let d = NewParticle {
            position,
            theta: rng.range(0.0, 6.3),
            velocity: [0.0; 2],
            omega: 0.0,
            radius,
            fixed: k % 17 == 0,
            fixed_rotation: false,
            material: 0,
            corners,
        };
        p.push_particle(&d, 1.0, 1.0, 1e-3);
    }
    for k in (0..n).step_by(23) {
        p.active[k] = false;
    }
    p
}

#[test]
fn cell_list_contacts_equal_brute_force() {
    let walls = [
        WallSegment {
            a: [0.0, 0.3],
            b: [30.0, 0.3],
        },
        WallSegment {
            a: [0.2, 0.0],
            b: [0.2, 20.0],
        },
    ];
    let mut total = 0;
    for seed in 0..20 {
        let polygons = seed % 2 == 1;
        let p = packing(seed, 300 + 37 * seed as usize, polygons);
        let mut shapes = RotatedCorners::default();
        rotate_corners(&p, &mut shapes);
        let ranges: &[f64] = if polygons { &[1.0] } else { &[1.0, 1.2] };
        for &range in ranges {
            // Cells at the minimum size and larger ones: the result must not depend on it.
            let min_cell = range * 2.0 * p.max_radius();
            for cell in [min_cell, range * 2.7] {
                let grid = Grid::new([0.0, 30.0], [0.0, 20.0], cell);
                let mut cells = CellList::default();
                cells.build(&grid, &p.q[0], &p.active);
                let mut found = Vec::new();
                find_contacts(&grid, &cells, &p, &shapes, &walls, range, &mut found);
                let expected = brute_force_contacts(&p, &shapes, &walls, range);
                assert_eq!(found, expected, "seed {seed}, range {range}, cell {cell}");
                total += found.len();
            }
        }
    }
    assert!(
        total > 10_000,
        "the packings must be dense enough to test anything ({total})"
    );
}
