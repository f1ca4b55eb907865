// Overlap-area geometry of convex polygons (src/overlap/, SPEC 2.3). Two polygons:
// each one's edges facing the other cut to the part inside it (`edges_inside`), whose
// ends are corners or crossings of the outlines (`polygon_polygon`); the twin of
// src/overlap/polygon.rs, step for step (issue 37 item 1). A polygon and a wall: p's
// edges cut by the wall's line and the lines across its ends (`polygon_wall`). The
// line through the two crossings farthest apart gives the normal, its midpoint the
// force point. (The CPU path also keeps a hint per candidate that lets a resting or
// apart pair skip the cut, src/overlap/hint.rs; the result is the cut's either way.)
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

// The parts of a's edges `edges` inside b, whose half-planes `planes` are the only ones
// that can cut them (`polygon_polygon` finds both: the edges facing each other).
fn edges_inside(a: ptr<function, Outline>, edges: u32, b: ptr<function, Outline>, planes: u32,
                h: vec2<i32>, run: bool) -> Inside {
    var r = Inside(0u, 0u, vec2<u32>(0u), vec2<u32>(0u), 0u, vec2<f32>(0.0), vec2<f32>(0.0), 0.0);
    if (!run || edges == 0u) { return r; }
    // The half-planes, the first eight kept in registers: each corner read is a load of
    // its own (lane by lane on a software adapter), and the cut below reads each
    // half-plane once per edge.
    var kept = Planes(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0),
                      vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    var n_kept = 0u;
    var each = planes;
    while (each != 0u && n_kept < 8u) {
        let f = firstTrailingBit(each);
        each &= each - 1u;
        let ba = corner_at(b, f, h);
        let bb = corner_at(b, next_corner(b, f), h);
        kept = keep_plane(kept, n_kept, vec4<f32>(ba, -(bb.y - ba.y), bb.x - ba.x));
        n_kept++;
    }
    var left = edges;
    while (left != 0u) {
        let e = firstTrailingBit(left);
        left &= left - 1u;
        let x = corner_at(a, e, h);
        let y = corner_at(a, next_corner(a, e), h);
        // The part of x-y inside the half-planes (z - b_f).m_f >= 0 of b.
        var cut = uncut();
        var cutting = planes;
        var k = 0u;
        while (cutting != 0u) {
            let f = firstTrailingBit(cutting);
            cutting &= cutting - 1u;
            var pl = kept_plane(kept, k);
            if (k >= 8u) {
                let fa = corner_at(b, f, h);
                let fb = corner_at(b, next_corner(b, f), h);
                pl = vec4<f32>(fa, -(fb.y - fa.y), fb.x - fa.x);
            }
            k++;
            cut_by(&cut, dot(x - pl.xy, pl.zw), dot(y - pl.xy, pl.zw), f);
        }
        if (cut.x_in) {
            r.corners |= 1u << e;
            r.sum += x;
        }
        if (!cut.empty && cut.t0 < cut.t1) {
            r.pieces |= 1u << e;
            r.area2 += cross2(x + cut.t0 * (y - x), x + cut.t1 * (y - x));
            if (cut.fin > 0u) {
                r.cross |= 1u << (2u * e);
                r.entry = put_nibble(r.entry, e, cut.fin - 1u);
                r.cross_sum += x + cut.t0 * (y - x);
            }
            if (cut.fout > 0u) {
                r.cross |= 2u << (2u * e);
                r.exit = put_nibble(r.exit, e, cut.fout - 1u);
                r.cross_sum += x + cut.t1 * (y - x);
            }
        }
    }
    return r;
}

// Crossing k of `in_p` (bit k of `cross`): p's edge and q's edge that cross there.
fn crossing_edges(in_p: Inside, k: u32) -> vec2<u32> {
    let e = k >> 1u;
    return vec2<u32>(e, nibble(select(in_p.entry, in_p.exit, (k & 1u) == 1u), e));
}

// Crossing k in f32 clip coordinates.
fn crossing_at(p: ptr<function, Outline>, q: ptr<function, Outline>, in_p: Inside, k: u32,
               h: vec2<i32>) -> vec2<f32> {
    let pq = crossing_edges(in_p, k);
    let x = corner_at(p, pq.x, h);
    let y = corner_at(p, next_corner(p, pq.x), h);
    return x + edge_cut(x, y, q, pq.y, h) * (y - x);
}

// The exact (u, w) of up to four crossings (bit k of the p pass's `cross` in `key`),
// each computed once: a crossing ends one part of an edge and starts the next, and a
// crossing's (u, w) is the costliest value here. Two polygons resting on each other
// cross twice; only a deep overlap crosses more than four times, and its area is then
// large enough for f32 (`polygon_polygon`).
struct Crossings {
    key: vec4<u32>,
    u: vec4<f32>,
    w: vec4<f32>,
};

fn crossings_uw(p: ptr<function, Outline>, q: ptr<function, Outline>, in_p: Inside,
                fr: Frame) -> Crossings {
    var c = Crossings(vec4<u32>(64u), vec4<f32>(0.0), vec4<f32>(0.0));
    var left = in_p.cross;
    var slot = 0u;
    while (left != 0u) {
        let k = firstTrailingBit(left);
        left &= left - 1u;
        let pq = crossing_edges(in_p, k);
        let uw = crossing_uw(p, pq.x, q, pq.y, fr);
        let here = vec4<u32>(0u, 1u, 2u, 3u) == vec4<u32>(slot);
        c.key = select(c.key, vec4<u32>(k), here);
        c.u = select(c.u, vec4<f32>(uw.x), here);
        c.w = select(c.w, vec4<f32>(uw.y), here);
        slot++;
    }
    return c;
}

// Crossing k's (u, w) and 1, or 0 if it is not among them.
fn crossing_of(c: Crossings, k: u32) -> vec3<f32> {
    let hit = select(vec4<f32>(0.0), vec4<f32>(1.0), c.key == vec4<u32>(k));
    return vec3<f32>(dot(hit, c.u), dot(hit, c.w), dot(hit, vec4<f32>(1.0)));
}

// The trapezoid sum 1/2 sum (w_s + w_e)(u_s - u_e) over the parts of a's edges inside
// the other polygon (a_is_p: a is p, the other q), each end exact (`corner_uw`, or the
// crossing's from `c`); and whether a crossing was missing from `c`. A crossing is
// named by the p pass's bit: p entering q through edge f is bit 2f, and there q's edge
// leaves p; p leaving q is bit 2f + 1, and there q's edge enters p.
fn pieces_area(a: ptr<function, Outline>, ins: Inside, a_is_p: bool, fr: Frame,
               c: Crossings) -> vec2<f32> {
    var area = 0.0;
    var missing = 0.0;
    var left = ins.pieces;
    while (left != 0u) {
        let e = firstTrailingBit(left);
        left &= left - 1u;
        var s = corner_uw(a, e, fr);
        var t = corner_uw(a, next_corner(a, e), fr);
        if ((ins.cross & (1u << (2u * e))) != 0u) {
            let k = select(2u * nibble(ins.entry, e) + 1u, 2u * e, a_is_p);
            let x = crossing_of(c, k);
            s = x.xy;
            missing += 1.0 - x.z;
        }
        if ((ins.cross & (2u << (2u * e))) != 0u) {
            let k = select(2u * nibble(ins.exit, e), 2u * e + 1u, a_is_p);
            let x = crossing_of(c, k);
            t = x.xy;
            missing += 1.0 - x.z;
        }
        area += (s.y + t.y) * (s.x - t.x);
    }
    return vec2<f32>(0.5 * area, missing);
}

// Area contact of polygon p (centre ci) with polygon q (centre cj), in clip
// coordinates: f32 units relative to the frame point h. Area in units^2.
fn polygon_polygon(p: ptr<function, Outline>, q: ptr<function, Outline>, h: vec2<i32>,
                   ci: vec2<f32>, cj: vec2<f32>) -> AreaContact {
    // The edges facing each other along the line of centres u (from i to j): q lies
    // beyond its nearest reach l_q, p short of its farthest h_p; p's edges reaching
    // beyond l_q and q's reaching short of h_p are the only ones that meet
    // (src/overlap/polygon.rs, the twin). Room for f32's rounding of the reaches.
    var u = vec2<f32>(0.0, 1.0);
    if (length(cj - ci) > 0.0) { u = (cj - ci) / length(cj - ci); }
    let h_p = reach_along(p, u, h);
    let l_q = -reach_along(q, -u, h);
    let room = 1.0e-5 * (abs(h_p) + abs(l_q)) + 1.0e-6 * (*p).reach;
    if (h_p < l_q - room) { return no_contact(); }
    let p_edges = facing_edges(p, u, l_q - room, h);
    let q_edges = facing_edges(q, -u, -(h_p + room), h);
    let in_p = edges_inside(p, p_edges, q, q_edges, h, true);
    let n_x = countOneBits(in_p.cross);
    // Two crossings, p entering q at one and leaving it at the other (polygons resting
    // on each other): q's part of the overlap's outline is the chain of q's edges from
    // where p leaves q to where it enters it again, and q's own cut is not needed. Nor
    // is it when p lies inside q (no crossing, p's edges inside). Otherwise it is: more
    // crossings, or none and q inside p (or no overlap).
    let entries = in_p.cross & 0x55555555u;
    let exits = in_p.cross & 0xAAAAAAAAu;
    let chained = countOneBits(entries) == 1u && countOneBits(exits) == 1u;
    let p_inside = n_x == 0u && in_p.pieces != 0u;
    // With none of p's outline in q they overlap only if q lies inside p, and then so
    // does its first corner.
    let q_in_p = in_p.pieces != 0u || contains(p, corner_at(q, 0u, h), h);
    let in_q = edges_inside(q, q_edges, p, p_edges, h, !chained && !p_inside && q_in_p);
    if (in_p.pieces == 0u && in_q.pieces == 0u) { return no_contact(); }
    // The chain: q's corners g_out + 1 ... g_in, from the crossing out of q (on q's edge
    // g_out) to the one into it (on q's edge g_in); on one edge, none, or all of q's if
    // the crossings follow each other the other way round it.
    let k_in = firstTrailingBit(entries);
    let k_out = firstTrailingBit(exits);
    let g_in = crossing_edges(in_p, k_in).y;
    let g_out = crossing_edges(in_p, k_out).y;
    let nq = (*q).n;
    var links = select(0u, (g_in + nq - g_out) % nq, chained);
    if (chained && g_in == g_out) {
        let along_q = corner_at(q, next_corner(q, g_in), h) - corner_at(q, g_in, h);
        let out_to_in = crossing_at(p, q, in_p, k_in, h) - crossing_at(p, q, in_p, k_out, h);
        if (dot(out_to_in, along_q) < 0.0) { links = nq; }
    }
    var chain_sum = vec2<f32>(0.0);
    for (var k = 0u; k < links; k++) {
        chain_sum += corner_at(q, (g_out + 1u + k) % nq, h);
    }
    let n_p = countOneBits(in_p.corners);
    let n_q = select(countOneBits(in_q.corners), links, chained);
    let q_sum = select(in_q.sum, chain_sum, chained);
    if (n_p + n_q + n_x < 3u) { return no_contact(); }
    let scale = length(cj - ci) + (*p).reach;
    // The two crossings farthest apart (src/overlap/disk.rs `farthest_pair`).
    var best = -1.0;
    var xa = vec2<f32>(0.0);
    var xb = vec2<f32>(0.0);
    var ka = 0u;
    var kb = 0u;
    var left = in_p.cross;
    while (left != 0u) {
        let a = firstTrailingBit(left);
        left &= left - 1u;
        let pa = crossing_at(p, q, in_p, a, h);
        var others = left;
        while (others != 0u) {
            let b = firstTrailingBit(others);
            others &= others - 1u;
            let pb = crossing_at(p, q, in_p, b, h);
            let d = length(pb - pa);
            if (d > best) { best = d; xa = pa; xb = pb; ka = a; kb = b; }
        }
    }
    var g = no_contact();
    g.found = true;
    var along = vec2<f32>(0.0, 1.0);
    if (length(cj - ci) > 0.0) { along = (ci - cj) / length(cj - ci); }
    // The f32 crossings carry ~6e-8 scale: a chord several times that still gives the
    // frame's direction; the chord's size and the normal come from the exact crossings.
    let chord = length(xb - xa);
    var fr: Frame;
    let framed = best >= 0.0 && chord > 4.0e-7 * scale;
    var nn = along;
    var s = vec2<f32>(0.0);
    if (framed) {
        let t = (xb - xa) / chord;
        nn = vec2<f32>(-t.y, t.x);
        s = 0.5 * (xa + xb);
        // Corners of i inside j lie on j's side of the line, corners of j on i's side.
        let side = dot(nn, in_p.sum - f32(n_p) * s) - dot(nn, q_sum - f32(n_q) * s);
        if (side > 0.0 || (side == 0.0 && dot(nn, ci - cj) < 0.0)) { nn = -nn; }
        fr = make_frame(h, s, nn);
    } else {
        // Fewer than two crossings or a vanishing chord: n along the centres, S at the
        // mean of the overlap's corners.
        g.point = (in_p.sum + q_sum + in_p.cross_sum) / f32(n_p + n_q + n_x);
        fr = make_frame(h, g.point, nn);
    }
    let c = crossings_uw(p, q, in_p, fr);
    if (framed) {
        // The crossings again, exact: one between two nearly parallel edges is poorly
        // placed along them by the f32 cut.
        let xa3 = crossing_of(c, ka);
        let xb3 = crossing_of(c, kb);
        let ua = xa3.xy;
        let ub = xb3.xy;
        let d = ub - ua;
        let len = length(d);
        if (len > 1.0e-7 * scale && xa3.z * xb3.z > 0.0) {
            let tt = (d.x * fr.t + d.y * fr.n) / len;
            g.n = vec2<f32>(-tt.y, tt.x) * sign(dot(vec2<f32>(-tt.y, tt.x), nn));
            g.chord = len;
            let mid = 0.5 * (ua + ub);
            g.point = fr.at + mid.x * fr.t + mid.y * fr.n;
        } else {
            g.n = nn;
            g.point = s;
            g.chord = chord;
        }
    } else {
        g.n = along;
        g.chord = 0.0;
    }
    let from_p = pieces_area(p, in_p, true, fr, c);
    var from_q = pieces_area(q, in_q, false, fr, c);
    if (chained) {
        // The chain's trapezoids, from the crossing out of q to the one into it.
        let x_out = crossing_of(c, k_out);
        let x_in = crossing_of(c, k_in);
        var prev = x_out.xy;
        var a = 0.0;
        for (var k = 0u; k < links; k++) {
            let x = corner_uw(q, (g_out + 1u + k) % nq, fr);
            a += (prev.y + x.y) * (prev.x - x.x);
            prev = x;
        }
        a += (prev.y + x_in.y) * (prev.x - x_in.x);
        from_q = vec2<f32>(0.5 * a, 2.0 - x_out.z - x_in.z);
    }
    g.area = from_p.x + from_q.x;
    if (from_p.y + from_q.y > 0.0) {
        // More than four crossings: a deep overlap, whose f32 area is good enough.
        g.area = 0.5 * (in_p.area2 + in_q.area2);
    }
    // (The CPU path counts no overlap thinner than 1e-13 of the radii as a contact,
    // src/overlap/hint.rs THICKNESS_FLOOR: far below f32's resolution here.)
    if (g.area <= 0.0) { return no_contact(); }
    g.l = reduced_arm(length(g.point - ci), length(g.point - cj), scale);
    return g;
}

// Area contact of polygon p (centre at the origin, coordinates in units) with the wall
// segment wa-wb whose line is `l` (geometry.wgsl `wall_line`): the part of p beyond the
// wall's line and between the lines across its ends. As for two polygons, each edge of
// p is cut to its part inside those three half-planes (f32, which only finds the
// lines); the area is the trapezoid sum over the outline's pieces in a frame along the
// wall, with w a point's exact distance from the wall's line and u measured along it
// from p's deepest corner. The outline's other pieces add nothing to it:
// on the wall's line w = 0, and the lines across the ends are perpendicular to it (u
// stays the same along them). The chord is the stretch of the wall's line inside p.
fn polygon_wall(p: ptr<function, Outline>, wa: vec2<f32>, wb: vec2<f32>, l: WallLine) -> AreaContact {
    let ab = wb - wa;
    let len = length(ab);
    if (len == 0.0) { return no_contact(); }
    let m = l.n;
    // The wall's line through the foot of the centre, from its exact distance: an end
    // point can be far (its f32 offset then carries f32's precision of that distance).
    let dist = i64_to_f32(l.c64) / Q30 + l.small;
    let foot = -dist * m;
    let t = vec2<f32>(m.y, -m.x);
    // u from p's deepest corner: the points of a small overlap lie near it, and their
    // u (a few units from it) keep f32's relative precision, as the chord needs.
    let np = (*p).n;
    var deepest = 0u;
    var least = 3.0e38;
    for (var k = 0u; k < np; k++) {
        let along = dot(corner_at(p, k, vec2<i32>(0)), m);
        if (along < least) { least = along; deepest = k; }
    }
    let base = ow(p, deepest);
    let u_a = dot(wa - vec2<f32>(base), t);
    let u_b = dot(wb - vec2<f32>(base), t);
    // Beyond the wall's line; past end a; short of end b.
    let zero = vec4<f32>(0.0);
    let cuts = Planes(vec4<f32>(foot, -m), vec4<f32>(wa, ab), vec4<f32>(wb, -ab),
                      zero, zero, zero, zero, zero);
    let c0 = corner_rel(p, 0u);
    var cx = c0;
    var x = at_of(p, cx, vec2<i32>(0));
    var xuw = vec2<f32>(corner_u_of(p, cx, base, t), corner_wall_w_of(p, cx, l));
    var area = 0.0;
    var lo = 3.0e38;
    var hi = -3.0e38;
    var sum = vec2<f32>(0.0);
    var count = 0u;
    var a_in = true;
    var b_in = true;
    for (var e = 0u; e < np; e++) {
        var cy = c0;
        if (e + 1u < np) { cy = corner_rel(p, e + 1u); }
        let y = at_of(p, cy, vec2<i32>(0));
        let yuw = vec2<f32>(corner_u_of(p, cy, base, t), corner_wall_w_of(p, cy, l));
        // The wall's ends: corners of the overlap where p holds them.
        a_in = a_in && cross2(y - x, wa - x) >= 0.0;
        b_in = b_in && cross2(y - x, wb - x) >= 0.0;
        var cut = uncut();
        for (var k = 0u; k < 3u; k++) {
            let pl = kept_plane(cuts, k);
            cut_by(&cut, dot(x - pl.xy, pl.zw), dot(y - pl.xy, pl.zw), k);
        }
        if (cut.x_in) {
            sum += x;
            count++;
        }
        if (!cut.empty && cut.t0 < cut.t1) {
            let on_wall = crossing_param(xuw.y, yuw.y);
            var s_uw = xuw;
            if (cut.fin > 0u) {
                s_uw = wall_cut_uw(xuw, yuw, on_wall, cut.fin, cut.t0, u_a, u_b);
            }
            var e_uw = yuw;
            if (cut.fout > 0u) {
                e_uw = wall_cut_uw(xuw, yuw, on_wall, cut.fout, cut.t1, u_a, u_b);
            }
            if (cut.fin == 1u) {
                lo = min(lo, s_uw.x);
                hi = max(hi, s_uw.x);
            }
            if (cut.fout == 1u) {
                lo = min(lo, e_uw.x);
                hi = max(hi, e_uw.x);
            }
            area += (s_uw.y + e_uw.y) * (s_uw.x - e_uw.x);
            // The overlap's corners where p's outline crosses into it and out of it.
            if (cut.fin > 0u) {
                sum += x + cut.t0 * (y - x);
                count++;
            }
            if (cut.fout > 0u) {
                sum += x + cut.t1 * (y - x);
                count++;
            }
        }
        cx = cy;
        x = y;
        xuw = yuw;
    }
    if (a_in) {
        sum += wa;
        count++;
        lo = min(lo, u_a);
        hi = max(hi, u_a);
    }
    if (b_in) {
        sum += wb;
        count++;
        lo = min(lo, u_b);
        hi = max(hi, u_b);
    }
    if (count < 3u || area <= 0.0) { return no_contact(); }
    let scale = len + (*p).reach;
    var g = no_contact();
    g.found = true;
    g.area = 0.5 * area;
    g.n = m;
    g.point = sum / f32(count);
    g.l = max(length(g.point), 1.0e-6 * scale);
    if (hi > lo) {
        g.chord = hi - lo;
        // On the wall's line: at the foot of the centre moved along t.
        g.point = (0.5 * (lo + hi) + dot(vec2<f32>(base), t)) * t - dist * m;
        g.l = max(length(g.point), 1.0e-6 * scale);
    }
    return g;
}

// (u, w) where p's edge from x to y meets cut line `line` (1: the wall's, 2 and 3:
// across end a and end b) at parameter t from x: on the wall's line at the exact
// parameter from the ends' w (`on_wall`); on an end's line, the end's u and w along the
// edge from its nearer end.
fn wall_cut_uw(xuw: vec2<f32>, yuw: vec2<f32>, on_wall: vec2<f32>, line: u32, t: f32,
               u_a: f32, u_b: f32) -> vec2<f32> {
    if (line == 1u) { return vec2<f32>(interpolate_w(xuw.x, yuw.x, on_wall).x, 0.0); }
    return vec2<f32>(select(u_b, u_a, line == 2u),
                     interpolate_w(xuw.y, yuw.y, vec2<f32>(t, 1.0 - t)).x);
}

// Along t from the integer point `base` of the corner read as c (exact offset, one
// rounding).
fn corner_u_of(p: ptr<function, Outline>, c: vec2<i32>, base: vec2<i32>, t: vec2<f32>) -> f32 {
    return dot(vec2<f32>((*p).base + c - base) + e_of(p, c), t);
}

// The distance from the wall's line (units, positive on the centre's side) of the
// corner read as c: the centre's exact (c - a).q plus the corner's w.q in 64-bit
// integers, and the small parts (remainders, the turn beta of q).
fn corner_wall_w_of(p: ptr<function, Outline>, c: vec2<i32>, l: WallLine) -> f32 {
    let w = (*p).base + c;
    let exact = add64(l.c64, add64(smul(w.x, l.q.x), smul(w.y, l.q.y)));
    return i64_to_f32(exact) / Q30 + l.small + dot(e_of(p, c), l.n)
        - l.beta * dot(vec2<f32>(w), l.t) - l.alpha * dot(vec2<f32>(w), l.n);
}

// The area contact of particle i with particle j (both polygons), in length units with
// the force point relative to centre i. Corners are exact in a frame at j's centre and
// clipped in f32 relative to the middle of the pair.
fn polygons_ij(i: u32, j: u32) -> AreaContact {
    let o = offset_ij(i, j);
    // Centres more than 1.5 cells apart cannot touch (and their corners would not fit
    // an i32 in the frame).
    if (!o.near || any(abs(o.d) > vec2<i32>(FRAC_ONE + FRAC_ONE / 2))) { return no_contact(); }
    var p = load_outline(i, o.d, o.e);
    var q = load_outline(j, vec2<i32>(0), vec2<f32>(0.0));
    let h = o.d / vec2<i32>(2);
    let ci = vec2<f32>(o.d - h) + o.e;
    var g = polygon_polygon(&p, &q, h, ci, vec2<f32>(-h));
    let u = params.unit;
    g.area *= u * u;
    g.chord *= u;
    g.l *= u;
    g.point = (g.point - ci) * u;
    return g;
}

// An offset in f32 units (exact when near, else to f32 precision).
fn offset_units(o: Offset) -> vec2<f32> {
    if (o.near) { return vec2<f32>(o.d) + o.e; }
    return offset_vector(o) * params.inv_unit;
}

// The area contact of particle i with wall w, in length units in i's frame.
fn polygon_wall_iw(i: u32, w: u32) -> AreaContact {
    let s = state[i];
    let wall = walls[w];
    let oa = offset(wall.a_anchor, wall.a_frac, wall.a_rem, s.anchor, s.frac, s.q[0].xy);
    let ob = offset(wall.b_anchor, wall.b_frac, wall.b_rem, s.anchor, s.frac, s.q[0].xy);
    let l = wall_line(i, w);
    if (!l.near) { return no_contact(); }
    var p = load_outline(i, vec2<i32>(0), vec2<f32>(0.0));
    var g = polygon_wall(&p, offset_units(oa), offset_units(ob), l);
    let u = params.unit;
    g.area *= u * u;
    g.chord *= u;
    g.l *= u;
    g.point *= u;
    return g;
}

// ---- Disks under the overlap-area law (mixed scenes; src/overlap/) ----
//
// The CPU path computes these areas in f64 by general formulas (triangles in a circle,
// lens, segment). In f32 those cancel badly for a small overlap, so here each area is
// built from an overlap depth that is exact in position units: a circular segment of
// known sagitta, a lens of two segments, a triangle at a corner plus a segment. Only a
// polygon-disk overlap that is none of these (a deep one) falls back to the general
// formula in f32.

// x - sin x, by its series where it cancels.
fn x_minus_sin(x: f32) -> f32 {
    if (x > 1.0) { return x - sin(x); }
    let x2 = x * x;
    return x * x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0 - x2 * (1.0 / 362880.0 - x2 / 39916800.0))));
}

// Area of the circular segment of radius r beyond a chord at depth e (the sagitta):
// r^2/2 (x - sin x) with x the central angle, x = 4 asin(sqrt(e / 2r)); asin by its
// series for small arguments (relative error below 1e-9 up to 0.25).
fn segment_area(r: f32, e: f32) -> f32 {
    let y = sqrt(clamp(e / (2.0 * r), 0.0, 1.0));
    var a = 0.0;
    if (y > 0.25) {
        a = asin(y);
    } else {
        let y2 = y * y;
        a = y * (1.0 + y2 * (1.0 / 6.0 + y2 * (3.0 / 40.0 + y2 * (5.0 / 112.0 + y2 * (35.0 / 1152.0 + y2 * (63.0 / 2816.0))))));
    }
    return 0.5 * r * r * x_minus_sin(4.0 * a);
}

// The lens of two disks (src/overlap/disk.rs `disk_disk_area`), in length units with the
// force point relative to centre i. The overlap delta is exact (geometry.wgsl); the
// sagittas of the two segments are delta (r_j + d - r_i) / 2d and delta (r_i + d - r_j) / 2d.
fn disks_area_ij(i: u32, j: u32) -> AreaContact {
    let g = disk_disk(i, j);
    if (!g.near || g.delta <= 0.0) { return no_contact(); }
    let ri = props[i].radius;
    let rj = props[j].radius;
    let d = g.r;
    var c = no_contact();
    c.found = true;
    c.n = g.n;
    if (d <= abs(ri - rj)) {
        // One inside the other: the smaller disk's area, at its centre.
        let small = min(ri, rj);
        c.area = 3.14159265 * small * small;
        if (ri >= rj) { c.point = -g.n * d; }
        c.l = reduced_arm(length(c.point), length(c.point + g.n * d), ri + rj);
        return c;
    }
    let ei = g.delta * (rj + d - ri) / (2.0 * d);
    let ej = g.delta * (ri + d - rj) / (2.0 * d);
    c.area = segment_area(ri, ei) + segment_area(rj, ej);
    c.chord = 2.0 * sqrt(max(ej * (2.0 * rj - ej), 0.0));
    c.point = -g.n * (ri - ei);
    c.l = reduced_arm(ri - ei, rj - ej, ri + rj);
    return c;
}

// A disk and a wall (src/overlap/disk.rs `disk_wall_area`): the segment beyond the wall's
// line, of the exact depth of geometry.wgsl's `disk_wall`, scaled by the part of its
// chord that lies over the wall (an approximation at the wall's ends, as on the CPU).
fn disk_wall_area(i: u32, w: u32) -> AreaContact {
    let s = state[i];
    let wall = walls[w];
    let r = props[i].radius;
    let oa = offset(s.anchor, s.frac, s.q[0].xy, wall.a_anchor, wall.a_frac, wall.a_rem);
    let p = offset_vector(oa);   // centre - a
    let len = length(wall.ab);
    if (len == 0.0) { return no_contact(); }
    let tt = wall.ab / len;
    // The depth beyond the wall's line, exact (geometry.wgsl `wall_line`).
    let l = wall_line(i, w);
    if (!l.near) { return no_contact(); }
    let m = l.n;
    let delta = wall_depth(l, props[i].radius_units, props[i].radius_rem) * params.unit;
    let dist = r - delta;
    if (delta <= 0.0) { return no_contact(); }
    let h = sqrt(delta * (2.0 * r - delta));
    // The chord's ends relative to the foot of the centre, cut at the wall's ends: not
    // from `along` +- h, which far from a would round at f32's precision of `along`.
    let along = dot(p, tt);
    let lo = max(-h, -along);
    let hi = min(h, len - along);
    if (hi <= lo) { return no_contact(); }
    var c = no_contact();
    c.found = true;
    c.area = segment_area(r, delta) * (hi - lo) / (2.0 * h);
    c.n = m;
    c.chord = hi - lo;
    c.point = -dist * m + (0.5 * (lo + hi)) * tt;
    c.l = max(length(c.point), 1.0e-9 * r);
    return c;
}

// Signed area of the triangle (0, a, b) inside the circle of radius r about the origin
// (src/overlap/disk.rs `triangle_in_circle`): the fallback for deep polygon-disk overlaps.
fn triangle_in_circle(a: vec2<f32>, b: vec2<f32>, r: f32) -> f32 {
    let d = b - a;
    let qa = dot(d, d);
    let qb = 2.0 * dot(a, d);
    let qc = dot(a, a) - r * r;
    var ts = array<f32, 4>(0.0, 1.0, 1.0, 1.0);
    var n = 1u;
    let disc = qb * qb - 4.0 * qa * qc;
    if (qa > 0.0 && disc > 0.0) {
        let s = sqrt(disc);
        let t1 = (-qb - s) / (2.0 * qa);
        let t2 = (-qb + s) / (2.0 * qa);
        if (t1 > 0.0 && t1 < 1.0) { ts[n] = t1; n++; }
        if (t2 > 0.0 && t2 < 1.0) { ts[n] = t2; n++; }
    }
    ts[n] = 1.0;
    var sum = 0.0;
    for (var k = 0u; k < n; k++) {
        let p = a + ts[k] * d;
        let q = a + ts[k + 1u] * d;
        let m = a + 0.5 * (ts[k] + ts[k + 1u]) * d;
        let c = p.x * q.y - p.y * q.x;
        if (dot(m, m) <= r * r) { sum += 0.5 * c; } else { sum += 0.5 * r * r * atan2(c, dot(p, q)); }
    }
    return sum;
}

// Overlap depth (units) of point w + e inside the circle of radius r_units + r_rem
// about the origin: exact, as a disk-point pair (geometry.wgsl).
fn depth_in_circle(w: vec2<i32>, e: vec2<f32>, r_units: u32, r_rem: f32) -> f32 {
    let dist = distance_units(w, e);
    var whole = f32(r_units) - f32(dist.whole);
    if (dist.whole < 0x80000000u) { whole = f32(i32(r_units) - i32(dist.whole)); }
    return whole + (r_rem - dist.corr);
}

// Corner a minus corner b of an outline, from the exact integer offset (one rounding).
fn corner_delta(p: ptr<function, Outline>, a: u32, b: u32) -> vec2<f32> {
    return vec2<f32>(ow(p, a) - ow(p, b)) + (corner_e(p, a) - corner_e(p, b));
}

// How far along the unit vector u from the point x, `depth` inside the circle of radius
// r about the origin, the circle is reached: s^2 + 2 b s - k = 0 with b = x.u and
// k = r^2 - |x|^2 = depth (2r - depth), without cancelling.
fn circle_reach(x: vec2<f32>, u: vec2<f32>, depth: f32, r: f32) -> f32 {
    let k = depth * (2.0 * r - depth);
    let b = dot(x, u);
    let root = sqrt(b * b + k);
    if (b > 0.0) { return k / (b + root); }
    return root - b;
}

// Where edge m of p crosses the circle of radius r about the origin: the k-th crossing
// along the edge (xy) and whether there is one (z).
fn circle_crossing(p: ptr<function, Outline>, m: u32, k: u32, r: f32) -> vec3<f32> {
    let a = corner_at(p, m, vec2<i32>(0));
    let d = corner_at(p, next_corner(p, m), vec2<i32>(0)) - a;
    let qa = dot(d, d);
    let qb = 2.0 * dot(a, d);
    let disc = qb * qb - 4.0 * qa * (dot(a, a) - r * r);
    if (qa <= 0.0 || disc < 0.0) { return vec3<f32>(0.0); }
    let t = (-qb + select(-sqrt(disc), sqrt(disc), k == 1u)) / (2.0 * qa);
    if (t < 0.0 || t >= 1.0) { return vec3<f32>(0.0); }
    return vec3<f32>(a + t * d, 1.0);
}

// Area contact of polygon `poly` and disk `disk` (polygon_is_i: which one is i), in
// length units with the force point relative to centre i. Frame: the disk's centre.
fn polygon_disk_ij(poly: u32, disk: u32, polygon_is_i: bool) -> AreaContact {
    let o = offset_ij(poly, disk);
    if (!o.near || any(abs(o.d) > vec2<i32>(FRAC_ONE + FRAC_ONE / 2))) { return no_contact(); }
    var p = load_outline(poly, o.d, o.e);
    let ru = props[disk].radius_units;
    let rr = props[disk].radius_rem;
    let r = f32(ru) + rr;                       // units
    let cp = vec2<f32>(o.d) + o.e;             // polygon centre
    let np = p.n;
    var inside = 0u;
    var mask = 0u;
    for (var m = 0u; m < np; m++) {
        let dm = depth_in_circle(ow(&p, m), corner_e(&p, m), ru, rr);
        if (dm > 0.0) { inside++; mask |= 1u << m; }
    }
    // Edges with both ends outside that the circle cuts twice (`cut` of them with the
    // disk's centre on their outer side), and whether the centre is inside the polygon.
    // With no corner inside, no edge cut and the centre outside there is no overlap.
    var cut = 0u;
    var cut_any = 0u;
    var edge = 0u;
    var centre_inside = true;
    for (var m = 0u; m < np; m++) {
        let m2 = (m + 1u) % np;
        let a = corner_at(&p, m, vec2<i32>(0));
        let ab = corner_at(&p, m2, vec2<i32>(0)) - a;
        let outside = cross2(ab, -a) < 0.0;
        if (outside) { centre_inside = false; }
        let t = -dot(a, ab) / dot(ab, ab);
        let f = a + t * ab;
        let ends_out = (mask & ((1u << m) | (1u << m2))) == 0u;
        if (ends_out && t > 0.0 && t < 1.0 && dot(f, f) < r * r) {
            cut_any++;
            if (outside) { cut++; edge = m; }
        }
    }
    if (inside == 0u && cut == 0u && !centre_inside) { return no_contact(); }
    var g = no_contact();
    var towards_disk = vec2<f32>(0.0);
    var done = false;
    if (inside == 0u && cut == 1u && cut_any == 1u) {
        // A sliver under one face: a segment whose depth is exact from an integer dot
        // product with the face's normal in Q30. That normal q is the f32 normal, off
        // the face's true normal n by a turn beta and a stretch alpha (~6e-8, which half
        // a diameter out is 3e-8 d): q = (1 + alpha) n + beta t, so
        // w.n = w.q - beta (w.t) - alpha (w.q), with beta = q.t and 1 + alpha = |q| from
        // exact integer products (issue 19).
        let a = edge;
        let b = (edge + 1u) % np;
        let abi = ow(&p, b) - ow(&p, a);
        let ab = vec2<f32>(abi);
        let len = length(ab);
        let t = ab / len;
        let nout = vec2<f32>(t.y, -t.x);         // out of the polygon, towards the disk
        let nq = vec2<i32>(round(nout * Q30));
        let beta = i64_to_f32(add64(smul(nq.x, abi.x), smul(nq.y, abi.y))) / (Q30 * len);
        let q2 = add64(smul(nq.x, nq.x), smul(nq.y, nq.y));
        let alpha = 0.5 * i64_to_f32(sub64(q2, vec2<u32>(0u, 0x10000000u))) / (Q30 * Q30);
        let wq = add64(smul(ow(&p, a).x, nq.x), smul(ow(&p, a).y, nq.y));
        let exact = add64(wq, vec2<u32>(ru << 30u, ru >> 2u));
        let w_t = dot(vec2<f32>(ow(&p, a)), t);
        let delta = i64_to_f32(exact) / Q30 + rr + dot(corner_e(&p, a), nout)
            - beta * w_t - alpha * i64_to_f32(wq) / Q30;
        if (delta <= 0.0) { return no_contact(); }
        g.area = segment_area(r, delta);
        g.chord = 2.0 * sqrt(max(delta * (2.0 * r - delta), 0.0));
        g.point = -(r - delta) * nout;
        towards_disk = nout;
        done = true;
    }
    if (!done && inside > 0u && cut_any == 0u) {
        // A run of corners inside (one or more in a row), no other edge cut: the polygon
        // from the crossing into the run, along it, to the crossing out of it, plus the
        // minor segment beyond their chord (src/overlap/disk.rs `corner_cap`). The crossings
        // come from the end corners' exact depths, the polygon's area from integer
        // offsets about the first crossing; unless the corners inside are not in a row
        // or the disk's centre lies beyond the chord (a major segment): the general
        // formula.
        var first = np;
        for (var m = 0u; m < np; m++) {
            let before = (m + np - 1u) % np;
            if ((mask & (1u << m)) != 0u && (mask & (1u << before)) == 0u) { first = m; }
        }
        var count = 0u;
        if (first < np) {
            while (count < np && (mask & (1u << ((first + count) % np))) != 0u) { count++; }
        }
        if (first < np && count == inside) {
            let last = (first + count - 1u) % np;
            let v1 = corner_at(&p, first, vec2<i32>(0));
            let u1 = normalize(corner_delta(&p, (first + np - 1u) % np, first));
            let u2 = normalize(corner_delta(&p, (last + 1u) % np, last));
            let s1 = circle_reach(v1, u1, depth_in_circle(ow(&p, first), corner_e(&p, first), ru, rr), r);
            let v2 = corner_at(&p, last, vec2<i32>(0));
            let s2 = circle_reach(v2, u2, depth_in_circle(ow(&p, last), corner_e(&p, last), ru, rr), r);
            var twice = 0.0;
            var prev = -s1 * u1;
            for (var k = 1u; k < count; k++) {
                let next = corner_delta(&p, (first + k) % np, first) - s1 * u1;
                twice += cross2(prev, next);
                prev = next;
            }
            let x21 = corner_delta(&p, last, first) + s2 * u2 - s1 * u1;
            twice += cross2(prev, x21);
            let chord = length(x21);
            let half = 0.5 * chord;
            let sag = half * half / (r + sqrt(max(r * r - half * half, 0.0)));
            let mid = v1 + s1 * u1 + 0.5 * x21;
            let tt = x21 / max(chord, 1.0e-30);
            let nn = vec2<f32>(-tt.y, tt.x);
            let centre_side = dot(nn, -mid);
            let corner_side = dot(nn, v1 - mid);
            if (centre_side * corner_side >= 0.0) {
                g.area = 0.5 * abs(twice) + segment_area(r, sag);
                g.chord = chord;
                g.point = mid;
                towards_disk = nn * select(-1.0, 1.0, centre_side + corner_side > 0.0);
                done = true;
            }
        }
    }
    if (!done) {
        // Deep or unusual: the general formula in f32 (src/overlap/disk.rs `polygon_disk`),
        // the force point between the two crossings of the outlines farthest apart. The
        // crossings are found again for each pair of edges rather than listed (a
        // per-thread list is local memory on a GPU), in the CPU's order: by edge, then
        // along it.
        let edges = np;
        var area = 0.0;
        for (var m = 0u; m < edges; m++) {
            let a = corner_at(&p, m, vec2<i32>(0));
            let b = corner_at(&p, next_corner(&p, m), vec2<i32>(0));
            area += triangle_in_circle(a, b, r);
        }
        if (area <= 0.0) { return no_contact(); }
        g.area = area;
        towards_disk = -cp / max(length(cp), 1.0e-30);
        if (length(cp) == 0.0) { towards_disk = vec2<f32>(0.0, -1.0); }
        var best = -1.0;
        for (var ea = 0u; ea < edges; ea++) {
            for (var ka = 0u; ka < 2u; ka++) {
                let xa = circle_crossing(&p, ea, ka, r);
                if (xa.z == 0.0) { continue; }
                for (var eb = ea; eb < edges; eb++) {
                    for (var kb = select(0u, ka + 1u, eb == ea); kb < 2u; kb++) {
                        let xb = circle_crossing(&p, eb, kb, r);
                        if (xb.z == 0.0) { continue; }
                        let d = length(xb.xy - xa.xy);
                        if (d > best) {
                            best = d;
                            g.point = 0.5 * (xa.xy + xb.xy);
                            g.chord = d;
                            let tt = (xb.xy - xa.xy) / max(d, 1.0e-30);
                            towards_disk = vec2<f32>(-tt.y, tt.x);
                        }
                    }
                }
            }
        }
        if (best > 1.0e-6 * r) {
            // The disk's side: its centre and the polygon's corners inside it.
            var side = dot(towards_disk, -g.point);
            for (var m = 0u; m < np; m++) {
                if ((mask & (1u << m)) != 0u) { side += dot(towards_disk, corner_at(&p, m, vec2<i32>(0)) - g.point); }
            }
            if (side < 0.0) { towards_disk = -towards_disk; }
        } else {
            g.point = vec2<f32>(0.0);
            g.chord = 0.0;
            towards_disk = -cp / max(length(cp), 1.0e-30);
            if (length(cp) == 0.0) { towards_disk = vec2<f32>(0.0, -1.0); }
        }
    }
    g.found = true;
    g.n = select(towards_disk, -towards_disk, polygon_is_i);
    let scale = length(cp) + 2.0 * r;
    g.l = reduced_arm(length(g.point - cp), length(g.point), scale);
    let u = params.unit;
    g.area *= u * u;
    g.chord *= u;
    g.l *= u;
    if (polygon_is_i) { g.point -= cp; }
    g.point *= u;
    return g;
}

// The area contact of particles i and j, whatever their shapes (force point relative
// to centre i). The pipelines are built for the shapes a scene has (`POLYGON_SHAPES`,
// `DISK_SHAPES`): the branches of the others compile away, since a thread that skips a
// branch still waits for its neighbours that take it, and a software adapter runs every
// branch of every thread.
fn area_contact(i: u32, j: u32) -> AreaContact {
    if (!DISK_SHAPES) { return polygons_ij(i, j); }
    if (!POLYGON_SHAPES) { return disks_area_ij(i, j); }
    let pi = props[i].shape.y > 0u;
    let pj = props[j].shape.y > 0u;
    if (pi && pj) { return polygons_ij(i, j); }
    if (pi) { return polygon_disk_ij(i, j, true); }
    if (pj) { return polygon_disk_ij(j, i, false); }
    return disks_area_ij(i, j);
}

fn area_contact_wall(i: u32, w: u32) -> AreaContact {
    if (!DISK_SHAPES) { return polygon_wall_iw(i, w); }
    if (!POLYGON_SHAPES) { return disk_wall_area(i, w); }
    if (props[i].shape.y > 0u) { return polygon_wall_iw(i, w); }
    return disk_wall_area(i, w);
}
