// A polygon and a disk (twin of src/overlap/disk.rs `polygon_disk`).

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
