// Stage (src/cpu/neighbours.rs `table`; at a rebuild of the lists only, before the new lists
// are built): a fresh table holding the springs of the old lists' candidates that touch.
// A contact that closed is simply not carried over: no deletion, no tombstones. After an
// upload the table already holds the springs (TABLE_CURRENT) and is kept; the host may
// ask for the table of the current lists between steps (FLUSH).

fn storing() -> bool {
    let w = lists_word();
    return (w & (REBUILD | FLUSH)) != 0u && (w & TABLE_CURRENT) == 0u;
}

// A grid-stride loop: the table has 8 slots per particle, more than 65535 workgroups
// cover beyond 262 144 particles.
@compute @workgroup_size(WG)
fn clear_table(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(num_workgroups) groups: vec3<u32>) {
    if (!storing()) { return; }
    for (var s = gid.x; s <= params.table_mask; s += groups.x * WG) {
        atomicStore(&table[s].i, EMPTY);
    }
}

// Key (id of i, partner key of j); `owner`: i's memory slot (for a halt). Returns the
// entry's slot (EMPTY when the table is full).
fn insert(i: u32, j: u32, value: f32, owner: u32) -> u32 {
    var slot = hash_pair(i, j) & params.table_mask;
    for (var probe = 0u; probe <= params.table_mask; probe++) {
        let r = atomicCompareExchangeWeak(&table[slot].i, EMPTY, i);
        if (r.exchanged) {
            table[slot].j = j;
            table[slot].value = value;
            return slot;
        }
        if (r.old_value == EMPTY) { continue; } // spurious failure: try the slot again
        slot = (slot + 1u) & params.table_mask;
    }
    halt(HALT_TABLE_FULL, owner);
    return EMPTY;
}

@compute @workgroup_size(WG)
fn store_history(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted() || !storing()) { return; }
    let swept = sub_springs_kept();
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * params.list_cap + k;
        if (touching[slot] != 0u) {
            let e = insert(ids[i], partner_key(contact_j[slot]), hist_in[slot], i);
            // A spheropolygon pair's sub-contact springs (a disk pair's rolling
            // spring) go beside the entry.
            if (swept && e != EMPTY) { table_sub[e] = sub_hist[slot]; }
        }
    }
}
