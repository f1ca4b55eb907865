// Overlap-area geometry of convex polygons (src/overlap/, SPEC 2.3). Two polygons:
// each one's edges facing the other cut to the part inside it (`edges_inside`), whose
// ends are corners or crossings of the outlines (`polygon_polygon`); the twin of
// src/overlap/polygon.rs, step for step (issue 37 item 1). A polygon and a wall: p's
// edges cut by the wall's line and the lines across its ends (`polygon_wall`). The
// line through the two crossings farthest apart gives the normal, its midpoint the
// force point. (The CPU path also keeps a hint per candidate that lets a resting or
// apart pair skip the cut, src/overlap/hint.rs; the result is the cut's either way.)

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
