// Contact geometry of disks and walls (src/geometry.rs), in relative coordinates.

struct Geometry {
    n: vec2<f32>,      // unit normal from 2 to 1
    delta: f32,        // overlap
    r: f32,            // centre distance (mirror disk for walls)
    sigma: f32,
    arm: vec2<f32>,    // contact point minus the centre of particle 1
};

// d = p1 - p2 (from `rel`).
fn disk_disk(d: vec2<f32>, r1: f32, r2: f32) -> Geometry {
    let r = length(d);
    var n = vec2<f32>(0.0, 1.0);
    if (r > 0.0) { n = d / r; }
    let sigma = r1 + r2;
    let delta = sigma - r;
    let arm = r1 - 0.5 * delta;
    return Geometry(n, delta, r, sigma, -n * arm);
}

// p = particle centre minus the wall's first end point.
fn disk_wall(p: vec2<f32>, radius: f32, ab: vec2<f32>) -> Geometry {
    let len2 = dot(ab, ab);
    var s = 0.0;
    if (len2 > 0.0) { s = clamp(dot(p, ab) / len2, 0.0, 1.0); }
    let d = p - s * ab;
    let dist = length(d);
    var n = vec2<f32>(-ab.y, ab.x) / max(sqrt(len2), 1.17549435e-38);
    if (dist > 0.0) { n = d / dist; }
    let delta = radius - dist;
    let arm = radius - 0.5 * delta;
    return Geometry(n, delta, 2.0 * dist, 2.0 * radius, -n * arm);
}

fn wall_offset(i: u32, w: u32) -> vec2<f32> {
    return rel(state[i].anchor, state[i].q[0].xy, walls[w].anchor, walls[w].frac);
}
