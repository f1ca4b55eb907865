// Fixed-point orientations and exactly rotated polygon corners (SPEC 3 precision; host
// twin src/gpu/orientation.rs, bit for bit).
//
// An orientation is a whole number of turn units `turn` (u32; 2^32 units per full turn,
// so one unit is 2 pi / 2^32 = 1.46e-9 rad and whole turns wrap by themselves) plus an
// f32 remainder in turn units, kept in [-0.5, 0.5] (q[0].z of State). The Gear values
// q[1..5].z stay in radians.
//
// Why: a polygon's corner half a diameter from its centre moves 0.5 d per radian, and
// the overlap of two resting polygons (1e-5 d at SI stiffness) must be right to 1e-3, so
// corners are needed to ~1e-9 d: angles to ~2e-9 rad and sin, cos to ~2e-9. An f32
// angle near pi resolves only 2.4e-7 rad, f32 sin and cos 6e-8, and a resting grain's
// rotation per step (1e-10 rad) would be rounded away. So corners are kept in position
// units (position.wgsl) and rotated once per particle and step in integer arithmetic,
// with sin and cos in Q31 fixed point from a Taylor series (`rotate_corners`, into
// `corners[].zw`); the remainder's rotation, below 0.4 units, is added to first order in
// f32 where a contact reads a corner (`corner_spin`).

const TURN_UNIT: f32 = 1.4629180792671596e-9;   // 2 pi / 2^32 rad
const INV_TURN_UNIT: f32 = 683565275.57643158;  // 2^32 / (2 pi)
const Q31_ONE: u32 = 0x80000000u;
const TWO_PI_Q29: u32 = 3373259426u;            // round(2 pi 2^29)

// Adds a rotation (radians) to the orientation.
fn turn_by(s: ptr<function, State>, by: f32) {
    (*s).q[0].z += by * INV_TURN_UNIT;
}

// Moves whole turn units of the remainder into `turn` (exact: rem - round(rem) is
// representable). A remainder of more than a quarter turn only comes from a diverging
// step; it is clamped so that the conversion stays defined, and the divergence check
// catches the run.
fn renormalize_turn(s: ptr<function, State>) {
    let rem = (*s).q[0].z;
    let whole = round(clamp(rem, -1.0e9, 1.0e9));
    (*s).q[0].z = rem - whole;
    (*s).turn = (*s).turn + bitcast<u32>(i32(whole));
}

// The orientation in radians, in [-pi, pi) (output and f32 uses only).
fn angle(s: State) -> f32 {
    return (f32(bitcast<i32>(s.turn)) + s.q[0].z) * TURN_UNIT;
}

// a * b / 2^31 for Q31 magnitudes (at most 1.0 = 2^31), truncated.
fn mul_q31(a: u32, b: u32) -> u32 {
    let p = mul_wide(a, b);
    return (p.y << 1u) | (p.x >> 31u);
}

// (sin, cos) of 2 pi turn / 2^32 in Q31 (magnitudes clamped below 1.0 so that they fit
// an i32), to about 2e-9. Reduction to the nearest quarter turn is exact in integers;
// on [-pi/4, pi/4] the Taylor series are taken to y^13 and y^14 (next terms < 1e-12).
fn turn_sin_cos(turn: u32) -> vec2<i32> {
    let k = (turn + 0x20000000u) >> 30u;
    let r = bitcast<i32>(turn - (k << 30u));   // in [-2^29, 2^29)
    let p = mul_wide(u32(abs(r)), TWO_PI_Q29);
    let y = (p.y << 2u) | (p.x >> 30u);       // |r| 2 pi / 2^32 in Q31
    let z = mul_q31(y, y);
    var f = Q31_ONE - z / 156u;
    f = Q31_ONE - mul_q31(z / 110u, f);
    f = Q31_ONE - mul_q31(z / 72u, f);
    f = Q31_ONE - mul_q31(z / 42u, f);
    f = Q31_ONE - mul_q31(z / 20u, f);
    f = Q31_ONE - mul_q31(z / 6u, f);
    var g = Q31_ONE - z / 182u;
    g = Q31_ONE - mul_q31(z / 132u, g);
    g = Q31_ONE - mul_q31(z / 90u, g);
    g = Q31_ONE - mul_q31(z / 56u, g);
    g = Q31_ONE - mul_q31(z / 30u, g);
    g = Q31_ONE - mul_q31(z / 12u, g);
    g = Q31_ONE - mul_q31(z / 2u, g);
    var sn = i32(min(mul_q31(y, f), 0x7FFFFFFFu));
    let cs = i32(min(g, 0x7FFFFFFFu));
    if (r < 0) { sn = -sn; }
    if (k == 1u) { return vec2<i32>(cs, -sn); }
    if (k == 2u) { return vec2<i32>(-sn, -cs); }
    if (k == 3u) { return vec2<i32>(-cs, sn); }
    return vec2<i32>(sn, cs);
}

// a * b as a two's-complement 64-bit integer.
fn smul(a: i32, b: i32) -> vec2<u32> {
    let m = mul_wide(u32(abs(a)), u32(abs(b)));
    if ((a < 0) != (b < 0)) { return sub64(vec2<u32>(0u, 0u), m); }
    return m;
}

// A 64-bit value divided by 2^31, rounded (the result must fit an i32).
fn round_q31(v: vec2<u32>) -> i32 {
    let r = add64(v, vec2<u32>(0x40000000u, 0u));
    return bitcast<i32>((r.y << 1u) | (r.x >> 31u));
}

// R(theta) v for a corner v in whole units and sc = turn_sin_cos(turn).
fn rotate_units(v: vec2<i32>, sc: vec2<i32>) -> vec2<i32> {
    let x = sub64(smul(sc.y, v.x), smul(sc.x, v.y));
    let z = add64(smul(sc.x, v.x), smul(sc.y, v.y));
    return vec2<i32>(round_q31(x), round_q31(z));
}

// Rotates particle i's corners to its orientation in `s`: corners[].xy in the body
// frame, corners[].zw in the world orientation, both in whole units.
fn rotate_corners(i: u32, s: State) {
    let sh = props[i].shape;
    if (sh.y == 0u) { return; }
    let sc = turn_sin_cos(s.turn);
    for (var m = 0u; m < sh.y; m++) {
        let c = corners[sh.x + m];
        corners[sh.x + m] = vec4<i32>(c.xy, rotate_units(c.xy, sc));
    }
}

// The first-order move (units) of a rotated corner w for the orientation remainder.
fn corner_spin(w: vec2<i32>, rem_turns: f32) -> vec2<f32> {
    return (rem_turns * TURN_UNIT) * vec2<f32>(-f32(w.y), f32(w.x));
}
