//! The cell list (counting sort) finds exactly the brute-force contacts (SPEC 3).

use talus::cell_list::{CellList, Grid};
use talus::contacts::{brute_force_contacts, find_contacts};
use talus::geometry::WallSegment;
use talus::rng::Rng;
use talus::state::{NewDisk, Particles};

/// A random polydisperse packing: `n` disks with diameters in [0.5, 1.5] in a 30 × 20 box,
/// dense enough that many pairs touch; a few fixed and a few inactive.
fn packing(seed: u64, n: usize) -> Particles {
    let mut rng = Rng::new(seed);
    let mut p = Particles::default();
    for k in 0..n {
        let d = NewDisk {
            position: [rng.range(0.0, 30.0), rng.range(0.0, 20.0)],
            theta: 0.0,
            velocity: [0.0; 2],
            omega: 0.0,
            radius: 0.5 * rng.range(0.5, 1.5),
            fixed: k % 17 == 0,
            fixed_rotation: false,
            material: 0,
        };
        p.push_disk(&d, 1.0, 1.0, 1e-3);
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
        let p = packing(seed, 300 + 37 * seed as usize);
        for range in [1.0, 1.2] {
            // Cells at the minimum size and larger ones: the result must not depend on it.
            for cell in [range * 1.5, range * 2.7] {
                let grid = Grid::new([0.0, 30.0], [0.0, 20.0], cell);
                let mut cells = CellList::default();
                cells.build(&grid, &p.q[0], &p.active);
                let mut found = Vec::new();
                find_contacts(&grid, &cells, &p, &walls, range, &mut found);
                let expected = brute_force_contacts(&p, &walls, range);
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
