// Stage (src/neighbours.rs `carry_over`; at a rebuild of the lists only): each new
// candidate's tangential history from the spring table, where the rebuild has just
// stored the old lists' springs (store_history); a missing key is a pair that was not in
// contact (0).
// The table: open addressing, linear probing, key (i, j) of ids (or a wall's code for
// j) with i < j, i claimed by compare-and-swap. Only the thread of particle i ever
// writes keys with first id i, so
// two threads never race for the same key; slot positions may vary between runs but a
// lookup always finds the one entry of its key, so results are deterministic.

fn lookup(i: u32, j: u32) -> f32 {
    var slot = hash_pair(i, j) & params.table_mask;
    for (var probe = 0u; probe <= params.table_mask; probe++) {
        let k = atomicLoad(&table[slot].i);
        if (k == EMPTY) { return 0.0; }
        if (k == i && table[slot].j == j) { return table[slot].value; }
        slot = (slot + 1u) & params.table_mask;
    }
    return 0.0;
}

@compute @workgroup_size(WG)
fn gather_history(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted() || !rebuilding()) { return; }
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * MAX_CONTACTS + k;
        hist_in[slot] = lookup(ids[i], partner_key(contact_j[slot]));
    }
}
