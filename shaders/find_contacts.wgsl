// Stage (src/cpu/neighbours.rs `list_candidates`; at a rebuild of the lists only): for
// particle i, every j of a higher id in the 3x3 cells around it whose circles come
// within the skin of the law's range, sorted by id, then its walls. Each candidate is also entered
// in j's `down` list (slot index i * list_cap + k), which the reduction needs; that
// list is filled by atomics and sorted where it is read. Whether a candidate touches is
// decided at every step, in contact_forces (`touches`, `touches_wall`).

// Whether disks (or the circumscribed circles of) i and j come within range + skin.
// f32 with room for its rounding: a candidate too many costs nothing.
fn is_candidate(i: u32, j: u32) -> bool {
    let o = offset_ij(i, j);
    if (!o.near) { return false; }
    let v = offset_vector(o);
    let reach = params.range_factor * (props[i].radius + props[j].radius) + params.skin;
    return dot(v, v) <= reach * reach * (1.0 + 4.0e-5);
}

fn is_wall_candidate(i: u32, w: u32) -> bool {
    let g = disk_wall(i, w);
    if (!g.near) { return false; }
    // g.r is twice the distance to the wall (disk_wall's mirror disk).
    let reach = params.range_factor * props[i].radius + params.skin;
    return 0.5 * g.r <= reach * (1.0 + 2.0e-5);
}

// Records where particle i is as its lists are built (for survey's `moved`).
fn mark_listed(i: u32) {
    let a = state[i].anchor;
    state[i].listed_anchor = (u32(a.x) & 0xFFFFu) | (u32(a.y) << 16u);
    state[i].listed_frac = state[i].frac;
}

@compute @workgroup_size(WG)
fn find_contacts(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_cap || !rebuilding()) { return; }
    if (i >= live() || halted() || !is_active(i)) { contact_count[i] = 0u; return; }
    mark_listed(i);
    // The list is built in place, in i's `params.list_cap` slots of contact_j.
    let base = i * params.list_cap;
    var n = 0u;
    let id_i = ids[i];
    let fixed_i = is_fixed(i);
    let copy_i = copy_of(props[i].flags);
    let c = cell_coords(state[i].anchor);
    let z0 = max(i32(c.y) - 1, 0);
    let z1 = min(c.y + 1u, params.nz - 1u);
    var x0 = max(i32(c.x) - 1, 0);
    var x1 = i32(min(c.x + 1u, params.nx - 1u));
    // Periodic in x (at least three columns, validated): the columns on either side,
    // across the seam too.
    let periodic = params.period_cells > 0u;
    if (periodic) { x0 = i32(c.x) - 1; x1 = i32(c.x) + 1; }
    let hashed = hashed_grid();
    var full = false;
    for (var z = u32(z0); z <= z1 && !full; z++) {
        for (var xs = x0; xs <= x1 && !full; xs++) {
            var x = u32(xs);
            if (periodic) { x = u32((xs + i32(params.nx)) % i32(params.nx)); }
            let cell = bucket(vec2<u32>(x, z));
            let start = cell_start[cell];
            let end = start + atomicLoad(&cell_count[cell]);
            for (var s = start; s < end; s++) {
                let j = sorted[s];
                let id_j = ids[j];
                if (id_j <= id_i || (fixed_i && is_fixed(j))) { continue; }
                // Copies of the scene share the cells but never touch.
                if (copy_of(props[j].flags) != copy_i) { continue; }
                // A bucket of a hashed grid may hold other cells too (and be visited
                // for each of them): only this cell's particles count here.
                if (hashed && any(cell_coords(state[j].anchor) != vec2<u32>(x, z))) { continue; }
                if (!is_candidate(i, j)) { continue; }
                if (n == params.list_cap) { halt(HALT_CONTACTS_FULL, i); full = true; break; }
                // Insertion sort by id: the order must not depend on the cell layout or
                // on the memory order.
                var k = n;
                while (k > 0u && ids[contact_j[base + k - 1u]] > id_j) {
                    contact_j[base + k] = contact_j[base + k - 1u];
                    k--;
                }
                contact_j[base + k] = j;
                n++;
            }
        }
    }
    if (!fixed_i && !full) {
        for (var w = 0u; w < params.n_walls; w++) {
            if (!is_wall_candidate(i, w)) { continue; }
            if (n == params.list_cap) { halt(HALT_CONTACTS_FULL, i); break; }
            contact_j[base + n] = WALL_BASE + w;
            n++;
        }
    }
    for (var k = 0u; k < n; k++) {
        let j = contact_j[base + k];
        if (j < WALL_BASE) {
            let d = atomicAdd(&down_count[j], 1u);
            if (d < params.list_cap) {
                down[j * params.list_cap + d] = base + k;
            } else {
                halt(HALT_CONTACTS_FULL, j);
            }
        }
    }
    contact_count[i] = n;
    // Under the overlap-area law and for spheropolygons contact_forces takes a thread
    // per pair: the list of them (in no particular order; each pair's result goes to its
    // own slot).
    if ((POLYGONS || SPHEROPOLYGONS) && n > 0u) {
        let first = atomicAdd(&pairs.count, n);
        for (var k = 0u; k < n; k++) { pairs.slot[first + k] = base + k; }
    }
}
