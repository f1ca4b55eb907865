//! Contact detection: candidate pairs from the cell list, kept when they interact.
//!
//! For each active particle i (in id order) the 3×3 block of cells around it is scanned
//! and every j > i within the law's range becomes a contact, followed by i's wall
//! contacts. The list is therefore ordered by i, which fixes the order of every later sum.
//! Pairs of two fixed particles are skipped: neither moves. Polygons are first screened by
//! their circumscribed circles, then kept when their outlines overlap.

use crate::base::geometry::{WallSegment, disk_disk, disk_wall, wall_from};
use crate::cpu::cell_list::{CellList, Grid};
use crate::cpu::orientation::RotatedCorners;
use crate::overlap::{overlap_area, polygon_disk, polygon_wall};
use crate::state::Particles;
use crate::state::offset;

/// Ids at and above this refer to walls: `WALL_BASE + wall index`.
pub const WALL_BASE: u32 = 0xFFFF_0000;

/// A contact between particle `i` and particle (or wall) `j`, with i < j.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pair {
    pub i: u32,
    pub j: u32,
}

impl Pair {
    pub fn is_wall(&self) -> bool {
        self.j >= WALL_BASE
    }
}

/// The broad test of a pair: whether the circumscribed circles are within the law's
/// range (`range_factor` · σ; a wall: within `range_factor` · r of it). A NaN distance
/// (a diverged state) is not.
pub fn circles_touch(
    particles: &Particles,
    walls: &[WallSegment],
    range_factor: f64,
    pair: Pair,
) -> bool {
    let i = pair.i as usize;
    if pair.is_wall() {
        let wall = &walls[(pair.j - WALL_BASE) as usize];
        let g = disk_wall(particles.radius[i], &wall_from(wall, particles.position(i)));
        return !g.r.is_nan() && g.r < range_factor * g.sigma;
    }
    // |d| < range (r_i + r_j), squared: no square root (a NaN compares false).
    let j = pair.j as usize;
    let d = offset(particles, i, j);
    let reach = range_factor * (particles.radius[i] + particles.radius[j]);
    d[0] * d[0] + d[1] * d[1] < reach * reach
}

/// Whether particles i and j interact: disks within `range_factor` · σ, polygons whose
/// circumscribed circles overlap and whose outlines intersect (SPEC 2.3). Like the
/// forces, computed from the offset of the pair only.
pub fn interacts(
    particles: &Particles,
    corners: &RotatedCorners,
    range_factor: f64,
    i: usize,
    j: usize,
) -> bool {
    let d = offset(particles, i, j);
    let (ri, rj) = (particles.radius[i], particles.radius[j]);
    let g = disk_disk(d, ri, rj);
    // A NaN distance (a diverged state) interacts with nothing.
    if g.r.is_nan() || g.r >= range_factor * g.sigma {
        return false;
    }
    match (particles.is_polygon(i), particles.is_polygon(j)) {
        (true, true) => overlap_area(corners.of(i), corners.of(j), d) > 0.0,
        (true, false) => polygon_disk(corners.of(i), d, rj, true).is_some(),
        (false, true) => polygon_disk(corners.of(j), [-d[0], -d[1]], ri, false).is_some(),
        (false, false) => true,
    }
}

/// Whether particle i touches wall w.
pub fn touches_wall(
    particles: &Particles,
    corners: &RotatedCorners,
    range_factor: f64,
    i: usize,
    wall: &WallSegment,
) -> bool {
    let w = wall_from(wall, particles.position(i));
    let g = disk_wall(particles.radius[i], &w);
    // A NaN distance (a diverged state) interacts with nothing.
    if g.r.is_nan() || g.r >= range_factor * g.sigma {
        return false;
    }
    if particles.is_polygon(i) {
        return polygon_wall(corners.of(i), &w).is_some();
    }
    true
}

/// Finds all interacting pairs. `range_factor` scales σ = r_i + r_j to the interaction
/// distance (1 for the spring-dashpot law, r0 for the continuous one).
pub fn find_contacts(
    grid: &Grid,
    cells: &CellList,
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    range_factor: f64,
    out: &mut Vec<Pair>,
) {
    out.clear();
    let pos = &particles.q[0];
    for i in 0..particles.len() {
        if !particles.active[i] {
            continue;
        }
        let pi = [pos[i][0], pos[i][1]];
        let (cx, cz) = grid.cell_coords(pi);
        let first = out.len();
        for z in cz.saturating_sub(1)..=(cz + 1).min(grid.nz - 1) {
            for x in cx.saturating_sub(1)..=(cx + 1).min(grid.nx - 1) {
                for &j in cells.cell(grid, x, z) {
                    let ju = j as usize;
                    if ju <= i || (particles.fixed[i] && particles.fixed[ju]) {
                        continue;
                    }
                    if interacts(particles, corners, range_factor, i, ju) {
                        out.push(Pair { i: i as u32, j });
                    }
                }
            }
        }
        // Neighbour cells are visited in grid order; sort i's pairs by j so the contact
        // order does not depend on the cell layout.
        out[first..].sort_unstable();
        if particles.fixed[i] {
            continue;
        }
        for (w, wall) in walls.iter().enumerate() {
            if touches_wall(particles, corners, range_factor, i, wall) {
                out.push(Pair {
                    i: i as u32,
                    j: WALL_BASE + w as u32,
                });
            }
        }
    }
}

/// Reference O(N²) search used by tests to check `find_contacts`.
pub fn brute_force_contacts(
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    range_factor: f64,
) -> Vec<Pair> {
    let mut out = Vec::new();
    for i in 0..particles.len() {
        if !particles.active[i] {
            continue;
        }
        for j in i + 1..particles.len() {
            if !particles.active[j] || (particles.fixed[i] && particles.fixed[j]) {
                continue;
            }
            if interacts(particles, corners, range_factor, i, j) {
                out.push(Pair {
                    i: i as u32,
                    j: j as u32,
                });
            }
        }
        if particles.fixed[i] {
            continue;
        }
        for (w, wall) in walls.iter().enumerate() {
            if touches_wall(particles, corners, range_factor, i, wall) {
                out.push(Pair {
                    i: i as u32,
                    j: WALL_BASE + w as u32,
                });
            }
        }
    }
    out
}
