//! Walls that move (issue 43 item 3): a surface moving along its wall (scene
//! `walls[k].velocity`: a belt, a shearing wall), whose velocity enters the relative
//! velocity of every contact with the wall, on both paths and for every shape; and a
//! segment that moves as a whole (`walls[k].motion`: a piston, an oscillating floor),
//! placed at the time of each step's contacts, the neighbour lists rebuilt as it goes.

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
        text.contains("walls[0].velocity")
            && text.contains("not along the wall")
            && text.contains("motion"),
        "{text}"
    );
    v["walls"][0]["velocity"] = json!([1.0, 0.0]);
    talus::scene::parse(&v.to_string(), &[]).expect("a belt along the wall");
}

// Walls that move as a whole (`walls[k].motion`).

fn disk_law() -> serde_json::Value {
    json!({ "law": "spring_dashpot", "k_n": 1.0e4, "gamma_n": 20.0, "k_t": 2.0e3,
            "gamma_t": 10.0, "mu": MU })
}

#[test]
fn a_piston_sends_a_free_disk_off_at_one_plus_e_times_its_speed() {
    // A wall moving at v = 0.5 along +x from 2.5 diameters away meets a free disk at rest
    // (g = 0), far beyond the neighbour lists' reach when they were built: only a
    // rebuild as the wall moves lists the pair. In the wall's frame the disk comes in
    // at v and leaves at e v (the material form's restitution, the wall infinitely
    // heavy), so it leaves at (1 + e) v; the wall's velocity enters the contact's
    // (with a still wall's velocity the dashpot would take another e). Measured: 4.2e-4
    // above (1 + e) v on the CPU (where the dashpot's jump at first touch falls between
    // two steps: 2.3e-3 at dt = 1e-3, as a disk thrown at a still wall rebounds 4e-3
    // short there), the GPU (lavapipe) within 1e-6 of the CPU.
    let (v, e) = (0.5, 0.8);
    for path in PATHS {
        let mut s = scene_value(
            json!({ "law": "spring_dashpot", "restitution": e, "contact_time": 0.05, "mu": MU }),
            json!([{ "kind": "list", "material": "m",
                     "particles": [{ "position": [0.0, 0.0], "diameter": 1.0 }] }]),
        );
        s["dt"] = json!(2e-4);
        s["walls"] = json!([{ "from": [-2.5, -5.0], "to": [-2.5, 5.0],
                              "motion": { "velocity": [v, 0.0] } }]);
        let Some(mut run) = engine(path, "piston", sim(&s)) else {
            continue;
        };
        run.advance(25_000).unwrap();
        let sim = run.sim().unwrap();
        let speed = sim.particles.velocity(0, sim.dt())[0];
        let x = sim.particles.position(0)[0];
        eprintln!(
            "{path:?}: the disk leaves at {speed} (x = {x}) against (1 + e) v = {}",
            (1.0 + e) * v
        );
        assert!(
            (speed / ((1.0 + e) * v) - 1.0).abs() < 2e-3,
            "{path:?}: the disk leaves at {speed} against (1 + e) v = {}",
            (1.0 + e) * v
        );
        // It is ahead of the wall (at −2.5 + v t = 0 at t = 5).
        assert!(x > 0.5, "{path:?}: the disk at {x} is behind the wall");
    }
}

/// A disk (unit mass and diameter, g = 1) resting on a floor that oscillates up and down
/// by A sin(ω t), A = 0.05, with A ω² = `lift` g; from t = 0 it moves with the floor.
/// Every 10 steps over two periods: the disk's height above the floor and its velocity
/// against the floor's; None on the GPU path without an adapter.
fn on_a_shaking_floor(path: Path, lift: f64) -> Option<Vec<(f64, f64)>> {
    let a = 0.05;
    let w = (lift / a).sqrt();
    let period = std::f64::consts::TAU / w;
    let mut s = scene_value(
        disk_law(),
        json!([{ "kind": "list", "material": "m",
                 "particles": [{ "position": [0.0, 0.5 - 1e-4], "diameter": 1.0,
                                 "velocity": [0.0, a * w] }] }]),
    );
    s["gravity"] = json!({ "g": [0.0, -1.0] });
    s["dt"] = json!(1e-3);
    s["walls"] = json!([{ "from": [-10.0, 0.0], "to": [10.0, 0.0],
                          "motion": { "amplitude": [0.0, a], "period": period } }]);
    let mut run = engine(path, "shaking_floor", sim(&s))?;
    let mut out = Vec::new();
    let steps = (2.0 * period / 1e-3) as u64;
    for _ in 0..steps / 10 {
        run.advance(10).unwrap();
        let sim = run.sim().unwrap();
        let t = sim.time();
        let floor = a * (w * t).sin();
        let floor_v = a * w * (w * t).cos();
        out.push((
            sim.particles.position(0)[1] - floor,
            sim.particles.velocity(0, sim.dt())[1] - floor_v,
        ));
    }
    Some(out)
}

#[test]
fn a_disk_rides_a_floor_shaken_below_g_and_leaves_it_above() {
    // Below A ω² = g the floor never pulls away from the disk: it rides it, its height
    // above the floor the radius less the overlap m (g + a)/k_n (a the floor's
    // acceleration, so within 1.5e-4 of 0.5 − 1e-4), its velocity the floor's. Above
    // (A ω² = 2 g) the floor falls away faster than g where its acceleration passes −g,
    // and the disk flies. Measured: below, the height within 5e-5 and the velocity
    // within 2.7e-4 of the floor's; above, gaps up to 0.2 (CPU and GPU, lavapipe, alike
    // to the digits printed).
    for path in PATHS {
        let Some(ride) = on_a_shaking_floor(path, 0.5) else {
            continue;
        };
        let (height, speed) = ride.iter().fold((0.0f64, 0.0f64), |(h, v), &(z, u)| {
            (h.max((z - (0.5 - 1e-4)).abs()), v.max(u.abs()))
        });
        eprintln!("{path:?}, A ω² = g/2: height off by {height:.2e}, velocity off by {speed:.2e}");
        assert!(
            height < 2e-4 && speed < 1e-2,
            "{path:?}: the disk left the floor: {height}, {speed}"
        );
        let fly = on_a_shaking_floor(path, 2.0).unwrap();
        let gap = fly.iter().map(|&(z, _)| z - 0.5).fold(f64::MIN, f64::max);
        eprintln!("{path:?}, A ω² = 2 g: the largest gap {gap:.3}");
        assert!(
            gap > 1e-2,
            "{path:?}: the disk never left the floor (gap {gap})"
        );
    }
}

/// Two rows of ten disks in a box whose lid comes down at 0.03 while it shakes
/// sideways by 0.05 sin(2π t), touching the top row from t ≈ 1.
fn pressed_rows() -> serde_json::Value {
    let mut list = Vec::new();
    for k in 0..20 {
        let (row, col) = (k / 10, k % 10);
        let x = 0.55 + col as f64 * 1.0 + 0.5 * row as f64;
        list.push(json!({ "position": [x, 0.5 + 0.87 * row as f64], "diameter": 1.0 }));
    }
    let mut s = scene_value(
        disk_law(),
        json!([{ "kind": "list", "material": "m", "particles": list }]),
    );
    s["gravity"] = json!({ "g": [0.0, -1.0] });
    s["dt"] = json!(1e-3);
    s["walls"] = json!([
        { "from": [0.0, 0.0], "to": [11.0, 0.0] },
        { "from": [0.0, 0.0], "to": [0.0, 5.0] },
        { "from": [11.0, 0.0], "to": [11.0, 5.0] },
        { "from": [-1.0, 1.9], "to": [12.0, 1.9],
          "motion": { "velocity": [0.0, -0.03], "amplitude": [0.05, 0.0], "period": 1.0 } }]);
    s
}

#[test]
fn gpu_moving_walls_agree_with_the_cpu_and_resume_bitwise() {
    // 2000 steps of the pressed rows: the GPU path within f32 reach of the CPU's (the
    // lid placed to f32's precision of its displacement); the lid presses the rows
    // (the floor carries more than their weight); both paths resume bitwise from a
    // checkpoint, the walls placed by the time alone. Measured (lavapipe): 1.7e-6 d;
    // the floor carries 910 against the rows' weight of 20.
    let v = pressed_rows();
    let run = |path: Path| {
        let mut e = engine(path, "pressed_rows", sim(&v))?;
        e.advance(2000).unwrap();
        Some(e.sim().unwrap().clone())
    };
    let cpu = run(Path::Cpu).unwrap();
    let floor: f64 = (cpu.pairs.iter().zip(&cpu.contacts))
        .filter(|(p, _)| p.j == talus::cpu::contacts::WALL_BASE)
        .map(|(_, c)| c.force[1])
        .sum();
    let weight: f64 = cpu.particles.mass.iter().sum();
    eprintln!("the floor carries {floor:.2} against the rows' weight {weight:.2}");
    assert!(
        floor > 1.5 * weight,
        "the lid does not press: {floor} against {weight}"
    );
    if let Some(gpu) = run(Path::Gpu) {
        let off = (0..cpu.particles.len())
            .map(|i| {
                let (p, q) = (cpu.particles.position(i), gpu.particles.position(i));
                (p[0] - q[0]).hypot(p[1] - q[1])
            })
            .fold(0.0, f64::max);
        eprintln!("GPU against CPU: {off:.2e} d");
        assert!(off < 1e-5, "GPU {off:e} d off the CPU");
    }
    let scene = parse(&v);
    for path in PATHS {
        assert_resumes_bitwise(path, "pressed_rows_resume", &scene, 2000, 900, |_| {});
    }
}

#[test]
fn wall_motions_are_refused_where_they_are_wrong_and_named_by_check() {
    let mut v = pressed_rows();
    for (motion, key, reason) in [
        (
            json!({ "amplitude": [0.1, 0.0] }),
            "walls[3].motion.period",
            "required",
        ),
        (
            json!({ "velocity": [0.1, 0.0], "period": 1.0 }),
            "walls[3].motion.period",
            "amplitude",
        ),
        (
            json!({ "amplitude": [0.1, 0.0], "period": -1.0 }),
            "walls[3].motion.period",
            "positive",
        ),
        (json!({ "speed": 1.0 }), "speed", ""),
        // 0.3 per step of 1e-3, beyond half the smallest radius (0.25).
        (
            json!({ "velocity": [0.0, -300.0] }),
            "walls[3].motion",
            "max_step_displacement",
        ),
    ] {
        v["walls"][3]["motion"] = motion.clone();
        let text = talus::scene::parse(&v.to_string(), &[])
            .err()
            .map(|e| e.to_string())
            .unwrap_or_else(|| panic!("{motion} accepted"));
        assert!(
            text.contains(key) && text.contains(reason),
            "{motion}: {text}"
        );
    }
    // Along x in a domain periodic in x: the segment would not wrap.
    let mut v = pressed_rows();
    v["domain"] = json!({ "x": [0.0, 11.0], "z": [-1.0, 20.0], "periodic_x": true });
    v["walls"] = json!([{ "from": [0.0, 0.0], "to": [11.0, 0.0],
                          "motion": { "amplitude": [0.1, 0.0], "period": 1.0 } }]);
    let text = talus::scene::parse(&v.to_string(), &[])
        .expect_err("refused")
        .to_string();
    assert!(
        text.contains("walls[0].motion") && text.contains("periodic"),
        "{text}"
    );
    v["walls"][0]["motion"] = json!({ "amplitude": [0.0, 0.1], "period": 1.0 });
    talus::scene::parse(&v.to_string(), &[]).expect("shaking along z is fine");
    let dir = tmp("walls", "motion_check");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rows.json");
    std::fs::write(&path, pressed_rows().to_string()).unwrap();
    let out = talus_ok(["check", path.to_str().unwrap()]);
    assert!(
        out.contains("walls[3].motion") && out.contains("v = (0, -0.03), A = (0.05, 0), T = 1"),
        "{out}"
    );
}

#[test]
fn pictures_draw_the_walls_where_they_were() {
    // The pressed rows run to t = 1.25 through `talus run`: the analysis of the final
    // snapshot places each wall as the run did (the lid 0.0375 lower, shifted sideways
    // by 0.05 sin(2π · 1.25) = 0.05), the grains picture draws those in its view, and
    // walls.vtp holds them.
    let dir = tmp("walls", "pictures");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("rows.json");
    let mut v = pressed_rows();
    v["stop"] = json!({ "time": 1.25 });
    std::fs::write(&scene, v.to_string()).unwrap();
    let out = dir.join("run");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    talus_ok([
        "run",
        "-q",
        "--backend",
        "cpu",
        &s(&scene),
        "--out",
        &s(&out),
    ]);
    let input = talus::analyze::input::load(&out, None).unwrap();
    let t = input.time;
    let lid = input.walls[3];
    let dx = 0.05 * (std::f64::consts::TAU * t).sin();
    let expected = [[-1.0 + dx, 1.9 - 0.03 * t], [12.0 + dx, 1.9 - 0.03 * t]];
    for k in 0..2 {
        for a in 0..2 {
            assert!(
                (lid[k][a] - expected[k][a]).abs() < 1e-12,
                "the lid at t = {t}: {lid:?} against {expected:?}"
            );
        }
    }
    assert_eq!(input.walls[0], [[0.0, 0.0], [11.0, 0.0]]);
    let svg = std::fs::read_to_string(out.join("pictures").join("grains.svg")).unwrap();
    let lines = svg.matches("stroke=\"rgb(90,70,50)\"").count();
    // The view is the heap's outline and a margin: the floor, the lid and the left
    // side lie in it, the right side (0.45 beyond the grains) at its edge.
    assert!(
        (3..=4).contains(&lines),
        "walls drawn in the grains picture: {lines}"
    );
    // walls.vtp for ParaView: the four lines, the lid where the analysis has it.
    let vtp = common::vtp::read(&out.join("pictures").join("walls.vtp"));
    let points = vtp.get("Points", "Points");
    assert_eq!(points.len(), 4 * 6, "{points:?}");
    let lid: Vec<f64> = points[18..24].to_vec();
    let want = [
        expected[0][0],
        expected[0][1],
        0.0,
        expected[1][0],
        expected[1][1],
        0.0,
    ];
    assert!(
        lid.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6),
        "walls.vtp's lid {lid:?} against {want:?}"
    );
    assert_eq!(vtp.get("CellData", "wall"), &[0.0, 1.0, 2.0, 3.0]);
}
