//! Neighbour search by a uniform cell list built with a counting sort (SPEC 3):
//! `cell_index` → `cell_histogram` → `prefix_sum` (exclusive) → `scatter`.
//!
//! Each stage is a separate function with the shape of a compute kernel, so the GPU path
//! mirrors them one to one. The scatter is stable (particles of a cell stay in id order),
//! which makes the neighbour order, and with it every sum, deterministic.

/// A uniform grid over the domain with square cells of side `cell_size`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub origin: [f64; 2],
    pub cell_size: f64,
    pub nx: u32,
    pub nz: u32,
}

/// Marks a particle that is in no cell (inactive).
pub const NO_CELL: u32 = u32::MAX;

impl Grid {
    /// A grid covering `[x0, x1] × [z0, z1]` with cells at least `min_cell` wide.
    pub fn new(x: [f64; 2], z: [f64; 2], min_cell: f64) -> Self {
        let nx = (((x[1] - x[0]) / min_cell).floor() as u32).max(1);
        let nz = (((z[1] - z[0]) / min_cell).floor() as u32).max(1);
        // Stretch the cell so that nx cells fill the width exactly; it stays ≥ min_cell.
        let cell_size = ((x[1] - x[0]) / nx as f64)
            .max((z[1] - z[0]) / nz as f64)
            .max(min_cell);
        Self {
            origin: [x[0], z[0]],
            cell_size,
            nx,
            nz,
        }
    }

    /// A grid for a domain periodic in x: `nx` cells of at least `min_cell` fill the
    /// period exactly (cells across the seam are neighbours), square, as many rows as
    /// fit in z (the last row takes what lies beyond, as `cell_coords` clamps).
    pub fn periodic(x: [f64; 2], z: [f64; 2], min_cell: f64) -> Self {
        let nx = (((x[1] - x[0]) / min_cell).floor() as u32).max(1);
        let cell_size = (x[1] - x[0]) / nx as f64;
        let nz = (((z[1] - z[0]) / cell_size).floor() as u32).max(1);
        Self {
            origin: [x[0], z[0]],
            cell_size,
            nx,
            nz,
        }
    }

    /// This grid with its cells doubled until they are at least `min_cell` wide (the
    /// same origin; the last cells may reach beyond the domain): the GPU path's grid for
    /// the neighbour lists. Its fixed-point unit is the old one times a power of two, so
    /// positions that lay on the old grid's units lie on the new one's.
    pub fn coarsened(&self, min_cell: f64) -> Self {
        let mut g = self.clone();
        while g.cell_size < min_cell {
            g.cell_size *= 2.0;
            g.nx = g.nx.div_ceil(2);
            g.nz = g.nz.div_ceil(2);
        }
        g
    }

    pub fn cell_count(&self) -> usize {
        self.nx as usize * self.nz as usize
    }

    /// Cell coordinates of a point, clamped into the grid.
    pub fn cell_coords(&self, p: [f64; 2]) -> (u32, u32) {
        let cx = ((p[0] - self.origin[0]) / self.cell_size).floor();
        let cz = ((p[1] - self.origin[1]) / self.cell_size).floor();
        let clamp = |c: f64, n: u32| c.max(0.0).min((n - 1) as f64) as u32;
        (clamp(cx, self.nx), clamp(cz, self.nz))
    }
}

/// The sorted particle order and each cell's range in it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellList {
    /// Cell of each particle, or NO_CELL.
    pub cell_of: Vec<u32>,
    /// Number of particles per cell.
    pub count: Vec<u32>,
    /// Exclusive prefix sum of `count`: the first slot of each cell in `sorted`.
    pub start: Vec<u32>,
    /// Particle ids ordered by cell.
    pub sorted: Vec<u32>,
}

/// Stage 1: the cell of each active particle.
pub fn cell_index(grid: &Grid, positions: &[[f64; 3]], active: &[bool], cell_of: &mut Vec<u32>) {
    cell_of.clear();
    cell_of.extend(positions.iter().zip(active).map(|(p, &a)| {
        if !a {
            return NO_CELL;
        }
        let (cx, cz) = grid.cell_coords([p[0], p[1]]);
        cz * grid.nx + cx
    }));
}

/// Stage 2: how many particles each cell holds.
pub fn cell_histogram(cell_of: &[u32], cells: usize, count: &mut Vec<u32>) {
    count.clear();
    count.resize(cells, 0);
    for &c in cell_of {
        if c != NO_CELL {
            count[c as usize] += 1;
        }
    }
}

/// Stage 3: exclusive prefix sum; returns the total.
pub fn prefix_sum(input: &[u32], output: &mut Vec<u32>) -> u32 {
    output.clear();
    let mut total = 0u32;
    for &v in input {
        output.push(total);
        total += v;
    }
    total
}

/// Stage 4: stable scatter of particle ids into cell order.
pub fn scatter(cell_of: &[u32], start: &[u32], total: u32, sorted: &mut Vec<u32>) {
    sorted.clear();
    sorted.resize(total as usize, 0);
    let mut next = start.to_vec();
    for (i, &c) in cell_of.iter().enumerate() {
        if c != NO_CELL {
            sorted[next[c as usize] as usize] = i as u32;
            next[c as usize] += 1;
        }
    }
}

impl CellList {
    /// Runs the four stages.
    pub fn build(&mut self, grid: &Grid, positions: &[[f64; 3]], active: &[bool]) {
        cell_index(grid, positions, active, &mut self.cell_of);
        cell_histogram(&self.cell_of, grid.cell_count(), &mut self.count);
        let total = prefix_sum(&self.count, &mut self.start);
        scatter(&self.cell_of, &self.start, total, &mut self.sorted);
    }

    /// Particle ids in cell (cx, cz).
    pub fn cell(&self, grid: &Grid, cx: u32, cz: u32) -> &[u32] {
        let c = (cz * grid.nx + cx) as usize;
        let s = self.start[c] as usize;
        &self.sorted[s..s + self.count[c] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefix_sum_is_exclusive() {
        let mut out = Vec::new();
        assert_eq!(prefix_sum(&[3, 0, 2, 1], &mut out), 6);
        assert_eq!(out, vec![0, 3, 3, 5]);
    }

    #[test]
    fn every_active_particle_is_sorted_once_into_its_cell() {
        let grid = Grid::new([0.0, 10.0], [0.0, 5.0], 1.0);
        let pos: Vec<[f64; 3]> = (0..50)
            .map(|i| {
                [
                    (i * 37 % 100) as f64 / 10.0,
                    (i * 13 % 50) as f64 / 10.0,
                    0.0,
                ]
            })
            .collect();
        let mut active = vec![true; 50];
        active[7] = false;
        let mut cl = CellList::default();
        cl.build(&grid, &pos, &active);
        assert_eq!(cl.sorted.len(), 49);
        let mut seen = cl.sorted.clone();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 49);
        assert!(!cl.sorted.contains(&7));
        for cz in 0..grid.nz {
            for cx in 0..grid.nx {
                let ids = cl.cell(&grid, cx, cz);
                assert!(
                    ids.windows(2).all(|w| w[0] < w[1]),
                    "stable scatter keeps id order"
                );
                for &i in ids {
                    assert_eq!(
                        grid.cell_coords([pos[i as usize][0], pos[i as usize][1]]),
                        (cx, cz)
                    );
                }
            }
        }
    }
}
