// Contact geometry of disks and walls (src/base/geometry.rs), from fixed-point offsets
// (position.wgsl): the overlap comes out as a whole number of units plus a small f32
// part, so it keeps its relative precision however small it is.

struct Geometry {
    n: vec2<f32>,      // unit normal from 2 to 1
    delta: f32,        // overlap
    r: f32,            // centre distance (mirror disk for walls)
    sigma: f32,
    arm: vec2<f32>,    // contact point minus the centre of particle 1
    near: bool,        // false: too far apart to interact (all else unset)
};

fn far_apart() -> Geometry {
    return Geometry(vec2<f32>(0.0, 1.0), -1.0e30, 1.0e30, 0.0, vec2<f32>(0.0), false);
}

// Two disks, or a disk and a point (radius 0), from the offset o = centre 1 - centre 2.
// sigma = r1 + r2 is given in units (whole + remainder); r1 in length.
fn point_pair(o: Offset, sig_whole: i32, sig_rem: f32, r1: f32) -> Geometry {
    if (!o.near) { return far_apart(); }
    let dist = distance_units(o.d, o.e);
    let u = params.unit;
    let r = (f32(dist.whole) + dist.corr) * u;
    // sigma - |d| in whole units is exact in i32 (|d| < 2^31 whenever it can matter).
    var whole_overlap = f32(sig_whole) - f32(dist.whole);
    if (dist.whole < 0x80000000u) { whole_overlap = f32(sig_whole - i32(dist.whole)); }
    let delta = (whole_overlap + (sig_rem - dist.corr)) * u;
    let sigma = (f32(sig_whole) + sig_rem) * u;
    var n = vec2<f32>(0.0, 1.0);
    let v = vec2<f32>(o.d) + o.e;
    if (r > 0.0) { n = v / length(v); }
    return Geometry(n, delta, r, sigma, -n * (r1 - 0.5 * delta), true);
}

fn disk_disk(i: u32, j: u32) -> Geometry {
    return disk_disk_at(offset_ij(i, j), i, j);
}

// `disk_disk` from the pair's offset o = centre i - centre j.
fn disk_disk_at(o: Offset, i: u32, j: u32) -> Geometry {
    return point_pair(o, i32(props[i].radius_units + props[j].radius_units),
                      props[i].radius_rem + props[j].radius_rem, props[i].radius);
}

// --- the line of a wall, exactly (issue 18) ---

// Q30: unit vectors in integers, 2^30 to one.
const Q30: f32 = 1073741824.0;

// A 64-bit value times 2^30, modulo 2^64.
fn shl30(v: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(v.x << 30u, (v.y << 30u) | (v.x >> 2u));
}

// The line of wall w seen from particle i's centre c. The wall carries its unit normal
// n in Q30 integers, q (host: gpu/mod.rs `wall_normal`), and the turn beta of q off n.
// (c - a).q is exact in 64-bit integers: (da 2^30 + df).q from the anchor and frac
// differences, modulo 2^64, which is the true value within 8 cells of the line (the
// large products cancel). With q = (1 + alpha) n + beta t, the true distance is
// (c - a).n = ((c - a).q - beta (c - a).t) / (1 + alpha) (alpha, beta ~2^-31, to first
// order), plus the remainders' part: exact for any line,
// long and inclined; an axis-aligned one has q = (0, 2^30) or so, alpha = beta = 0.
struct WallLine {
    n: vec2<f32>,       // the unit normal, from the line towards c
    t: vec2<f32>,       // along the wall, from a to b
    q: vec2<i32>,       // n in Q30
    c64: vec2<u32>,     // (c - a).q, units x 2^30, two's complement, >= 0
    small: f32,         // the rest of c's distance from the line (units)
    beta: f32,          // q's turn off n, oriented with q
    alpha: f32,         // q's stretch: q = (1 + alpha) n + beta t
    near: bool,         // c within 4 cells of the line (else c64 may have wrapped)
};

fn wall_line(i: u32, w: u32) -> WallLine {
    let s = state[i];
    let wall = wall_at(w);
    let t = wall.ab / max(length(wall.ab), 1.0e-30);
    var n = vec2<f32>(-t.y, t.x);
    var q = wall.nq;
    var beta = wall.beta;
    let da = s.anchor - wall.a_anchor;
    let df = vec2<i32>(s.frac) - vec2<i32>(wall.a_frac);
    var c64 = add64(shl30(add64(smul(da.x, q.x), smul(da.y, q.y))),
                    add64(smul(df.x, q.x), smul(df.y, q.y)));
    let er = s.q[0].xy - wall.a_rem;
    let p = offset_vector(offset(s.anchor, s.frac, s.q[0].xy, wall.a_anchor, wall.a_frac, wall.a_rem));
    let along = dot(p, t) * params.inv_unit;
    let near = abs(dot(p, n)) < 4.0 * params.cell_size;
    if (i64_to_f32(c64) / Q30 + dot(er, n) - beta * along < 0.0) {
        n = -n;
        q = -q;
        beta = -beta;
        c64 = sub64(vec2<u32>(0u, 0u), c64);
    }
    // (c - a).n = ((c - a).q - beta along) / (1 + alpha), to first order in alpha.
    let raw = i64_to_f32(c64) / Q30;
    let small = dot(er, n) - beta * along - wall.alpha * raw;
    return WallLine(n, t, q, c64, small, beta, wall.alpha, near);
}

// How deep a disk of radius r (whole units and remainder) reaches beyond the line: r
// less the centre's distance, in units, with the large parts cancelling in integers.
fn wall_depth(l: WallLine, r_units: u32, r_rem: f32) -> f32 {
    let exact = sub64(vec2<u32>(r_units << 30u, r_units >> 2u), l.c64);
    return i64_to_f32(exact) / Q30 + r_rem - l.small;
}

// A disk and a wall segment a-b, seen as a mirror disk (r = 2 dist, sigma = 2 radius).
// End points are exact point pairs; the interior is exact from the wall's line
// (`wall_line`), axis-aligned or inclined.
fn disk_wall(i: u32, w: u32) -> Geometry {
    let s = state[i];
    let pr = props[i];
    let wall = wall_at(w);
    let oa = offset(s.anchor, s.frac, s.q[0].xy, wall.a_anchor, wall.a_frac, wall.a_rem);
    let p = offset_vector(oa);
    let ab = wall.ab;
    let len2 = dot(ab, ab);
    var t = 0.0;
    if (len2 > 0.0) { t = clamp(dot(p, ab) / len2, 0.0, 1.0); }
    let radius = pr.radius;
    var g: Geometry;
    if (t <= 0.0 || t >= 1.0) {
        var o = oa;
        if (t >= 1.0) {
            o = offset(s.anchor, s.frac, s.q[0].xy, wall.b_anchor, wall.b_frac, wall.b_rem);
        }
        g = point_pair(o, i32(pr.radius_units), pr.radius_rem, radius);
        if (!g.near) { return g; }
    } else {
        let l = wall_line(i, w);
        if (!l.near) { return far_apart(); }
        let delta = wall_depth(l, pr.radius_units, pr.radius_rem) * params.unit;
        g = Geometry(l.n, delta, 0.0, 0.0, -l.n * (radius - 0.5 * delta), true);
    }
    // Mirror disk: the law sees two disks of this radius at twice the distance.
    g.sigma = 2.0 * radius;
    g.r = g.sigma - 2.0 * g.delta;
    return g;
}

// Wall w placed at the time of this step's contacts (src/sim/walls.rs `place_walls`):
// its ends at t = 0 moved by its displacement, in fixed point (to f32's precision of
// the displacement, `renormalize_axis`); a wall that does not move as it is.
fn wall_at(w: u32) -> Wall {
    var wall = walls[w];
    if (!wall_moves(w)) { return wall; }
    let d = wall_displacement(w, contact_time()) * params.inv_unit;
    let ax = renormalize_axis(wall.a_rem.x + d.x, wall.a_anchor.x, wall.a_frac.x);
    let az = renormalize_axis(wall.a_rem.y + d.y, wall.a_anchor.y, wall.a_frac.y);
    let bx = renormalize_axis(wall.b_rem.x + d.x, wall.b_anchor.x, wall.b_frac.x);
    let bz = renormalize_axis(wall.b_rem.y + d.y, wall.b_anchor.y, wall.b_frac.y);
    wall.a_anchor = vec2<i32>(ax.anchor, az.anchor);
    wall.a_frac = vec2<u32>(ax.frac, az.frac);
    wall.a_rem = vec2<f32>(ax.rem, az.rem);
    wall.b_anchor = vec2<i32>(bx.anchor, bz.anchor);
    wall.b_frac = vec2<u32>(bx.frac, bz.frac);
    wall.b_rem = vec2<f32>(bx.rem, bz.rem);
    return wall;
}
