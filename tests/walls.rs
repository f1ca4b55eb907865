//! Walls whose surface moves along them (scene `walls[k].velocity`: a belt, a shearing
//! wall; issue 43 item 3): the surface's velocity enters the relative velocity of every
//! contact with the wall, on both paths and for every shape.

mod common;
use common::*;
use serde_json::json;

const MU: f64 = 0.4;
const BELT: f64 = 1.0;

/// A block that cannot turn resting on a floor whose surface moves at `BELT` along +x,
/// g = 1: a disk under the spring-dashpot law, a square under the overlap-area law, or a
/// rod under paper 004's law. Returns its velocity along x after `t1` and after `t2`
/// (from rest at t = 0), and the friction force on it at t1 in units of its weight; None
/// on the GPU path without an adapter.
fn block_on_a_belt(path: Path, shape: &str, t1: f64, t2: f64) -> Option<(f64, f64, f64)> {
    let mut block = json!({ "position": [0.0, 0.4999], "diameter": 1.0, "fixed_rotation": true });
    let (law, extra) = match shape {
        "disk" => (
            json!({ "law": "spring_dashpot", "k_n": 1.0e4, "gamma_n": 20.0, "k_t": 2.0e3,
                    "gamma_t": 10.0, "mu": MU }),
            json!({}),
        ),
        "square" => (
            json!({ "law": "overlap_area", "k_n": 1.0e4, "eta_n": 0.5, "eta_t": 1.0, "mu": MU }),
            json!({ "polygon": { "corners": 4 } }),
        ),
        _ => (
            json!({ "law": "hertz_cohesive", "k_n": 1.0e4, "k_t": 2.0e3, "gamma_n": 20.0,
                    "gamma_t": 10.0, "mu": MU, "bond": 0.0, "d_c": 1.0e-4 }),
            json!({ "rod": { "aspect": 3.0 } }),
        ),
    };
    let mut list = json!({ "kind": "list", "material": "m", "particles": [] });
    for (k, v) in extra.as_object().unwrap() {
        list[k] = v.clone();
    }
    if shape == "square" {
        // Regular polygons in a list are inscribed in the circle of `diameter`: a face
        // along the floor is √2/4 below the centre.
        block["position"] = json!([0.0, 0.25 * 2f64.sqrt() - 1e-4]);
        block["theta"] = json!(std::f64::consts::FRAC_PI_4);
    }
    list["particles"] = json!([block]);
    let mut v = scene_value(law, json!([list]));
    v["walls"] = json!([{ "from": [-100.0, 0.0], "to": [100.0, 0.0], "velocity": [BELT, 0.0] }]);
    v["gravity"] = json!({ "g": [0.0, -1.0] });
    v["dt"] = json!(2e-4);
    let mut e = engine(path, "block_on_a_belt", sim(&v))?;
    let dt = 2e-4;
    e.advance((t1 / dt).round() as u64).unwrap();
    let s = e.sim().unwrap();
    let v1 = s.particles.velocity(0, s.dt())[0];
    let weight = s.particles.mass[0];
    let f_t: f64 = (s.pairs.iter().zip(&s.contacts))
        .filter(|(p, _)| p.is_wall())
        .map(|(_, c)| c.force[0])
        .sum::<f64>()
        / weight;
    e.advance(((t2 - t1) / dt).round() as u64).unwrap();
    let s = e.sim().unwrap();
    Some((v1, f_t, s.particles.velocity(0, s.dt())[0]))
}

#[test]
fn a_block_on_a_belt_is_dragged_at_mu_m_g_until_it_moves_with_the_belt() {
    // Sliding, the belt pulls the block forward with μ m g, so it gains speed at μ g
    // (0.4 per unit time) until it moves with the belt, at t = 1/μ = 2.5; then it rides
    // the belt without slipping. Measured: within 2·10⁻¹³ of μ g t and μ m g on the CPU
    // path, 8·10⁻⁸ on the GPU path (lavapipe; its f32 spring and forces); at t = 5 within
    // 2.4·10⁻⁸ of the belt's speed on both.
    for shape in ["disk", "square", "rod"] {
        let mut cpu = None;
        for path in PATHS {
            let Some((v1, f_t, v2)) = block_on_a_belt(path, shape, 1.5, 5.0) else {
                continue;
            };
            eprintln!("{shape}, {path:?}: v(1.5) = {v1}, friction {f_t} m g, v(5) = {v2}");
            // The GPU path against the CPU path on the same scene.
            match cpu {
                None => cpu = Some((v1, f_t)),
                Some((c1, cf)) => assert!(
                    (v1 / c1 - 1.0).abs() < 1e-6 && (f_t / cf - 1.0).abs() < 1e-6,
                    "{shape}: GPU {v1}, {f_t} against CPU {c1}, {cf}"
                ),
            }
            assert!(
                (v1 / (MU * 1.5) - 1.0).abs() < 1e-6,
                "{shape}, {path:?}: speed {v1} at t = 1.5 against μ g t = {}",
                MU * 1.5
            );
            assert!(
                (v2 - BELT).abs() < 1e-6,
                "{shape}, {path:?}: speed {v2} at t = 5 against the belt's {BELT}"
            );
            // The friction at t = 1.5 is μ m g (m g: the block's weight `f_t` is
            // divided by).
            assert!(
                (f_t / MU - 1.0).abs() < 1e-6,
                "{shape}, {path:?}: friction {f_t} m g against μ m g"
            );
        }
    }
}

#[test]
fn a_wall_moving_across_its_line_is_refused_naming_the_key() {
    let mut v = scene_value(
        json!({ "law": "spring_dashpot", "k_n": 1.0e4, "gamma_n": 20.0, "k_t": 2.0e3,
                "gamma_t": 10.0, "mu": MU }),
        json!([{ "kind": "list", "material": "m",
                 "particles": [{ "position": [0.0, 0.5], "diameter": 1.0 }] }]),
    );
    v["walls"] = json!([{ "from": [-10.0, 0.0], "to": [10.0, 0.0], "velocity": [1.0, 0.1] }]);
    let err = talus::scene::parse(&v.to_string(), &[]).expect_err("refused");
    let text = err.to_string();
    assert!(
        text.contains("walls[0].velocity") && text.contains("not along the wall"),
        "{text}"
    );
    v["walls"][0]["velocity"] = json!([1.0, 0.0]);
    talus::scene::parse(&v.to_string(), &[]).expect("a belt along the wall");
}
