// Stage 4 (src/cpu/cell_list.rs `scatter`): particle ids into cell order. The slot within a
// cell comes from an atomic counter, so the order *within* a cell varies from run to
// run; nothing downstream depends on it, because find_contacts sorts each particle's
// contacts by partner id. The counts, read for the last time by scan_level0 and cleared
// by scan_add0, serve here as the per-cell cursor.

@compute @workgroup_size(WG)
fn scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_cap || cell_of[i] == EMPTY || !rebuilding()) { return; }
    let c = cell_of[i];
    let slot = cell_start[c] + atomicAdd(&cell_count[c], 1u);
    sorted[slot] = i;
}
