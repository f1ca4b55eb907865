// Spheropolygons under paper 004's law (SPEC 2.4; src/overlap/spheropolygon.rs
// `sub_contacts`, src/cpu/forces/rods.rs `pair_force` and `spheropolygon_candidate`): a
// pair's contact is a set of vertex-edge sub-contacts of the cores, each with overlap
// delta = r_i + r_j - distance(vertex, edge) and its own tangential spring, keyed by
// the sub-contact (`SubSprings`). The GPU path takes cores of one corner (a disk: a
// point swept by its radius) or two (a rod's segment), so a pair has at most four
// sub-contacts (two vertices on each side), all of them keeping their springs
// (MAX_SUB); polygon cores are refused on the host (`GpuSimulation::resume_with_gpu`).
//
// Precision as for disks (position.wgsl): points are whole position units plus f32
// remainders in a frame at i's centre; a vertex-edge distance is cross(E, D)/|E| with
// the cross product exact in 64-bit integers, and the overlap is taken from
// sigma |E| - |cross(E, D)|, whose large parts cancel in integers, so delta keeps its
// relative precision however shallow the contact. A wall is a segment of sweep 0; a
// rod's vertex against a wall's interior uses the wall's exact line (`wall_line`).
//
// A swept particle's sweep radius follows its corners in `corners` (one entry: whole
// units in x, the f32 remainder's bits in y; host: src/gpu/transfer.rs `sweep_entry`).

const VERTEX_I: u32 = 0u;
const VERTEX_J: u32 = 65536u;
const VERTICES: u32 = 131072u;
const MAX_SUB: u32 = 4u;

// A point of a core in the pair's frame: whole units and an f32 remainder (units).
struct Point {
    w: vec2<i32>,
    e: vec2<f32>,
};

// A core in the pair's frame: one point (a disk) or a segment a-b, swept by r (whole
// units and remainder). `centre`: its particle's centre (units, f32).
struct Core {
    a: Point,
    b: Point,
    n: u32,
    r_units: i32,
    r_rem: f32,
    centre: vec2<f32>,
};

fn point_f(p: Point) -> vec2<f32> {
    return vec2<f32>(p.w) + p.e;
}

// Particle k's core with its centre at `base` + `e` in the frame.
fn load_core(k: u32, base: vec2<i32>, e: vec2<f32>) -> Core {
    let sh = props[k].shape;
    let centre = Point(base, e);
    if (sh.y == 0u) {
        return Core(centre, centre, 1u, i32(props[k].radius_units), props[k].radius_rem,
                    point_f(centre));
    }
    let spin = state[k].q[0].z;
    let ca = corners[sh.x].zw;
    let cb = corners[sh.x + 1u].zw;
    let sweep = corners[sh.x + sh.y];
    let a = Point(base + ca, e + corner_spin(ca, spin));
    let b = Point(base + cb, e + corner_spin(cb, spin));
    return Core(a, b, sh.y, sweep.x, bitcast<f32>(sweep.y), point_f(centre));
}

fn core_point(c: Core, k: u32) -> Point {
    if (k == 1u) { return c.b; }
    return c.a;
}

// One sub-contact, seen from the vertex's side until `add_sub` orients it.
struct Sub {
    key: u32,
    delta: f32,        // r_vertex + r_edge - distance (units)
    n: vec2<f32>,      // unit normal from the edge's side to the vertex's
    c: vec2<f32>,      // the closest point of the edge's core (units, frame)
    end: u32,          // 0: inside the edge; 1, 2: at its end a, b
    found: bool,       // within the cohesion range
};

// The signed 64-bit integer |v|: (magnitude, -1 or 1).
fn abs64(v: vec2<u32>) -> vec3<u32> {
    if ((v.y & 0x80000000u) != 0u) {
        let m = sub64(vec2<u32>(0u, 0u), v);
        return vec3<u32>(m, 0u);
    }
    return vec3<u32>(v, 1u);
}

// Vertex v against the segment a-b (a point when a = b), sigma = the two sweeps (whole
// units and remainder), `gap` the cohesion range (units); `vc` the vertex's particle
// centre (the normal's side when the vertex lies on the edge).
fn vertex_edge(v: Point, a: Point, b: Point, sig_w: i32, sig_r: f32, gap: f32,
               vc: vec2<f32>) -> Sub {
    var s = Sub(0u, 0.0, vec2<f32>(0.0, 1.0), vec2<f32>(0.0), 0u, false);
    let ef = (vec2<f32>(b.w) - vec2<f32>(a.w)) + (b.e - a.e);
    let df = (vec2<f32>(v.w) - vec2<f32>(a.w)) + (v.e - a.e);
    // Beyond 2^31 units the integers below would wrap; such a vertex is far out of
    // range (cores fit within a cell of 2^30 units).
    if (any(abs(df) > vec2<f32>(1.9e9)) || any(abs(ef) > vec2<f32>(1.9e9))) { return s; }
    let l2 = dot(ef, ef);
    var t = 0.0;
    if (l2 > 0.0) { t = clamp(dot(df, ef) / l2, 0.0, 1.0); }
    var dist0 = false;
    if (t > 0.0 && t < 1.0) {
        let d = v.w - a.w;
        let de = v.e - a.e;
        let e = b.w - a.w;
        let ee = b.e - a.e;
        // cross(E, D) exactly, and its sign: the side of the edge the vertex is on.
        let c = abs64(sub64(smul(e.x, d.y), smul(e.y, d.x)));
        let sign = select(-1.0, 1.0, c.z == 1u);
        let corr = sign * (cross2(vec2<f32>(e), de) + cross2(ee, vec2<f32>(d)) + cross2(ee, de));
        // |E + ee| = L + fl with L whole and fl small.
        let efw = vec2<f32>(e);
        let big_l = u32(round(length(efw)));
        let e2 = add64(mul_wide(u32(abs(e.x)), u32(abs(e.x))), mul_wide(u32(abs(e.y)), u32(abs(e.y))));
        let fl = (i64_to_f32(sub64(e2, mul_wide(big_l, big_l))) + 2.0 * dot(efw, ee) + dot(ee, ee))
            / (f32(big_l) + sqrt(l2));
        let len = f32(big_l) + fl;
        // delta |E| = sigma |E| - |cross|: the large parts cancel in integers.
        let x = i64_to_f32(sub64(smul(sig_w, i32(big_l)), c.xy)) + f32(sig_w) * fl
            + sig_r * len - corr;
        s.delta = x / len;
        s.n = sign * vec2<f32>(-ef.y, ef.x) / sqrt(l2);
        s.c = point_f(a) + t * ef;
        dist0 = c.x == 0u && c.y == 0u && corr == 0.0;
    } else {
        var end = a;
        s.end = 1u;
        if (t >= 1.0) {
            end = b;
            s.end = 2u;
        }
        let d = v.w - end.w;
        let de = v.e - end.e;
        let dist = distance_units(d, de);
        s.delta = f32(sig_w - i32(dist.whole)) + sig_r - dist.corr;
        let g = vec2<f32>(d) + de;
        let r = length(g);
        if (r > 0.0) { s.n = g / r; } else { dist0 = true; }
        s.c = point_f(end);
    }
    if (dist0) {
        // The vertex on the edge: the edge's normal toward the vertex's centre.
        var m = vec2<f32>(0.0, 1.0);
        if (l2 > 0.0) { m = vec2<f32>(ef.y, -ef.x) / sqrt(l2); }
        if (dot(m, vc - s.c) < 0.0) { m = -m; }
        s.n = m;
    }
    s.found = s.delta > -gap;
    return s;
}

// A vertex of particle i (`corner`: its rotated corner, whole units from i's centre, and
// its remainder) against the interior of wall w, exactly from the wall's line
// (geometry.wgsl `wall_line`, `wall_depth`): Sub with end 0, or end 1, 2 when the
// vertex lies beyond the wall's ends (then `vertex_edge` against that end).
fn vertex_wall(l: WallLine, w: u32, i: u32, corner: vec2<i32>, ce: vec2<f32>, r_units: i32,
               r_rem: f32, gap: f32) -> Sub {
    var s = Sub(0u, 0.0, l.n, vec2<f32>(0.0), 0u, false);
    let wall = wall_at(w);
    let st = state[i];
    let oa = offset(st.anchor, st.frac, st.q[0].xy, wall.a_anchor, wall.a_frac, wall.a_rem);
    let cf = vec2<f32>(corner) + ce;
    let p = offset_vector(oa) + cf * params.unit;
    let len2 = dot(wall.ab, wall.ab);
    var t = 0.0;
    if (len2 > 0.0) { t = dot(p, wall.ab) / len2; }
    if (t <= 0.0 || t >= 1.0) {
        s.end = select(1u, 2u, t >= 1.0);
        return s;
    }
    // (V - a).q = (c - a).q + corner.q, units x 2^30, and the rest of the distance.
    var c64 = add64(l.c64, add64(smul(corner.x, l.q.x), smul(corner.y, l.q.y)));
    var raw = i64_to_f32(c64) / Q30;
    var small = l.small + dot(ce, l.n) - l.beta * dot(cf, l.t)
        - l.alpha * (raw - i64_to_f32(l.c64) / Q30);
    if (raw + small < 0.0) {
        // The vertex beyond the line (the centre is on the near side): its distance,
        // as the CPU path measures it, from the far side.
        c64 = sub64(vec2<u32>(0u, 0u), c64);
        raw = -raw;
        small = -small;
        s.n = -l.n;
    }
    let exact = sub64(vec2<u32>(u32(r_units) << 30u, u32(r_units) >> 2u), c64);
    s.delta = i64_to_f32(exact) / Q30 + r_rem - small;
    s.c = cf - (raw + small) * s.n;
    s.found = s.delta > -gap;
    return s;
}

// The sub-contacts found so far (at most MAX_SUB with the cores above).
struct Subs {
    count: u32,
    key: array<u32, MAX_SUB>,
    delta: array<f32, MAX_SUB>,
    n: array<vec2<f32>, MAX_SUB>,      // from j to i
    point: array<vec2<f32>, MAX_SUB>,  // the middle of the overlap (units, frame at i)
};

// Adds a sub-contact; `flip`: the vertex is j's (its normal turned to point from j to
// i). A pair of vertices is listed once, whichever side found it first.
fn add_sub(subs: ptr<function, Subs>, s: Sub, key: u32, flip: bool, r_vertex: f32,
           r_edge: f32, v: vec2<f32>) {
    if (!s.found || (*subs).count >= MAX_SUB) { return; }
    if ((key & VERTICES) != 0u) {
        for (var k = 0u; k < (*subs).count; k++) {
            if ((*subs).key[k] == key) { return; }
        }
    }
    let k = (*subs).count;
    (*subs).key[k] = key;
    (*subs).delta[k] = s.delta;
    // The middle of the overlap, between the two surfaces along n.
    let s_edge = s.c + r_edge * s.n;
    let s_vertex = v - r_vertex * s.n;
    (*subs).point[k] = 0.5 * (s_edge + s_vertex);
    (*subs).n[k] = select(s.n, -s.n, flip);
    (*subs).count = k + 1u;
}

// The key of a sub-contact: vertex k of one side against edge 0 of the other, or the
// pair of vertices (i's, j's) when it lies beyond an end.
fn sub_key(s: Sub, k: u32, flip: bool) -> u32 {
    if (s.end == 0u) { return select(VERTEX_I, VERTEX_J, flip) | (k << 8u); }
    let end = s.end - 1u;
    if (flip) { return VERTICES | (end << 8u) | k; }
    return VERTICES | (k << 8u) | end;
}

// Vertices of `verts` against the segment of `edges` (`flip`: the vertices are j's).
fn vertices_on_edge(subs: ptr<function, Subs>, verts: Core, edges: Core, flip: bool,
                    gap: f32) {
    if (edges.n < 2u) { return; }
    let sig_w = verts.r_units + edges.r_units;
    let sig_r = verts.r_rem + edges.r_rem;
    let rv = f32(verts.r_units) + verts.r_rem;
    let re = f32(edges.r_units) + edges.r_rem;
    for (var k = 0u; k < verts.n; k++) {
        let v = core_point(verts, k);
        let s = vertex_edge(v, edges.a, edges.b, sig_w, sig_r, gap, verts.centre);
        add_sub(subs, s, sub_key(s, k, flip), flip, rv, re, point_f(v));
    }
}

// The sub-contacts of particles i and j (offset o = centre i - centre j).
fn pair_subs(i: u32, j: u32, o: Offset, gap: f32) -> Subs {
    var subs: Subs;
    subs.count = 0u;
    let p = load_core(i, vec2<i32>(0), vec2<f32>(0.0));
    let q = load_core(j, -o.d, -o.e);
    if (p.n == 1u && q.n == 1u) {
        // Two disks: the one pair of vertices (src/overlap/spheropolygon.rs `vertices`).
        let s = vertex_edge(p.a, q.a, q.a, p.r_units + q.r_units, p.r_rem + q.r_rem, gap,
                            p.centre);
        add_sub(&subs, s, VERTICES, false, f32(p.r_units) + p.r_rem,
                f32(q.r_units) + q.r_rem, point_f(p.a));
        return subs;
    }
    vertices_on_edge(&subs, p, q, false, gap);
    vertices_on_edge(&subs, q, p, true, gap);
    return subs;
}

// The sub-contacts of particle i with wall w (a segment of sweep 0).
fn wall_subs(i: u32, w: u32, gap: f32) -> Subs {
    var subs: Subs;
    subs.count = 0u;
    let p = load_core(i, vec2<i32>(0), vec2<f32>(0.0));
    let wall = wall_at(w);
    let st = state[i];
    let oa = offset(wall.a_anchor, wall.a_frac, wall.a_rem, st.anchor, st.frac, st.q[0].xy);
    let ob = offset(wall.b_anchor, wall.b_frac, wall.b_rem, st.anchor, st.frac, st.q[0].xy);
    let l = wall_line(i, w);
    let rv = f32(p.r_units) + p.r_rem;
    if (!l.near) { return subs; }
    // i's vertices against the wall: its interior exactly from the line, its ends as
    // points.
    for (var k = 0u; k < p.n; k++) {
        let v = core_point(p, k);
        var s = vertex_wall(l, w, i, v.w, v.e, p.r_units, p.r_rem, gap);
        if (s.end != 0u) {
            let at_b = s.end == 2u;
            var o = oa;
            if (at_b) { o = ob; }
            if (!o.near) { continue; }
            let end = Point(o.d, o.e);
            s = vertex_edge(v, end, end, p.r_units, p.r_rem, gap, p.centre);
            s.end = select(1u, 2u, at_b);
        }
        add_sub(&subs, s, sub_key(s, k, false), false, rv, 0.0, point_f(v));
    }
    // The wall's ends against i's segment (the centre of a wall's vertex is taken at
    // i's, as on the CPU path: it only orients a vertex lying on the core).
    if (p.n == 2u) {
        for (var k = 0u; k < 2u; k++) {
            var o = oa;
            if (k == 1u) { o = ob; }
            if (!o.near) { continue; }
            let v = Point(o.d, o.e);
            let s = vertex_edge(v, p.a, p.b, p.r_units, p.r_rem, gap, vec2<f32>(0.0));
            add_sub(&subs, s, sub_key(s, k, true), true, 0.0, rv, point_f(v));
        }
    }
    return subs;
}

// The force of spheropolygon candidate `slot` of particle i (src/cpu/forces/rods.rs
// `spheropolygon_candidate`): every sub-contact under the law with its own spring from
// the slot's `sub_hist`, summed into the candidate's force and torques. In the outputs
// the pair has the deepest sub-contact's normal and overlap, at the centre of its
// sub-contacts' normal forces.
fn spheropolygon_force(i: u32, slot: u32, m1: f32, v1: vec3<f32>) {
    let j = contact_j[slot];
    let wall = j >= WALL_BASE;
    let gap = params.d_c * params.inv_unit;
    var subs: Subs;
    var d_ij = vec2<f32>(0.0);
    var v2 = vec3<f32>(0.0);
    var m12 = m1;
    var mass = m1;
    var rmin = props[i].radius;
    // Beyond the circumscribed circles (`radius` is a core's farthest corner plus its
    // sweep) no sub-contact is in range: most candidates end here.
    // (`circles_near` takes them with the law's range factor, whose margin holds d_c).
    if (wall) {
        let reach = (params.range_factor - 1.0 + 1.0e-5) * props[i].radius;
        if (disk_wall(i, j - WALL_BASE).delta >= -reach) {
            subs = wall_subs(i, j - WALL_BASE, gap);
        } else {
            subs.count = 0u;
        }
        v2 = vec3<f32>(wall_velocity(j - WALL_BASE), 0.0);
    } else if (!circles_near(i, j)) {
        subs.count = 0u;
    } else {
        let o = offset_ij(i, j);
        // Centres more than 1.5 cells apart cannot touch (cores fit in a cell).
        if (o.near && all(abs(o.d) <= vec2<i32>(1610612736))) {
            subs = pair_subs(i, j, o, gap);
        } else {
            subs.count = 0u;
        }
        d_ij = offset_vector(o);
        v2 = velocity(j);
        let m2 = props[j].mass;
        m12 = m1 * m2 / (m1 + m2);
        mass = 2.0 * m12;
        rmin = min(rmin, props[j].radius);
    }
    let old = sub_hist[slot];
    var springs = SubSprings(vec4<u32>(EMPTY), vec4<f32>(0.0));
    if (subs.count == 0u) {
        contact_ft[slot] = vec4<f32>(0.0);
        sub_hist[slot] = springs;
        touching[slot] = 0u;
        return;
    }
    touching[slot] = 1u;
    let u = params.unit;
    var f = vec2<f32>(0.0);
    var torque = vec2<f32>(0.0);
    var energy = 0.0;
    var deepest = 0u;
    // The reported point: the arm l of least-squares F ⊗ l = Σ_k f_k ⊗ l_k, l = (Fᵀ M)/|F|²
    // with M = Σ_k f_k ⊗ l_k (src/cpu/forces/rods.rs `centre_of_forces`): M's columns by l's x, y.
    var moment_x = vec2<f32>(0.0);
    var moment_y = vec2<f32>(0.0);
    var sizes = 0.0;
    for (var k = 0u; k < subs.count; k++) {
        let key = subs.key[k];
        let n = subs.n[k];
        let l1 = subs.point[k] * u;
        let l2 = l1 + d_ij;
        let s1 = v1.z * vec2<f32>(-l1.y, l1.x);
        var s2 = vec2<f32>(0.0);
        if (wall) { s2 = v2.xy; } else { s2 = v2.xy + v2.z * vec2<f32>(-l2.y, l2.x); }
        let v12 = v1.xy + s1 - s2;
        let t = tangent(n);
        var history = 0.0;
        for (var m = 0u; m < MAX_SUB; m++) {
            if (old.key[m] == key) { history = old.xi[m]; }
        }
        let input = ContactInput(subs.delta[k] * u, 0.0, 0.0, -dot(v12, n), dot(v12, t),
                                 m12, mass, history, params.dt, m12, 0u, 0.0, 0.0);
        let r = evaluate(input);
        let fk = r.f_n * n + r.f_t * t;
        f += fk;
        torque += vec2<f32>(cross2(l1, fk), -cross2(l2, fk));
        energy += r.energy;
        moment_x += fk * l1.x;
        moment_y += fk * l1.y;
        sizes += dot(fk, fk);
        springs.key[k] = key;
        springs.xi[k] = r.history;
        if (subs.delta[k] > subs.delta[deepest]) { deepest = k; }
    }
    contact_ft[slot] = vec4<f32>(f, torque);
    sub_hist[slot] = springs;
    let delta = subs.delta[deepest] * u;
    let finite = abs(f.x) <= 3.0e38 && abs(f.y) <= 3.0e38;
    let too_deep = delta / rmin > params.max_overlap;
    if (!finite) { halt(HALT_NOT_FINITE, i); }
    if (too_deep) { halt(HALT_OVERLAP, i); }
    if (RECORD || !finite || too_deep) {
        let n = subs.n[deepest];
        var arm = subs.point[deepest] * u;
        let norm = dot(f, f);
        if (norm > 1.0e-12 * sizes) { arm = vec2<f32>(dot(f, moment_x), dot(f, moment_y)) / norm; }
        contact_info[slot] = vec4<f32>(dot(f, n), dot(f, tangent(n)), delta, energy);
        contact_geo[slot] = vec4<f32>(n, arm);
    }
}
