//! The cell list (counting sort) finds exactly the brute-force contacts (SPEC 3), and
//! so do the neighbour lists with a skin between their rebuilds (issue 13).

use talus::base::geometry::WallSegment;
use talus::base::rng::Rng;
use talus::cpu::cell_list::{CellList, Grid};
use talus::cpu::contacts::{brute_force_contacts, find_contacts, interacts, touches_wall};
use talus::cpu::neighbours::NeighbourList;
use talus::cpu::orientation::{RotatedCorners, rotate_corners};
use talus::shape::{circumradius, ellipse_polygon};
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
            sweep: 0.0,
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

/// The contacts among a neighbour list's candidates, as `find_contacts` tests them.
fn listed_contacts(
    list: &NeighbourList,
    p: &Particles,
    shapes: &RotatedCorners,
    walls: &[WallSegment],
    range: f64,
) -> Vec<talus::cpu::contacts::Pair> {
    list.pairs
        .iter()
        .copied()
        .filter(|q| {
            if q.is_wall() {
                let w = &walls[(q.j - talus::cpu::contacts::WALL_BASE) as usize];
                touches_wall(p, shapes, range, q.i as usize, w)
            } else {
                interacts(p, shapes, range, q.i as usize, q.j as usize)
            }
        })
        .collect()
}

#[test]
fn neighbour_lists_hold_every_contact_until_a_particle_moves_half_the_skin() {
    // Issue 13: the candidates listed at a rebuild contain every contact (in the order
    // find_contacts gives) as long as no particle has moved by more than skin/2; then
    // `needs_rebuild` says so. Random packings of disks and polygons, moved at random
    // by up to just below skin/2 (and once by more).
    let walls = [WallSegment {
        a: [0.0, 0.3],
        b: [30.0, 0.3],
    }];
    let mut rng = Rng::new(13);
    let (mut checked, mut moved_contacts) = (0, 0);
    for seed in 0..12 {
        let polygons = seed % 2 == 1;
        let mut p = packing(100 + seed, 400, polygons);
        let range = if polygons || seed % 4 == 0 { 1.0 } else { 1.2 };
        let skin = [0.0, 0.1, 0.3, 0.6][(seed % 4) as usize];
        let mut shapes = RotatedCorners::default();
        rotate_corners(&p, &mut shapes);
        let mut list = NeighbourList::default();
        let table = talus::cpu::springs::SpringTable::default();
        let max_d = 2.0 * p.max_radius();
        let ids: Vec<u32> = (0..p.len() as u32).collect();
        list.rebuild(
            ([0.0, 30.0], [0.0, 20.0]),
            &p,
            &ids,
            &walls,
            range,
            max_d,
            skin,
            &table,
        );
        assert_eq!(
            listed_contacts(&list, &p, &shapes, &walls, range),
            brute_force_contacts(&p, &shapes, &walls, range),
            "seed {seed}: at the rebuild"
        );
        if skin == 0.0 {
            assert!(list.needs_rebuild(&p), "skin 0 rebuilds every step");
            continue;
        }
        assert!(!list.needs_rebuild(&p));
        // Each particle moves by just under skin/2 in a random direction and turns.
        let at_rebuild = p.q[0][7];
        for k in 0..p.len() {
            let a = rng.range(0.0, std::f64::consts::TAU);
            let r = 0.4999 * skin * rng.uniform().sqrt();
            p.q[0][k][0] += r * a.cos();
            p.q[0][k][1] += r * a.sin();
            p.q[0][k][2] += rng.range(-1.0, 1.0);
        }
        rotate_corners(&p, &mut shapes);
        assert!(
            !list.needs_rebuild(&p),
            "seed {seed}: moved less than skin/2"
        );
        let expected = brute_force_contacts(&p, &shapes, &walls, range);
        assert_eq!(
            listed_contacts(&list, &p, &shapes, &walls, range),
            expected,
            "seed {seed}: after moving"
        );
        checked += 1;
        moved_contacts += expected.len();
        // One particle a little farther: the list must be rebuilt.
        p.q[0][7] = [at_rebuild[0] + 0.501 * skin, at_rebuild[1], at_rebuild[2]];
        assert!(
            list.needs_rebuild(&p),
            "seed {seed}: moved more than skin/2"
        );
    }
    assert!(
        checked >= 6 && moved_contacts > 2000,
        "{checked} packings, {moved_contacts} contacts"
    );
}

#[test]
fn neighbour_lists_in_any_memory_order_hold_the_same_pairs_in_the_same_order() {
    // Issue 13 item 4: particles held in another memory order (`ids`: each slot's id)
    // give the same candidates, by id, each particle's in the same order (by partner
    // id, walls last), and down lists by increasing partner id: what fixes the order of
    // every force sum.
    let walls = [WallSegment {
        a: [0.0, 0.3],
        b: [30.0, 0.3],
    }];
    let mut rng = Rng::new(4);
    let mut compared = 0;
    for seed in 0..6 {
        let polygons = seed % 2 == 1;
        let p = packing(200 + seed, 400, polygons);
        let table = talus::cpu::springs::SpringTable::default();
        let domain = ([0.0, 30.0], [0.0, 20.0]);
        let build = |p: &Particles, ids: &[u32]| {
            let mut list = NeighbourList::default();
            list.rebuild(
                domain,
                p,
                ids,
                &walls,
                1.0,
                2.0 * p.max_radius(),
                0.3,
                &table,
            );
            list
        };
        let identity: Vec<u32> = (0..p.len() as u32).collect();
        let plain = build(&p, &identity);
        // A random memory order: order[new] = old slot (= id here).
        let mut order = identity.clone();
        for k in (1..order.len()).rev() {
            order.swap(k, (rng.uniform() * (k + 1) as f64) as usize % (k + 1));
        }
        let mut shuffled = p.clone();
        shuffled.permute(&order);
        let list = build(&shuffled, &order);
        for id in 0..p.len() {
            let slot = order.iter().position(|&o| o as usize == id).unwrap();
            let mine =
                |l: &NeighbourList, s: usize, ids: &[u32]| -> Vec<talus::cpu::contacts::Pair> {
                    l.pairs[l.start[s] as usize..l.start[s + 1] as usize]
                        .iter()
                        .map(|&q| talus::cpu::neighbours::id_pair(q, ids))
                        .collect()
                };
            assert_eq!(
                mine(&list, slot, &order),
                mine(&plain, id, &identity),
                "seed {seed}, id {id}"
            );
            let down: Vec<u32> = list.down
                [list.down_start[slot] as usize..list.down_start[slot + 1] as usize]
                .iter()
                .map(|&k| order[list.pairs[k as usize].i as usize])
                .collect();
            let plain_down: Vec<u32> = plain.down
                [plain.down_start[id] as usize..plain.down_start[id + 1] as usize]
                .iter()
                .map(|&k| plain.pairs[k as usize].i)
                .collect();
            assert_eq!(down, plain_down, "seed {seed}, id {id}: down list");
            compared += plain_down.len();
        }
    }
    assert!(compared > 3000, "{compared} pairs compared");
}
