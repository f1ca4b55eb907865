// Stage (src/springs.rs `gather_history`): the tangential history of every contact from
// the previous step's table; a missing key is a contact that just opened (0).
// The table: open addressing, linear probing, key (i, j) with i < j, i claimed by
// compare-and-swap. Only the thread of particle i ever writes keys with first id i, so
// two threads never race for the same key; slot positions may vary between runs but a
// lookup always finds the one entry of its key, so results are deterministic.

fn lookup_old(i: u32, j: u32) -> f32 {
    var slot = hash_pair(i, j) & params.table_mask;
    for (var probe = 0u; probe <= params.table_mask; probe++) {
        let k = atomicLoad(&table_old[slot].i);
        if (k == EMPTY) { return 0.0; }
        if (k == i && table_old[slot].j == j) { return table_old[slot].value; }
        slot = (slot + 1u) & params.table_mask;
    }
    return 0.0;
}

@compute @workgroup_size(WG)
fn gather_history(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * MAX_CONTACTS + k;
        hist_in[slot] = lookup_old(i, contact_j[slot]);
    }
}
