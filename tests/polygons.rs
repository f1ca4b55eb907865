//! Convex polygons with the overlap-area law (SPEC 2.3, paper 000 sec. 2.2): the overlap
//! geometry against an independent computation, symmetry, and the law in small scenes
//! with analytic answers.

mod common;
use common::*;
use serde_json::json;
use talus::base::rng::Rng;
use talus::shape::{P2, area, ellipse_polygon, world};

/// The overlap area by a different construction than clipping: the convex hull of every
/// corner of one polygon inside the other and every edge–edge intersection.
fn hull_area(p: &[P2], q: &[P2]) -> f64 {
    let inside = |x: P2, poly: &[P2]| {
        let n = poly.len();
        (0..n).all(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]) >= -1e-12
        })
    };
    let mut pts: Vec<P2> = p.iter().copied().filter(|x| inside(*x, q)).collect();
    pts.extend(q.iter().copied().filter(|x| inside(*x, p)));
    for a in 0..p.len() {
        let (p0, p1) = (p[a], p[(a + 1) % p.len()]);
        for b in 0..q.len() {
            let (q0, q1) = (q[b], q[(b + 1) % q.len()]);
            let d = [p1[0] - p0[0], p1[1] - p0[1]];
            let e = [q1[0] - q0[0], q1[1] - q0[1]];
            let den = d[0] * e[1] - d[1] * e[0];
            if den.abs() < 1e-300 {
                continue;
            }
            let w = [q0[0] - p0[0], q0[1] - p0[1]];
            let t = (w[0] * e[1] - w[1] * e[0]) / den;
            let s = (w[0] * d[1] - w[1] * d[0]) / den;
            if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&s) {
                pts.push([p0[0] + t * d[0], p0[1] + t * d[1]]);
            }
        }
    }
    if pts.len() < 3 {
        return 0.0;
    }
    // Andrew's monotone chain.
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let turn = |o: P2, a: P2, b: P2| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut hull: Vec<P2> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &P2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &x in iter {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], x) <= 0.0
            {
                hull.pop();
            }
            hull.push(x);
        }
        hull.pop();
    }
    area(&hull)
}

/// A random convex polygon in the world frame, and its centre.
fn random_polygon(rng: &mut Rng, centre: P2) -> (Vec<P2>, P2) {
    let corners = 3 + (rng.next_u64() % 14) as u32;
    let a = rng.range(0.5, 1.5);
    let body = ellipse_polygon(corners, a, a * rng.range(0.4, 1.0), rng.range(0.0, 1.0));
    let mut w = Vec::new();
    world(&body, centre, rng.range(0.0, std::f64::consts::TAU), &mut w);
    (w, centre)
}

fn distance_to_outline(x: P2, poly: &[P2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % n]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let t = (((x[0] - a[0]) * ab[0] + (x[1] - a[1]) * ab[1])
                / (ab[0] * ab[0] + ab[1] * ab[1]))
                .clamp(0.0, 1.0);
            (x[0] - a[0] - t * ab[0]).hypot(x[1] - a[1] - t * ab[1])
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn overlap_geometry_of_random_convex_pairs() {
    let mut rng = Rng::new(7);
    let (mut overlapping, mut generic, mut shallow) = (0, 0, 0);
    for _ in 0..5000 {
        let (p, ci) = random_polygon(&mut rng, [0.0, 0.0]);
        let cj = [rng.range(-1.2, 1.2), rng.range(-1.2, 1.2)];
        let (q, cj) = random_polygon(&mut rng, cj);
        let expect = hull_area(&p, &q);
        let Some((g, point)) = polygon_polygon_world(&p, ci, &q, cj) else {
            assert!(expect < 1e-12, "missed an overlap of area {expect}");
            continue;
        };
        overlapping += 1;
        // Area: two constructions agree to rounding.
        assert!(
            (g.area - expect).abs() < 1e-12,
            "area {} vs {expect}",
            g.area
        );
        assert!(g.n[0].is_finite() && g.n[1].is_finite() && g.l > 0.0);
        assert!((g.n[0].hypot(g.n[1]) - 1.0).abs() < 1e-12);
        if g.chord > 1e-6 {
            generic += 1;
            // S is the midpoint of two points on both outlines, half a chord apart along t.
            let t = [-g.n[1], g.n[0]];
            for s in [-0.5, 0.5] {
                let x = [point[0] + s * g.chord * t[0], point[1] + s * g.chord * t[1]];
                assert!(
                    distance_to_outline(x, &p) < 1e-9,
                    "crossing point on i's outline"
                );
                assert!(
                    distance_to_outline(x, &q) < 1e-9,
                    "crossing point on j's outline"
                );
            }
            // n points from j to i: moving i along n shrinks the overlap. Checked for
            // contacts (overlaps below a tenth of the smaller polygon); a deeper overlap,
            // where the outlines may cross four times, has no meaningful direction and
            // stops a run long before (limits.max_overlap).
            if g.area < 0.1 * area(&p).min(area(&q)) {
                shallow += 1;
                let eps = 1e-4 * g.chord;
                let moved: Vec<P2> = p
                    .iter()
                    .map(|v| [v[0] + eps * g.n[0], v[1] + eps * g.n[1]])
                    .collect();
                let after = hull_area(&moved, &q);
                assert!(after < g.area, "moving i along n must reduce the overlap");
            }
        }
        // Swapping i and j: same area, point and arm; opposite normal.
        let (h, h_point) = polygon_polygon_world(&q, cj, &p, ci).unwrap();
        assert!((h.area - g.area).abs() < 1e-12);
        assert!(
            (h.l - g.l).abs() < 1e-12,
            "l {} vs {}: {g:?} vs {h:?}\n p {p:?} ci {ci:?}\n q {q:?} cj {cj:?}",
            g.l,
            h.l
        );
        if g.chord > 1e-6 {
            assert!((h_point[0] - point[0]).abs() < 1e-12 && (h_point[1] - point[1]).abs() < 1e-12);
            assert!((h.n[0] + g.n[0]).abs() < 1e-9 && (h.n[1] + g.n[1]).abs() < 1e-9);
        }
    }
    assert!(
        overlapping > 1500 && generic > 1000 && shallow > 300,
        "{overlapping} overlapping, {generic} generic, {shallow} shallow"
    );
}

/// A square of side s (corners on the circle of diameter s√2), listed at `theta`.
fn square(position: [f64; 2], side: f64, theta: f64) -> serde_json::Value {
    json!({ "position": position, "diameter": side * 2f64.sqrt(), "theta": theta })
}

fn area_law(k_n: f64, eta_n: f64, mu: f64) -> serde_json::Value {
    json!({ "law": "overlap_area", "k_n": k_n, "eta_n": eta_n, "mu": mu })
}

fn polygon_scene(
    law: serde_json::Value,
    particles: Vec<serde_json::Value>,
    corners: u32,
) -> serde_json::Value {
    scene_value(
        law,
        json!([{ "kind": "list", "material": "m", "polygon": { "corners": corners }, "particles": particles }]),
    )
}

#[test]
fn swapping_the_two_polygons_gives_equal_and_opposite_forces() {
    let a = json!({ "position": [0.0, 0.0], "diameter": 1.0, "theta": 0.3, "velocity": [0.2, 0.1], "omega": 0.5 });
    let b = json!({ "position": [0.85, 0.2], "diameter": 1.1, "theta": 1.1, "velocity": [-0.1, 0.0], "omega": -0.2 });
    let run = |list: Vec<serde_json::Value>| {
        let mut v = polygon_scene(area_law(1e4, 0.3, 0.5), list, 7);
        v["dt"] = json!(1e-4);
        // A deep overlap on purpose: the forces of a generic configuration.
        v["limits"] = json!({ "initial_overlap": 1e9 });
        let mut s = sim(&v);
        s.step().unwrap();
        assert_eq!(s.pairs.len(), 1, "the two heptagons overlap");
        (
            s.contacts[0],
            s.particles.position(0),
            s.particles.position(1),
        )
    };
    let (c1, a1, b1) = run(vec![a.clone(), b.clone()]);
    let (c2, b2, a2) = run(vec![b, a]);
    for (x, y) in [(a1, a2), (b1, b2)] {
        assert!(
            (x[0] - y[0]).abs() < 1e-15 && (x[1] - y[1]).abs() < 1e-15,
            "the same motion either way"
        );
    }
    let f = c1.force[0].hypot(c1.force[1]);
    assert!(f > 0.0);
    // c1.force acts on A, c2.force on B.
    assert!(
        (c1.force[0] + c2.force[0]).abs() < 1e-12 * f
            && (c1.force[1] + c2.force[1]).abs() < 1e-12 * f
    );
    assert!((c1.point[0] - c2.point[0]).abs() < 1e-14 && (c1.point[1] - c2.point[1]).abs() < 1e-14);
    // Torques about each centre (where the contact was evaluated: the force point less
    // its arm) from the common force point: angular momentum about the origin is
    // conserved, τ_A + τ_B + r_A × F + r_B × (−F) = 0.
    let cross = |l: [f64; 2], f: [f64; 2]| l[0] * f[1] - l[1] * f[0];
    let at = |c: &talus::cpu::forces::ContactForce| [c.point[0] - c.arm[0], c.point[1] - c.arm[1]];
    let tau_a = cross(c1.arm, c1.force);
    let tau_b = cross(c2.arm, c2.force);
    let total = tau_a + tau_b + cross(at(&c1), c1.force) + cross(at(&c2), c2.force);
    assert!(total.abs() < 1e-12 * f, "angular momentum balance {total}");
}

/// The tolerance of a balance on each path: the CPU path's f64, the GPU path's f32
/// forces (the area from the overlap's depth in f32, the arm and the law; measured on
/// lavapipe: 2.2e-5 of the weight for the square on a floor, 6e-6 for the floor under a
/// disk on a square).
fn balance_tolerance(path: Path) -> f64 {
    match path {
        Path::Cpu => 1e-6,
        Path::Gpu => 1e-4,
    }
}

#[test]
fn a_square_resting_on_a_floor_carries_its_weight_by_k_a_over_l() {
    for path in PATHS {
        square_on_a_floor(path);
    }
}

fn square_on_a_floor(path: Path) {
    let (k_n, side) = (1e4, 1.0);
    let mut v = polygon_scene(
        area_law(k_n, 0.5, 0.5),
        vec![square([0.0, 0.52], side, std::f64::consts::FRAC_PI_4)],
        4,
    );
    v["dt"] = json!(2e-4);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-3.0, 0.0], "to": [3.0, 0.0] }]);
    let start = sim(&v);
    let m = start.particles.mass[0];
    assert!(
        (m - 1.2732395447351628 * side * side).abs() < 1e-12,
        "mass of the actual square"
    );
    let Some(mut e) = engine(path, "a square resting on a floor", start) else {
        return;
    };
    e.advance(40_000).unwrap();
    let s = e.sim().unwrap();
    // Independent geometry: a flat square whose centre is at height z penetrates by
    // δ = s/2 − z; A = s δ, and the force point is on the floor under the centre: l = z.
    let z = s.particles.position(0)[1];
    let delta = 0.5 * side - z;
    let balance = k_n * side * delta / z;
    assert_eq!(s.pairs.len(), 1, "{path:?}");
    assert!(
        (balance - m).abs() < balance_tolerance(path) * m,
        "{path:?}: k A/l = {balance} vs m g = {m}"
    );
    assert!(
        (4.0 * s.particles.q[0][0][2]).cos() < -0.999999,
        "{path:?}: still flat"
    );
}

/// A square on a floor under gravity tilted by θ (the floor is an incline), μ = 0.5,
/// gravity ramped over the first time unit so the tangential spring loads without
/// overshoot, on `path`: (displacement along the incline, velocity at t = 2, the
/// velocity of sliding with g (sin θ − μ cos θ) from the start); None without a GPU.
fn incline_motion(path: Path, theta_deg: f64) -> Option<(f64, f64, f64)> {
    let (k_n, mu) = (1e4, 0.5);
    let th = theta_deg.to_radians();
    let mut v = polygon_scene(
        area_law(k_n, 0.5, mu),
        vec![square([0.0, 0.5], 1.0, std::f64::consts::FRAC_PI_4)],
        4,
    );
    v["dt"] = json!(2e-4);
    v["gravity"] = json!({ "g": [th.sin(), -th.cos()], "ramp_time": 1.0 });
    v["walls"] = json!([{ "from": [-50.0, 0.0], "to": [50.0, 0.0] }]);
    let mut e = engine(path, "a square on an incline", sim(&v))?;
    e.advance(10_000).unwrap();
    let s = e.sim().unwrap();
    let vx = s.particles.velocity(0, 2e-4)[0];
    // ∫0^2 of the ramp min(t, 1) is 1.5.
    let expected = (th.sin() - mu * th.cos()).max(0.0) * 1.5;
    Some((s.particles.position(0)[0], vx, expected))
}

#[test]
fn a_square_on_an_incline_sticks_below_tan_theta_mu_and_slides_above() {
    for path in PATHS {
        // tan θ = μ at 26.57°.
        for theta in [20.0, 25.0] {
            // Only the tangential spring's deflection, m g sin θ / k_t ≈ 2e-4.
            let Some((x, _, _)) = incline_motion(path, theta) else {
                return;
            };
            assert!(x.abs() < 1e-3, "{path:?}, θ = {theta}°: sticks, moved {x}");
        }
        for theta in [29.0, 35.0] {
            let Some((_, vx, expected)) = incline_motion(path, theta) else {
                return;
            };
            assert!(
                (vx - expected).abs() < 0.02 * expected,
                "{path:?}, θ = {theta}°: slides with g (sin θ − μ cos θ): v = {vx}, expected {expected}"
            );
        }
    }
}

/// Two polygons collide (no gravity, no friction); returns the total energy (kinetic
/// + elastic) at every step.
fn collision_energies(
    eta_n: f64,
    corners: u32,
    a: serde_json::Value,
    b: serde_json::Value,
) -> Vec<f64> {
    let mut v = polygon_scene(area_law(1e4, eta_n, 0.0), vec![a, b], corners);
    let dt = 1e-4;
    v["dt"] = json!(dt);
    let mut s = sim(&v);
    let mut out = Vec::new();
    let mut touched = false;
    for _ in 0..(2.0 / dt) as usize {
        s.step().unwrap();
        touched |= !s.pairs.is_empty();
        let e = s.energies();
        out.push(e.kinetic() + e.elastic);
    }
    assert!(touched, "the polygons must collide");
    assert!(s.pairs.is_empty(), "and separate again");
    out
}

fn heptagons(eta_n: f64) -> Vec<f64> {
    let a =
        json!({ "position": [-0.6, 0.0], "diameter": 1.0, "theta": 0.2, "velocity": [0.5, 0.0] });
    let b =
        json!({ "position": [0.6, 0.05], "diameter": 1.0, "theta": 1.3, "velocity": [-0.5, 0.0] });
    collision_energies(eta_n, 7, a, b)
}

#[test]
fn collision_energy_is_bounded_without_damping_and_decays_with_it() {
    // Two squares face to face: f = k^n A/l = k^n L δ / l(δ) depends on δ alone, so the
    // collision is conservative and the energy comes back to integration accuracy.
    // During contact the stored energy is estimated as f δ / 2, which ignores the slow
    // change of l (δ/l ≈ 2 % here).
    let q = std::f64::consts::FRAC_PI_4;
    let a = json!({ "position": [-0.6, 0.0], "diameter": 2f64.sqrt(), "theta": q, "velocity": [0.5, 0.0] });
    let b = json!({ "position": [0.6, 0.0], "diameter": 2f64.sqrt(), "theta": q, "velocity": [-0.5, 0.0] });
    let faces = collision_energies(0.0, 4, a, b);
    let e0 = faces[0];
    let worst = faces.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max);
    let last = *faces.last().unwrap();
    eprintln!(
        "squares: during contact {:.2e}, after {:.2e} relative",
        worst / e0,
        (last - e0).abs() / e0
    );
    assert!(
        worst < 1e-2 * e0,
        "face to face: energy estimate off by {worst:.2e} of {e0}"
    );
    // Measured 6.7e-4, 1.2e-4 and 7.8e-5 at dt = 2e-4, 1e-4 and 5e-5 (Gear across the
    // kink of the force at first touch).
    assert!(
        (last - e0).abs() < 3e-4 * e0,
        "face to face: energy after {last} vs before {e0}"
    );
    // An oblique collision of heptagons: the area law is not conservative in general
    // (the normal turns with the intersection line and l changes), but the energy stays
    // bounded.
    let free = heptagons(0.0);
    let e0 = free[0];
    let peak = free.iter().cloned().fold(0.0, f64::max);
    let last = *free.last().unwrap();
    eprintln!("heptagons without damping: peak {peak:.5}, after {last:.5}, before {e0:.5}");
    assert!(peak < 1.05 * e0, "bounded: peak {peak} vs {e0}");
    assert!(
        last > 0.8 * e0 && last < 1.05 * e0,
        "after {last} vs before {e0}"
    );
    // With damping the energy never grows and the collision dissipates.
    let damped = heptagons(0.5);
    let e0 = damped[0];
    for w in damped.windows(2) {
        assert!(
            w[1] <= w[0] + 1e-3 * e0,
            "energy must not grow: {} -> {}",
            w[0],
            w[1]
        );
    }
    let last = *damped.last().unwrap();
    assert!(last < 0.9 * e0, "damping dissipates: {last} vs {e0}");
}

/// The area of polygon ∩ disk by integrating, over x, the overlap of the two vertical
/// intervals (both are convex), with composite Simpson on fine strips: independent of
/// the edge-by-edge circle formula.
fn integrated_area(p: &[P2], c: P2, r: f64) -> f64 {
    let lo = p
        .iter()
        .map(|v| v[0])
        .fold(f64::INFINITY, f64::min)
        .max(c[0] - r);
    let hi = p
        .iter()
        .map(|v| v[0])
        .fold(f64::NEG_INFINITY, f64::max)
        .min(c[0] + r);
    if hi <= lo {
        return 0.0;
    }
    let column = |x: f64| -> f64 {
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        let n = p.len();
        for k in 0..n {
            let (u, v) = (p[k], p[(k + 1) % n]);
            if (u[0] - x) * (v[0] - x) <= 0.0 && u[0] != v[0] {
                let z = u[1] + (x - u[0]) / (v[0] - u[0]) * (v[1] - u[1]);
                a = a.min(z);
                b = b.max(z);
            }
        }
        let h = (r * r - (x - c[0]) * (x - c[0])).max(0.0).sqrt();
        (b.min(c[1] + h) - a.max(c[1] - h)).max(0.0)
    };
    let n = 200_000;
    let h = (hi - lo) / n as f64;
    let mut s = column(lo) + column(hi);
    for k in 1..n {
        s += column(lo + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

#[test]
fn polygon_disk_and_disk_disk_overlaps() {
    use talus::overlap::disk_disk_area;
    let mut rng = Rng::new(11);
    let mut checked = 0;
    for _ in 0..300 {
        let (p, cp) = random_polygon(&mut rng, [0.0, 0.0]);
        let c = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
        let r = rng.range(0.3, 0.8);
        let expect = integrated_area(&p, c, r);
        let Some((g, point)) = polygon_disk_world(&p, cp, c, r, true) else {
            assert!(expect < 1e-9, "missed an overlap of area {expect}");
            continue;
        };
        checked += 1;
        assert!(
            (g.area - expect).abs() < 1e-7,
            "area {} vs {expect}",
            g.area
        );
        let (h, _) = polygon_disk_world(&p, cp, c, r, false).unwrap();
        assert_eq!(h.area, g.area);
        assert!((h.l - g.l).abs() < 1e-12);
        if g.chord > 1e-6 && g.area < 0.1 * area(&p).min(std::f64::consts::PI * r * r) {
            assert_eq!(
                (h.n[0], h.n[1]),
                (-g.n[0], -g.n[1]),
                "swapped: opposite normal"
            );
            // Crossings on both outlines, and n pointing from the disk to the polygon.
            let t = [-g.n[1], g.n[0]];
            for s in [-0.5, 0.5] {
                let x = [point[0] + s * g.chord * t[0], point[1] + s * g.chord * t[1]];
                assert!(distance_to_outline(x, &p) < 1e-9);
                assert!(((x[0] - c[0]).hypot(x[1] - c[1]) - r).abs() < 1e-9);
            }
            let eps = 1e-4 * g.chord;
            let moved: Vec<P2> = p
                .iter()
                .map(|v| [v[0] + eps * g.n[0], v[1] + eps * g.n[1]])
                .collect();
            assert!(
                integrated_area(&moved, c, r) < g.area,
                "moving i along n shrinks the overlap"
            );
        }
    }
    assert!(checked > 100, "{checked} overlapping pairs");
    // Two disks: the lens against the integral over a 16-gon-free circle pair, by the
    // same strip integration of the two circles' vertical chords.
    for (d, r1, r2) in [(1.9, 1.0, 1.0), (1.2, 1.0, 0.5), (0.9999, 0.5, 0.5)] {
        let g = disk_disk_area([d, 0.0], r1, r2).unwrap();
        let n = 400_000;
        let (lo, hi) = ((d - r1).max(-r2), r2.min(d + r1));
        let h = (hi - lo) / n as f64;
        let col = |x: f64| {
            let a = (r1 * r1 - (x - d) * (x - d)).max(0.0).sqrt();
            let b = (r2 * r2 - x * x).max(0.0).sqrt();
            2.0 * a.min(b)
        };
        let mut s = col(lo) + col(hi);
        for k in 1..n {
            s += col(lo + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        let expect = s * h / 3.0;
        assert!(
            (g.area - expect).abs() < 1e-6 * expect.max(1e-6),
            "lens {} vs {expect}",
            g.area
        );
        assert_eq!(g.n, [1.0, 0.0]);
    }
}

#[test]
fn a_disk_rests_on_a_square_and_the_floor_carries_both() {
    for path in PATHS {
        disk_on_a_square(path);
    }
}

fn disk_on_a_square(path: Path) {
    // A square on the floor and a disk on its top face, both under the area law
    // (polygon–disk and polygon–wall contacts): at rest the floor carries the weight of
    // both and the square the weight of the disk.
    let mut v = scene_value(
        area_law(1e4, 0.5, 0.5),
        json!([
            { "kind": "list", "material": "m", "polygon": { "corners": 4 },
              "particles": [{ "position": [0.0, 0.5], "diameter": 2f64.sqrt(),
                              "theta": std::f64::consts::FRAC_PI_4 }] },
            { "kind": "list", "material": "m", "particles": [{ "position": [0.0, 1.4], "diameter": 0.8 }] }
        ]),
    );
    v["dt"] = json!(2e-4);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-3.0, 0.0], "to": [3.0, 0.0] }]);
    let start = sim(&v);
    let (square, disk) = (start.particles.mass[0], start.particles.mass[1]);
    let weight = square + disk;
    let Some(mut e) = engine(path, "a disk on a square", start) else {
        return;
    };
    e.advance(40_000).unwrap();
    let s = e.sim().unwrap();
    let floor: f64 = s
        .pairs
        .iter()
        .zip(&s.contacts)
        .filter(|(p, _)| p.is_wall())
        .map(|(_, c)| c.force[1])
        .sum();
    let on_square: f64 = s
        .pairs
        .iter()
        .zip(&s.contacts)
        .filter(|(p, _)| p.i == 0 && p.j == 1)
        .map(|(_, c)| -c.force[1])
        .sum();
    let tol = balance_tolerance(path);
    assert!(
        (floor - weight).abs() < tol * weight,
        "{path:?}: floor carries {floor} of {weight}"
    );
    assert!(
        (on_square - disk).abs() < tol * disk,
        "{path:?}: square carries {on_square} of {disk}"
    );
}

/// The elastic force direction and size (A/l along n) of polygon i against j.
fn overlap_force(p: &[P2], ci: P2, q: &[P2], cj: P2) -> [f64; 2] {
    match polygon_polygon_world(p, ci, q, cj) {
        Some((g, _)) => {
            assert!(
                g.area.is_finite() && g.l.is_finite() && g.n[0].is_finite() && g.n[1].is_finite(),
                "non-finite geometry"
            );
            [g.area / g.l * g.n[0], g.area / g.l * g.n[1]]
        }
        None => [0.0, 0.0],
    }
}

/// Largest change of the force between neighbouring steps of a sweep, in units of the
/// largest force of the sweep; and that largest force.
fn largest_jump(steps: usize, config: impl Fn(f64) -> (Vec<P2>, P2, Vec<P2>, P2)) -> (f64, f64) {
    let forces: Vec<[f64; 2]> = (0..=steps)
        .map(|k| {
            let (p, ci, q, cj) = config(k as f64 / steps as f64);
            overlap_force(&p, ci, &q, cj)
        })
        .collect();
    let scale = forces.iter().map(|f| f[0].hypot(f[1])).fold(0.0, f64::max);
    let jump = forces
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .fold(0.0, f64::max);
    (jump / scale, scale)
}

#[test]
fn degenerate_contacts_give_finite_forces_that_vary_continuously() {
    // SPEC 2.3: a corner through a face, parallel edges, spike against spike. Each sweep
    // passes through the degenerate configuration in 2000 steps; a flip of the normal or
    // a jump of the force point would change the force by a good part of its size in one
    // step, a continuous force by ~1/2000 of it per unit slope.
    let square = |c: P2, side: f64, theta: f64| {
        let mut w = Vec::new();
        let body = ellipse_polygon(
            4,
            side * 2f64.sqrt(),
            side * 2f64.sqrt(),
            std::f64::consts::FRAC_PI_4,
        );
        world(&body, c, theta, &mut w);
        w
    };
    let n = 2000;
    // A square's corner pushed through the top face of another, from 0.01 outside to 0.05 inside.
    let corner = largest_jump(n, |s| {
        let cj = [0.0, 0.5 + 0.5 * 2f64.sqrt() + 0.01 - 0.06 * s];
        (
            square(cj, 1.0, std::f64::consts::FRAC_PI_4),
            cj,
            square([0.0, 0.0], 1.0, 0.0),
            [0.0, 0.0],
        )
    });
    // Parallel faces: the upper square turns through 0 (faces parallel) at overlap 1e-3.
    let parallel = largest_jump(n, |s| {
        let cj = [0.2, 1.0 - 1e-3];
        (
            square(cj, 1.0, (s - 0.5) * 2e-3),
            cj,
            square([0.0, 0.0], 1.0, 0.0),
            [0.0, 0.0],
        )
    });
    // Parallel faces whose ends pass each other: sliding along the face through the
    // point where the corners meet.
    let sliding = largest_jump(n, |s| {
        let cj = [0.9 + 0.2 * s, 1.0 - 1e-3];
        (
            square(cj, 1.0, 0.0),
            cj,
            square([0.0, 0.0], 1.0, 0.0),
            [0.0, 0.0],
        )
    });
    // Spike against spike: two squares corner to corner, the upper one sliding sideways
    // through exact alignment at a fixed depth.
    let spikes = largest_jump(n, |s| {
        let cj = [(s - 0.5) * 0.02, 2f64.sqrt() - 0.01];
        let q = std::f64::consts::FRAC_PI_4;
        (
            square(cj, 1.0, q),
            cj,
            square([0.0, 0.0], 1.0, q),
            [0.0, 0.0],
        )
    });
    for (name, (jump, scale)) in [
        ("corner", corner),
        ("parallel", parallel),
        ("sliding", sliding),
        ("spikes", spikes),
    ] {
        eprintln!("{name}: largest step {jump:.2e} of the largest force {scale:.2e}");
        assert!(scale > 0.0, "{name}: in contact");
        assert!(
            jump < 0.02,
            "{name}: the force jumps by {jump:.2e} of its size"
        );
    }
}

#[test]
fn damped_polygon_piles_settle_with_leapfrog_and_gear_is_warned_about() {
    // A small R8 pile (12-gons on the hexagonal lattice, k^n = 1e7 N/m, η^n = 1, μ = 0)
    // at dt = 2e-6 s: leapfrog settles; Gear's predictor-corrector keeps pumping energy
    // into the damped contacts (its kinetic energy stays near the elastic one), which is
    // what the scene check warns about, and leapfrog gets no warning.
    let pile = |integrator: &str| {
        let path = std::path::Path::new("scenes/r8_polygon_pile_reduced.json");
        let set = [
            "particles[0].bottom_row=9".to_string(),
            "contact.mu=0".into(),
            "contact.eta_n=1".into(),
            "gravity.ramp_time=0.01".into(),
            format!("integrator={integrator}"),
        ];
        talus::scene::load(path, &set).unwrap()
    };
    let warned = |s: &talus::scene::Scene| {
        talus::scene::warnings(s)
            .iter()
            .any(|w| w.contains("pumps energy"))
    };
    assert!(warned(&pile("gear5")), "Gear at this step is warned about");
    assert!(!warned(&pile("leapfrog")), "leapfrog is not");
    let ratio = |integrator: &str| {
        let mut s = talus::sim::Simulation::new(pile(integrator)).unwrap();
        for _ in 0..25_000 {
            s.step().unwrap();
        }
        let e = s.energies();
        e.kinetic() / e.elastic
    };
    let (lf, gear) = (ratio("leapfrog"), ratio("gear5"));
    eprintln!("kinetic/elastic after 0.05 s: leapfrog {lf:.2e}, Gear {gear:.2e}");
    assert!(lf < 1e-6, "leapfrog settles: {lf:.2e}");
    assert!(gear > 1e-3, "Gear vibrates: {gear:.2e}");
}
