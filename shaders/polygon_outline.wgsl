// Convex polygons in the overlap-area law (src/overlap/, SPEC 2.3): what every polygon
// query shares. The pieces: `AreaContact`, a polygon's `Outline` in the pair's frame and
// its corners, the frame along a contact line, crossings of two edges, the cut of an edge
// by half-planes. The queries: polygon.wgsl (two polygons), polygon_wall.wgsl,
// polygon_disk.wgsl, disk_area.wgsl; which one a pair takes: area_contact.wgsl. They are
// assembled in that order after this file (src/gpu/modules.rs).
//
// Precision (SPEC 3; README "Precision"). Corners are whole position units in a frame
// at particle j's centre (exact: the fixed-point offset and corners rotated in integers,
// orientation.wgsl) plus small f32 remainders. The cutting runs in f32, in units, in a
// frame centred between the pair: it finds the lines that bound the overlap, the
// crossings, the force point and the normal to ~3e-8 d, plenty for them. Not for the
// area: a resting contact is a sliver ~1e-5 d thin, and f32 corners half a diameter out
// carry 3e-8 d. So the area is computed again from the lines, in a frame along the
// contact line: each overlap corner's distance w from that line comes from exact 64-bit
// integer dot and cross products (a corner of p or q directly; a crossing by
// interpolating along whichever of its two edges is flatter, from the nearer end), and
// A = 1/2 sum (w_s + w_e)(u_s - u_e) over the boundary's pieces needs the coordinates u
// along the line only to f32. A/l is then right to ~1e-9 d however thin the overlap.

// Set when the pipelines are built for the overlap-area law (src/gpu/kernels.rs). The
// other laws compile without the polygon branches, which would otherwise cost every
// disk contact registers.
override POLYGONS: bool = false;
// Corners of a polygon at most (src/shape/mod.rs). The cut keeps a bit per edge and two per
// crossing in a u32 and an edge's number in four bits: at most 16.
const MAX_CORNERS: u32 = 16u;
// Which shapes the scene has, now or from its sources (src/gpu/kernels.rs `Build`), and
// whether it has walls: the pipelines leave out the contact branches of the others.
override POLYGON_SHAPES: bool = true;
override DISK_SHAPES: bool = true;
override WALLS: bool = true;
// Set when the pipelines are built for spheropolygons (law hertz_cohesive;
// spheropolygon.wgsl); like POLYGONS, contact_forces then takes a thread per pair.
override SPHEROPOLYGONS: bool = false;

struct AreaContact {
    area: f32,
    n: vec2<f32>,       // from j to i
    point: vec2<f32>,   // force point S
    chord: f32,
    l: f32,
    found: bool,
};

fn no_contact() -> AreaContact {
    return AreaContact(0.0, vec2<f32>(0.0, 1.0), vec2<f32>(0.0), 0.0, 0.0, false);
}

// A polygon in a contact frame, read where it lies: corner m is `base` plus its rotated
// corner `corners[first + m].zw` in whole units, plus an f32 remainder `e` shared by
// all and the first-order turn of the orientation remainder `spin` (turn units) about
// the centre `base`. No copy of the corners: a per-thread array of them is local
// memory on a GPU, and on a software adapter every thread's copy is zeroed and written
// lane by lane (issue 14 item 5).
// `reach`: the circumscribed radius (units).
struct Outline {
    first: u32,
    n: u32,
    base: vec2<i32>,
    e: vec2<f32>,
    spin: f32,
    reach: f32,
};

fn load_outline(k: u32, base: vec2<i32>, e: vec2<f32>) -> Outline {
    let sh = props[k].shape;
    let reach = f32(props[k].radius_units) + props[k].radius_rem;
    return Outline(sh.x, sh.y, base, e, state[k].q[0].z, reach);
}

// The centre in f32 units relative to the point h of the frame.
fn centre_at(o: ptr<function, Outline>, h: vec2<i32>) -> vec2<f32> {
    return vec2<f32>((*o).base - h) + (*o).e;
}

// Corner m as stored: whole units relative to the centre, rotated (`rotate_corners`).
// Each read is a load from memory per thread, lane by lane on a software adapter: the
// functions below take a corner once read (`c`) where they can.
fn corner_rel(o: ptr<function, Outline>, m: u32) -> vec2<i32> {
    return corners[(*o).first + m].zw;
}

// Corner m in whole units.
fn ow(o: ptr<function, Outline>, m: u32) -> vec2<i32> {
    return (*o).base + corner_rel(o, m);
}

// The corner after m.
fn next_corner(o: ptr<function, Outline>, m: u32) -> u32 {
    return select(m + 1u, 0u, m + 1u >= (*o).n);
}

// The remainder (units) of the corner read as c.
fn e_of(o: ptr<function, Outline>, c: vec2<i32>) -> vec2<f32> {
    return (*o).e + corner_spin(c, (*o).spin);
}

// The corner read as c in f32 units relative to the point h of the frame.
fn at_of(o: ptr<function, Outline>, c: vec2<i32>, h: vec2<i32>) -> vec2<f32> {
    return vec2<f32>((*o).base + c - h) + e_of(o, c);
}

// The remainder of corner m (units).
fn corner_e(o: ptr<function, Outline>, m: u32) -> vec2<f32> {
    return e_of(o, corner_rel(o, m));
}

// Corner m in f32 units relative to the point h of the frame.
fn corner_at(o: ptr<function, Outline>, m: u32, h: vec2<i32>) -> vec2<f32> {
    return at_of(o, corner_rel(o, m), h);
}

fn reduced_arm(li: f32, lj: f32, scale: f32) -> f32 {
    let floor = 1.0e-6 * scale;
    let a = max(li, floor);
    let b = max(lj, floor);
    return a * b / (a + b);
}

// --- exact distances from the contact line ---

// The frame of the exact area: the point o (whole units; `at` in clip coordinates) on
// the contact line, its unit normal n in f32 and in Q30 integers, and the direction t
// along the line; (t, n) is right-handed. Clip coordinates are relative to h.
struct Frame {
    o: vec2<i32>,
    nq: vec2<i32>,
    n: vec2<f32>,
    t: vec2<f32>,
    at: vec2<f32>,
    h: vec2<i32>,
};

fn make_frame(h: vec2<i32>, s: vec2<f32>, n: vec2<f32>) -> Frame {
    let o = h + vec2<i32>(round(s));
    return Frame(o, vec2<i32>(round(n * Q30)), n, vec2<f32>(n.y, -n.x), vec2<f32>(o - h), h);
}

// (u, w) of corner m: w exact; u along the line from the exact integer offset of the
// corner from the frame point o, rounded once in f32, so a corner near the contact
// keeps f32's relative precision of its small distance from it (issue 19).
fn corner_uw(o: ptr<function, Outline>, m: u32, fr: Frame) -> vec2<f32> {
    return corner_uw_of(o, corner_rel(o, m), fr);
}

// `corner_uw` of the corner read as c: w = (x - o).n from an exact 64-bit dot product.
fn corner_uw_of(o: ptr<function, Outline>, c: vec2<i32>, fr: Frame) -> vec2<f32> {
    let d = (*o).base + c - fr.o;
    let e = e_of(o, c);
    let exact = add64(smul(d.x, fr.nq.x), smul(d.y, fr.nq.y));
    return vec2<f32>(dot(vec2<f32>(d) + e, fr.t), i64_to_f32(exact) / Q30 + dot(e, fr.n));
}

// (b - a) x (x - a) of three corners (whole units and remainders), the large part exact
// in 64-bit integers and the remainders to first order.
fn cross_units(aw: vec2<i32>, ae: vec2<f32>, bw: vec2<i32>, be: vec2<f32>,
               xw: vec2<i32>, xe: vec2<f32>) -> f32 {
    let ab = bw - aw;
    let ax = xw - aw;
    let exact = sub64(smul(ab.x, ax.y), smul(ab.y, ax.x));
    let abe = be - ae;
    let axe = xe - ae;
    return i64_to_f32(exact) + (f32(ab.x) * axe.y - f32(ab.y) * axe.x)
        + (abe.x * f32(ax.y) - abe.y * f32(ax.x));
}

// Where a segment whose ends are at signed distances dx, dy crosses a line: the
// parameter from each end, (s, 1 - s), each its own quotient (1 - s taken from s near
// 1 would keep only f32's absolute precision, 6e-8, of a small number).
fn crossing_param(dx: f32, dy: f32) -> vec2<f32> {
    if (dx == dy) { return vec2<f32>(0.5); }
    return clamp(vec2<f32>(dx, -dy) / (dx - dy), vec2<f32>(0.0), vec2<f32>(1.0));
}

// w at parameters s = (from x, from y) between ends with wx, wy, from the nearer end;
// and the size of its error in units of the parameter's relative error.
fn interpolate_w(wx: f32, wy: f32, s: vec2<f32>) -> vec2<f32> {
    if (s.x <= 0.5) { return vec2<f32>(wx + s.x * (wy - wx), s.x * abs(wy - wx)); }
    return vec2<f32>(wy + s.y * (wx - wy), s.y * abs(wy - wx));
}

// (u, w) of the crossing of p's edge mp with q's edge mq, interpolated along the
// flatter of the two with the exact crossing parameter. (The f32 clip's crossing of two
// nearly parallel edges can be far off along them: its u is not used.)
fn crossing_uw(p: ptr<function, Outline>, mp: u32, q: ptr<function, Outline>, mq: u32,
               fr: Frame) -> vec2<f32> {
    let cx = corner_rel(p, mp);
    let cy = corner_rel(p, next_corner(p, mp));
    let ca = corner_rel(q, mq);
    let cb = corner_rel(q, next_corner(q, mq));
    let xw = (*p).base + cx;
    let yw = (*p).base + cy;
    let aw = (*q).base + ca;
    let bw = (*q).base + cb;
    let xe = e_of(p, cx);
    let ye = e_of(p, cy);
    let ae = e_of(q, ca);
    let be = e_of(q, cb);
    let s = crossing_param(cross_units(aw, ae, bw, be, xw, xe), cross_units(aw, ae, bw, be, yw, ye));
    let r = crossing_param(cross_units(xw, xe, yw, ye, aw, ae), cross_units(xw, xe, yw, ye, bw, be));
    let px = corner_uw_of(p, cx, fr);
    let py = corner_uw_of(p, cy, fr);
    let qa = corner_uw_of(q, ca, fr);
    let qb = corner_uw_of(q, cb, fr);
    let on_p = interpolate_w(px.y, py.y, s);
    let on_q = interpolate_w(qa.y, qb.y, r);
    if (on_p.y <= on_q.y) { return vec2<f32>(interpolate_w(px.x, py.x, s).x, on_p.x); }
    return vec2<f32>(interpolate_w(qa.x, qb.x, r).x, on_q.x);
}

// --- polygon against polygon: the overlap from the edges, with no clipped copy ---
//
// The overlap of two convex polygons is bounded by the parts of p's edges inside q and
// the parts of q's edges inside p. Each edge is cut to the interval of it inside every
// half-plane of the other polygon (`edges_inside`); the interval's ends are a corner or
// a crossing of the outlines, known by the two edges that cross. Everything the
// contact needs comes from these intervals with no list of the overlap's corners: the
// crossings (an interval of p that starts or ends inside an edge), the corners of each
// polygon inside the other, and the area, A = 1/2 sum over the intervals of
// (w_s + w_e)(u_s - u_e) in the frame of the contact line (the trapezoid rule needs
// each boundary piece's ends, not their order). Only the edges facing each other are
// cut, by the half-planes facing them (`facing_edges`: along the line of centres u, p's
// edges reaching beyond q's nearest point and q's reaching short of p's farthest);
// src/overlap/polygon.rs takes the same steps in f64, and these loops keep everything
// in registers (a per-thread list of clipped corners is local memory on a GPU, issue
// 14 item 5).

// Polygon a's edges inside polygon b. Bit e of `pieces`: part of edge e (corner e to
// the next) lies in b; of `cross`, bit 2e: that part starts at a crossing with b's edge
// nibble e of `entry` (else at corner e), bit 2e + 1: it ends at a crossing with b's
// edge nibble e of `exit` (else at corner e + 1). Bit e of `corners`: corner e lies in
// b; `sum` adds those corners up, `cross_sum` the crossings (f32 clip coordinates).
struct Inside {
    pieces: u32,
    cross: u32,
    entry: vec2<u32>,
    exit: vec2<u32>,
    corners: u32,
    sum: vec2<f32>,
    cross_sum: vec2<f32>,
    area2: f32,   // sum of s x e over the parts (twice their share of the f32 area)
};

fn put_nibble(v: vec2<u32>, e: u32, x: u32) -> vec2<u32> {
    let bits = x << (4u * (e & 7u));
    if (e < 8u) { return vec2<u32>(v.x | bits, v.y); }
    return vec2<u32>(v.x, v.y | bits);
}

fn nibble(v: vec2<u32>, e: u32) -> u32 {
    return (select(v.y, v.x, e < 8u) >> (4u * (e & 7u))) & 15u;
}

// Where the edge x-y crosses the line of b's edge f (x + s (y - x), the f32 parameter
// of the cut in `edges_inside`).
fn edge_cut(x: vec2<f32>, y: vec2<f32>, b: ptr<function, Outline>, f: u32, h: vec2<i32>) -> f32 {
    let ba = corner_at(b, f, h);
    let bb = corner_at(b, next_corner(b, f), h);
    let m = vec2<f32>(-(bb.y - ba.y), bb.x - ba.x);
    let dx = dot(x - ba, m);
    let dy = dot(y - ba, m);
    return dx / (dx - dy);
}

// `run`: false skips it (every loop runs no turn: on a software adapter, which takes
// every branch of every thread, a branch skipped costs as much as one taken, and a loop
// of no turns costs one).
// The part [t0, t1] of an edge x-y inside some half-planes (Cyrus-Beck): the lines it
// enters and leaves by (their number + 1; 0: it starts at x, ends at y), whether x is
// inside them all, and whether the edge lies wholly outside one.
struct Cut {
    t0: f32,
    t1: f32,
    fin: u32,
    fout: u32,
    x_in: bool,
    empty: bool,
};

fn uncut() -> Cut {
    return Cut(0.0, 1.0, 0u, 0u, true, false);
}

// Cuts by the half-plane (z - a).m >= 0, line number `line`, where x and y lie at dx
// and dy (counter-clockwise outlines: inside is to the left of each edge).
fn cut_by(c: ptr<function, Cut>, dx: f32, dy: f32, line: u32) {
    (*c).x_in = (*c).x_in && dx >= 0.0;
    if (dx < 0.0 && dy < 0.0) { (*c).empty = true; }
    let s = dx / (dx - dy);
    if (dx < 0.0 && dy >= 0.0 && s > (*c).t0) { (*c).t0 = s; (*c).fin = line + 1u; }
    if (dx >= 0.0 && dy < 0.0 && s < (*c).t1) { (*c).t1 = s; (*c).fout = line + 1u; }
}

// Up to eight half-planes (a point of the line, xy; its inward normal, zw).
struct Planes {
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
    p3: vec4<f32>,
    p4: vec4<f32>,
    p5: vec4<f32>,
    p6: vec4<f32>,
    p7: vec4<f32>,
};

fn keep_plane(k: Planes, slot: u32, v: vec4<f32>) -> Planes {
    return Planes(select(k.p0, v, slot == 0u), select(k.p1, v, slot == 1u),
                  select(k.p2, v, slot == 2u), select(k.p3, v, slot == 3u),
                  select(k.p4, v, slot == 4u), select(k.p5, v, slot == 5u),
                  select(k.p6, v, slot == 6u), select(k.p7, v, slot == 7u));
}

fn kept_plane(k: Planes, slot: u32) -> vec4<f32> {
    var v = k.p0;
    v = select(v, k.p1, slot == 1u);
    v = select(v, k.p2, slot == 2u);
    v = select(v, k.p3, slot == 3u);
    v = select(v, k.p4, slot == 4u);
    v = select(v, k.p5, slot == 5u);
    v = select(v, k.p6, slot == 6u);
    return select(v, k.p7, slot == 7u);
}

// The largest reach of a's corners along u (clip coordinates): `reaches` in
// src/overlap/polygon.rs.
fn reach_along(a: ptr<function, Outline>, u: vec2<f32>, h: vec2<i32>) -> f32 {
    var most = -3.0e38;
    for (var k = 0u; k < (*a).n; k++) {
        most = max(most, dot(corner_at(a, k, h), u));
    }
    return most;
}

// The edges of a that reach to the far side of the line u.x = t: those with a corner
// there (`facing_edges` in src/overlap/polygon.rs).
fn facing_edges(a: ptr<function, Outline>, u: vec2<f32>, t: f32, h: vec2<i32>) -> u32 {
    let n = (*a).n;
    var beyond = 0u;
    for (var k = 0u; k < n; k++) {
        if (dot(corner_at(a, k, h), u) >= t) { beyond |= 1u << k; }
    }
    return beyond | (beyond >> 1u) | ((beyond & 1u) << (n - 1u));
}

// Whether the point x (clip coordinates) lies inside a, on an edge counting as inside.
fn contains(a: ptr<function, Outline>, x: vec2<f32>, h: vec2<i32>) -> bool {
    let n = (*a).n;
    let a0 = corner_at(a, 0u, h);
    var c = a0;
    var inside = true;
    for (var k = 0u; k < n; k++) {
        var d = a0;
        if (k + 1u < n) { d = corner_at(a, k + 1u, h); }
        inside = inside && cross2(d - c, x - c) >= 0.0;
        c = d;
    }
    return inside;
}
