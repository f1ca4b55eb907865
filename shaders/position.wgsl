// Fixed-point positions (SPEC 3 precision; host twin src/gpu/position.rs).
//
// A coordinate is a whole cell `anchor` (i32), a whole number of units `frac` in
// [0, 2^30) below one cell, with unit = cell_size / 2^30 (about 1e-9 of a diameter), and
// an f32 remainder `rem` in units, kept in [-0.5, 0.5] (q[0].xy of State). Radii are
// stored the same way (`radius_units` + `radius_rem`).
//
// Why: overlaps are 1e-5..1e-2 of a diameter and must be right to 1e-3, so the overlap
// delta = sigma - |d| needs about 1e-9 d absolute. In f32, |d| ~ sigma ~ 1 d carries only
// 6e-8 d, and a resting particle's position update (1e-10 d per step) is rounded away.
// Here the vector between neighbours is an exact i32 number of units plus the difference
// of two remainders, and |d| is computed as a whole number of units plus a small f32
// correction from an exact 64-bit integer residual. Nothing relies on the order of
// float operations (no error-free transformations), so compilers that reassociate or
// fuse float arithmetic cannot break it; the cost is a few dozen integer operations per
// pair.

const FRAC_ONE: i32 = 1073741824;   // 2^30 units per cell
const FRAC_MASK: i32 = 1073741823;

// The vector from point j to point i: exact `d` units plus `e` (remainders), valid when
// `near` (anchors at most one cell apart, which every pair within range is).
struct Offset {
    d: vec2<i32>,
    e: vec2<f32>,
    da: vec2<i32>,
    near: bool,
};

fn offset(ai: vec2<i32>, fi: vec2<u32>, ri: vec2<f32>,
          aj: vec2<i32>, fj: vec2<u32>, rj: vec2<f32>) -> Offset {
    let da = ai - aj;
    let near = all(abs(da) <= vec2<i32>(1));
    // Wraps when not near; then only `da` and the f32 vector are used.
    let d = da * FRAC_ONE + (vec2<i32>(fi) - vec2<i32>(fj));
    return Offset(d, ri - rj, da, near);
}

fn offset_ij(i: u32, j: u32) -> Offset {
    // Only the position's fields (a copy of the whole State would load 128 bytes each).
    let ai = state[i].anchor;
    return offset(ai, state[i].frac, state[i].q[0].xy,
                  image_anchor(ai, state[j].anchor), state[j].frac, state[j].q[0].xy);
}

// In a domain periodic in x (params.period_cells > 0), the anchor of the image of aj
// nearest to ai (src/state.rs `nearest_image`): shifted by the period in whole cells,
// so that the offset stays exact. Between two particles only, never to a wall's end.
fn image_anchor(ai: vec2<i32>, aj: vec2<i32>) -> vec2<i32> {
    if (params.period_cells == 0u) { return aj; }
    let p = i32(params.period_cells);
    let dx = ai.x - aj.x;
    var a = aj;
    if (dx > p / 2) { a.x += p; } else if (dx < -(p / 2)) { a.x -= p; }
    return a;
}

// An anchor's cell column brought into [0, period) (src/sim/start.rs `wrap`): a centre
// that left through one side comes back through the other, by whole cells (exact).
fn wrap_anchor(a: vec2<i32>) -> vec2<i32> {
    if (params.period_cells == 0u) { return a; }
    let p = i32(params.period_cells);
    var w = a;
    if (w.x < 0) { w.x += p; } else if (w.x >= p) { w.x -= p; }
    return w;
}

// The offset as an f32 vector in length units, to f32's relative precision of its
// length wherever the two points are.
fn offset_vector(o: Offset) -> vec2<f32> {
    if (o.near) { return (vec2<f32>(o.d) + o.e) * params.unit; }
    let df = vec2<f32>(o.d - o.da * FRAC_ONE);
    return vec2<f32>(o.da) * params.cell_size + (df + o.e) * params.unit;
}

// Position from the grid origin, in f32 (domain checks and output only).
fn position(s: State) -> vec2<f32> {
    return vec2<f32>(s.anchor) * params.cell_size + (vec2<f32>(s.frac) + s.q[0].xy) * params.unit;
}

// --- 64-bit integer arithmetic on (lo, hi) pairs ---

fn mul_wide(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xFFFFu;
    let a1 = a >> 16u;
    let b0 = b & 0xFFFFu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = (p00 >> 16u) + (p01 & 0xFFFFu) + (p10 & 0xFFFFu);
    let lo = (p00 & 0xFFFFu) | (mid << 16u);
    let hi = p11 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u);
    return vec2<u32>(lo, hi);
}

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

fn sub64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(a.x - b.x, a.y - b.y - select(0u, 1u, a.x < b.x));
}

// A two's-complement 64-bit integer to the nearest f32 (within 2 roundings).
fn i64_to_f32(v: vec2<u32>) -> f32 {
    let negative = (v.y & 0x80000000u) != 0u;
    var m = v;
    if (negative) { m = sub64(vec2<u32>(0u, 0u), v); }
    let x = f32(m.y) * 4294967296.0 + f32(m.x);
    return select(x, -x, negative);
}

// |d + e| in units as a whole number `whole` plus an f32 `corr` (|corr| < ~1e3).
// r0 is |d| rounded in f32; the residual |d + e|^2 - r0^2 = (|d|^2 - r0^2) + 2 d.e + e.e
// has its large part computed exactly in 64-bit integers, and then
// |d + e| - r0 = residual / (r0 + |d + e|) without cancellation.
struct Distance {
    whole: u32,   // up to 2^31.5 for neighbours one cell apart diagonally
    corr: f32,
};

fn distance_units(d: vec2<i32>, e: vec2<f32>) -> Distance {
    let df = vec2<f32>(d);
    let r0 = u32(round(length(df)));
    let ax = u32(abs(d.x));
    let az = u32(abs(d.y));
    let exact = sub64(add64(mul_wide(ax, ax), mul_wide(az, az)), mul_wide(r0, r0));
    let t = i64_to_f32(exact) + 2.0 * dot(df, e) + dot(e, e);
    let r0f = f32(r0);
    var corr = 0.0;
    if (t != 0.0) { corr = t / (r0f + sqrt(max(r0f * r0f + t, 0.0))); }
    return Distance(r0, corr);
}

// Moves whole units of the remainder into `frac` and whole cells into `anchor`
// (exact: rem - round(rem) is representable), so that |rem| <= 0.5 and
// 0 <= frac < 2^30.
fn renormalize(s: ptr<function, State>) {
    // Per axis, without a loop: an index into a vector that is not a constant puts the
    // whole state in memory on most compilers.
    let x = renormalize_axis((*s).q[0].x, (*s).anchor.x, (*s).frac.x);
    let z = renormalize_axis((*s).q[0].y, (*s).anchor.y, (*s).frac.y);
    (*s).q[0] = vec4<f32>(x.rem, z.rem, (*s).q[0].zw);
    (*s).anchor = wrap_anchor(vec2<i32>(x.anchor, z.anchor));
    (*s).frac = vec2<u32>(x.frac, z.frac);
}

// One coordinate of a fixed-point position (anchor, frac, remainder).
struct Axis {
    anchor: i32,
    frac: u32,
    rem: f32,
};

fn renormalize_axis(rem_in: f32, anchor: i32, frac: u32) -> Axis {
    var rem = rem_in;
    var a = anchor;
    // A move of a cell or more in one step (only while diverging): whole cells first.
    if (abs(rem) >= 5.0e8) {
        let c = trunc(rem / f32(FRAC_ONE));
        rem -= c * f32(FRAC_ONE);
        a += i32(c);
    }
    let whole = round(rem);
    rem -= whole;
    let f = i32(frac) + i32(whole);
    a += f >> 30u;
    return Axis(a, u32(f & FRAC_MASK), rem);
}

// --- q1 = v dt in fixed point (issue 14 item 5) ---
// q1 is whole units (position units along x and z, turn units of the rotation:
// State.q1_whole) plus an f32 rest in length and radians (q[1].xyz), at most half a unit
// after `renormalize_q1`. Each step adds to q1 an increment much smaller than q1 itself
// (2 q2 in free fall); in f32 alone the sum rounds by half an ulp of q1 at every step,
// and the velocity drifts (6e-5 of it over 10^4 steps). Here the whole units add exactly
// and only the increment is rounded.

// q1 in length and radians (f32: the velocity the contacts see).
fn q1_total(whole: vec4<i32>, rest: vec4<f32>) -> vec3<f32> {
    return vec3<f32>(vec2<f32>(whole.xy) * params.unit, f32(whole.z) * TURN_UNIT) + rest.xyz;
}

// Moves the whole units of q1's rest into q1_whole.
fn renormalize_q1(s: ptr<function, State>) {
    let w = round((*s).q[1].xy * params.inv_unit);
    let t = round((*s).q[1].z * INV_TURN_UNIT);
    (*s).q1_whole += vec4<i32>(vec2<i32>(w), i32(t), 0);
    let rest = vec3<f32>((*s).q[1].xy - w * params.unit, (*s).q[1].z - t * TURN_UNIT);
    (*s).q[1] = vec4<f32>(rest, (*s).q[1].w);
}

// Moves the position and the orientation by q1's whole units, exactly (the rest moves
// them through `displace` and `turn_by`).
fn move_by_whole_q1(s: ptr<function, State>) {
    let f = vec2<i32>((*s).frac) + (*s).q1_whole.xy;
    (*s).anchor = wrap_anchor((*s).anchor + (f >> vec2<u32>(30u)));
    (*s).frac = vec2<u32>(f & vec2<i32>(FRAC_MASK));
    (*s).turn += bitcast<u32>((*s).q1_whole.z);
}

// Adds a displacement (length units) to the position.
fn displace(s: ptr<function, State>, by: vec2<f32>) {
    let r = (*s).q[0].xy + by * params.inv_unit;
    (*s).q[0] = vec4<f32>(r, (*s).q[0].zw);
}
