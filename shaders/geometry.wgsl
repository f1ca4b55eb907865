// Contact geometry of disks and walls (src/geometry.rs), from fixed-point offsets
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
    let pi = props[i];
    let pj = props[j];
    return point_pair(offset_ij(i, j), i32(pi.radius_units + pj.radius_units),
                      pi.radius_rem + pj.radius_rem, pi.radius);
}

// A disk and a wall segment a-b, seen as a mirror disk (r = 2 dist, sigma = 2 radius).
// End points are exact point pairs; the interior of an axis-aligned wall is exact along
// its normal; the interior of an inclined wall falls back to f32 from its end point a
// (6e-8 of the distance along the wall).
fn disk_wall(i: u32, w: u32) -> Geometry {
    let s = state[i];
    let pr = props[i];
    let wall = walls[w];
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
    } else if (ab.x == 0.0 || ab.y == 0.0) {
        // Normal along axis k; the coordinate along k is exact in units.
        let k = select(0u, 1u, ab.y == 0.0);
        if (abs(oa.da[k]) > 1) { return far_apart(); }
        let along = f32(oa.d[k]) + oa.e[k];
        let sgn = select(-1.0, 1.0, along >= 0.0);
        let whole = i32(sgn) * oa.d[k];
        let corr = sgn * oa.e[k];
        var n = vec2<f32>(0.0);
        n[k] = sgn;
        let u = params.unit;
        let delta = (f32(i32(pr.radius_units) - whole) + (pr.radius_rem - corr)) * u;
        g = Geometry(n, delta, 0.0, 0.0, -n * (radius - 0.5 * delta), true);
    } else {
        let d = p - t * ab;
        let dist = length(d);
        var n = vec2<f32>(-ab.y, ab.x) / sqrt(len2);
        if (dist > 0.0) { n = d / dist; }
        let delta = radius - dist;
        g = Geometry(n, delta, 0.0, 0.0, -n * (radius - 0.5 * delta), true);
    }
    // Mirror disk: the law sees two disks of this radius at twice the distance.
    g.sigma = 2.0 * radius;
    g.r = g.sigma - 2.0 * g.delta;
    return g;
}
