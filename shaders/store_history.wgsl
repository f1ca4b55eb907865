// Stage (src/springs.rs `store_history`): a fresh table holding the updated history of
// this step's contacts. A contact that closed is simply not carried over: no deletion,
// no tombstones, and a contact that opens and closes within a step is never seen twice.

@compute @workgroup_size(WG)
fn clear_table(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if (s <= params.table_mask) { atomicStore(&table_new[s].i, EMPTY); }
}

fn insert_new(i: u32, j: u32, value: f32) {
    var slot = hash_pair(i, j) & params.table_mask;
    for (var probe = 0u; probe <= params.table_mask; probe++) {
        let r = atomicCompareExchangeWeak(&table_new[slot].i, EMPTY, i);
        if (r.exchanged) {
            table_new[slot].j = j;
            table_new[slot].value = value;
            return;
        }
        if (r.old_value == EMPTY) { continue; } // spurious failure: try the slot again
        slot = (slot + 1u) & params.table_mask;
    }
    halt(HALT_TABLE_FULL, i);
}

@compute @workgroup_size(WG)
fn store_history(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * MAX_CONTACTS + k;
        insert_new(i, contact_j[slot], hist_out[slot]);
    }
}
