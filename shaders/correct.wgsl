// Stage: Gear corrector (src/integrate/gear.rs `correct`), c0 = 3/20 for
// velocity-dependent forces (Allen & Tildesley). Each particle's contact forces are summed
// here as it is corrected (`acceleration`, reduce_forces.wgsl).

// Whether to predict the particle for the next step once corrected (src/sim/mod.rs
// `correct_ahead`; `Kernel::CorrectAhead`): the host asks for it when another step
// follows on the device at once, with no insertion before its prediction.
override AHEAD: bool = false;

// The corrector's coefficients c_k (src/integrate/gear.rs `CORRECTOR`); c2 = 1.
const GEAR_C0: f32 = 3.0 / 20.0;
const GEAR_C1: f32 = 251.0 / 360.0;
const GEAR_C3: f32 = 11.0 / 18.0;
const GEAR_C4: f32 = 1.0 / 6.0;
const GEAR_C5: f32 = 1.0 / 60.0;

fn correct_one(s: ptr<function, State>, accel: vec4<f32>) {
    let half_dt2 = 0.5 * params.dt * params.dt;
    let delta = half_dt2 * accel - (*s).q[2];
    turn_by(s, GEAR_C0 * delta.z);
    displace(s, GEAR_C0 * delta.xy);
    (*s).q[1] += GEAR_C1 * delta;
    renormalize_q1(s);
    (*s).q[2] += delta;
    (*s).q[3] += GEAR_C3 * delta;
    (*s).q[4] += GEAR_C4 * delta;
    (*s).q[5] += GEAR_C5 * delta;
}

@compute @workgroup_size(WG)
fn correct(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    // The state is read once and written once: the boundaries, the prediction and the
    // survey below take this copy (a software adapter reads and writes a State word by
    // word and lane by lane).
    var s = state[i];
    let integrated = is_integrated(i);
    if (integrated) {
        // Forces were evaluated at the predicted state, i.e. at time t + dt.
        let g = gravity_at(f32(atomicLoad(&control[C_STEP]) + 1u));
        correct_one(&s, acceleration(i, g));
        renormalize(&s);
        renormalize_turn(&s);
    }
    // The boundaries (boundaries.wgsl; src/sim/insert.rs `remove_escaped`).
    leave_domain(i, s);
    // The next step's prediction and survey (predict.wgsl `predict_particle`): one
    // dispatch and one pass over the state less per step. A particle the boundaries
    // just removed is not predicted.
    if (AHEAD && is_integrated(i)) {
        predict_one(&s);
        renormalize(&s);
        renormalize_turn(&s);
        rotate_corners(i, s);
    }
    if (integrated) { state[i] = s; }
    if (AHEAD) { survey_one_at(i, AHEAD_REBUILD, s); }
}
