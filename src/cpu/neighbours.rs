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
//!
//! Memory order (issue 13 item 4): the particle arrays may be held in an order other
//! than the ids' (`Simulation::advance` sorts them by cell at every rebuild, for
//! locality). The list then works on memory slots, and `ids` gives each slot's particle
//! id; everything that fixes an order goes by id: a pair's lower id is its i, a
//! particle's candidates come by increasing partner id, the down lists by increasing
//! partner id, the spring table is keyed by ids. Only the order of the particles' groups
//! in `pairs` follows memory, and no sum depends on it, so results are bitwise the same
//! in any memory order.

use crate::base::geometry::{WallSegment, disk_wall, wall_from};
use crate::cpu::cell_list::Grid;
use crate::cpu::contacts::{Pair, WALL_BASE};
use crate::cpu::springs::{SpringTable, pair_key};
use crate::overlap::Hint;
use crate::state::{Dof, Particles, gather};
use std::sync::atomic::{AtomicU32, Ordering};

pub use crate::scene::DEFAULT_SKIN;

#[derive(Clone, Debug, Default)]
pub struct NeighbourList {
    /// Candidate pairs of memory slots, grouped by i (the lower id) in slot order, each
    /// group by increasing partner id; walls are j = WALL_BASE + w, after particles.
    pub pairs: Vec<Pair>,
    /// Slot i's candidates (as the lower id) are `pairs[start[i]..start[i + 1]]`.
    pub start: Vec<u32>,
    /// Slot j's candidates as the higher id are the indices
    /// `down[down_start[j]..down_start[j + 1]]` into `pairs`, by increasing partner id.
    pub down_start: Vec<u32>,
    pub down: Vec<u32>,
    /// Each candidate's tangential history after the last completed step (0: no contact).
    pub history: Vec<f64>,
    /// Spheropolygon scenes (law hertz_cohesive): each candidate's sub-contact springs,
    /// moved with the slots like `history` (empty under the other laws).
    pub sub_history: Vec<crate::cpu::springs::SubSprings>,
    /// Each candidate's hint of what its last evaluation found (polygon pairs,
    /// `overlap::Hint`): it decides only how much work the next evaluation takes, never
    /// its result, so it is not part of the state (no checkpoint keeps it). Moved with
    /// the slots like `history`; updated in place by the evaluation, each slot by its
    /// own candidate.
    pub hints: Hints,
    /// Positions at the last rebuild, and which particles were active then.
    at: Vec<Dof>,
    active: Vec<bool>,
    /// The grid of the rebuilds: cells of at least range + skin, and the active
    /// particles sorted by cell (a sparse cell list: memory and time O(N), whatever the
    /// domain's area).
    grid: Option<Grid>,
    cells: Vec<Cell>,
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
            || crate::base::parallel::position_first(particles.len(), |i| self.moved(particles, i))
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

    /// The grid of a rebuild for candidates within `reach`: the last one while its
    /// cells are wide enough. `period`: the domain's period in x (0: none).
    pub fn grid_for(&self, domain: ([f64; 2], [f64; 2]), reach: f64, period: f64) -> Grid {
        match &self.grid {
            Some(g) if g.cell_size >= reach => g.clone(),
            _ if period > 0.0 => Grid::periodic(domain.0, domain.1, reach),
            _ => Grid::new(domain.0, domain.1, reach),
        }
    }

    /// Lists the candidates of the current state and carries the history over: from
    /// the old list's slots, or, the first time, from `table`. `ids`: each memory
    /// slot's particle id.
    #[allow(clippy::too_many_arguments)]
    pub fn rebuild(
        &mut self,
        domain: ([f64; 2], [f64; 2]),
        particles: &Particles,
        ids: &[u32],
        walls: &[WallSegment],
        range_factor: f64,
        max_diameter: f64,
        skin: f64,
        table: &SpringTable,
    ) {
        let reach = range_factor * max_diameter + skin;
        let grid = self.grid_for(domain, reach, particles.period_x);
        sort_by_cell(&grid, particles, ids, &mut self.cells);
        let mut pairs = Vec::with_capacity(self.pairs.len().max(4 * particles.len()));
        let mut start = Vec::with_capacity(particles.len() + 1);
        let s = Search {
            grid: &grid,
            cells: &self.cells,
            particles,
            ids,
            walls,
            range_factor,
            skin,
        };
        list_candidates(&s, &mut pairs, &mut start);
        if self.is_built() && self.sub_history.len() == self.pairs.len() {
            let origin = origins(&self.pairs, &pairs, ids);
            let old = std::mem::take(&mut self.sub_history);
            self.sub_history = (origin.iter())
                .map(|o| o.map_or_else(Default::default, |k| old[k]))
                .collect();
        } else if !self.is_built() && !table.sub.is_empty() {
            // The first list of a state with sub-contact springs (a checkpoint's).
            self.sub_history = (pairs.iter())
                .map(|&p| {
                    table
                        .sub
                        .get(&pair_key(id_pair(p, ids)))
                        .copied()
                        .unwrap_or_default()
                })
                .collect();
        } else {
            // No spheropolygon springs to carry: they start afresh.
            self.sub_history.clear();
        }
        let history = if self.is_built() {
            let origin = origins(&self.pairs, &pairs, ids);
            self.hints = Hints(
                (origin.iter())
                    .map(|o| AtomicU32::new(o.map_or(0, |k| self.hints.get(k).0)))
                    .collect(),
            );
            carry_over(&origin, &self.history)
        } else {
            self.hints = Hints::none(pairs.len());
            pairs
                .iter()
                .map(|&p| table.lookup(pair_key(id_pair(p, ids))).unwrap_or(0.0))
                .collect()
        };
        down_lists(&pairs, &start, ids, &mut self.down_start, &mut self.down);
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
    /// (`in_contact`) with its history, keyed by ids, inserted in list order (as
    /// `store_history` built it).
    pub fn table(&self, in_contact: &[bool], ids: &[u32]) -> SpringTable {
        let n = in_contact.iter().filter(|&&c| c).count();
        let mut t = SpringTable::with_capacity_for(n);
        for ((p, h), &c) in self.pairs.iter().zip(&self.history).zip(in_contact) {
            if c {
                t.insert(pair_key(id_pair(*p, ids)), *h);
            }
        }
        if self.sub_history.len() == self.pairs.len() {
            for (p, s) in self.pairs.iter().zip(&self.sub_history) {
                if s.count > 0 {
                    t.sub.insert(pair_key(id_pair(*p, ids)), *s);
                }
            }
        }
        t
    }

    /// Moves the list with its particles to a new memory order: `order[new] = old` slot,
    /// `inverse[old] = new`, and `ids` the slots' ids in the new order. Each group keeps
    /// its candidates (and their order, which goes by id); the groups follow their
    /// particles. Returns, for each new candidate index, its old index, for the arrays
    /// kept per candidate elsewhere. Particles inserted since the rebuild have no
    /// candidates yet (the list is stale and is rebuilt before use).
    pub fn permute(&mut self, order: &[u32], inverse: &[u32], ids: &[u32]) -> Vec<u32> {
        if !self.is_built() {
            return Vec::new();
        }
        let mut from = Vec::with_capacity(self.pairs.len());
        let mut pairs = Vec::with_capacity(self.pairs.len());
        let mut start = Vec::with_capacity(order.len() + 1);
        let listed = self.start.len() - 1;
        for (new, &old) in order.iter().enumerate() {
            start.push(pairs.len() as u32);
            let old = old as usize;
            if old >= listed {
                continue;
            }
            for k in self.start[old]..self.start[old + 1] {
                let p = self.pairs[k as usize];
                let j = if p.is_wall() {
                    p.j
                } else {
                    inverse[p.j as usize]
                };
                pairs.push(Pair { i: new as u32, j });
                from.push(k);
            }
        }
        start.push(pairs.len() as u32);
        self.history = gather(&self.history, &from);
        self.hints = Hints(
            (from.iter())
                .map(|&k| AtomicU32::new(self.hints.get(k as usize).0))
                .collect(),
        );
        if self.sub_history.len() == self.pairs.len() {
            self.sub_history = gather(&self.sub_history, &from);
        }
        down_lists(&pairs, &start, ids, &mut self.down_start, &mut self.down);
        self.pairs = pairs;
        self.start = start;
        if self.at.len() == order.len() {
            self.at = gather(&self.at, order);
            self.active = gather(&self.active, order);
        } else {
            // Stale (`stale` stays true): the next use rebuilds.
            self.at.clear();
            self.active.clear();
        }
        from
    }
}

/// The candidates' hints (`NeighbourList::hints`): one word each, which the evaluation
/// of candidate k reads and rewrites through a shared list (no other candidate touches
/// slot k, so the order of the threads changes nothing).
#[derive(Debug, Default)]
pub struct Hints(Vec<AtomicU32>);

impl Hints {
    fn none(n: usize) -> Self {
        Self((0..n).map(|_| AtomicU32::new(0)).collect())
    }

    /// Candidate k's hint (none for a slot the list does not have).
    #[inline]
    pub fn get(&self, k: usize) -> Hint {
        Hint(self.0.get(k).map_or(0, |h| h.load(Ordering::Relaxed)))
    }

    #[inline]
    pub fn set(&self, k: usize, h: Hint) {
        if let Some(slot) = self.0.get(k) {
            slot.store(h.0, Ordering::Relaxed);
        }
    }

    /// Every hint forgotten (the next evaluation starts from none).
    pub fn forget(&self) {
        self.0.iter().for_each(|h| h.store(0, Ordering::Relaxed));
    }

    /// How many candidates have a hint.
    pub fn known(&self) -> usize {
        self.0
            .iter()
            .filter(|h| h.load(Ordering::Relaxed) != 0)
            .count()
    }
}

impl Clone for Hints {
    fn clone(&self) -> Self {
        Self(
            (self.0.iter())
                .map(|h| AtomicU32::new(h.load(Ordering::Relaxed)))
                .collect(),
        )
    }
}

/// A pair of memory slots as the pair of their ids (walls stay as they are).
#[inline]
pub fn id_pair(p: Pair, ids: &[u32]) -> Pair {
    Pair {
        i: ids[p.i as usize],
        j: partner_key(p, ids),
    }
}

/// The partner of a candidate in the order that sorts a group: its id, or the wall
/// (walls after every particle).
#[inline]
fn partner_key(p: Pair, ids: &[u32]) -> u32 {
    if p.is_wall() { p.j } else { ids[p.j as usize] }
}

/// The order that sorts the active particles by cell (by id within a cell), the
/// inactive ones last (by slot): `order[new] = old` slot, for `Simulation::advance`.
pub fn cell_order(grid: &Grid, particles: &Particles, ids: &[u32]) -> Vec<u32> {
    let mut cells = Vec::new();
    sort_by_cell(grid, particles, ids, &mut cells);
    let mut order: Vec<u32> = cells.iter().map(|&(_, _, slot)| slot).collect();
    order.extend((0..particles.len() as u32).filter(|&i| !particles.active[i as usize]));
    order
}

/// A cell's key: its copy of the scene (`replicas`), its row, then its column (u64: a
/// domain 10⁵ diameters square has 10¹⁰ cells). Copies lie on the same grid but in
/// separate runs of keys, so that a particle never finds another copy's.
fn cell_key(grid: &Grid, copy: u32, x: u32, z: u32) -> u64 {
    (copy as u64 * grid.nz as u64 + z as u64) * grid.nx as u64 + x as u64
}

/// Every active particle as (cell key, id, slot), sorted: by cell, and by id within a
/// cell.
fn sort_by_cell(grid: &Grid, particles: &Particles, ids: &[u32], out: &mut Vec<Cell>) {
    let q = &particles.q[0];
    out.clear();
    out.extend(
        crate::base::parallel::map(particles.len(), |i| {
            let (x, z) = grid.cell_coords([q[i][0], q[i][1]]);
            (cell_key(grid, particles.copy[i], x, z), ids[i], i as u32)
        })
        .into_iter()
        .filter(|&(_, _, i)| particles.active[i as usize]),
    );
    crate::base::parallel::sort_unstable(out);
}

/// A particle of the sparse cell list: (cell key, id, memory slot).
type Cell = (u64, u32, u32);

/// The particles of copy `copy` in the cells x0..=x1 of row z: one run of the sorted
/// list.
fn row_of_cells<'a>(
    grid: &Grid,
    cells: &'a [Cell],
    copy: u32,
    [x0, x1]: [u32; 2],
    z: u32,
) -> &'a [Cell] {
    let (lo, hi) = (cell_key(grid, copy, x0, z), cell_key(grid, copy, x1, z));
    let a = cells.partition_point(|c| c.0 < lo);
    let b = a + cells[a..].partition_point(|c| c.0 <= hi);
    &cells[a..b]
}

/// What a rebuild searches: the sparse cell list over the particles, and the walls.
struct Search<'a> {
    grid: &'a Grid,
    cells: &'a [Cell],
    particles: &'a Particles,
    ids: &'a [u32],
    walls: &'a [WallSegment],
    range_factor: f64,
    skin: f64,
}

/// The candidates of every active particle, in contact order, and where each particle's
/// start (each particle's found on its own, on every thread).
fn list_candidates(s: &Search, out: &mut Vec<Pair>, start: &mut Vec<u32>) {
    let lists = crate::base::parallel::map(s.particles.len(), |i| {
        let mut v = Vec::new();
        candidates_of(s, i, &mut v);
        v
    });
    for v in lists {
        start.push(out.len() as u32);
        out.extend(v);
    }
    start.push(out.len() as u32);
}

/// Slot i's candidates in contact order: partners of higher id within range + skin by
/// increasing id, then the walls. A pair of two fixed particles is never a candidate
/// (neither moves); an inactive particle has none.
fn candidates_of(s: &Search, i: usize, out: &mut Vec<Pair>) {
    let (particles, grid, skin) = (s.particles, s.grid, s.skin);
    if !particles.active[i] {
        return;
    }
    let pos = &particles.q[0];
    let pi = [pos[i][0], pos[i][1]];
    let (cx, cz) = grid.cell_coords(pi);
    let (x0, x1) = (cx.saturating_sub(1), (cx + 1).min(grid.nx - 1));
    // Across the seam of a periodic domain (at least three cells wide, validated): the
    // column at the other end, a run of its own.
    let period = particles.period_x;
    let seam = match (period > 0.0, cx) {
        (true, 0) => Some(grid.nx - 1),
        (true, c) if c == grid.nx - 1 => Some(0),
        _ => None,
    };
    let mut found: Vec<(u32, u32)> = Vec::new();
    for z in cz.saturating_sub(1)..=(cz + 1).min(grid.nz - 1) {
        // The three cells x0..=x1 of a row are one run of the sorted list.
        let near = row_of_cells(grid, s.cells, particles.copy[i], [x0, x1], z);
        let across = seam.map_or(&[][..], |c| {
            row_of_cells(grid, s.cells, particles.copy[i], [c, c], z)
        });
        for &(_, id, j) in near.iter().chain(across) {
            let ju = j as usize;
            if id <= s.ids[i] || (particles.fixed[i] && particles.fixed[ju]) {
                continue;
            }
            let dx = crate::state::nearest_image(pos[ju][0] - pi[0], period);
            let dz = pos[ju][1] - pi[1];
            let reach = s.range_factor * (particles.radius[i] + particles.radius[ju]) + skin;
            // A NaN distance (a diverged state) is no candidate.
            if dx * dx + dz * dz < reach * reach {
                found.push((id, j));
            }
        }
    }
    found.sort_unstable();
    out.extend(found.into_iter().map(|(_, j)| Pair { i: i as u32, j }));
    if particles.fixed[i] {
        return;
    }
    for (w, wall) in s.walls.iter().enumerate() {
        let g = disk_wall(particles.radius[i], &wall_from(wall, pi));
        if 0.5 * g.r < s.range_factor * particles.radius[i] + skin {
            out.push(Pair {
                i: i as u32,
                j: WALL_BASE + w as u32,
            });
        }
    }
}

/// For each new candidate, the index of the same pair in the old list (None: a new
/// pair): both lists are in the same memory order and sorted by (slot of i, partner
/// id), so one merge finds every pair that stays a candidate.
/// Each new candidate's value from the old list (`origins`); a new pair starts at 0.
fn carry_over(origin: &[Option<usize>], values: &[f64]) -> Vec<f64> {
    (origin.iter())
        .map(|o| o.map_or(0.0, |k| values[k]))
        .collect()
}

fn origins(old: &[Pair], new: &[Pair], ids: &[u32]) -> Vec<Option<usize>> {
    let key = |p: &Pair| (p.i, partner_key(*p, ids));
    let mut out = Vec::with_capacity(new.len());
    let mut k = 0;
    for p in new {
        while k < old.len() && key(&old[k]) < key(p) {
            k += 1;
        }
        out.push((k < old.len() && old[k] == *p).then_some(k));
    }
    out
}

/// For each slot the candidates in which it is the higher id (j), by increasing partner
/// id: a counting sort of the candidate indices by j, stable, over the groups (`groups`:
/// each slot's first candidate, as `NeighbourList::start`) taken in id order.
fn down_lists(
    pairs: &[Pair],
    groups: &[u32],
    ids: &[u32],
    start: &mut Vec<u32>,
    down: &mut Vec<u32>,
) {
    let n = groups.len() - 1;
    start.clear();
    start.resize(n + 1, 0);
    for p in pairs.iter().filter(|p| !p.is_wall()) {
        start[p.j as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    down.clear();
    down.resize(start[n] as usize, 0);
    let mut next = start[..n].to_vec();
    let mut by_id = vec![0u32; n];
    for (slot, &id) in ids.iter().enumerate() {
        by_id[id as usize] = slot as u32;
    }
    for &i in &by_id {
        let i = i as usize;
        for k in groups[i]..groups[i + 1] {
            let p = pairs[k as usize];
            if !p.is_wall() {
                let slot = &mut next[p.j as usize];
                down[*slot as usize] = k;
                *slot += 1;
            }
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
        let ids = [0, 1, 2, 3, 4];
        assert_eq!(
            carry_over(&origins(&old, &new, &ids), &values),
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
        let groups = [0, 2, 4, 5, 5];
        let (mut start, mut down) = (Vec::new(), Vec::new());
        down_lists(&pairs, &groups, &[0, 1, 2, 3], &mut start, &mut down);
        assert_eq!(start, vec![0, 0, 0, 2, 4]);
        assert_eq!(down, vec![0, 2, 1, 4]);
    }

    #[test]
    fn down_lists_follow_ids_not_memory() {
        // Slots 0, 1, 2 hold ids 2, 0, 1: the pairs (id 0, id 2) = slots (1, 0) and
        // (id 1, id 2) = slots (2, 0) are both in slot 0's down list, id 0's first.
        let ids = [2, 0, 1];
        let pairs = [pair(1, 0), pair(2, 0)];
        let groups = [0, 0, 1, 2];
        let (mut start, mut down) = (Vec::new(), Vec::new());
        down_lists(&pairs, &groups, &ids, &mut start, &mut down);
        assert_eq!(down, vec![0, 1]);
        // Slots 1 and 2 holding ids 1 and 0: memory puts (id 1, id 2) first, the down
        // list still (id 0, id 2).
        let ids = [2, 1, 0];
        let groups = [0, 0, 1, 2];
        down_lists(&pairs, &groups, &ids, &mut start, &mut down);
        assert_eq!(down, vec![1, 0]);
    }
}
