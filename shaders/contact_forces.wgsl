// Stage (src/forces.rs `contact_forces`): each contact on its own: geometry, relative
// velocity at the contact point, law. Stores the force on i, both torques, the normal
// and contact point it used, and the updated history; flags a diverging contact.

fn velocity(i: u32) -> vec3<f32> {
    return state[i].q[1].xyz / params.dt;
}

@compute @workgroup_size(WG)
fn contact_forces(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    let ri = props[i].radius;
    let m1 = props[i].mass;
    let v1 = velocity(i);
    for (var k = 0u; k < contact_count[i]; k++) {
        let slot = i * MAX_CONTACTS + k;
        let j = contact_j[slot];
        var g: Geometry;
        var v2 = vec3<f32>(0.0);
        var d_ij = vec2<f32>(0.0);   // centre i minus centre j
        var rmin = ri;
        var m12 = m1;
        var mass = m1;
        let wall = j >= WALL_BASE;
        if (!wall) {
            d_ij = offset_vector(offset_ij(i, j));
            v2 = velocity(j);
            rmin = min(ri, props[j].radius);
            let m2 = props[j].mass;
            m12 = m1 * m2 / (m1 + m2);
            mass = 2.0 * m12;
        }
        // The law sees the rate of delta: the overlap's for disks, L v_n / l for the
        // overlap area (delta = A/l; src/forces.rs `area_contact_input`).
        var rate = 1.0;
        if (POLYGONS) {
            var a: AreaContact;
            if (wall) { a = area_contact_wall(i, j - WALL_BASE, false); } else { a = area_contact(i, j, false); }
            var delta = 0.0;
            var depth = 0.0;
            rate = 0.0;
            if (a.found && a.l > 0.0) {
                delta = a.area / a.l;
                if (a.chord > 0.0) { depth = a.area / a.chord; }
                rate = a.chord / a.l;
            }
            g = Geometry(a.n, delta, depth, 0.0, a.point, true);
        } else if (wall) {
            g = disk_wall(i, j - WALL_BASE);
        } else {
            g = disk_disk(i, j);
        }
        let l1 = g.arm;
        let l2 = d_ij + l1;
        let s1 = v1.z * vec2<f32>(-l1.y, l1.x);
        var s2 = vec2<f32>(0.0);
        if (!wall) { s2 = v2.z * vec2<f32>(-l2.y, l2.x); }
        // Relative velocity of the two surfaces at the contact point.
        let v12 = v1.xy + s1 - v2.xy - s2;
        let t = tangent(g.n);
        let input = ContactInput(g.delta, g.r, g.sigma, -dot(v12, g.n) * rate, dot(v12, t),
                                 m12, mass, hist_in[slot], params.dt);
        let res = evaluate(input);
        let f = res.f_n * g.n + res.f_t * t;
        contact_out[slot] = ContactOut(vec4<f32>(f, cross2(l1, f), -cross2(l2, f)),
                                       vec4<f32>(res.f_n, res.f_t, g.delta, res.energy),
                                       vec4<f32>(g.n, l1));
        hist_out[slot] = res.history;
        let finite = abs(f.x) <= 3.0e38 && abs(f.y) <= 3.0e38;
        if (!finite) { halt(HALT_NOT_FINITE, i); }
        if (g.delta / rmin > params.max_overlap) { halt(HALT_OVERLAP, i); }
    }
}
