// Stage 3 (src/cpu/cell_list.rs `prefix_sum`): exclusive prefix sum of the cell counts, in
// three levels of 256-element workgroup scans (up to 256^3 cells). Level 0 scans the
// counts into cell_start and writes each block's total to scan[0..]; level 1 scans those
// totals in place and writes its block totals at scan[scan_offset2..]; level 2 scans
// those (one workgroup); then the block offsets are added back down. Only at a rebuild of
// the neighbour lists (issue 13).

const SCAN_WG: u32 = 256u;
var<workgroup> tile: array<u32, SCAN_WG>;
var<workgroup> lists: u32;

// Whether the lists are rebuilt this step, as a value uniform over the workgroup (the
// scans hold barriers, which must not sit behind a branch on a storage read).
fn rebuilding_here(lid: u32) -> bool {
    if (lid == 0u) { lists = lists_word(); }
    return (workgroupUniformLoad(&lists) & REBUILD) != 0u;
}

// Exclusive scan of `tile` by the workgroup (Hillis-Steele); returns the block total.
fn scan_tile(lid: u32) -> u32 {
    let own = tile[lid];
    workgroupBarrier();
    for (var off = 1u; off < SCAN_WG; off *= 2u) {
        var add = 0u;
        if (lid >= off) { add = tile[lid - off]; }
        workgroupBarrier();
        tile[lid] += add;
        workgroupBarrier();
    }
    let total = tile[SCAN_WG - 1u];
    let inclusive = tile[lid];
    workgroupBarrier();
    tile[lid] = inclusive - own;
    return total;
}

@compute @workgroup_size(SCAN_WG)
fn scan_level0(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(local_invocation_id) lid: vec3<u32>,
               @builtin(workgroup_id) wid: vec3<u32>) {
    if (!rebuilding_here(lid.x)) { return; }
    let c = gid.x;
    var v = 0u;
    if (c < params.cells) { v = atomicLoad(&cell_count[c]); }
    tile[lid.x] = v;
    let total = scan_tile(lid.x);
    if (c < params.cells) { cell_start[c] = tile[lid.x]; }
    if (lid.x == 0u) { scan[wid.x] = total; }
}

@compute @workgroup_size(SCAN_WG)
fn scan_level1(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(local_invocation_id) lid: vec3<u32>,
               @builtin(workgroup_id) wid: vec3<u32>) {
    if (!rebuilding_here(lid.x)) { return; }
    let b = gid.x;
    var v = 0u;
    if (b < params.scan_blocks1) { v = scan[b]; }
    tile[lid.x] = v;
    let total = scan_tile(lid.x);
    if (b < params.scan_blocks1) { scan[b] = tile[lid.x]; }
    if (lid.x == 0u) { scan[params.scan_offset2 + wid.x] = total; }
}

@compute @workgroup_size(SCAN_WG)
fn scan_level2(@builtin(local_invocation_id) lid: vec3<u32>) {
    if (!rebuilding_here(lid.x)) { return; }
    var v = 0u;
    if (lid.x < params.scan_blocks2) { v = scan[params.scan_offset2 + lid.x]; }
    tile[lid.x] = v;
    scan_tile(lid.x);
    if (lid.x < params.scan_blocks2) { scan[params.scan_offset2 + lid.x] = tile[lid.x]; }
}

@compute @workgroup_size(SCAN_WG)
fn scan_add1(@builtin(global_invocation_id) gid: vec3<u32>) {
    let b = gid.x;
    if (b < params.scan_blocks1 && rebuilding()) { scan[b] += scan[params.scan_offset2 + b / SCAN_WG]; }
}

// Also clears each cell's count, read for the last time by scan_level0: `scatter` counts
// again from 0 as its cursor (src/cpu/cell_list.rs `scatter`; one dispatch less per rebuild).
@compute @workgroup_size(SCAN_WG)
fn scan_add0(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = gid.x;
    if (c < params.cells && rebuilding()) {
        cell_start[c] += scan[c / SCAN_WG];
        atomicStore(&cell_count[c], 0u);
    }
}
