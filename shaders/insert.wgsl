// Stage: insert_from_sources (src/create/source.rs `emit`). Candidate k of a source is
// drawn on the host from the source's own random stream, so only *when* it is placed
// depends on the state. Two kernels: every particle marks the due candidates it would
// touch (parallel), then one thread places the due, free candidates in order. Nothing
// is read back, so the queue never stalls.

fn touches(c: Candidate, p: u32) -> bool {
    // Only the particles of the candidate's own copy of the scene are in its way.
    if (copy_of(c.flags) != copy_of(props[p].flags)) { return false; }
    let o = offset(c.anchor, c.frac, c.rem, image_anchor(c.anchor, state[p].anchor),
                   state[p].frac, state[p].q[0].xy);
    if (!o.near) { return false; }
    let d = offset_vector(o);
    let s = c.radius + props[p].radius;
    return dot(d, d) < s * s;
}

@compute @workgroup_size(WG)
fn insert_check(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = gid.x;
    if (p >= live() || halted() || !is_active(p)) { return; }
    let step = atomicLoad(&control[C_STEP]);
    for (var s = 0u; s < params.n_sources; s++) {
        let src = sources[s];
        for (var c = 0u; c < INSERT_WINDOW; c++) {
            let k = src.inserted + c;
            if (k >= src.count) { break; }
            let cand = candidates[src.first + k];
            if (cand.due_step > step) { break; }
            if (touches(cand, p)) {
                atomicOr(&control[C_BLOCKED + s * INSERT_WINDOW + c], 1u);
            }
        }
    }
}

@compute @workgroup_size(1)
fn insert_place() {
    if (halted()) { return; }
    let step = atomicLoad(&control[C_STEP]);
    let first_new = live();
    for (var s = 0u; s < params.n_sources; s++) {
        var blocked = false;
        for (var c = 0u; c < INSERT_WINDOW; c++) {
            let flag = atomicExchange(&control[C_BLOCKED + s * INSERT_WINDOW + c], 0u);
            let k = sources[s].inserted;
            if (blocked || k >= sources[s].count) { continue; }
            let cand = candidates[sources[s].first + k];
            if (cand.due_step > step || flag != 0u) { blocked = true; continue; }
            // Particles placed earlier in this step are not in the parallel check.
            let n = live();
            for (var p = first_new; p < n; p++) {
                if (touches(cand, p)) { blocked = true; }
            }
            if (blocked) { continue; }
            var st: State;
            st.q[0] = vec4<f32>(cand.rem, cand.turn_rem, 0.0);
            st.turn = cand.turn;
            st.q[1] = vec4<f32>(cand.velocity, 0.0, 0.0);
            renormalize_q1(&st);
            if (params.integrator == 0u) {
                // Gear starts with the gravitational acceleration in q2.
                let h = 0.5 * params.dt * params.dt;
                st.q[2] = vec4<f32>(h * gravity_at(f32(step)), 0.0, 0.0);
            }
            st.anchor = cand.anchor;
            st.frac = cand.frac;
            state[n] = st;
            // Ids are never reused: a new particle's is the number of particles so far.
            ids[n] = n;
            props[n] = Props(cand.radius, cand.mass, cand.inv_inertia, cand.flags,
                             cand.radius_units, cand.radius_rem, cand.shape);
            rotate_corners(n, st);
            atomicStore(&control[C_LIVE], n + 1u);
            request_rebuild();
            sources[s].inserted = k + 1u;
        }
    }
}
