// Stage (src/sim/mod.rs `survey`, src/cpu/neighbours.rs `moved`): after the prediction, whether
// a particle has moved by more than skin/2 since the lists were built; then this step
// rebuilds them. The displacement comes from the fixed-point position (whole cells and
// units), so the decision is the same on every run. Insertions and removals ask for a
// rebuild where they happen (insert, boundaries).

fn moved(s: State) -> bool {
    // The anchor when listed, from its two 16-bit halves; anchors move by far less than
    // 2^15 cells between two rebuilds, so the wrapped difference is the true one.
    let la = vec2<i32>(i32(s.listed_anchor << 16u) >> 16u, i32(s.listed_anchor) >> 16u);
    let da = ((s.anchor - la + vec2<i32>(32768)) & vec2<i32>(0xFFFF)) - vec2<i32>(32768);
    if (any(abs(da) > vec2<i32>(1))) { return true; }
    let d = vec2<f32>(da) * f32(FRAC_ONE) + vec2<f32>(vec2<i32>(s.frac) - vec2<i32>(s.listed_frac));
    // skin/2 in units, a hair smaller for the f32 rounding of d.
    let half = 0.5 * params.skin * params.inv_unit * (1.0 - 1.0e-4);
    return dot(d, d) > half * half;
}

// Particle i's part of the survey; Gear's `predict` runs it for each particle once
// predicted (one dispatch fewer per step), leapfrog's step the kernel below. `bit`: the
// lists' bit it sets, REBUILD for this step, AHEAD_REBUILD for the next (a prediction
// run ahead in `correct`).
fn survey_one(i: u32, bit: u32) {
    survey_one_at(i, bit, state[i]);
}

// `survey_one` for particle i at state s (the caller's copy, as it stores it); also
// halts the run when its step q1 = v dt is longer than the bound (issue 16: a grain
// faster than that tunnels through fixed rows; src/sim/divergence.rs `SurveyWatch::survey_one`).
fn survey_one_at(i: u32, bit: u32, s: State) {
    if (params.max_step2 > 0.0 && is_active(i)) {
        let step = q1_total(s.q1_whole, s.q[1]).xy;
        let r = props[i].radius;
        if (dot(step, step) > params.max_step2 * r * r) { halt(HALT_TOO_FAST, i); }
    }
    if (params.skin <= 0.0) {
        if (i == 0u) { atomicOr(&control[C_LISTS], bit); }
        return;
    }
    if (is_active(i) && moved(s)) { atomicOr(&control[C_LISTS], bit); }
    // Moving walls (src/sim/walls.rs), once per survey: at the step surveyed (the next
    // one for a prediction run ahead).
    if (i == 0u && params.n_walls > 0u) {
        let step = atomicLoad(&control[C_STEP]) + select(0u, 1u, bit == AHEAD_REBUILD);
        if (walls_moved(step)) { atomicOr(&control[C_LISTS], bit); }
    }
}

@compute @workgroup_size(WG)
fn survey(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= live() || halted()) { return; }
    survey_one(i, REBUILD);
}
