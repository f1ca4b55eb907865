//! Neighbour (Verlet) lists with a skin (issue 13): the candidate pairs of every particle
//! within the law's range plus a skin, listed at a rebuild; between rebuilds each step
//! evaluates only these candidates, and each candidate's slot carries its tangential
//! history.
//!
//! A pair is a candidate when its centres are closer than range_factor (r_i + r_j) + skin
//! (a wall: when the distance to it is below range_factor r_i + skin). Contacts are
//! decided by the circumscribed circles first (SPEC 2.3), which no rotation changes, so
//! as long as no particle has moved by more than skin/2 since the rebuild, every pair
//! that can touch is a candidate: the list is rebuilt as soon as one has (and whenever a
//! particle was inserted or removed). The candidates of particle i come in contact order
//! (partners j > i ascending, then walls), so the contacts found among them, in list
//! order, are exactly those `contacts::find_contacts` finds, in its order: results do not
//! depend on the skin or on when the list was rebuilt.
//!
//! History: a candidate's slot holds its spring after the last completed step (0 when
//! not in contact). At a rebuild each new slot takes the value of the same pair's old
//! slot (both lists are sorted by pair: one merge, no hashing), a new pair starts at 0.
//! A list built for the first time takes the values from the spring table the state was
//! created with (a checkpoint's).

use crate::cell_list::Grid;
use crate::contacts::{Pair, WALL_BASE};
use crate::geometry::{WallSegment, disk_wall, wall_from};
use crate::springs::{SpringTable, pair_key};
use crate::state::{Dof, Particles};

/// The default skin, as a fraction of the largest diameter.
pub const DEFAULT_SKIN: f64 = 0.3;

#[derive(Clone, Debug, Default)]
pub struct NeighbourList {
    /// Candidate pairs, sorted by (i, j); walls are j = WALL_BASE + w, after particles.
    pub pairs: Vec<Pair>,
    /// Particle i's candidates (as the lower id) are `pairs[start[i]..start[i + 1]]`.
    pub start: Vec<u32>,
    /// Particle j's candidates as the higher id are the indices
    /// `down[down_start[j]..down_start[j + 1]]` into `pairs`, in increasing i.
    pub down_start: Vec<u32>,
    pub down: Vec<u32>,
    /// Each candidate's tangential history after the last completed step (0: no contact).
    pub history: Vec<f64>,
    /// Positions at the last rebuild, and which particles were active then.
    at: Vec<Dof>,
    active: Vec<bool>,
    /// The grid of the rebuilds: cells of at least range + skin, and the active
    /// particles sorted by cell (a sparse cell list: memory and time O(N), whatever the
    /// domain's area).
    grid: Option<Grid>,
    cells: Vec<(u64, u32)>,
    /// The skin of the last rebuild.
    pub skin: f64,
    /// How many times the list was built.
    pub rebuilds: u64,
}

impl NeighbourList {
    pub fn is_built(&self) -> bool {
        self.grid.is_some()
    }

    /// Whether the list must be rebuilt before evaluating `particles`: never built, a
    /// particle inserted or removed, or one moved by more than skin/2 since the rebuild.
    pub fn needs_rebuild(&self, particles: &Particles) -> bool {
        self.stale(particles)
            || crate::parallel::position_first(particles.len(), |i| self.moved(particles, i))
                .is_some()
    }

    /// Whether the list must be rebuilt whatever the particles' motion: never built, no
    /// skin, or particles inserted since.
    pub fn stale(&self, particles: &Particles) -> bool {
        !self.is_built() || self.skin <= 0.0 || particles.len() != self.at.len()
    }

    /// Whether particle i (of a list that is not `stale`) was removed, or moved by more
    /// than skin/2, since the rebuild. A position that is not finite has "moved".
    #[inline]
    pub fn moved(&self, particles: &Particles, i: usize) -> bool {
        self.moved_to(i, particles.q[0][i], particles.active[i])
    }

    /// `moved` for particle i now at `position`, active or not.
    #[inline]
    pub fn moved_to(&self, i: usize, position: Dof, active: bool) -> bool {
        let (a, b) = (position, self.at[i]);
        let d2 = (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
        active != self.active[i] || d2.is_nan() || d2 > 0.25 * self.skin * self.skin
    }

    /// Lists the candidates of the current state and carries the history over: from
    /// the old list's slots, or, the first time, from `table`.
    #[allow(clippy::too_many_arguments)]
    pub fn rebuild(
        &mut self,
        domain: ([f64; 2], [f64; 2]),
        particles: &Particles,
        walls: &[WallSegment],
        range_factor: f64,
        max_diameter: f64,
        skin: f64,
        table: &SpringTable,
    ) {
        let reach = range_factor * max_diameter + skin;
        let grid = match &self.grid {
            Some(g) if g.cell_size >= reach => g.clone(),
            _ => Grid::new(domain.0, domain.1, reach),
        };
        sort_by_cell(&grid, particles, &mut self.cells);
        let mut pairs = Vec::with_capacity(self.pairs.len().max(4 * particles.len()));
        let mut start = Vec::with_capacity(particles.len() + 1);
        list_candidates(
            &grid,
            &self.cells,
            particles,
            walls,
            range_factor,
            skin,
            &mut pairs,
            &mut start,
        );
        let history = if self.is_built() {
            carry_over(&self.pairs, &self.history, &pairs)
        } else {
            pairs
                .iter()
                .map(|&p| table.lookup(pair_key(p)).unwrap_or(0.0))
                .collect()
        };
        self.down_start.clear();
        self.down.clear();
        down_lists(
            &pairs,
            particles.len(),
            &mut self.down_start,
            &mut self.down,
        );
        self.pairs = pairs;
        self.start = start;
        self.history = history;
        self.at.clone_from(&particles.q[0]);
        self.active.clone_from(&particles.active);
        self.grid = Some(grid);
        self.skin = skin;
        self.rebuilds += 1;
    }

    /// The spring table of the last completed step: every candidate in contact then
    /// (`in_contact`) with its history, inserted in list order (as `store_history`
    /// built it).
    pub fn table(&self, in_contact: &[bool]) -> SpringTable {
        let n = in_contact.iter().filter(|&&c| c).count();
        let mut t = SpringTable::with_capacity_for(n);
        for ((p, h), &c) in self.pairs.iter().zip(&self.history).zip(in_contact) {
            if c {
                t.insert(pair_key(*p), *h);
            }
        }
        t
    }
}

/// A cell's key: its row, then its column (u64: a domain 10⁵ diameters square has 10¹⁰
/// cells).
fn cell_key(grid: &Grid, x: u32, z: u32) -> u64 {
    z as u64 * grid.nx as u64 + x as u64
}

/// Every active particle as (cell key, id), sorted: by cell, and by id within a cell.
fn sort_by_cell(grid: &Grid, particles: &Particles, out: &mut Vec<(u64, u32)>) {
    let q = &particles.q[0];
    out.clear();
    out.extend(
        crate::parallel::map(particles.len(), |i| {
            let (x, z) = grid.cell_coords([q[i][0], q[i][1]]);
            (cell_key(grid, x, z), i as u32)
        })
        .into_iter()
        .filter(|&(_, i)| particles.active[i as usize]),
    );
    crate::parallel::sort_unstable(out);
}

/// The particles of the cells x0..=x1 of row z: one run of the sorted list.
fn row_of_cells<'a>(
    grid: &Grid,
    cells: &'a [(u64, u32)],
    x0: u32,
    x1: u32,
    z: u32,
) -> &'a [(u64, u32)] {
    let (lo, hi) = (cell_key(grid, x0, z), cell_key(grid, x1, z));
    let a = cells.partition_point(|c| c.0 < lo);
    let b = a + cells[a..].partition_point(|c| c.0 <= hi);
    &cells[a..b]
}

/// The candidates of every active particle, in contact order, and where each particle's
/// start (each particle's found on its own, on every thread).
#[allow(clippy::too_many_arguments)]
fn list_candidates(
    grid: &Grid,
    cells: &[(u64, u32)],
    particles: &Particles,
    walls: &[WallSegment],
    range_factor: f64,
    skin: f64,
    out: &mut Vec<Pair>,
    start: &mut Vec<u32>,
) {
    let lists = crate::parallel::map(particles.len(), |i| {
        let mut v = Vec::new();
        candidates_of(grid, cells, particles, walls, range_factor, skin, i, &mut v);
        v
    });
    for v in lists {
        start.push(out.len() as u32);
        out.extend(v);
    }
    start.push(out.len() as u32);
}

/// Particle i's candidates in contact order: partners j > i within range + skin by
/// increasing j, then the walls. A pair of two fixed particles is never a candidate
/// (neither moves); an inactive particle has none.
#[allow(clippy::too_many_arguments)]
fn candidates_of(
    grid: &Grid,
    cells: &[(u64, u32)],
    particles: &Particles,
    walls: &[WallSegment],
    range_factor: f64,
    skin: f64,
    i: usize,
    out: &mut Vec<Pair>,
) {
    if !particles.active[i] {
        return;
    }
    let pos = &particles.q[0];
    let pi = [pos[i][0], pos[i][1]];
    let (cx, cz) = grid.cell_coords(pi);
    let (x0, x1) = (cx.saturating_sub(1), (cx + 1).min(grid.nx - 1));
    for z in cz.saturating_sub(1)..=(cz + 1).min(grid.nz - 1) {
        // The three cells x0..=x1 of a row are one run of the sorted list.
        for &(_, j) in row_of_cells(grid, cells, x0, x1, z) {
            let ju = j as usize;
            if ju <= i || (particles.fixed[i] && particles.fixed[ju]) {
                continue;
            }
            let (dx, dz) = (pos[ju][0] - pi[0], pos[ju][1] - pi[1]);
            let reach = range_factor * (particles.radius[i] + particles.radius[ju]) + skin;
            // A NaN distance (a diverged state) is no candidate.
            if dx * dx + dz * dz < reach * reach {
                out.push(Pair { i: i as u32, j });
            }
        }
    }
    out.sort_unstable();
    if particles.fixed[i] {
        return;
    }
    for (w, wall) in walls.iter().enumerate() {
        let g = disk_wall(particles.radius[i], &wall_from(wall, pi));
        if 0.5 * g.r < range_factor * particles.radius[i] + skin {
            out.push(Pair {
                i: i as u32,
                j: WALL_BASE + w as u32,
            });
        }
    }
}

/// Each new candidate's history from the old list: both are sorted by pair, so one
/// merge finds every pair that stays a candidate; a new pair starts at 0.
fn carry_over(old: &[Pair], values: &[f64], new: &[Pair]) -> Vec<f64> {
    let mut out = Vec::with_capacity(new.len());
    let mut k = 0;
    for p in new {
        while k < old.len() && old[k] < *p {
            k += 1;
        }
        out.push(if k < old.len() && old[k] == *p {
            values[k]
        } else {
            0.0
        });
    }
    out
}

/// For each particle the candidates in which it is the higher id (j), by increasing i:
/// a counting sort of the candidate indices by j, stable in list order.
fn down_lists(pairs: &[Pair], n: usize, start: &mut Vec<u32>, down: &mut Vec<u32>) {
    start.resize(n + 1, 0);
    for p in pairs.iter().filter(|p| !p.is_wall()) {
        start[p.j as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    down.resize(start[n] as usize, 0);
    let mut next = start[..n].to_vec();
    for (k, p) in pairs.iter().enumerate() {
        if !p.is_wall() {
            let slot = &mut next[p.j as usize];
            down[*slot as usize] = k as u32;
            *slot += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(i: u32, j: u32) -> Pair {
        Pair { i, j }
    }

    #[test]
    fn history_moves_with_its_pair_and_new_pairs_start_at_zero() {
        let old = [pair(0, 1), pair(0, 3), pair(1, 2), pair(2, WALL_BASE)];
        let values = [1.0, 2.0, 3.0, 4.0];
        let new = [
            pair(0, 3),
            pair(0, 4),
            pair(1, 2),
            pair(2, 3),
            pair(2, WALL_BASE),
        ];
        assert_eq!(
            carry_over(&old, &values, &new),
            vec![2.0, 0.0, 3.0, 0.0, 4.0]
        );
    }

    #[test]
    fn down_lists_hold_each_higher_id_in_increasing_lower_id() {
        let pairs = [
            pair(0, 2),
            pair(0, 3),
            pair(1, 2),
            pair(1, WALL_BASE),
            pair(2, 3),
        ];
        let (mut start, mut down) = (Vec::new(), Vec::new());
        down_lists(&pairs, 4, &mut start, &mut down);
        assert_eq!(start, vec![0, 0, 0, 2, 4]);
        assert_eq!(down, vec![0, 2, 1, 4]);
    }
}
