//! Helpers shared by the integration tests: small scenes built in code.
#![allow(dead_code)]

use serde_json::{Value, json};
use talus::scene::{self, Scene};
use talus::sim::Simulation;

pub mod pairs;
pub mod wgsl;

/// A scene around `particles` and `contact`, with a large domain, no gravity by default.
pub fn scene_value(contact: Value, particles: Value) -> Value {
    json!({
        "name": "test",
        "dt": 1e-4,
        "stop": { "time": 1.0 },
        "gravity": { "g": [0.0, 0.0] },
        "domain": { "x": [-100.0, 100.0], "z": [-100.0, 100.0] },
        "materials": { "m": { "density": 1.2732395447351628 } },
        "contact": contact,
        "particles": particles,
        "output": { "checkpoint_every": 0 }
    })
}

pub fn parse(v: &Value) -> Scene {
    match scene::parse(&v.to_string(), &[]) {
        Ok(s) => s,
        Err(e) => panic!("test scene is invalid: {e}"),
    }
}

pub fn sim(v: &Value) -> Simulation {
    Simulation::new(parse(v)).expect("simulation builds")
}

/// Centre distance of particles a and b.
pub fn distance(sim: &Simulation, a: usize, b: usize) -> f64 {
    let (p, q) = (sim.particles.position(a), sim.particles.position(b));
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
}

/// Linear interpolation of the time at which `f` crosses zero between two samples.
pub fn crossing(t0: f64, f0: f64, t1: f64, f1: f64) -> f64 {
    t0 + (t1 - t0) * f0 / (f0 - f1)
}

/// Head-on collision of two equal unit disks (m = 1, radius 0.5) approaching at relative
/// speed `v0`; returns (contact duration from the overlap δ > 0, restitution).
pub fn head_on(contact: Value, v0: f64, dt: f64, integrator: &str) -> (f64, f64) {
    let mut v = scene_value(
        contact,
        json!([{ "kind": "list", "material": "m", "particles": [
            { "position": [-0.6, 0.0], "diameter": 1.0, "velocity": [0.5 * v0, 0.0] },
            { "position": [0.6, 0.0], "diameter": 1.0, "velocity": [-0.5 * v0, 0.0] }
        ]}]),
    );
    v["dt"] = json!(dt);
    v["integrator"] = json!(integrator);
    let mut s = sim(&v);
    let (mut t_in, mut t_out) = (None, None);
    let mut prev = (s.time(), 1.0 - distance(&s, 0, 1));
    for _ in 0..10_000_000 {
        s.step().expect("no divergence");
        let now = (s.time(), 1.0 - distance(&s, 0, 1));
        if t_in.is_none() && prev.1 <= 0.0 && now.1 > 0.0 {
            t_in = Some(crossing(prev.0, prev.1, now.0, now.1));
        }
        if t_in.is_some() && prev.1 > 0.0 && now.1 <= 0.0 {
            t_out = Some(crossing(prev.0, prev.1, now.0, now.1));
        }
        prev = now;
        // well separated again: measure the outgoing speed in free flight
        if t_out.is_some() && now.1 < -0.05 {
            break;
        }
    }
    let vel = |i| s.particles.velocity(i, s.dt())[0];
    let v_out = vel(1) - vel(0);
    (
        t_out.expect("separated") - t_in.expect("collided"),
        v_out / v0,
    )
}

/// A GPU device for a test, or None (with a message) when there is no adapter, unless
/// TALUS_REQUIRE_GPU=1 (CI), where a missing adapter fails the test.
pub fn gpu(test: &str) -> Option<talus::gpu::device::Gpu> {
    match talus::gpu::device::Gpu::open() {
        Ok(g) => Some(g),
        Err(e) if !talus::gpu::device::gpu_required() => {
            eprintln!("SKIPPED {test}: {e} (set TALUS_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        Err(e) => panic!("TALUS_REQUIRE_GPU=1 and {test} has no GPU: {e}"),
    }
}

/// A layer-by-layer pile of fixed rows: 16, 13, 10, 7, 4 and 1 unit particles (30°
/// outline, rows (√3/2) d high) dropped every 1.5 s from 0.3 d above the pile onto a
/// floor; disks or heptagons.
pub fn layered_pile(polygons: bool) -> serde_json::Value {
    let mut block = json!({ "kind": "layered", "material": "m", "diameter": 1.0,
                            "base_width": 16.0, "slope": 30.0, "interval": 1.5, "gap": 0.3,
                            "row_height": 0.8660254037844386 });
    let law = if polygons {
        block["polygon"] = json!({ "corners": 7 });
        json!({ "law": "overlap_area", "k_n": 2000.0, "eta_n": 0.5, "mu": 0.5 })
    } else {
        json!({ "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0, "k_t": 571.4, "gamma_t": 2.0, "mu": 0.5 })
    };
    let mut v = scene_value(law, json!([block]));
    v["domain"] = json!({ "x": [-30.0, 30.0], "z": [-2.0, 20.0] });
    v["dt"] = json!(0.002);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-30.0, 0.0], "to": [30.0, 0.0] }]);
    v
}

/// Corners given in world coordinates, relative to the centre c (the contact geometry
/// takes corners relative to their centre and the offset between centres).
pub fn relative(v: &[[f64; 2]], c: [f64; 2]) -> Vec<[f64; 2]> {
    v.iter().map(|x| [x[0] - c[0], x[1] - c[1]]).collect()
}

/// `polygon_polygon` of polygons given in world coordinates, with the force point back
/// in world coordinates.
pub fn polygon_polygon_world(
    p: &[[f64; 2]],
    ci: [f64; 2],
    q: &[[f64; 2]],
    cj: [f64; 2],
) -> Option<(talus::overlap::AreaContact, [f64; 2])> {
    let d = [ci[0] - cj[0], ci[1] - cj[1]];
    talus::overlap::polygon_polygon(&relative(p, ci), &relative(q, cj), d)
        .map(|g| (g, [ci[0] + g.arm[0], ci[1] + g.arm[1]]))
}

/// `polygon_disk` of a polygon (world corners, centre cp) and the disk (c, r), with the
/// force point back in world coordinates.
pub fn polygon_disk_world(
    p: &[[f64; 2]],
    cp: [f64; 2],
    c: [f64; 2],
    r: f64,
    polygon_is_i: bool,
) -> Option<(talus::overlap::AreaContact, [f64; 2])> {
    let ci = if polygon_is_i { cp } else { c };
    talus::overlap::polygon_disk(
        &relative(p, cp),
        [cp[0] - c[0], cp[1] - c[1]],
        r,
        polygon_is_i,
    )
    .map(|g| (g, [ci[0] + g.arm[0], ci[1] + g.arm[1]]))
}
