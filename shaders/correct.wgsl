// Stage: Gear corrector (src/integrate/gear.rs `correct`), c0 = 3/20 for
// velocity-dependent forces (Allen & Tildesley). Each particle's contact forces are summed
// here as it is corrected (`acceleration`, reduce_forces.wgsl).

// Whether to predict the particle for the next step once corrected (src/sim.rs
// `correct_ahead`; `Kernel::CorrectAhead`): the host asks for it when another step
// follows on the device at once, with no insertion before its prediction.
override AHEAD: bool = false;

fn correct_one(s: ptr<function, State>, accel: vec4<f32>) {
    let half_dt2 = 0.5 * params.dt * params.dt;
    let delta = half_dt2 * accel - (*s).q[2];
    turn_by(s, (3.0 / 20.0) * delta.z);
    displace(s, (3.0 / 20.0) * delta.xy);
    (*s).q[1] += (251.0 / 360.0) * delta;
    renormalize_q1(s);
    (*s).q[2] += delta;
    (*s).q[3] += (11.0 / 18.0) * delta;
    (*s).q[4] += (1.0 / 6.0) * delta;
    (*s).q[5] += (1.0 / 60.0) * delta;
}

@compute @workgroup_size(WG)
fn correct(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    if (is_integrated(i)) {
        // Forces were evaluated at the predicted state, i.e. at time t + dt.
        let g = gravity_at(f32(atomicLoad(&control[C_STEP]) + 1u));
        var s = state[i];
        correct_one(&s, acceleration(i, g));
        renormalize(&s);
        renormalize_turn(&s);
        state[i] = s;
    }
    // The boundaries (boundaries.wgsl; src/sim.rs `remove_escaped`).
    leave_domain(i);
    // The next step's prediction and survey (predict.wgsl): one dispatch and one pass
    // over the state less per step.
    if (AHEAD) { predict_particle(i, AHEAD_REBUILD); }
}
