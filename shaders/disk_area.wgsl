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
    let wall = wall_at(w);
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
