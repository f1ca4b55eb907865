//! What a scene asks of an adapter: the particles the GPU path holds for it (those
//! there are and every one its sources and layered rows will add) and its buffers that
//! grow with them. The upload checks them before it draws or allocates anything,
//! `talus check --backend gpu` prints them against the adapter, and `talus info` turns
//! them around into the largest scene an adapter holds (issue 38 item 3).

use super::buckets::bucket_count;
use super::layout::{Candidate, Entry, State, SubSprings};
use super::{MAX_CELLS_PER_SIDE, MAX_CONTACTS, MAX_WORKGROUPS, WG};
use crate::create;
use crate::sim::Simulation;

/// The particles a scene's run holds at most, its candidates per particle and the bytes
/// of each buffer that grows with them.
#[derive(Clone, Debug, PartialEq)]
pub struct Footprint {
    pub particles: u64,
    /// Candidates per particle (`list_capacity`).
    pub list_cap: u32,
    /// The cells of the GPU's grid along x and z (range plus skin wide).
    pub grid: [u32; 2],
    /// Each buffer's name and bytes, the largest first.
    pub buffers: Vec<(&'static str, u64)>,
}

impl Footprint {
    /// The workgroups of a per-particle dispatch (one thread per particle).
    pub fn workgroups(&self) -> u64 {
        self.particles.div_ceil(WG as u64)
    }

    /// Why an adapter that binds at most `binding` bytes in one buffer cannot hold the
    /// scene, or `None`.
    pub fn misfit(&self, binding: u64) -> Option<String> {
        let [nx, nz] = self.grid;
        if nx >= MAX_CELLS_PER_SIDE || nz >= MAX_CELLS_PER_SIDE {
            return Some(format!(
                "the cell grid has {nx} × {nz} cells, the GPU path handles at most {} per \
                 side; make the domain smaller",
                MAX_CELLS_PER_SIDE - 1
            ));
        }
        if self.workgroups() > MAX_WORKGROUPS {
            return Some(format!(
                "{} particles need {} workgroups in one dispatch and the GPU path issues at \
                 most {MAX_WORKGROUPS} (about 4.19 million particles); use --backend cpu",
                self.particles,
                self.workgroups()
            ));
        }
        let (what, bytes) = self.buffers.iter().find(|&&(_, b)| b > binding)?;
        Some(format!(
            "the {what} buffer needs {bytes} bytes and the adapter binds at most {binding}"
        ))
    }
}

/// The footprint of `n` particles, `to_come` of them still to be drawn by point sources,
/// with `list_cap` candidates each (`swept`: and the sub-contact springs of rods, or
/// the rolling springs of disks), on a
/// grid of `cells` (buckets).
pub fn of_count(n: u64, to_come: u64, list_cap: u32, swept: bool, cells: u64) -> Footprint {
    let mut buffers = vec![
        ("particle state", n * size_of::<State>() as u64),
        ("contact", n * list_cap as u64 * 16),
        (
            "spring table",
            table_capacity(n) * size_of::<Entry>() as u64,
        ),
        ("source candidate", to_come * size_of::<Candidate>() as u64),
        ("cell", cells * 4),
    ];
    if swept {
        buffers.push((
            "sub-contact spring",
            n * list_cap as u64 * size_of::<SubSprings>() as u64,
        ));
    }
    buffers.sort_by(|a, b| b.1.cmp(&a.1));
    Footprint {
        particles: n,
        list_cap,
        grid: [1, 1],
        buffers,
    }
}

/// A scene's footprint: its particles, those its point sources will still insert, and
/// the layered rows still to come at their most (as the upload sizes them).
pub fn footprint(sim: &Simulation) -> Footprint {
    let (point_sources, layered_specs) = crate::sim::creators(&sim.scene);
    // Every copy of the scene has its sources, copy after copy (`replicas`).
    let per_copy = point_sources.len() + layered_specs.len();
    let mut to_come = 0u64;
    let mut layered = 0u64;
    for (s, st) in sim.sources.iter().enumerate() {
        let k = s % per_copy.max(1);
        if let Some(spec) = point_sources.get(k) {
            to_come += spec.count.saturating_sub(st.inserted) as u64;
        } else if let Some(spec) = layered_specs.get(k - point_sources.len()) {
            layered += (st.inserted..crate::scene::rows::max_rows(spec))
                .map(|row| create::layered::row_capacity(spec, row) as u64)
                .sum::<u64>();
        }
    }
    let n = (sim.particles.len() as u64)
        .saturating_add(to_come)
        .saturating_add(layered)
        .max(1);
    let grid = super::device_grid(sim);
    let cells = bucket_count(&grid, n.min(u32::MAX as u64) as u32);
    let swept = super::keeps_sub_springs(sim);
    Footprint {
        grid: [grid.nx, grid.nz],
        ..of_count(n, to_come, super::list_capacity(sim), swept, cells)
    }
}

/// Slots of the spring table for n particles: a power of two (the hash's mask), about
/// eight per particle (a dense packing has ~2 contacts per particle as the lower id: the
/// table stays about a quarter full, and probes stay short).
pub(super) fn table_capacity(n: u64) -> u64 {
    (8 * n).next_power_of_two().max(64)
}

/// The most particles the GPU path holds where a buffer binds at most `binding` bytes,
/// with `list_cap` candidates each (`MAX_CONTACTS` for disks and polygons; rods more,
/// `list_capacity`) and `swept` the rods' sub-contact springs: every buffer that grows
/// with them within it (the cells at their most, two hashed buckets a particle), and one
/// thread per particle in a dispatch of at most `MAX_WORKGROUPS` workgroups (`talus info`
/// prints it).
pub fn max_particles(binding: u64, list_cap: u32, swept: bool) -> u64 {
    let fits = |n: u64| {
        let cells = (2 * n).next_power_of_two().max(1024);
        of_count(n, 0, list_cap, swept, cells)
            .misfit(binding)
            .is_none()
    };
    let (mut lo, mut hi) = (0, MAX_WORKGROUPS * WG as u64 + 1);
    // fits(lo) and not fits(hi): the sizes grow with n.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) { lo = mid } else { hi = mid }
    }
    lo
}

/// The largest scenes `talus info` names: disks and polygons, and rods of aspect 5 and
/// 10 (their lists hold more candidates, `list_capacity`, and each a sub-contact spring).
pub fn largest_scenes(binding: u64) -> [(&'static str, u64); 3] {
    [
        (
            "disks or polygons",
            max_particles(binding, MAX_CONTACTS, false),
        ),
        ("rods of aspect 5", max_particles(binding, 48, true)),
        ("rods of aspect 10", max_particles(binding, 64, true)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_scene_fits_and_one_more_does_not() {
        for (list_cap, swept) in [(MAX_CONTACTS, false), (48, true), (64, true)] {
            let binding = 128 << 20;
            let n = max_particles(binding, list_cap, swept);
            let cells = |n: u64| (2 * n).next_power_of_two().max(1024);
            let at = |n| of_count(n, 0, list_cap, swept, cells(n));
            assert!(at(n).misfit(binding).is_none(), "{n} fits");
            assert!(at(n + 1).misfit(binding).is_some(), "{} does not", n + 1);
        }
        // Rods' longer lists and sub-contact springs make their largest scene smaller.
        let [(_, disks), (_, rods5), (_, rods10)] = largest_scenes(128 << 20);
        assert!(rods10 < rods5 && rods5 < disks, "{disks} {rods5} {rods10}");
        // Without a binding limit, the dispatch limit.
        assert_eq!(
            max_particles(u64::MAX, 64, true),
            MAX_WORKGROUPS * WG as u64
        );
    }
}
