// Stage (src/cpu/neighbours.rs `carry_over`; at a rebuild of the lists only): each new
// candidate's tangential history from the spring table, where the rebuild has just
// stored the old lists' springs (store_history); a missing key is a pair that was not in
// contact (0).
// The table: open addressing, linear probing, key (i, j) of ids (or a wall's code for
// j) with i < j, i claimed by compare-and-swap. Only the thread of particle i ever
// writes keys with first id i, so
// two threads never race for the same key; slot positions may vary between runs but a
// lookup always finds the one entry of its key, so results are deterministic.

// The table slot of key (i, j), EMPTY when it is not there.
fn find_entry(i: u32, j: u32) -> u32 {
    var slot = hash_pair(i, j) & params.table_mask;
    for (var probe = 0u; probe <= params.table_mask; probe++) {
        let k = atomicLoad(&table[slot].i);
        if (k == EMPTY) { return EMPTY; }
        if (k == i && table[slot].j == j) { return slot; }
        slot = (slot + 1u) & params.table_mask;
    }
    return EMPTY;
}

// Particle p's down list (its candidates as the higher id) sorted by the id of the lower
// particle: the order in which `kick_sum` adds them at every step until the next rebuild
// (src/cpu/neighbours.rs `down_lists` builds them in that order; find_contacts appends them
// in whatever order its threads arrive). Sorted in place, once per rebuild.
fn sort_down_list(p: u32) {
    let nd = min(atomicLoad(&down_count[p]), params.list_cap);
    let base = p * params.list_cap;
    for (var a = 1u; a < nd; a++) {
        let s = down[base + a];
        let key = ids[s / params.list_cap];
        var k = a;
        while (k > 0u && ids[down[base + k - 1u] / params.list_cap] > key) {
            down[base + k] = down[base + k - 1u];
            k--;
        }
        down[base + k] = s;
    }
}

@compute @workgroup_size(WG)
fn gather_history(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted() || !rebuilding()) { return; }
    let swept = sub_springs_kept();
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * params.list_cap + k;
        let e = find_entry(ids[i], partner_key(contact_j[slot]));
        var value = 0.0;
        if (e != EMPTY) { value = table[e].value; }
        hist_in[slot] = value;
        // A spheropolygon pair's springs are its sub-contacts', a disk pair's rolling
        // spring beside its tangential one (`table_sub`).
        if (swept) {
            var sub = SubSprings(vec4<u32>(EMPTY), vec4<f32>(0.0));
            if (e != EMPTY) { sub = table_sub[e]; }
            sub_hist[slot] = sub;
        }
    }
    sort_down_list(i);
}
