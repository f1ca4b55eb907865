// A polygon against a wall segment (twin of src/overlap/wall.rs).

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
