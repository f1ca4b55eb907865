//! The hashed grid: cells mapped to buckets when a dense grid has more cells than one
//! dispatch clears (twin of `bucket` in shaders/common.wgsl).

use super::*;

/// The spatial hash: the cell's coordinates times large primes (Teschner et al. 2003),
/// mixed by Wellons's lowbias32 so that every bit of the bucket depends on both.
pub const HASH_X: u32 = 73_856_093;

pub const HASH_Z: u32 = 19_349_663;

pub const HASH_MIX_1: u32 = 0x7feb_352d;

pub const HASH_MIX_2: u32 = 0x846c_a68b;

/// Buckets of a hashed grid at most (a power of two below MAX_CELLS).
pub const MAX_BUCKETS: u64 = 1 << 21;

/// The bucket of cell (cx, cz) in a grid of `buckets` buckets (twin of `bucket` in
/// common.wgsl): the cell itself when the grid is dense (nx nz ≤ buckets), else a
/// spatial hash.
pub fn bucket(grid: &crate::cpu::cell_list::Grid, buckets: u32, cx: u32, cz: u32) -> u32 {
    if grid.nx > buckets / grid.nz {
        let mut h = cx.wrapping_mul(HASH_X) ^ cz.wrapping_mul(HASH_Z);
        h ^= h >> 16;
        h = h.wrapping_mul(HASH_MIX_1);
        h ^= h >> 15;
        h = h.wrapping_mul(HASH_MIX_2);
        h ^= h >> 16;
        h % buckets
    } else {
        cz * grid.nx + cx
    }
}

/// The buckets of the device's grid: about two per particle when the grid has more
/// than four times as many cells, or more than MAX_CELLS (a hashed grid: issue 13,
/// memory and rebuild time O(N) whatever the domain's area, and a pour 10⁵ d wide
/// runs); otherwise every cell (a dense grid, whose neighbouring cells are neighbours in
/// memory).
pub fn bucket_count(grid: &crate::cpu::cell_list::Grid, n_cap: u32) -> u64 {
    let cells = grid.nx as u64 * grid.nz as u64;
    let hashed = (2 * n_cap as u64)
        .next_power_of_two()
        .clamp(1024, MAX_BUCKETS);
    if cells > MAX_CELLS || cells > 4 * hashed {
        hashed
    } else {
        cells
    }
}
