//! `talus sweep`: the product of seeds and grid values run into one folder each, the
//! statistics collected, a killed sweep continued, a failing run reported while the
//! others go on, a run made as a Slurm task would make it (`run-one`) bitwise the same
//! as the same run made locally. Through the binary, on the CPU path.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn talus(threads: usize, args: &[&str]) -> Command {
    let mut c = common::command(["--threads", &threads.to_string()]);
    c.args(args);
    c
}

fn run(threads: usize, args: &[&str]) -> Output {
    talus(threads, args).output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("talus-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A small pour of the default heap: `time` of simulated time, 200 grains at 20 per unit.
fn sweep_args<'a>(out: &'a str, time: &'a str) -> Vec<&'a str> {
    vec![
        "sweep",
        "-q",
        "--backend",
        "cpu",
        "--out",
        out,
        "--set",
        time,
        "--set",
        "particles[1].count=200",
        "--set",
        "particles[1].rate=20",
        "--set",
        "output.checkpoint_every=4",
    ]
}

fn runs_of(dir: &Path) -> Vec<PathBuf> {
    let mut runs: Vec<PathBuf> = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    runs.sort();
    runs
}

/// A CSV file as a header and rows of cells (no quoted cells in the columns used here).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

#[test]
fn a_sweep_runs_every_combination_and_collects_its_statistics() {
    let dir = scratch("grid");
    let out = dir.to_str().unwrap();
    let mut args = sweep_args(out, "stop.time=12");
    args.extend([
        "--seeds",
        "1..2",
        "--grid",
        "contact.mu=0.3,0.6",
        "--jobs",
        "2",
    ]);
    let o = run(2, &args);
    assert!(o.status.success(), "{}", text(&o));

    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    let names: Vec<&str> = (plan["runs"].as_array().unwrap().iter())
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "0000-mu0.3-seed1",
            "0001-mu0.3-seed2",
            "0002-mu0.6-seed1",
            "0003-mu0.6-seed2"
        ]
    );
    for r in runs_of(&dir) {
        for f in [
            "final.bin",
            "summary.json",
            "measures.json",
            "analysis/summary.json",
        ] {
            assert!(r.join(f).is_file(), "{} lacks {f}", r.display());
        }
        // Each run's scene is the base scene with its own values.
        let scene: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(r.join("scene.json")).unwrap()).unwrap();
        let name = r.file_name().unwrap().to_str().unwrap();
        assert_eq!(scene["seed"], if name.ends_with("seed1") { 1 } else { 2 });
        assert_eq!(
            scene["contact"]["mu"],
            if name.contains("mu0.3") { 0.3 } else { 0.6 }
        );
    }
    // Seeds differ, so their heaps do.
    let bin = |k: usize| std::fs::read(runs_of(&dir)[k].join("final.bin")).unwrap();
    assert_ne!(bin(0), bin(1));

    // points.csv against means and deviations computed here from runs.csv.
    let (rh, rows) = csv(&dir.join("collect/runs.csv"));
    let (ph, points) = csv(&dir.join("collect/points.csv"));
    assert_eq!((rows.len(), points.len()), (4, 2));
    for quantity in [
        "height_d",
        "packing_fraction_lower_half",
        "coordination_interior",
    ] {
        for (p, point) in points.iter().enumerate() {
            let values: Vec<f64> = (rows.iter())
                .filter(|r| r[column(&rh, "point")] == p.to_string())
                .map(|r| r[column(&rh, quantity)].parse().unwrap())
                .collect();
            assert_eq!(values.len(), 2);
            let mean = (values[0] + values[1]) / 2.0;
            let std = (values[0] - values[1]).abs() / 2f64.sqrt();
            let got = |s: &str| -> f64 {
                point[column(&ph, &format!("{quantity}_{s}"))]
                    .parse()
                    .unwrap()
            };
            assert!(
                (got("mean") - mean).abs() <= 1e-12 * mean.abs(),
                "{quantity} mean"
            );
            assert!(
                (got("std") - std).abs() <= 1e-9 * std.max(1e-300),
                "{quantity} std"
            );
            assert!((got("se") - std / 2f64.sqrt()).abs() <= 1e-9 * std.max(1e-300));
            assert_eq!(point[column(&ph, "contact.mu")], ["0.3", "0.6"][p]);
        }
    }
    // Profiles averaged with their spread, drawn with bands.
    let (bh, bands) = csv(&dir.join("collect/profiles/point0_packing.csv"));
    assert_eq!(bh, ["x", "mean", "std", "n"]);
    assert!(!bands.is_empty());
    let svg = std::fs::read_to_string(dir.join("collect/packing.svg")).unwrap();
    assert!(svg.contains("<polygon"), "no band drawn");
    assert!(
        svg.contains("depth below the top [mean diameters]")
            && svg.contains("packing fraction [-]"),
        "axes with units"
    );

    // A run made the way a Slurm array task makes it, on another thread count, is the
    // same to the bit.
    let copy = scratch("grid-task");
    std::fs::create_dir_all(copy.join("runs")).unwrap();
    for f in ["sweep.json", "scene.json"] {
        std::fs::copy(dir.join(f), copy.join(f)).unwrap();
    }
    let o = run(
        1,
        &[
            "sweep",
            "run-one",
            copy.to_str().unwrap(),
            "--index",
            "2",
            "-q",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    for f in ["final.bin", "log.csv", "measures.json"] {
        let a = common::output_without_provenance(&dir.join("runs/0002-mu0.6-seed1").join(f));
        let b = common::output_without_provenance(&copy.join("runs/0002-mu0.6-seed1").join(f));
        assert!(a == b, "{f} differs between the local sweep and run-one");
    }
    // Run again, run-one does nothing to a measured run.
    let o = run(
        1,
        &["sweep", "run-one", copy.to_str().unwrap(), "--index", "2"],
    );
    assert!(text(&o).contains("measured already"), "{}", text(&o));
    let o = run(
        1,
        &["sweep", "run-one", copy.to_str().unwrap(), "--index", "4"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("runs 0 to 3"), "{}", text(&o));

    // The same sweep as a Slurm job array: the batch script, not run.
    let mut args = sweep_args(out, "stop.time=12");
    args.extend([
        "--seeds",
        "1..2",
        "--grid",
        "contact.mu=0.3,0.6",
        "--slurm",
        "--cpus",
        "2",
    ]);
    let o = run(1, &args);
    assert!(o.status.success(), "{}", text(&o));
    let sbatch = std::fs::read_to_string(dir.join("sweep.sbatch")).unwrap();
    let abs = dir.canonicalize().unwrap();
    assert!(sbatch.contains("#SBATCH --array=0-3\n"), "{sbatch}");
    assert!(
        sbatch.contains(&format!("sweep run-one '{}' --index", abs.display())),
        "{sbatch}"
    );
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&copy).ok();
}

#[test]
fn a_killed_sweep_continues_where_it_stopped() {
    // The whole sweep, then the same one killed in its second run and started again.
    let whole = scratch("whole");
    let killed = scratch("killed");
    let args = |out: &Path| -> Vec<String> {
        let mut a: Vec<String> = sweep_args(out.to_str().unwrap(), "stop.time=60")
            .into_iter()
            .map(String::from)
            .collect();
        a.extend(["--seeds", "1..3", "--jobs", "1"].map(String::from));
        a
    };
    let w = args(&whole);
    let o = talus(1, &w.iter().map(String::as_str).collect::<Vec<_>>())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));

    let a = args(&killed);
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    let mut child = talus(1, &a)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let second = killed.join("runs/0001-seed2");
    let t = Instant::now();
    // Killed once the second run has a checkpoint and before it is measured.
    while !(second
        .join("checkpoints")
        .read_dir()
        .is_ok_and(|mut d| d.next().is_some()))
        && child.try_wait().unwrap().is_none()
        && t.elapsed() < Duration::from_secs(120)
    {
        std::thread::sleep(Duration::from_millis(2));
    }
    let killed_midway = child.try_wait().unwrap().is_none();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(killed_midway, "the sweep ended before it could be killed");
    assert!(!second.join("measures.json").exists());
    let first = killed.join("runs/0000-seed1/measures.json");
    let first_written = std::fs::metadata(&first).unwrap().modified().unwrap();

    let o = talus(1, &a).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("1 measured already, 2 to do"),
        "{}",
        text(&o)
    );
    assert_eq!(
        std::fs::metadata(&first).unwrap().modified().unwrap(),
        first_written,
        "the measured run was left alone"
    );
    for (w, k) in runs_of(&whole).iter().zip(runs_of(&killed)) {
        for f in ["final.bin", "log.csv", "measures.json"] {
            assert!(
                common::output_without_provenance(&w.join(f))
                    == common::output_without_provenance(&k.join(f)),
                "{f} of {} differs from the sweep that was not killed",
                k.display()
            );
        }
    }
    assert_eq!(
        std::fs::read(whole.join("collect/points.csv")).unwrap(),
        std::fs::read(killed.join("collect/points.csv")).unwrap()
    );
    std::fs::remove_dir_all(&whole).ok();
    std::fs::remove_dir_all(&killed).ok();
}

#[test]
fn a_failing_run_is_reported_and_the_others_go_on() {
    let dir = scratch("failing");
    let out = dir.to_str().unwrap();
    // A displacement bound no falling grain keeps: that run stops at once as diverged.
    let mut args = sweep_args(out, "stop.time=6");
    args.extend([
        "--grid",
        "limits.max_step_displacement=0.5,1e-6,0.4",
        "--jobs",
        "1",
    ]);
    let o = run(1, &args);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("1 of 3 runs failed: 0001-max_step_displacement1e-6-seed1"),
        "{}",
        text(&o)
    );
    let runs = runs_of(&dir);
    assert!(runs[0].join("measures.json").is_file());
    assert!(
        runs[2].join("measures.json").is_file(),
        "the run after the failure ran"
    );
    let failed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(runs[1].join("failed.json")).unwrap())
            .unwrap();
    assert_eq!(failed["code"], 1);
    assert!(
        failed["error"].as_str().unwrap().contains("diverged"),
        "{failed}"
    );
    let (h, rows) = csv(&dir.join("collect/runs.csv"));
    let status: Vec<&str> = rows
        .iter()
        .map(|r| r[column(&h, "status")].as_str())
        .collect();
    assert_eq!(status, ["measured", "failed", "measured"]);
    let o = run(1, &["sweep", "collect", out]);
    assert!(o.status.success());
    assert!(text(&o).contains("collected 2 of 3 runs"), "{}", text(&o));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_sweeps_are_refused_and_another_sweeps_folder_too() {
    let dir = scratch("refused");
    let out = dir.to_str().unwrap();
    for (extra, says) in [
        (&["--seeds", "5..1"][..], "--seeds 5..1"),
        (
            &["--grid", "seed=1,2"][..],
            "--grid seed=1,2: the seed is swept with --seeds",
        ),
        (
            &["--grid", "contact.mu=0.3,-1"][..],
            "run 0001-mu-1-seed1 (contact.mu=-1 seed=1): contact.mu",
        ),
        (
            &["--grid", "contact.mu"][..],
            "--grid contact.mu: expected KEY=V1,V2",
        ),
        (&["--jobs", "0"][..], "--jobs: must be at least 1"),
    ] {
        let mut args = sweep_args(out, "stop.time=1");
        args.extend(extra);
        let o = run(1, &args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o));
        assert!(text(&o).contains(says), "{extra:?}: {}", text(&o));
    }
    assert!(
        !dir.join("sweep.json").exists(),
        "nothing written for a refused sweep"
    );

    let mut args = sweep_args(out, "stop.time=1");
    args.extend(["--seeds", "1..2"]);
    assert!(run(1, &args).status.success());
    // A different sweep into the same folder: refused, then --force replaces it.
    let mut other = sweep_args(out, "stop.time=1");
    other.extend(["--seeds", "3"]);
    let o = run(1, &other);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("holds a different sweep"), "{}", text(&o));
    other.push("--force");
    let o = run(1, &other);
    assert!(o.status.success(), "{}", text(&o));
    let names: Vec<String> = (runs_of(&dir).iter())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["0000-seed3"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn reproduce_with_seeds_runs_each_variant_as_a_sweep() {
    let dir = scratch("reproduce");
    let out = dir.to_str().unwrap();
    let args = [
        "reproduce",
        "R1",
        "--seeds",
        "1..2",
        "--only",
        "nu1.5",
        "--backend",
        "cpu",
        "--out",
        out,
        "-q",
    ];
    let o = run(2, &args);
    assert!(o.status.success(), "{}", text(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("reproduce.json")).unwrap())
            .unwrap();
    let v = &report["variants"][0];
    assert_eq!(v["variant"], "pile-nu1.5");
    assert_eq!(v["measured"], 2);
    // A lattice pile without size disorder does not depend on the seed: both runs are the
    // same heap, so the spread over seeds is exactly zero.
    let repose = &v["statistics"]["repose_left_deg"];
    assert_eq!(repose["n"], 2);
    assert_eq!(repose["std"], 0.0, "{repose}");
    assert!(
        (25.0..35.0).contains(&repose["mean"].as_f64().unwrap()),
        "{repose}"
    );
    assert!(dir.join("pile-nu1.5/collect/points.csv").is_file());
    assert!(
        std::fs::read_to_string(dir.join("profiles.svg"))
            .unwrap()
            .contains("<polygon")
    );
    // Run again, it continues: nothing is run twice.
    let o = run(2, &args);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("2 measured already, 0 to do"),
        "{}",
        text(&o)
    );
    std::fs::remove_dir_all(&dir).ok();
}
