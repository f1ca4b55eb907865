// Stages 1 and 2 of the counting sort (src/cpu/cell_list.rs `cell_index`, `cell_histogram`):
// the cell of each active particle, counted in its cell at once (integer atomics: the
// counts do not depend on the order of the additions; one dispatch less per rebuild).
// The anchor *is* the cell, clamped into the grid. `clear_cells` clears the counters
// first. Like every stage of the cell list, it runs only when
// the neighbour lists are rebuilt (issue 13).

// A grid-stride loop: the dispatch stops at 65535 workgroups, the cells and particles
// may not.
@compute @workgroup_size(WG)
fn clear_cells(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(num_workgroups) groups: vec3<u32>) {
    if (!rebuilding()) { return; }
    if (gid.x == 0u) {
        atomicStore(&control[C_INACTIVE], 0u);
        atomicStore(&pairs.count, 0u);
    }
    let stride = groups.x * WG;
    for (var c = gid.x; c < max(params.cells, params.n_cap); c += stride) {
        if (c < params.cells) { atomicStore(&cell_count[c], 0u); }
        if (c < params.n_cap) { atomicStore(&down_count[c], 0u); }
    }
}

@compute @workgroup_size(WG)
fn cell_index(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_cap || !rebuilding()) { return; }
    if (i >= live()) { cell_of[i] = EMPTY; return; }
    if (!is_active(i)) {
        cell_of[i] = EMPTY;
        // The inactive particles fill `sorted` from the end of the live ones (in no
        // particular order): after the active ones in cell order, the new memory order
        // of permute.wgsl.
        sorted[live() - 1u - atomicAdd(&control[C_INACTIVE], 1u)] = i;
        return;
    }
    let c = bucket(cell_coords(state[i].anchor));
    cell_of[i] = c;
    // The histogram (src/cpu/cell_list.rs `cell_histogram`).
    atomicAdd(&cell_count[c], 1u);
}
