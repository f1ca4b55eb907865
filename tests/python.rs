//! The Python reader (`python/talus`, issue 41 item 1) against the Rust one: a run
//! written by `talus run`, read back by both, value for value. Needs a Python 3 with
//! numpy (`TALUS_PYTHON`, else `python3`, else `/usr/bin/python3`); without one the
//! tests say so and pass, unless `TALUS_REQUIRE_PYTHON=1` (set by `.ci/run`, whose
//! `scripts/test` installs `python3-numpy`).

mod common;

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;
use talus::io::snapshot;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("talus-python-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A Python 3 that imports numpy, or None (with a message) where there is none and
/// none is required.
fn python() -> Option<PathBuf> {
    let candidates = std::env::var_os("TALUS_PYTHON")
        .map(PathBuf::from)
        .into_iter()
        .chain(["python3", "/usr/bin/python3"].map(PathBuf::from));
    for p in candidates {
        let ok = Command::new(&p)
            .args(["-c", "import numpy"])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return Some(p);
        }
    }
    if std::env::var("TALUS_REQUIRE_PYTHON").as_deref() == Ok("1") {
        panic!("no Python 3 with numpy (TALUS_REQUIRE_PYTHON=1): apt-get install python3-numpy");
    }
    eprintln!(
        "skipped: no Python 3 with numpy (set TALUS_PYTHON, or apt-get install python3-numpy)"
    );
    None
}

/// Runs `code` with the reader importable (`PYTHONPATH=python`) in `cwd`; its stdout
/// as JSON, or its stderr as the error.
fn run_python(py: &Path, code: &str, cwd: &Path) -> Result<Value, String> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = Command::new(py)
        .args(["-c", code])
        .env("PYTHONPATH", repo.join("python"))
        .current_dir(cwd)
        .output()
        .unwrap();
    if !o.status.success() {
        return Err(String::from_utf8_lossy(&o.stderr).into_owned());
    }
    Ok(serde_json::from_slice(&o.stdout).expect("the script prints JSON"))
}

/// `talus run` of a small pile: disks in a row on a floor and a pentagon falling onto
/// them, with snapshots; the run folder `DIR/run`.
fn small_run(dir: &Path) -> PathBuf {
    let mut v = common::disks_and_a_pentagon();
    v["particles"][1]["particles"][0] =
        json!({ "position": [2.0, 1.6], "theta": 0.3, "diameter": 1.0 });
    v["name"] = json!("python-reader");
    // The floor shakes sideways (a moving wall, `talus.walls_at`).
    v["walls"][0]["motion"] =
        json!({ "velocity": [0.1, 0.0], "amplitude": [0.01, 0.0], "period": 0.07 });
    v["stop"] = json!({ "time": 0.05 });
    v["output"] = json!({ "snapshot_every": 0.02, "log_every": 0.01, "checkpoint_every": 0 });
    let scene = dir.join("scene.json");
    std::fs::write(&scene, v.to_string()).unwrap();
    let out = dir.join("run");
    let o = common::command(["run", "-q", "--backend", "cpu", "--out"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

const READ: &str = r#"
import json, sys, talus
run = talus.read_run("run")
s = run["final"]
c = s["contacts"]
print(json.dumps({
    "times": run["snapshots"].times.tolist(),
    "log_time": run["log"]["time"].tolist(),
    "summary_time": run["summary"]["time"],
    "time": s["time"], "step": s["step"], "provenance": s["provenance"],
    "id": s["id"].tolist(), "position": s["position"].tolist(),
    "velocity": s["velocity"].tolist(), "angle": s["angle"].tolist(),
    "angular_velocity": s["angular_velocity"].tolist(), "radius": s["radius"].tolist(),
    "fixed": s["fixed"].tolist(), "corners": s["corners"].tolist(),
    "vertices": [v.tolist() for v in s["vertices"]],
    "i": c["i"].tolist(), "j": c["j"].tolist(), "force": c["force"].tolist(),
    "point": c["point"].tolist(), "overlap": c["overlap"].tolist(),
    "walls": talus.walls_at(run["scene"], s["time"]).tolist(),
}))
"#;

#[test]
fn the_python_reader_reads_what_the_rust_one_reads() {
    let Some(py) = python() else { return };
    let dir = tmp("run");
    let run = small_run(&dir);
    // From the run's parent folder, with a relative path: the data is found beside
    // the metadata, not in the working directory.
    let got = run_python(&py, READ, &dir).unwrap_or_else(|e| panic!("{e}"));
    let s = snapshot::read(&run.join("final.json")).unwrap();
    let f = |k: &str| s.f64(&format!("particles.{k}")).unwrap().to_vec();
    let list = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let pairs = |v: &Value| -> Vec<[f64; 2]> {
        (v.as_array().unwrap().iter())
            .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
            .collect()
    };
    let zip = |a: Vec<f64>, b: Vec<f64>| -> Vec<[f64; 2]> {
        a.into_iter().zip(b).map(|(a, b)| [a, b]).collect()
    };
    // The particle table, bit for bit (JSON carries every f64 exactly).
    assert_eq!(got["time"].as_f64(), Some(s.meta.time));
    assert_eq!(got["step"].as_u64(), Some(s.meta.step));
    assert_eq!(got["provenance"], json!(s.meta.provenance), "what wrote it");
    assert_eq!(got["provenance"]["commit"], talus::base::provenance::COMMIT);
    let ids: Vec<u64> = (s.u32("particles.id").unwrap().iter())
        .map(|&i| i as u64)
        .collect();
    assert_eq!(got["id"], json!(ids));
    assert_eq!(pairs(&got["position"]), zip(f("x"), f("z")));
    assert_eq!(pairs(&got["velocity"]), zip(f("vx"), f("vz")));
    assert_eq!(list(&got["angle"]), f("theta"));
    assert_eq!(list(&got["angular_velocity"]), f("omega"));
    assert_eq!(list(&got["radius"]), f("radius"));
    assert_eq!(got["corners"], json!([0, 0, 0, 0, 0, 0, 0, 0, 5]));
    assert_eq!(got["fixed"].as_array().unwrap().len(), 9);
    // The pentagon's corners in the world frame: (x, z) + R(θ) v, each at the
    // circumscribed radius from the centre.
    let (cx, cz) = (s.f64("corners.x").unwrap(), s.f64("corners.z").unwrap());
    let (p, theta) = ([f("x")[8], f("z")[8]], f("theta")[8]);
    let corners = got["vertices"][8].as_array().unwrap();
    assert_eq!(corners.len(), 5);
    for (k, c) in corners.iter().enumerate() {
        let (sn, cs) = theta.sin_cos();
        let want = [
            p[0] + cs * cx[k] - sn * cz[k],
            p[1] + sn * cx[k] + cs * cz[k],
        ];
        let c = [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()];
        assert!(
            (c[0] - want[0]).abs() < 1e-14 && (c[1] - want[1]).abs() < 1e-14,
            "corner {k}: {c:?} against {want:?}"
        );
    }
    assert!(
        got["vertices"][0].as_array().unwrap().is_empty(),
        "a disk has none"
    );
    // The contacts: ids, the force on i as fn n + ft t (t = (−n_z, n_x)), the points.
    let cf = |k: &str| s.f64(&format!("contacts.{k}")).unwrap().to_vec();
    assert!(!cf("fn").is_empty(), "the pile has contacts");
    let i: Vec<u64> = (s.u32("contacts.i").unwrap().iter())
        .map(|&i| i as u64)
        .collect();
    assert_eq!(got["i"], json!(i));
    let (nx, nz, fnn, ft) = (cf("nx"), cf("nz"), cf("fn"), cf("ft"));
    for (k, force) in pairs(&got["force"]).into_iter().enumerate() {
        let want = [
            fnn[k] * nx[k] - ft[k] * nz[k],
            fnn[k] * nz[k] + ft[k] * nx[k],
        ];
        assert_eq!(force, want, "contact {k}");
    }
    assert_eq!(pairs(&got["point"]), zip(cf("px"), cf("pz")));
    assert_eq!(list(&got["overlap"]), cf("overlap"));
    // The run: snapshots in time order (t = 0, 0.02, 0.04), the log, the summary.
    let times = list(&got["times"]);
    assert_eq!(times.len(), 3, "{times:?}");
    assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");
    assert!(list(&got["log_time"]).len() >= 4);
    assert_eq!(got["summary_time"].as_f64(), Some(s.meta.time));
    // The walls where the run had them at the final time, as the Rust analysis places
    // them (the same formula in numpy: to rounding).
    let walls = talus::analyze::input::load(&run, None).unwrap().walls;
    let py_walls = got["walls"].as_array().unwrap();
    assert_eq!(py_walls.len(), walls.len());
    for (w, p) in walls.iter().zip(py_walls) {
        for (end, q) in w.iter().zip(pairs(p)) {
            assert!(
                (end[0] - q[0]).abs() < 1e-12 && (end[1] - q[1]).abs() < 1e-12,
                "wall end {q:?} against {end:?}"
            );
        }
    }
    assert!((walls[0][0][0] + 5.0).abs() > 1e-3, "the floor moved");
}

#[test]
fn the_python_reader_refuses_a_damaged_snapshot() {
    let Some(py) = python() else { return };
    let dir = tmp("damaged");
    let run = small_run(&dir);
    let bin = run.join("final.bin");
    let mut b = std::fs::read(&bin).unwrap();
    b[17] ^= 0x10;
    std::fs::write(&bin, &b).unwrap();
    let code = "import talus\ntalus.read_snapshot('run/final.json')";
    let err = run_python(&py, code, &dir).expect_err("a damaged snapshot reads");
    assert!(
        err.contains("SnapshotError") && err.contains("damaged"),
        "{err}"
    );
    // Unchecked on request: the data as it stands.
    let code = "import json, talus\nprint(json.dumps(len(talus.read_snapshot('run/final.json', verify=False)['id'])))";
    assert_eq!(run_python(&py, code, &dir).unwrap(), json!(9));
}

/// The README's install, as a user does it (issue 41): `pip install ./python` into a
/// fresh virtual environment (numpy from the system's site packages, no network: the
/// build uses the system's setuptools), then the reader imported from another folder
/// without `PYTHONPATH`.
#[test]
fn pip_installs_the_reader_into_a_fresh_venv() {
    let Some(py) = python() else { return };
    let has = |module: &str| {
        Command::new(&py)
            .args(["-c", &format!("import {module}")])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !(has("ensurepip") && has("setuptools")) {
        if std::env::var("TALUS_REQUIRE_PYTHON").as_deref() == Ok("1") {
            panic!(
                "no venv or setuptools (TALUS_REQUIRE_PYTHON=1): apt-get install python3-venv python3-setuptools"
            );
        }
        eprintln!(
            "skipped: no venv or setuptools (apt-get install python3-venv python3-setuptools)"
        );
        return;
    }
    let dir = tmp("venv");
    let venv = dir.join("venv");
    let o = Command::new(&py)
        .args(["-m", "venv", "--system-site-packages"])
        .arg(&venv)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "venv: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // A copy of the package, so that the build leaves nothing in the checkout.
    let src = dir.join("python");
    std::fs::create_dir_all(src.join("talus")).unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("python");
    for f in ["pyproject.toml", "README.md"] {
        std::fs::copy(repo.join(f), src.join(f)).unwrap();
    }
    for e in std::fs::read_dir(repo.join("talus")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "py") {
            std::fs::copy(&p, src.join("talus").join(p.file_name().unwrap())).unwrap();
        }
    }
    let o = Command::new(venv.join("bin/pip"))
        .args(["install", "-q", "--no-index", "--no-build-isolation"])
        .arg(&src)
        .env_remove("PYTHONPATH")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "pip install: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    small_run(&dir);
    let o = Command::new(venv.join("bin/python"))
        .args([
            "-c",
            "import talus; s = talus.read_snapshot('run/final.json'); print(s['position'].shape)",
        ])
        .env_remove("PYTHONPATH")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout).trim(), "(9, 2)");
    // Installed, not found beside it: the module lives in the venv.
    let o = Command::new(venv.join("bin/python"))
        .args(["-c", "import talus; print(talus.__file__)"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let at = String::from_utf8_lossy(&o.stdout);
    assert!(at.contains("site-packages"), "{at}");
}
