// Stage 2 (src/cell_list.rs `cell_histogram`): particles per cell. Integer atomics: the
// counts do not depend on the order of the additions.

@compute @workgroup_size(WG)
fn cell_histogram(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_cap || cell_of[i] == EMPTY || !rebuilding()) { return; }
    atomicAdd(&cell_count[cell_of[i]], 1u);
}
