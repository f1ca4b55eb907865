// Stage (src/contacts.rs `find_contacts`): for particle i, every j > i in the 3x3 cells
// around it within the law's range, sorted by j, then its walls. Each contact is also
// entered in j's `down` list (slot index i * MAX_CONTACTS + k), which the reduction
// needs; that list is filled by atomics and sorted where it is read.

// Whether disks i and j interact (r < range_factor * sigma). The f32 distance is right
// to ~1e-7 relative, so only pairs within 1e-5 of the boundary need the exact geometry.
fn in_range(i: u32, j: u32) -> bool {
    let o = offset_ij(i, j);
    if (!o.near) { return false; }
    let v = offset_vector(o);
    let reach = params.range_factor * (props[i].radius + props[j].radius);
    let r2 = dot(v, v);
    let margin = 2.0e-5 * reach * reach;
    if (r2 > reach * reach + margin) { return false; }
    // Polygons: inside the circumscribed circles, a contact is a positive overlap area.
    if (POLYGONS) { return area_contact(i, j, true).found; }
    if (r2 < reach * reach - margin) { return true; }
    let g = disk_disk(i, j);
    return g.r < params.range_factor * g.sigma;
}

fn touches_wall(i: u32, w: u32) -> bool {
    let g = disk_wall(i, w);
    if (POLYGONS) {
        // The circumscribed circle first (with f32 slack), then the area.
        if (g.delta < -1.0e-5 * props[i].radius) { return false; }
        return area_contact_wall(i, w, true).found;
    }
    return g.r < params.range_factor * g.sigma;
}

@compute @workgroup_size(WG)
fn find_contacts(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_cap) { return; }
    if (i >= live() || halted() || !is_active(i)) { contact_count[i] = 0u; return; }
    var found: array<u32, MAX_CONTACTS>;
    var n = 0u;
    let fixed_i = is_fixed(i);
    let c = cell_coords(state[i].anchor);
    let z0 = max(i32(c.y) - 1, 0);
    let z1 = min(c.y + 1u, params.nz - 1u);
    let x0 = max(i32(c.x) - 1, 0);
    let x1 = min(c.x + 1u, params.nx - 1u);
    for (var z = u32(z0); z <= z1; z++) {
        for (var x = u32(x0); x <= x1; x++) {
            let cell = z * params.nx + x;
            let start = cell_start[cell];
            let end = start + atomicLoad(&cell_count[cell]);
            for (var s = start; s < end; s++) {
                let j = sorted[s];
                if (j <= i || (fixed_i && is_fixed(j))) { continue; }
                if (!in_range(i, j)) { continue; }
                if (n == MAX_CONTACTS) { halt(HALT_CONTACTS_FULL, i); break; }
                // Insertion sort by j: the order must not depend on the cell layout.
                var k = n;
                while (k > 0u && found[k - 1u] > j) { found[k] = found[k - 1u]; k--; }
                found[k] = j;
                n++;
            }
        }
    }
    if (!fixed_i) {
        for (var w = 0u; w < params.n_walls; w++) {
            if (!touches_wall(i, w)) { continue; }
            if (n == MAX_CONTACTS) { halt(HALT_CONTACTS_FULL, i); break; }
            found[n] = WALL_BASE + w;
            n++;
        }
    }
    for (var k = 0u; k < n; k++) {
        let j = found[k];
        contact_j[i * MAX_CONTACTS + k] = j;
        if (j < WALL_BASE) {
            let d = atomicAdd(&down_count[j], 1u);
            if (d < MAX_CONTACTS) {
                down[j * MAX_CONTACTS + d] = i * MAX_CONTACTS + k;
            } else {
                halt(HALT_CONTACTS_FULL, j);
            }
        }
    }
    contact_count[i] = n;
}
