// Stage: leapfrog (src/integrate/leapfrog.rs `kick_drift`), paper 001 eq. 9-12, with
// q1 = dt v(t - dt/2). Each particle's contact forces are summed here as it moves
// (`acceleration`, reduce_forces.wgsl).

@compute @workgroup_size(WG)
fn kick_drift(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    // Read once: the boundaries take this copy.
    var s = state[i];
    if (is_integrated(i)) {
        let g = gravity_at(f32(atomicLoad(&control[C_STEP])));
        let a = acceleration(i, g);
        s.q[1] += a * params.dt * params.dt;
        renormalize_q1(&s);
        move_by_whole_q1(&s);
        turn_by(&s, s.q[1].z);
        displace(&s, s.q[1].xy);
        renormalize(&s);
        renormalize_turn(&s);
        state[i] = s;
        rotate_corners(i, s);
    }
    // The boundaries (boundaries.wgsl; src/sim/insert.rs `remove_escaped`).
    leave_domain(i, s);
}
