//! The `talus` binary: bad scenes give a clear error naming the key, exit code 2 and no
//! panic; a diverging run stops with the step, the particle ids and the checkpoint.

use serde_json::json;
use std::path::{Path, PathBuf};

mod common;

use common::{command, talus};

fn tmp(name: &str) -> PathBuf {
    common::tmp("cli", name)
}

/// The default scene with one edit applied to its JSON text.
fn scene_file(name: &str, edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    common::cli::default_scene_file(&tmp(name), edit)
}

fn assert_rejected(args: &[&str], must_mention: &[&str]) {
    let (code, _, err) = talus(args);
    assert_eq!(code, 2, "exit code for {args:?}; stderr: {err}");
    assert!(!err.contains("panicked"), "no panic: {err}");
    for m in must_mention {
        assert!(
            err.contains(m),
            "error for {args:?} should mention `{m}`: {err}"
        );
    }
}

#[test]
fn unknown_key_is_named() {
    let p = scene_file("unknown", |v| v["contact"]["k_nn"] = 1.0.into());
    assert_rejected(&["check", p.to_str().unwrap()], &["contact", "k_nn"]);
    let p = scene_file("unknown-top", |v| v["gravty"] = 1.0.into());
    assert_rejected(&["run", p.to_str().unwrap()], &["gravty"]);
}

#[test]
fn duplicate_keys_and_arrays_for_objects_are_named() {
    // serde_json keeps the last of two equal keys; a scene must not (issue 16).
    let text = talus::scene::DEFAULT_SCENE.replacen('{', r#"{"dt": 5.0,"#, 1);
    let p = tmp("dup").join("scene.json");
    std::fs::write(&p, text).unwrap();
    assert_rejected(&["check", p.to_str().unwrap()], &["dt", "twice"]);
    // An array where an object belongs would be read as its fields in order.
    let p = scene_file("array", |v| v["stop"] = serde_json::json!([4.0, 0.5]));
    assert_rejected(
        &["check", p.to_str().unwrap()],
        &["stop", "expected an object"],
    );
    let p = scene_file("array2", |v| {
        v["particles"][1]["velocity_spread"] = serde_json::json!(null);
        v["materials"] = serde_json::json!([[1.0]]);
    });
    let (code, _, err) = talus(["check", p.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn absurd_counts_are_refused_before_anything_is_allocated() {
    // Issue 16: a count of 4·10⁹ aborted on allocation, a lattice of 200 000 hung.
    assert_rejected(
        &["check", "--set", "particles[1].count=4294967295"],
        &["particles[1].count", "limits.max_particles"],
    );
    let r1 = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/r1_pile.json");
    assert_rejected(
        &["run", r1, "--set", "particles[0].bottom_row=200000"],
        &["particles[0].bottom_row", "limits.max_particles"],
    );
    assert_rejected(&["bench", "--sizes", "0"], &["--sizes"]);
    assert_rejected(&["bench", "--rod-sizes", "30000000"], &["--rod-sizes"]);
    // Meant: the limit raised, the same count is taken (a source streams its particles).
    let (code, _, err) = talus([
        "check",
        "--set",
        "particles[1].count=40000000",
        "--set",
        "limits.max_particles=1e8",
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn what_a_scene_creates_where_it_cannot_work_is_refused() {
    // Issue 16: a wall beyond the domain was inert, particles created outside it were
    // lost at once, a source blocked by its own row poured nothing; all exited 0.
    assert_rejected(
        &[
            "check",
            "--set",
            r#"walls=[{"from": [0, 0], "to": [1e308, 0]}]"#,
        ],
        &["walls[0].to", "1e308", "outside the domain"],
    );
    let r1 = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/r1_pile_reduced.json");
    assert_rejected(
        &["check", r1, "--set", "domain.z=[-0.01,0.01]"],
        &["particles[0]", "outside the domain"],
    );
    // The default scene's base row is fixed at z = 0: an outlet on it is blocked
    // everywhere, one above it is not.
    assert_rejected(
        &["check", "--set", "particles[1].position=[0,0.5]"],
        &["particles[1].position", "blocked everywhere"],
    );
    let (code, _, err) = talus(["check", "--set", "particles[1].position=[0,1.6]"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_name_that_is_a_path_is_refused() {
    // Without --out the name is the output folder: `..` or `/` would write anywhere.
    for name in ["../../escape", "/tmp/escape", ".hidden", "a/b", ""] {
        let set = format!("name={name}");
        assert_rejected(&["check", "--set", &set], &["name", "plain name"]);
    }
    let (code, out, err) = talus(["check", "--set", "name=heap-2.v1_x+y"]);
    assert_eq!(code, 0, "{out}{err}");
}

#[test]
fn wrong_type_is_named() {
    let p = scene_file("type", |v| v["dt"] = "small".into());
    assert_rejected(&["check", p.to_str().unwrap()], &["dt"]);
    let p = scene_file("type2", |v| v["particles"][1]["count"] = (-3).into());
    assert_rejected(&["check", p.to_str().unwrap()], &["particles[1].count"]);
}

#[test]
fn negative_radius_is_rejected() {
    let p = scene_file("radius", |v| v["particles"][0]["diameter"] = (-1.0).into());
    assert_rejected(
        &["check", p.to_str().unwrap()],
        &["particles[0].diameter", "positive"],
    );
    assert_rejected(
        &[
            "check",
            "--set",
            "particles[1].diameter={\"uniform\": [-1, 1]}",
        ],
        &["particles[1].diameter"],
    );
}

#[test]
fn missing_material_is_named() {
    let p = scene_file("material", |v| {
        v["particles"][1]["material"] = "sand".into()
    });
    assert_rejected(
        &["check", p.to_str().unwrap()],
        &["particles[1].material", "sand", "grain"],
    );
}

#[test]
fn time_step_too_large_for_the_stiffness() {
    assert_rejected(&["check", "--set", "dt=0.05"], &["dt", "t_c"]);
    // a shorter contact (a stiffer spring) makes the default dt too large as well
    assert_rejected(
        &["check", "--set", "contact.contact_time=0.005"],
        &["dt", "too large"],
    );
    assert_rejected(
        &[
            "check",
            "--set",
            r#"contact={"law": "spring_dashpot", "k_n": 1e7}"#,
        ],
        &["dt", "too large"],
    );
    // a mildly large dt only warns
    let (code, _, err) = talus(["check", "--set", "dt=0.006"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning") && err.contains("t_c/10"), "{err}");
}

/// Issue 20: the material form (restitution and contact time) is checked like any input:
/// each mistake names its key.
#[test]
fn the_material_form_refuses_what_does_not_belong() {
    let set = |contact: &str| {
        vec![
            "check".to_string(),
            "--set".into(),
            format!("contact={contact}"),
        ]
    };
    let cases: [(&str, &[&str]); 13] = [
        (
            r#"{"law": "spring_dashpot", "restitution": 0.75}"#,
            &["contact.contact_time", "required"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "k_n": 100}"#,
            &["contact.k_n", "stiffness form"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.1, "contact_time": 0.08}"#,
            &["contact.restitution", "0.1353", "clamp"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 1.2, "contact_time": 0.08, "clamp": false}"#,
            &["contact.restitution", "(0, 1]"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": -1}"#,
            &["contact.contact_time", "positive"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "nu": 1.5}"#,
            &["contact.delta0", "required"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "nu": 1.5, "delta0": 0.01}"#,
            &["contact.impact_speed", "required", "that relative speed"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "impact_speed": 1}"#,
            &["contact.impact_speed", "every speed"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "pairs": [{"materials": ["grain", "sand"]}]}"#,
            &["contact.pairs[0].materials", "sand", "walls"],
        ),
        (
            r#"{"law": "spring_dashpot", "restitution": 0.7, "contact_time": 0.08, "pairs": [{"materials": ["grain", "walls"]}, {"materials": ["walls", "grain"]}]}"#,
            &["contact.pairs[1].materials", "twice"],
        ),
        (
            r#"{"law": "spring_dashpot", "k_n": 2000, "pairs": [{"materials": ["grain", "walls"]}]}"#,
            &["contact.pairs", "material form"],
        ),
        (
            r#"{"law": "overlap_area", "restitution": 0.5, "contact_time": 0.05, "eta_n": 0.3}"#,
            &["contact.eta_n", "stiffness form"],
        ),
        (
            r#"{"law": "overlap_area", "restitution": 0.1, "contact_time": 0.05}"#,
            &["contact.restitution", "0.1353"],
        ),
    ];
    for (contact, mention) in cases {
        let args = set(contact);
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        assert_rejected(&args, mention);
    }
}

/// Issue 20: `talus check` prints what the contact law gives per pair of materials, and
/// the run's scene.json records the resolved coefficients.
#[test]
fn check_prints_the_resolved_pairs_and_the_run_records_them() {
    let (code, out, err) = talus(["check"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("material form"), "{out}");
    assert!(out.contains("grain–grain: e 0.750, t_c 5.000e-2"), "{out}");
    assert!(out.contains("grain–walls"), "{out}");
    // The stiffness form says what restitution its absolute damping gives each kind of
    // partner (not the same on a fixed one: the reason for the material form).
    let (_, out, _) = talus([
        "check",
        "--set",
        r#"contact={"law": "spring_dashpot", "k_n": 2000, "gamma_n": 10}"#,
    ]);
    assert!(out.contains("two moving (m_eff 0.5000): e 0.636"), "{out}");
    assert!(
        out.contains("on a fixed grain (m_eff 1.0000): e 0.720"),
        "{out}"
    );
    let dir = tmp("resolved");
    let (code, _, err) = talus([
        "run",
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "stop.time=0.1",
        "--set",
        "stop.kinetic_fraction=null",
        "--set",
        r#"contact.pairs=[{"materials": ["grain", "walls"], "restitution": 0.5}]"#,
    ]);
    assert_eq!(code, 0, "{err}");
    let scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("scene.json")).unwrap()).unwrap();
    let resolved = scene["contact"]["resolved"]
        .as_array()
        .expect("contact.resolved");
    assert_eq!(
        resolved.len(),
        2,
        "grain–grain and grain–walls: {resolved:?}"
    );
    let walls = &resolved[1];
    assert_eq!(walls["materials"], serde_json::json!(["grain", "walls"]));
    assert!((walls["restitution"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    assert!((walls["contact_time"].as_f64().unwrap() - 0.05).abs() < 1e-12);
    let (kappa, c) = talus::law::restitution::per_mass(0.5, 0.05, true).unwrap();
    assert_eq!(walls["k_n_per_mass"].as_f64().unwrap(), kappa);
    assert_eq!(walls["gamma_n_per_mass"].as_f64().unwrap(), c);
    // Read back (resume, sweeps), the record is recomputed, never an input.
    let text = std::fs::read_to_string(dir.join("scene.json")).unwrap();
    let again = talus::scene::parse(&text, &[]).expect("scene.json reads back");
    assert_eq!(serde_json::to_value(&again).unwrap(), scene);
}

#[test]
fn check_warns_when_resting_overlaps_are_below_the_gpu_resolution() {
    // Issue 19: the GPU path resolves overlaps to about a position unit (cell/2³⁰ ≈ 1e-9
    // d), so resting overlaps below ~1e-6 d get forces off by more than 1e-3 there. The
    // default heap with contacts of 7e-5 (k_n/m ≈ 2e9) rests at ~5e-10 d: a warning, not
    // an error.
    let (code, _, err) = talus([
        "check",
        "--set",
        "contact.contact_time=7e-5",
        "--set",
        "dt=5e-6",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning") && err.contains("GPU path resolves overlaps"),
        "{err}"
    );
    // At its own contact time (k_n/m ≈ 4e3) it rests at ~2.5e-4 d: no such warning.
    let (_, _, err) = talus(["check"]);
    assert!(!err.contains("GPU path resolves"), "{err}");
}

#[test]
fn unreadable_or_malformed_files() {
    assert_rejected(&["check", "/nonexistent/scene.json"], &["cannot read"]);
    let p = tmp("syntax").join("s.json");
    std::fs::write(&p, "{ \"dt\": 0.1, ").unwrap();
    assert_rejected(&["check", p.to_str().unwrap()], &["not valid JSON"]);
    assert_rejected(
        &["check", "--set", "particles[9].rate=1"],
        &["out of range"],
    );
}

#[test]
fn check_accepts_the_default_scene() {
    let (code, out, err) = talus(["check"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("81 particles at start (81 fixed)"), "{out}");
    // And what its pour will add, and when (issue 41 item 7): 800 disks at 5 per time
    // unit; with three copies, three times as many.
    assert!(
        out.contains("point source 0: 800 disks, 5 per time unit from t = 0 to t = 160")
            && out.contains("created during the run: up to 800 particles, 881 in all"),
        "{out}"
    );
    let (code, out, err) = talus(["check", "--set", "replicas=3"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("800 disks in each of the 3 copies")
            && out.contains("up to 2400 particles, 2643 in all"),
        "{out}"
    );
    // A layered pile: its rows, at most.
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/r7_layered_medium.json");
    let (code, out, err) = talus(["check", scene]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("layered pile 0: at most ") && out.contains("a row every 1 s"),
        "{out}"
    );
}

#[test]
fn diverging_run_stops_with_step_ids_and_checkpoint() {
    // Two disks thrown at each other far too fast for the spring: the overlap exceeds the
    // bound on the first contact.
    let p = tmp("diverge").join("s.json");
    let scene = serde_json::json!({
        "name": "diverge", "dt": 1e-3, "stop": { "time": 2.0 },
        "gravity": { "g": [0.0, 0.0] },
        "domain": { "x": [-10.0, 10.0], "z": [-10.0, 10.0] },
        "materials": { "m": { "density": 1.0 } },
        "contact": { "law": "spring_dashpot", "k_n": 100.0 },
        "particles": [{ "kind": "list", "material": "m", "particles": [
            { "position": [-3.0, 0.0], "diameter": 1.0, "velocity": [4.0, 0.0] },
            { "position": [3.0, 0.0], "diameter": 1.0, "velocity": [-4.0, 0.0] }
        ]}],
        "output": { "checkpoint_every": 0.25 }
    });
    std::fs::write(&p, scene.to_string()).unwrap();
    let out = tmp("diverge").join("out");
    let (code, _, err) = talus([
        "run",
        "-q",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("diverged at step") && err.contains("particles 0 and 1"),
        "{err}"
    );
    assert!(
        err.contains("last good checkpoint") && err.contains("ckpt_"),
        "{err}"
    );
    assert!(
        !out.join("summary.json").exists(),
        "no summary for a failed run"
    );
}

#[test]
fn gpu_backend_runs_the_default_scene_and_info_lists_adapters() {
    let (code, out, err) = talus(["info"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("GPU adapters (Vulkan, Metal, DX12)") && out.contains("--backend auto"),
        "{out}"
    );
    let has_gpu = !out.contains("none found");
    let dir = tmp("gpu");
    let (code, _, err) = talus([
        "run",
        "--backend",
        "gpu",
        "-q",
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "stop.time=2",
        "--set",
        "output.snapshot_every=1",
    ]);
    if !has_gpu {
        assert!(
            !talus::gpu::device::gpu_required(),
            "TALUS_REQUIRE_GPU=1 but no adapter"
        );
        eprintln!("SKIPPED gpu run: no adapter");
        assert_eq!(code, 1);
        assert!(err.contains("no GPU adapter found"), "{err}");
        return;
    }
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(
        summary["backend"].as_str().unwrap().starts_with("gpu"),
        "{summary}"
    );
    assert_eq!(summary["steps"], 1000);
    assert!(dir.join("snapshots/snap_0000000500.json").exists());
}

#[test]
fn resume_extends_a_run_and_refuses_physics_changes() {
    let dir = tmp("resume");
    let first = dir.join("first");
    let common = [
        "--set",
        "particles[1].count=30",
        "--set",
        "stop.kinetic_fraction=null",
    ];
    let mut args = vec![
        "run",
        "-q",
        "--out",
        first.to_str().unwrap(),
        "--set",
        "stop.time=4",
        "--set",
        "output.checkpoint_every=2",
    ];
    args.extend(common);
    let (code, _, err) = talus(&args);
    assert_eq!(code, 0, "{err}");
    // A finished run measures and draws its final state.
    for f in [
        "analysis/summary.json",
        "analysis/stress.csv",
        "pictures/forces.png",
        "pictures/grains.svg",
        "pictures/grains.vtp",
    ] {
        assert!(first.join(f).is_file(), "{f} written at the end of the run");
    }
    let ckpt = first.join("checkpoints/ckpt_0000002000.bin");
    let second = dir.join("second");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--resume",
        ckpt.to_str().unwrap(),
        "--out",
        second.to_str().unwrap(),
        "--set",
        "stop.time=6",
    ]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(second.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["time"], 6.0);
    assert_eq!(summary["steps"], 1000);
    let (code, _, err) = talus([
        "run",
        "-q",
        "--resume",
        ckpt.to_str().unwrap(),
        "--set",
        "contact.mu=1",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("contact.mu") && err.contains("only stop.*, output.* and skin"),
        "{err}"
    );
    // Resumed into its own folder (after a crash, say), the run keeps its log up to the
    // checkpoint and goes on from there; its later snapshots and checkpoints are written
    // again.
    let log_before = std::fs::read_to_string(first.join("log.csv")).unwrap();
    let midway = first.join("checkpoints/ckpt_0000001000.bin");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--resume",
        midway.to_str().unwrap(),
        "--out",
        first.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let log_after = std::fs::read_to_string(first.join("log.csv")).unwrap();
    let rows = |log: &str| -> Vec<String> {
        (log.lines())
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect()
    };
    assert_eq!(
        rows(&log_after),
        rows(&log_before),
        "a bitwise resume logs the same rows"
    );
    // Its head names both runs that wrote it, the first and the resumed one.
    let head: Vec<&str> = log_after
        .lines()
        .take_while(|l| l.starts_with('#'))
        .collect();
    assert_eq!(head.len(), 2, "{head:?}");
    assert!(
        head[0].contains("stop.time=4") && head[1].contains("--resume"),
        "{head:?}"
    );
}

#[test]
fn every_output_says_what_wrote_it() {
    // Issue 41 item 3: talus --version names the commit; a run's summary.json, its
    // snapshots and its log carry the version, the commit, the command line, the
    // threads and the backend.
    let (code, version, err) = talus(["--version"]);
    assert_eq!(code, 0, "{err}");
    let commit = talus::base::provenance::COMMIT;
    assert_eq!(
        version.trim(),
        format!("talus {} (commit {commit})", env!("CARGO_PKG_VERSION"))
    );
    let git = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output();
    if let Ok(o) = git
        && o.status.success()
    {
        // Built from this checkout (a commit made since needs a rebuild, which cargo
        // test does: build.rs watches HEAD).
        assert_eq!(commit, String::from_utf8_lossy(&o.stdout).trim());
    }
    let out = tmp("provenance");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--threads",
        "1",
        "--backend",
        "cpu",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "stop.time=0.2",
        "--set",
        "output.snapshot_every=0.1",
    ]);
    assert_eq!(code, 0, "{err}");
    let read = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(p)).unwrap()).unwrap()
    };
    let snapshot = std::fs::read_dir(out.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .unwrap();
    let snap: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(snapshot).unwrap()).unwrap();
    for (what, p) in [
        ("summary.json", read("summary.json")["provenance"].clone()),
        ("final.json", read("final.json")["provenance"].clone()),
        ("a snapshot", snap["provenance"].clone()),
    ] {
        assert_eq!(p["version"], env!("CARGO_PKG_VERSION"), "{what}: {p}");
        assert_eq!(p["commit"], commit, "{what}: {p}");
        assert_eq!(p["threads"], 1, "{what}: {p}");
        assert_eq!(p["backend"], "cpu", "{what}: {p}");
        let line: Vec<&str> = (p["command_line"].as_array().unwrap().iter())
            .map(|a| a.as_str().unwrap())
            .collect();
        assert_eq!(&line[1..3], ["run", "-q"], "{what}: {p}");
        assert!(line.contains(&"stop.time=0.2"), "{what}: {p}");
    }
    // The snapshots still read (the checksum covers the provenance too).
    talus::io::snapshot::read(&out.join("final.json")).unwrap();
    let log = std::fs::read_to_string(out.join("log.csv")).unwrap();
    let first = log.lines().next().unwrap();
    assert!(
        first.starts_with(&format!(
            "# talus {} (commit {commit}), backend cpu, 1 thread: ",
            env!("CARGO_PKG_VERSION")
        )) && first.contains("stop.time=0.2"),
        "{first}"
    );
    assert!(log.lines().nth(1).unwrap().starts_with("step,time,"));
}

#[test]
fn a_folder_holding_another_run_is_refused_unless_forced() {
    // Issue 16: a run into a folder an earlier run wrote mixed the two runs' snapshots and
    // checkpoints; then it silently removed the earlier run's. Now it is refused (exit 2,
    // nothing touched) unless --force clears them, so "the newest checkpoint" is this
    // run's.
    let dir = tmp("reused").join("run");
    let run = |time: &str, every: &str, extra: &[&str]| {
        let mut args = vec![
            "run".to_string(),
            "-q".into(),
            "--out".into(),
            dir.to_str().unwrap().into(),
        ];
        for set in [
            "particles[1].count=10".to_string(),
            format!("stop.time={time}"),
            format!("output.checkpoint_every={every}"),
            format!("output.snapshot_every={every}"),
        ] {
            args.extend(["--set".into(), set]);
        }
        args.extend(extra.iter().map(|s| s.to_string()));
        talus(args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let (code, _, err) = run("4", "1", &[]);
    assert_eq!(code, 0, "{err}");
    let count = |sub: &str| std::fs::read_dir(dir.join(sub)).unwrap().count();
    assert!(count("checkpoints") >= 3 && count("snapshots") >= 10);
    let summary = std::fs::read(dir.join("summary.json")).unwrap();
    let (code, _, err) = run("2", "2", &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(dir.to_str().unwrap()) && err.contains("--force") && err.contains("--resume"),
        "names the folder and the ways on: {err}"
    );
    assert_eq!(std::fs::read(dir.join("summary.json")).unwrap(), summary);
    assert!(
        count("checkpoints") >= 3 && count("snapshots") >= 10,
        "untouched"
    );
    // Resuming another folder's run into it is refused too.
    let other = tmp("reused").join("other");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--out",
        other.to_str().unwrap(),
        "--set",
        "particles[1].count=10",
        "--set",
        "stop.time=1",
    ]);
    assert_eq!(code, 0, "{err}");
    let ckpt = other.join("checkpoints/ckpt_0000000500.bin");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--resume",
        ckpt.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "stop.time=2",
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run("2", "2", &["--force"]);
    assert_eq!(code, 0, "{err}");
    let names = |sub: &str| -> Vec<String> {
        let mut v: Vec<String> = (std::fs::read_dir(dir.join(sub)).unwrap())
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(names("checkpoints"), ["ckpt_0000001000.bin"]);
    assert_eq!(
        names("snapshots"),
        [
            "snap_0000000000.bin",
            "snap_0000000000.json",
            "snap_0000001000.bin",
            "snap_0000001000.json"
        ]
    );
    // An empty folder, or one holding other files only, is no other run's.
    let fresh = tmp("reused").join("fresh");
    std::fs::create_dir_all(&fresh).unwrap();
    std::fs::write(fresh.join("notes.txt"), "mine").unwrap();
    let (code, _, err) = talus([
        "run",
        "-q",
        "--out",
        fresh.to_str().unwrap(),
        "--set",
        "particles[1].count=10",
        "--set",
        "stop.time=1",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(fresh.join("notes.txt").is_file());
}

#[cfg(unix)]
#[test]
fn an_interrupted_run_stops_cleanly_and_names_its_checkpoint() {
    // Issue 16: SIGINT (or SIGTERM) stops a run between two advances with exit code 130,
    // no summary.json (it marks a finished run) and no temporaries, and says where the
    // last checkpoint is; the run continues from there in its own folder.
    let dir = tmp("interrupt").join("run");
    let child = command(["run", "-q", "--backend", "cpu", "--out"])
        .arg(&dir)
        .args([
            "--set",
            "stop.time=1000",
            "--set",
            "stop.kinetic_fraction=null",
            "--set",
            "output.checkpoint_every=0.5",
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("binary runs");
    // Interrupt it once it has written a checkpoint.
    let started = std::time::Instant::now();
    let has_checkpoint = || {
        std::fs::read_dir(dir.join("checkpoints")).is_ok_and(|mut d| {
            d.any(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with("ckpt_")))
        })
    };
    while !has_checkpoint() {
        assert!(
            started.elapsed().as_secs() < 120,
            "no checkpoint within 2 minutes"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // SAFETY: kill(2) on the child's own process id.
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) },
        0
    );
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted at step"), "{err}");
    assert!(!dir.join("summary.json").exists(), "no summary: unfinished");
    for sub in ["", "snapshots", "checkpoints"] {
        for e in std::fs::read_dir(dir.join(sub)).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.ends_with(".tmp"), "temporary {name} left");
        }
    }
    // The checkpoint it names is the newest one, and the run continues from it.
    let named = err
        .split("last good checkpoint: ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .unwrap_or_else(|| panic!("names its checkpoint: {err}"));
    let newest = (std::fs::read_dir(dir.join("checkpoints")).unwrap())
        .map(|e| e.unwrap().path())
        .max()
        .unwrap();
    assert_eq!(std::path::Path::new(named), newest);
    let step: u64 = named[named.len() - 14..named.len() - 4].parse().unwrap();
    let until = format!("stop.time={}", step as f64 * 2e-3 + 0.2);
    let (code, _, err) = talus([
        "run",
        "-q",
        "--backend",
        "cpu",
        "--resume",
        named,
        "--out",
        dir.to_str().unwrap(),
        "--set",
        &until,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("summary.json").is_file());
}

#[test]
fn reproduce_only_names_the_variants_when_none_matches() {
    assert_rejected(
        &["reproduce", "R2", "--only", "c=2"],
        &["--only c=2", "c=1_15", "c=-1_150"],
    );
}

#[test]
fn reproduce_rods_is_for_r9_alone() {
    assert_rejected(
        &["reproduce", "R4", "--rods", "1000"],
        &["--rods", "R4", "only R9"],
    );
    assert_rejected(
        &["reproduce", "R9", "--rods", "3"],
        &["--rods 3", "at least 10"],
    );
    assert_rejected(
        &["reproduce", "R9", "--rods", "1000", "--full"],
        &["--rods", "--full"],
    );
}

#[test]
fn analyze_rejects_a_reversed_fit_range() {
    assert_rejected(
        &["analyze", "scenes/r1_pile.json", "--fit", "0.9", "0.2"],
        &["--fit 0.9 0.2", "FROM < TO"],
    );
}

#[test]
fn bench_with_a_time_budget_reports_steps_and_microseconds() {
    // --budget times as many steps as fit (at most --steps), and the JSON carries the
    // per-step figures scripts/gpu-check collects.
    let out = tmp("bench").join("bench.json");
    let (code, stdout, err) = talus([
        "bench",
        "--backend",
        "cpu",
        "--sizes",
        "200",
        "--polygon-sizes",
        "30",
        "--rod-sizes",
        "40",
        "--pour",
        "false",
        "--budget",
        "0.2",
        "--steps",
        "100000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "bench runs: {err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("JSON on stdout");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v, file, "the same report in --out");
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 3, "disks, polygons, rods");
    for r in results {
        let steps = r["steps"].as_u64().unwrap();
        let seconds = r["seconds"].as_f64().unwrap();
        assert!((8..100000).contains(&steps), "budgeted steps: {steps}");
        assert!(
            (0.2..5.0).contains(&seconds),
            "within the budget's batch: {seconds}"
        );
        let us = r["microseconds_per_step"].as_f64().unwrap();
        assert!((us * steps as f64 / 1e6 - seconds).abs() < 1e-6 * seconds.max(1.0));
    }
    assert_rejected(&["bench", "--budget", "0"], &["--budget"]);
}

#[test]
fn a_source_whose_outlet_stays_taken_is_reported() {
    // A grain resting on the floor right at a source's outlet: the source's first
    // particle can never be placed. The run ends at stop.time; it must not pass the
    // empty deposit off as what the scene asked for (stop 32: an R9 pour stalled at 223
    // of 300 rods without a word).
    let dir = tmp("stalled-source");
    let scene = dir.join("scene.json");
    let text = json!({
        "name": "stalled",
        "dt": 0.002,
        "stop": { "time": 20.0 },
        "gravity": { "g": [0.0, -1.0] },
        "domain": { "x": [-5.0, 5.0], "z": [-1.0, 10.0] },
        "materials": { "m": { "density": 1.0 } },
        "contact": { "law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0, "mu": 0.5 },
        "walls": [{ "from": [-5.0, 0.0], "to": [5.0, 0.0] }],
        "particles": [
            { "kind": "list", "material": "m", "particles": [{ "position": [0.0, 0.5], "diameter": 1.0 }] },
            { "kind": "point_source", "material": "m", "position": [0.0, 0.5], "spread": 0.0,
              "rate": 1.0, "count": 5, "diameter": 1.0, "velocity": [0.0, 0.0] }
        ],
        "output": { "snapshot_every": 0, "checkpoint_every": 0 }
    });
    std::fs::write(&scene, text.to_string()).unwrap();
    // Both paths: the GPU path's sources advance on the device.
    for backend in ["cpu", "gpu"] {
        let out = dir.join(backend);
        let (code, _, err) = talus([
            "run",
            scene.to_str().unwrap(),
            "-q",
            "--backend",
            backend,
            "--out",
            out.to_str().unwrap(),
        ]);
        if backend == "gpu" && err.contains("no GPU adapter") {
            assert!(
                !talus::gpu::device::gpu_required(),
                "TALUS_REQUIRE_GPU=1: {err}"
            );
            eprintln!("SKIPPED the GPU path: no adapter");
            continue;
        }
        assert_eq!(code, 0, "{backend}: {err}");
        assert!(
            err.contains("point source 0 placed 0 of its 5 particles")
                && err.contains("fell behind its rate at t = 0.0000"),
            "{backend}: warned even with -q: {err}"
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let s = &summary["sources"][0];
        assert_eq!(
            (s["count"].as_u64(), s["inserted"].as_u64()),
            (Some(5), Some(0)),
            "{summary}"
        );
        assert_eq!(s["waiting_since"].as_f64(), Some(0.0));
        assert_eq!(s["next_at"], json!([0.0, 0.5]));
    }
}

#[test]
fn a_headless_machine_gets_no_wayland_noise() {
    // Without a display session Mesa's device-select layer made libwayland print
    // "XDG_RUNTIME_DIR is invalid or not set" several times per process (into every
    // log and Slurm output); talus switches that layer off there.
    let out = command(["info"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .output()
        .expect("binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
}

#[test]
fn bench_kernels_times_each_kernel_of_the_gpu_path() {
    // --kernels: each GPU workload also gets its device time per kernel (the table
    // scripts/gpu-check collects on a real GPU); the CPU path has no kernels.
    let (code, stdout, err) = talus([
        "bench",
        "--backend",
        "cpu",
        "--backend",
        "gpu",
        "--sizes",
        "200",
        "--polygon-sizes",
        "30",
        "--rod-sizes",
        "20",
        "--pour",
        "false",
        "--steps",
        "20",
        "--kernels",
    ]);
    if err.contains("no GPU adapter") {
        assert!(
            !talus::gpu::device::gpu_required(),
            "TALUS_REQUIRE_GPU=1 but no adapter"
        );
        eprintln!("SKIPPED bench --kernels: no adapter");
        return;
    }
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 6, "three workloads on two paths");
    for r in results {
        let gpu = r["backend"].as_str().unwrap().starts_with("gpu");
        if !gpu {
            assert!(r.get("kernels").is_none(), "{r}");
            continue;
        }
        let t = &r["kernels"];
        assert_eq!(t["steps"], 128, "{t}");
        let kernels = t["kernels"].as_array().unwrap();
        let name = |k: &serde_json::Value| k["kernel"].as_str().unwrap().to_string();
        assert!(
            kernels.iter().any(|k| name(k) == "ContactForcesOnly"),
            "{t}"
        );
        let sum: f64 = kernels
            .iter()
            .map(|k| k["microseconds_per_step"].as_f64().unwrap())
            .sum();
        let total = t["microseconds_per_step"].as_f64().unwrap();
        assert!(total > 0.0 && (sum - total).abs() < 1e-6 * total, "{t}");
    }
    assert_eq!(
        err.matches("device time per step by kernel").count(),
        3,
        "{err}"
    );
}

#[test]
fn bench_measures_a_software_adapter_only_when_asked() {
    // `auto` (the default with cpu) measures the GPU path on a hardware adapter only;
    // lavapipe would take minutes and measure the CPU again.
    let args = |backend: &str| {
        vec![
            "bench",
            "--backend",
            backend,
            "--sizes",
            "100",
            "--polygon-sizes",
            "10",
            "--pour",
            "false",
            "--budget",
            "0.1",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>()
    };
    let a = args("auto");
    let (code, stdout, err) = talus(a.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let backends: Vec<&str> = v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["backend"].as_str().unwrap())
        .collect();
    if err.contains("no hardware GPU adapter") {
        assert!(backends.is_empty(), "nothing measured: {backends:?}");
    } else if backends.is_empty() {
        assert!(err.contains("not measured"), "says why: {err}");
    } else {
        assert!(
            backends.iter().all(|b| b.starts_with("gpu")),
            "{backends:?}"
        );
        assert!(
            !backends.iter().any(|b| b.contains("llvmpipe")),
            "{backends:?}"
        );
    }
}

/// `talus check --estimate` says the run's expected work (the model of
/// `run::expected_work`, tests/progress.rs) and a time for it on the CPU path: for a
/// pour, from the rates of stand-ins for its grown heap at several sizes (issue 37 item
/// 7); for a scene that only settles, from the scene itself.
#[test]
fn check_estimates_the_run_time() {
    let set = ["--set", "stop.time=20", "--set", "particles[1].count=100"];
    let mut args = vec!["check", "--estimate", "--backend", "cpu"];
    args.extend(set);
    let (code, out, err) = talus(&args);
    assert_eq!(code, 0, "{err}");
    let o: Vec<String> = set
        .iter()
        .skip(1)
        .step_by(2)
        .map(|s| s.to_string())
        .collect();
    let sim =
        talus::sim::Simulation::new(talus::scene::parse(talus::scene::DEFAULT_SCENE, &o).unwrap())
            .unwrap();
    let work = talus::run::expected_work(&sim, talus::run::total_steps(&sim)).total();
    assert!(
        out.contains(&format!("expected work: {work:.3e} particle-steps")),
        "{out}"
    );
    let line = out
        .lines()
        .find(|l| l.starts_with("cpu:") && l.contains("for the whole run"))
        .expect("a line for the CPU path");
    assert!(
        line.contains("particle-steps/s") && line.contains("for the whole run"),
        "{line}"
    );
    // The pour of 100 grains is timed on its grown heap: stand-ins of 200 particles (the
    // least) and no more, since 100 is below it.
    let grown: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("the heap grown to"))
        .collect();
    assert_eq!(grown.len(), 1, "{out}");
    assert!(grown[0].starts_with("cpu: the heap grown to 200"), "{out}");
    assert!(line.contains("as the heap grows"), "{line}");
    // A pile that only settles is timed as it stands.
    let (code, out, err) = talus([
        "check",
        "scenes/r1_pile_reduced.json",
        "--estimate",
        "--backend",
        "cpu",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("the heap grown"), "{out}");
    let line = out
        .lines()
        .find(|l| l.starts_with("cpu:"))
        .expect("a CPU line");
    assert!(
        line.contains("over steps") && line.contains("for the whole run"),
        "{line}"
    );
}

/// `talus check --backend gpu` says whether the scene fits the adapter a GPU run would
/// take, counting the particles its sources will add (issue 38 item 3): the 50 000-grain
/// heap fits any adapter talus runs on; 5·10⁶ grains need more workgroups in one
/// dispatch than the GPU path issues, on every adapter, and the check fails saying so.
#[test]
fn check_says_whether_a_scene_fits_the_gpu() {
    let heap = "scenes/heap_50k.json";
    let (code, out, err) = talus(["check", heap, "--backend", "gpu"]);
    if err.contains("no GPU adapter found") {
        assert!(
            !talus::gpu::device::gpu_required(),
            "TALUS_REQUIRE_GPU=1 but no adapter"
        );
        eprintln!("SKIPPED check --backend gpu: no adapter");
        assert_eq!(code, 1);
        return;
    }
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("GPU path on ") && out.contains("50000 particles at most"),
        "{out}"
    );
    assert!(out.contains("the scene fits"), "{out}");
    let (code, out, err) = talus([
        "check",
        heap,
        "--backend",
        "gpu",
        "--set",
        "particles[0].count=5000000",
        "--set",
        "limits.max_particles=1e7",
    ]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("5000000 particles at most"), "{out}");
    assert!(
        err.contains("does not fit") && err.contains("workgroups") && err.contains("--backend cpu"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_stage_goes_on_from_an_earlier_run_under_a_new_scene() {
    // Issue 41 item 4: pour for 20 time units, then tilt gravity by 5° and go on. The
    // stage starts from the earlier run's newest checkpoint (its end), at its time.
    let dir = tmp("stages");
    let (first, tilted, same, resumed) = (
        dir.join("pour"),
        dir.join("tilted"),
        dir.join("same"),
        dir.join("resumed"),
    );
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    let (code, _, err) = talus(["run", "-q", "--set", "stop.time=20", "--out", &s(&first)]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--from",
        &s(&first),
        "--set",
        "stop.time=24",
        "--set",
        "gravity.g=[0.08716,-0.99619]",
        "--out",
        &s(&tilted),
    ]);
    assert_eq!(code, 0, "{err}");
    let read = |p: PathBuf| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let summary = read(tilted.join("summary.json"));
    assert_eq!(summary["time"], 24.0);
    assert_eq!(summary["steps"], 2000, "from t = 20 to 24 at dt = 0.002");
    assert_eq!(
        read(tilted.join("scene.json"))["gravity"]["g"],
        json!([0.08716, -0.99619])
    );
    // The pour goes on where it was: more grains than at t = 20.
    let before = read(first.join("summary.json"))["particles"]
        .as_u64()
        .unwrap();
    assert!(summary["particles"].as_u64().unwrap() > before);
    // A stage that changes nothing is the resumed run, bit for bit.
    let ckpt = first.join("checkpoints/ckpt_0000010000.bin");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--from",
        &s(&ckpt),
        "--set",
        "stop.time=24",
        "--out",
        &s(&same),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = talus([
        "run",
        "-q",
        "--resume",
        &s(&ckpt),
        "--set",
        "stop.time=24",
        "--out",
        &s(&resumed),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(same.join("final.bin")).unwrap(),
        std::fs::read(resumed.join("final.bin")).unwrap()
    );
    // What a stage cannot change, named; a snapshot is no start.
    let refused = |extra: &[&str], from: &Path, must: &[&str]| {
        let mut args = vec!["run", "-q", "--from", from.to_str().unwrap()];
        args.extend(extra);
        let out = dir.join("refused");
        args.extend(["--out", out.to_str().unwrap()]);
        let (code, _, err) = talus(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        for m in must {
            assert!(err.contains(m), "{args:?}: {err}");
        }
        assert!(!out.join("summary.json").exists());
    };
    let st = ["--set", "stop.time=30"];
    refused(
        &[st[0], st[1], "--set", "particles[1].count=10"],
        &first,
        &["particles", "differs"],
    );
    refused(
        &[st[0], st[1], "--set", "dt=0.001"],
        &first,
        &["dt", "0.002"],
    );
    refused(
        &[st[0], st[1], "--set", "materials.grain.density=2"],
        &first,
        &["materials.grain"],
    );
    refused(&["--set", "stop.time=10"], &first, &["stop.time", "t = 20"]);
    refused(&st, &first.join("final.json"), &["snapshot", "checkpoints"]);
    refused(&st, &dir.join("nowhere"), &["nowhere"]);
}
