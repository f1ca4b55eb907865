// Stage: Gear predictor (src/integrate/gear.rs `predict`): a Taylor step of the six
// scaled derivatives, q_k += sum_{l>k} C(l, k) q_l; q1 in fixed point (position.wgsl).

// The binomials C(l, k) of q_l in q_k's update, GEAR_P<k><l> (src/integrate/gear.rs
// `PREDICTOR`); C(l, 0) = 1.
const GEAR_P12: f32 = 2.0;
const GEAR_P13: f32 = 3.0;
const GEAR_P14: f32 = 4.0;
const GEAR_P15: f32 = 5.0;
const GEAR_P23: f32 = 3.0;
const GEAR_P24: f32 = 6.0;
const GEAR_P25: f32 = 10.0;
const GEAR_P34: f32 = 4.0;
const GEAR_P35: f32 = 10.0;
const GEAR_P45: f32 = 5.0;

fn predict_one(s: ptr<function, State>) {
    let q1 = (*s).q[1];
    let q2 = (*s).q[2];
    let q3 = (*s).q[3];
    let q4 = (*s).q[4];
    let q5 = (*s).q[5];
    // The move q1 + q2 + ... + q5: q1's whole units exactly, the rest in f32.
    let step = q1 + q2 + q3 + q4 + q5;
    move_by_whole_q1(s);
    turn_by(s, step.z);
    displace(s, step.xy);
    (*s).q[1] += GEAR_P12 * q2 + GEAR_P13 * q3 + GEAR_P14 * q4 + GEAR_P15 * q5;
    renormalize_q1(s);
    (*s).q[2] += GEAR_P23 * q3 + GEAR_P24 * q4 + GEAR_P25 * q5;
    (*s).q[3] += GEAR_P34 * q4 + GEAR_P35 * q5;
    (*s).q[4] += GEAR_P45 * q5;
}

// Particle i predicted, then surveyed (`bit`: see `survey_one`). `correct` with AHEAD
// runs the same steps for the next step on its own copy of the state (src/sim/mod.rs
// `correct_ahead`).
fn predict_particle(i: u32, bit: u32) {
    var s = state[i];
    if (is_integrated(i)) {
        predict_one(&s);
        renormalize(&s);
        renormalize_turn(&s);
        state[i] = s;
        // Forces are evaluated at the predicted state.
        rotate_corners(i, s);
    }
    // The survey of the predicted particle (survey.wgsl; src/sim/mod.rs `survey_with`), on
    // the copy just written.
    survey_one_at(i, bit, s);
}

@compute @workgroup_size(WG)
fn predict(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    predict_particle(i, REBUILD);
}
