//! Helpers shared by the integration tests: small scenes built in code.
#![allow(dead_code)]

use serde_json::{Value, json};
use talus::scene::{self, Scene};
use talus::sim::Simulation;

pub mod cli;
pub mod mutate;
pub mod pairs;
pub mod resume;
pub mod vtp;
pub mod wgsl;

#[allow(unused_imports)] // each test binary uses some
pub use cli::{command, talus, talus_bin, talus_ok, tmp};
#[allow(unused_imports)]
pub use resume::{assert_resumes_bitwise, assert_same_state, carries_sub_springs};

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

/// The two paths a physics check runs on (issue 14 item 7: written once, run on both).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    Cpu,
    Gpu,
}

pub const PATHS: [Path; 2] = [Path::Cpu, Path::Gpu];

/// The engine of `path` for a simulation; None for the GPU path without an adapter
/// (skipped with a message, unless the GPU is required).
pub fn engine(path: Path, test: &str, sim: Simulation) -> Option<talus::run::Engine> {
    match path {
        Path::Cpu => Some(talus::run::Engine::cpu(sim)),
        Path::Gpu => {
            let gpu = self::gpu(test)?;
            let g = talus::gpu::GpuSimulation::with_gpu(sim, gpu).expect("uploads");
            Some(talus::run::Engine::Gpu(Box::new(g)))
        }
    }
}

/// Head-on collision of two equal unit disks (m = 1, radius 0.5) approaching at relative
/// speed `v0` from a gap of 0.002; returns (contact duration from the overlap δ > 0,
/// restitution).
pub fn head_on(contact: Value, v0: f64, dt: f64, integrator: &str) -> (f64, f64) {
    head_on_on(Path::Cpu, contact, v0, dt, integrator).expect("the CPU path runs")
}

/// `head_on` on either path (None: no GPU). Runs are deterministic, so the collision is
/// run twice: first in chunks of `CHUNK` steps to find the chunks where the overlap δ
/// turns positive and back, then again step by step through those two chunks only,
/// where δ's crossings of 0 are interpolated (a readback per step on the GPU path is
/// what costs).
pub fn head_on_on(
    path: Path,
    contact: Value,
    v0: f64,
    dt: f64,
    integrator: &str,
) -> Option<(f64, f64)> {
    let mut v = scene_value(
        contact,
        json!([{ "kind": "list", "material": "m", "particles": [
            { "position": [-0.501, 0.0], "diameter": 1.0, "velocity": [0.5 * v0, 0.0] },
            { "position": [0.501, 0.0], "diameter": 1.0, "velocity": [-0.5 * v0, 0.0] }
        ]}]),
    );
    v["dt"] = json!(dt);
    v["integrator"] = json!(integrator);
    head_on_scene(path, &v, v0, 1.0)
}

/// The head-on collision of any scene whose particles 0 and 1 lie on a horizontal line
/// 0.002 apart, closing at relative speed `v0`, with radii summing to `reach` (particle 1
/// may be fixed): (overlap time, restitution), as `head_on_on`.
pub fn head_on_scene(path: Path, v: &Value, v0: f64, reach: f64) -> Option<(f64, f64)> {
    const CHUNK: u64 = 16;
    let dt = v["dt"].as_f64().expect("dt");
    let overlap = |e: &mut talus::run::Engine| {
        let p = e.positions();
        let r = (p[0][0] - p[1][0]).hypot(p[0][1] - p[1][1]);
        (e.step() as f64 * dt, reach - r)
    };
    // The gap of 0.002 closes at v0: fly to just before it.
    let start = (0.95 * 0.002 / v0 / dt) as u64;
    let mut e = engine(path, "head_on", sim(v))?;
    e.advance(start).expect("no divergence");
    assert!(overlap(&mut e).1 < 0.0, "still apart");
    // Pass 1: the chunks in which δ turns positive and back to 0 or below.
    let (mut chunk_in, mut chunk_out) = (None, None);
    let mut prev = overlap(&mut e);
    for _ in 0..10_000_000 {
        let at = e.step();
        e.advance(CHUNK).expect("no divergence");
        let now = overlap(&mut e);
        if chunk_in.is_none() && now.1 > 0.0 {
            chunk_in = Some(at);
        } else if chunk_in.is_some() && prev.1 > 0.0 && now.1 <= 0.0 {
            chunk_out = Some(at);
            break;
        }
        prev = now;
    }
    let (chunk_in, chunk_out) = (chunk_in.expect("collided"), chunk_out.expect("separated"));
    // Pass 2: step by step through those chunks.
    let mut e = engine(path, "head_on", sim(v))?;
    let crossing_in = |e: &mut talus::run::Engine, from: u64, inwards: bool| {
        e.advance(from - e.step()).expect("no divergence");
        let mut prev = overlap(e);
        for _ in 0..=CHUNK {
            e.advance(1).expect("no divergence");
            let now = overlap(e);
            if (inwards && prev.1 <= 0.0 && now.1 > 0.0)
                || (!inwards && prev.1 > 0.0 && now.1 <= 0.0)
            {
                return crossing(prev.0, prev.1, now.0, now.1);
            }
            prev = now;
        }
        panic!("δ crosses 0 within the chunk from step {from}");
    };
    e.advance(start).expect("no divergence");
    let t_in = crossing_in(&mut e, chunk_in, true);
    let t_out = crossing_in(&mut e, chunk_out, false);
    // The outgoing speed in free flight, once Gear's higher derivatives have let go of
    // the contact (a few steps).
    e.advance(200).expect("no divergence");
    assert!(overlap(&mut e).1 < 0.0, "apart");
    let s = e.sim().unwrap();
    let vel = |i| s.particles.velocity(i, s.dt())[0];
    let v_out = vel(1) - vel(0);
    Some((t_out - t_in, v_out / v0))
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

/// A run's output file as two runs of the same physics must write it alike: the bytes,
/// less what says which command wrote them (issue 41's provenance): a log's `#` head,
/// and a snapshot's `provenance` with the checksum that covers it.
pub fn output_without_provenance(path: &std::path::Path) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let name = path.file_name().unwrap().to_string_lossy();
    if name.ends_with(".csv") {
        let text = String::from_utf8(bytes).unwrap();
        let body: String = (text.split_inclusive('\n'))
            .skip_while(|l| l.starts_with('#'))
            .collect();
        return body.into_bytes();
    }
    if name.ends_with(".json")
        && let Ok(mut v) = serde_json::from_slice::<Value>(&bytes)
        && v.get("format").and_then(Value::as_str) == Some("talus-snapshot")
    {
        let o = v.as_object_mut().unwrap();
        o.remove("provenance");
        o.remove("checksum");
        return serde_json::to_vec(&v).unwrap();
    }
    bytes
}

/// Eight disks of diameter 1 in a row on a floor wall (gravity 1) and a pentagon of
/// the same circle resting on them at (2, 1.45): disks among polygons in one scene.
pub fn disks_and_a_pentagon() -> Value {
    let row: Vec<_> = (0..8)
        .map(|k| json!({ "position": [k as f64 * 0.99, 0.499], "diameter": 1.0 }))
        .collect();
    let mut v = scene_value(
        json!({ "law": "overlap_area", "k_n": 1e4, "mu": 0.5 }),
        json!([{ "kind": "list", "material": "m", "particles": row },
               { "kind": "list", "material": "m", "polygon": { "corners": 5 },
                 "particles": [{ "position": [2.0, 1.45], "diameter": 1.0 }] }]),
    );
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["walls"] = json!([{ "from": [-5.0, 0.0], "to": [15.0, 0.0] }]);
    v
}
