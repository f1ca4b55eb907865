// Stage (src/sim/order.rs `Simulation::permute`, issue 13 item 4; at a rebuild of the lists
// only, after the cell list): the particles sorted in memory by cell, so that a
// particle's neighbours lie near it in memory. `sorted` holds the new order (the active
// particles by cell from `scatter`, then the inactive ones from `cell_index`); the
// state, properties and ids move in two passes (all reads, then all writes), and the
// cell list is renamed to the new slots: the particle at position s of `sorted` now
// lies in slot s. The particles' rotated corners stay where they are: `Props.shape`
// points at them. Nothing else per particle outlives the rebuild (the old lists' springs
// are in the table, keyed by ids).

fn permuting() -> bool {
    return rebuilding() && params.reorder != 0u && !halted();
}

@compute @workgroup_size(WG)
fn permute_gather(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if (s >= live() || !permuting()) { return; }
    let old = sorted[s];
    state_next[s] = state[old];
    props_next[s] = props[old];
    ids_next[s] = ids[old];
}

@compute @workgroup_size(WG)
fn permute_store(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if (s >= live() || !permuting()) { return; }
    state[s] = state_next[s];
    props[s] = props_next[s];
    ids[s] = ids_next[s];
    sorted[s] = s;
}
