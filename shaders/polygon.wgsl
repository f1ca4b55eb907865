// Overlap-area geometry of convex polygons (src/overlap.rs, SPEC 2.3), step for step:
// p clipped by the edges of q near the contact (Sutherland-Hodgman), remembering which
// corners are crossings of the two outlines; the line through the two crossings farthest
// apart gives the normal, its midpoint the force point.
//
// A pair is computed in a frame centred between the two particles: corners are
// -+ (c_j - c_i)/2 + R(theta)v, with the exact fixed-point offset rounded once to f32;
// a wall contact in particle i's frame. Corner coordinates then carry ~3e-8 d of
// rounding, so an area overlap A/l is resolved to about 1e-7 d (README, "Precision").

const MAX_CLIP: u32 = 36u;

// Set when the pipelines are built for a polygon scene (src/gpu/kernels.rs). Disk
// scenes compile without the polygon branches, whose large per-thread arrays would
// otherwise cost every disk contact registers and memory.
override POLYGONS: bool = false;
const ORIGIN_P: u32 = 0u;
const ORIGIN_Q: u32 = 1u;
const ORIGIN_CROSSING: u32 = 2u;

struct AreaContact {
    area: f32,
    n: vec2<f32>,       // from j to i
    point: vec2<f32>,   // force point S, relative to centre i
    chord: f32,
    l: f32,
    found: bool,
};

fn no_contact() -> AreaContact {
    return AreaContact(0.0, vec2<f32>(0.0, 1.0), vec2<f32>(0.0), 0.0, 0.0, false);
}

// (sin x, cos x) to about one ulp. Vulkan only requires sin and cos to be within 2^-11
// absolutely, and GPUs use fast hardware approximations (~4e-7): on a corner half a
// diameter out that would be 2e-7 d, more than the whole f32 budget of the overlap.
// Range reduction by quarter turns (pi/2 in two parts, the first product exact for the
// small multiples that occur: polygon angles are kept in [-pi, pi]), then Taylor series
// on [-pi/4, pi/4] (next terms below 2e-9).
fn sin_cos(x: f32) -> vec2<f32> {
    let q = round(x * 0.63661977236758134);
    let r = (x - q * 1.5707963705062866) + q * 4.37113900018624283e-8;
    let r2 = r * r;
    let s = r * (1.0 + r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362880.0)))));
    let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0 + r2 * (-1.0 / 3628800.0)))));
    let k = (i32(q) % 4 + 4) % 4;
    if (k == 0) { return vec2<f32>(s, c); }
    if (k == 1) { return vec2<f32>(c, -s); }
    if (k == 2) { return vec2<f32>(-s, -c); }
    return vec2<f32>(-c, s);
}

// Corners of particle k in the world orientation, shifted by `centre`.
fn load_polygon(k: u32, centre: vec2<f32>, out: ptr<function, array<vec2<f32>, 16>>) -> u32 {
    let sh = props[k].shape;
    let sc = sin_cos(state[k].q[0].z);
    let c = sc.y;
    let s = sc.x;
    for (var m = 0u; m < sh.y; m++) {
        let v = corners[sh.x + m];
        (*out)[m] = centre + vec2<f32>(c * v.x - s * v.y, s * v.x + c * v.y);
    }
    return sh.y;
}

fn shoelace(v: ptr<function, array<array<vec2<f32>, MAX_CLIP>, 2>>, b: u32, n: u32) -> f32 {
    var a = 0.0;
    for (var k = 0u; k < n; k++) {
        let p = (*v)[b][k];
        let q = (*v)[b][(k + 1u) % n];
        a += p.x * q.y - q.x * p.y;
    }
    return 0.5 * a;
}

// Mean of the corners: the fallback force point. Unlike the area centroid it needs no
// division by a vanishing area, so a degenerate overlap keeps S inside it.
fn corner_mean(v: ptr<function, array<array<vec2<f32>, MAX_CLIP>, 2>>, b: u32, n: u32) -> vec2<f32> {
    var c = vec2<f32>(0.0);
    for (var k = 0u; k < n; k++) { c += (*v)[b][k]; }
    return c / f32(n);
}

fn reduced_arm(li: f32, lj: f32, scale: f32) -> f32 {
    let floor = 1.0e-6 * scale;
    let a = max(li, floor);
    let b = max(lj, floor);
    return a * b / (a + b);
}

// Area contact of polygon p (np corners, centre ci) with polygon q (nq corners, centre
// cj); the force point comes back in the same frame.
fn polygon_polygon(p: ptr<function, array<vec2<f32>, 16>>, np: u32, ci: vec2<f32>,
                   q: ptr<function, array<vec2<f32>, 16>>, nq: u32, cj: vec2<f32>,
                   only_area: bool) -> AreaContact {
    var v: array<array<vec2<f32>, MAX_CLIP>, 2>;
    var origin: array<array<u32, MAX_CLIP>, 2>;   // origin | (on p's outline) << 2
    var count = array<u32, 2>(np, 0u);
    var r2 = 0.0;
    for (var k = 0u; k < np; k++) {
        v[0][k] = (*p)[k];
        origin[0][k] = ORIGIN_P | 4u;
        r2 = max(r2, dot((*p)[k] - ci, (*p)[k] - ci));
    }
    let r = sqrt(r2);
    var cur = 0u;
    for (var k = 0u; k < nq; k++) {
        let a = (*q)[k];
        let b = (*q)[(k + 1u) % nq];
        let m = vec2<f32>(-(b.y - a.y), b.x - a.x);
        let reach = r * length(m);
        let centre = dot(ci - a, m);
        if (centre >= reach) { continue; }
        if (centre <= -reach) { count[cur] = 0u; break; }
        let dst = 1u - cur;
        var out = 0u;
        let n = count[cur];
        for (var e = 0u; e < n; e++) {
            let x = v[cur][e];
            let y = v[cur][(e + 1u) % n];
            let dx = dot(x - a, m);
            let dy = dot(y - a, m);
            let on_p = (origin[cur][e] & 4u) != 0u;
            if (dx >= 0.0 && out < MAX_CLIP) {
                v[dst][out] = x;
                origin[dst][out] = origin[cur][e];
                out++;
            }
            if ((dx >= 0.0) != (dy >= 0.0) && out < MAX_CLIP) {
                let t = dx / (dx - dy);
                v[dst][out] = x + t * (y - x);
                var o = ORIGIN_Q;
                if (on_p) { o = ORIGIN_CROSSING; }
                // Leaving the half-plane the outline follows q's line; entering, the edge.
                var keep = on_p;
                if (dx >= 0.0) { keep = false; }
                origin[dst][out] = o | select(0u, 4u, keep);
                out++;
            }
        }
        count[dst] = out;
        cur = dst;
        if (out == 0u) { break; }
    }
    let n = count[cur];
    if (n < 3u) { return no_contact(); }
    let area = shoelace(&v, cur, n);
    if (area <= 0.0) { return no_contact(); }
    var g = no_contact();
    g.area = area;
    g.found = true;
    if (only_area) { return g; }
    // The two crossings farthest apart.
    var best = -1.0;
    var xa = vec2<f32>(0.0);
    var xb = vec2<f32>(0.0);
    for (var a = 0u; a < n; a++) {
        if ((origin[cur][a] & 3u) != ORIGIN_CROSSING) { continue; }
        for (var b = a + 1u; b < n; b++) {
            if ((origin[cur][b] & 3u) != ORIGIN_CROSSING) { continue; }
            let d = length(v[cur][b] - v[cur][a]);
            if (d > best) { best = d; xa = v[cur][a]; xb = v[cur][b]; }
        }
    }
    let scale = length(cj - ci) + r;
    var along = vec2<f32>(0.0, 1.0);
    if (length(cj - ci) > 0.0) { along = (ci - cj) / length(cj - ci); }
    let chord = length(xb - xa);
    if (best >= 0.0 && chord > 1.0e-6 * scale) {
        let t = (xb - xa) / chord;
        var nn = vec2<f32>(-t.y, t.x);
        let s = 0.5 * (xa + xb);
        // Corners of i inside j lie on j's side of the line, corners of j on i's side.
        var side = 0.0;
        for (var k = 0u; k < n; k++) {
            let o = origin[cur][k] & 3u;
            if (o == ORIGIN_P) { side += dot(nn, v[cur][k] - s); }
            if (o == ORIGIN_Q) { side -= dot(nn, v[cur][k] - s); }
        }
        if (side > 0.0 || (side == 0.0 && dot(nn, ci - cj) < 0.0)) { nn = -nn; }
        g.n = nn;
        g.point = s;
        g.chord = chord;
    } else {
        g.n = along;
        g.point = corner_mean(&v, cur, n);
        g.chord = 0.0;
    }
    g.l = reduced_arm(length(g.point - ci), length(g.point - cj), scale);
    return g;
}

// Clips polygon v[src] (n corners) by the half-plane (x - a).m >= 0 into v[1 - src].
fn clip_plain(v: ptr<function, array<array<vec2<f32>, MAX_CLIP>, 2>>, src: u32, n: u32,
              a: vec2<f32>, m: vec2<f32>) -> u32 {
    let dst = 1u - src;
    var out = 0u;
    for (var e = 0u; e < n; e++) {
        let x = (*v)[src][e];
        let y = (*v)[src][(e + 1u) % n];
        let dx = dot(x - a, m);
        let dy = dot(y - a, m);
        if (dx >= 0.0 && out < MAX_CLIP) { (*v)[dst][out] = x; out++; }
        if ((dx >= 0.0) != (dy >= 0.0) && out < MAX_CLIP) {
            (*v)[dst][out] = x + (dx / (dx - dy)) * (y - x);
            out++;
        }
    }
    return out;
}

// Area contact of polygon p (centre 0) with the wall segment wa-wb (relative to the
// centre): the part of p beyond the wall's line and between its end points.
fn polygon_wall(p: ptr<function, array<vec2<f32>, 16>>, np: u32, wa: vec2<f32>, wb: vec2<f32>,
                only_area: bool) -> AreaContact {
    let ab = wb - wa;
    let len = length(ab);
    if (len == 0.0) { return no_contact(); }
    var m = vec2<f32>(-ab.y, ab.x) / len;
    if (dot(m, -wa) < 0.0) { m = -m; }
    var v: array<array<vec2<f32>, MAX_CLIP>, 2>;
    for (var k = 0u; k < np; k++) { v[0][k] = (*p)[k]; }
    var n = clip_plain(&v, 0u, np, wa, -m);
    n = clip_plain(&v, 1u, n, wa, ab);
    n = clip_plain(&v, 0u, n, wb, -ab);
    if (n < 3u) { return no_contact(); }
    let area = shoelace(&v, 1u, n);
    if (area <= 0.0) { return no_contact(); }
    var g = no_contact();
    g.area = area;
    g.found = true;
    if (only_area) { return g; }
    var r = 0.0;
    for (var k = 0u; k < np; k++) { r = max(r, length((*p)[k])); }
    let scale = len + r;
    var lo = 3.0e38;
    var hi = -3.0e38;
    for (var k = 0u; k < n; k++) {
        let x = v[1][k];
        if (abs(dot(x - wa, m)) <= 1.0e-6 * scale) {
            let s = dot(x - wa, ab) / len;
            lo = min(lo, s);
            hi = max(hi, s);
        }
    }
    g.n = m;
    if (hi > lo) {
        g.point = wa + (0.5 * (lo + hi) / len) * ab;
        g.chord = hi - lo;
    } else {
        g.point = corner_mean(&v, 1u, n);
        g.chord = 0.0;
    }
    g.l = max(length(g.point), 1.0e-6 * scale);
    return g;
}

// The area contact of particle i with particle j (both polygons). It is computed in a
// frame centred between them, where the corners that meet are smallest, and the force
// point is returned relative to centre i.
fn polygons_ij(i: u32, j: u32, only_area: bool) -> AreaContact {
    var p: array<vec2<f32>, 16>;
    var q: array<vec2<f32>, 16>;
    let half = -0.5 * offset_vector(offset_ij(i, j));
    let np = load_polygon(i, -half, &p);
    let nq = load_polygon(j, half, &q);
    var g = polygon_polygon(&p, np, -half, &q, nq, half, only_area);
    g.point += half;
    return g;
}

// The area contact of particle i with wall w, in i's frame.
fn polygon_wall_iw(i: u32, w: u32, only_area: bool) -> AreaContact {
    var p: array<vec2<f32>, 16>;
    let np = load_polygon(i, vec2<f32>(0.0), &p);
    let s = state[i];
    let wall = walls[w];
    let oa = offset(wall.a_anchor, wall.a_frac, wall.a_rem, s.anchor, s.frac, s.q[0].xy);
    let ob = offset(wall.b_anchor, wall.b_frac, wall.b_rem, s.anchor, s.frac, s.q[0].xy);
    return polygon_wall(&p, np, offset_vector(oa), offset_vector(ob), only_area);
}
