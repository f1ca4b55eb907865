//! The claims of SPEC 6 (R1–R9), each checked on its reduced form as `talus reproduce`
//! runs it, with the tolerance and where it comes from stated beside each check. A claim
//! test fails when the claim is broken; what only the full size shows is in
//! docs/REPRODUCTION.md, not here.

mod common;
use serde_json::{Value, json};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    common::tmp("claims", name)
}

#[test]
fn reproduce_r1_gives_the_papers_stress_ratio_of_one_third() {
    // R1 reduced (paper 000 sec. 4.3): frictionless lattice pile on a fixed row; in the
    // interior of the first mobile row S_xx/S_zz = tan² 30° = 1/3, for ν = 1 and 3/2.
    let dir = tmp("reproduce");
    let run = |args: &[&str]| {
        let (code, _, err) = common::talus(args);
        (code, err)
    };
    let (code, err) = run(&[
        "reproduce",
        "R1",
        "--backend",
        "cpu",
        "-q",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("reproduce.json")).unwrap())
            .unwrap();
    // Both exponents of the spring-dashpot law, ν = 1 and 3/2 (paper 000 Fig. 6).
    let variants = report["variants"].as_array().unwrap();
    assert_eq!(variants.len(), 2);
    for v in variants {
        let ratio = v["stress_ratio_interior_row1"].as_f64().unwrap();
        assert!((ratio - 1.0 / 3.0).abs() < 0.03, "S_xx/S_zz = {ratio}: {v}");
    }
    // And the same S_zz in row 1 (measured: 1.3 % of its maximum apart at most).
    let c = &report["comparisons"][0];
    assert_eq!(c["variants"], json!(["pile", "pile-nu1.5"]));
    let diff = c["row1_szz_max_difference"].as_f64().unwrap();
    assert!(diff < 0.05, "ν = 1 and 3/2 differ by {diff}");
    assert!(dir.join("pile/pictures/forces.png").is_file());
    let (code, err) = run(&["reproduce", "R12"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown reproduction"), "{err}");
}

/// `talus reproduce ARGS --backend cpu -q` into a fresh folder `name`, which must
/// succeed: the folder and its reproduce.json.
fn reproduce(name: &str, args: &[&str]) -> (PathBuf, Value) {
    let dir = tmp(name);
    let o = common::command(["reproduce"])
        .args(args)
        .args(["--backend", "cpu", "-q", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.join("reproduce.json")).unwrap();
    (dir, serde_json::from_str(&text).unwrap())
}

/// The findings of one variant in a reproduce.json.
fn variant(report: &Value, name: &str) -> Value {
    (report["variants"].as_array().unwrap().iter())
        .find(|v| v["variant"] == name)
        .unwrap_or_else(|| panic!("no variant {name}"))
        .clone()
}

#[test]
fn reproduce_r9_packing_falls_with_the_aspect_ratio_and_with_cohesion() {
    // R9 reduced (paper 004 Fig. 2b), the four runs that carry its two trends (the other
    // four, Bo = 10² and the stiff Bo = 10⁴ runs, take half an hour): 300 rods poured
    // into a box 20 d wide. The packing fraction of the deposit's lower half falls with
    // d at Bo = 0 (0.877, 0.858, 0.738 at stop 28) and from Bo = 0 to 10³ at d = 5
    // (0.858 to 0.497). Two threads: the results are bitwise those of one.
    let (_, report) = reproduce(
        "reproduce-r9",
        &[
            "R9",
            "--only",
            "d2-bo0,d5-bo0,d10-bo0,d5-bo1000",
            "--threads",
            "2",
        ],
    );
    let phi = |name: &str| {
        variant(&report, name)["packing_fraction_lower_half"]
            .as_f64()
            .unwrap()
    };
    let (d2, d5, d10, cohesive) = (
        phi("d2-bo0"),
        phi("d5-bo0"),
        phi("d10-bo0"),
        phi("d5-bo1000"),
    );
    assert!(
        d2 > d5 && d5 > d10 && d5 - cohesive > 0.2,
        "d = 2, 5, 10: {d2}, {d5}, {d10}; d = 5, Bo = 10³: {cohesive}"
    );
    // reproduce.json says so in its trends.
    let trends: Vec<&str> = (report["trends"].as_array().unwrap().iter())
        .filter_map(|t| t.as_str())
        .filter(|t| t.starts_with("packing fraction"))
        .collect();
    assert_eq!(trends.len(), 2, "{trends:?}");
    assert!(
        trends.iter().all(|t| t.contains("falls, as in paper 004")),
        "{trends:?}"
    );
}

#[test]
fn reproduce_r2_full_stiff_piles_dip_alike_for_both_squeezes() {
    // R2 --full adds both squeezes at k_n = 10⁶ and 10⁷ N/m (issue 40 item 4): there the
    // overlaps under gravity are far below the squeeze of either c, row 1 jams fully,
    // and both dip alike (28-30 % measured), unlike at 10⁵ N/m where the dip deepens
    // with |c| (the claim above).
    let (_, report) = reproduce("reproduce-r2-stiff", &["R2", "--full", "--only", "kn="]);
    let names: Vec<&str> = (report["variants"].as_array().unwrap().iter())
        .map(|v| v["variant"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "c=-1_750-kn=1e6",
            "c=-1_150-kn=1e6",
            "c=-1_750-kn=1e7",
            "c=-1_150-kn=1e7"
        ]
    );
    let dip = |name: &str| variant(&report, name)["row1_dip"].as_f64().unwrap();
    for k_n in ["1e6", "1e7"] {
        let (light, strong) = (
            dip(&format!("c=-1_750-kn={k_n}")),
            dip(&format!("c=-1_150-kn={k_n}")),
        );
        assert!(
            light > 0.2 && strong > 0.2 && (light - strong).abs() < 0.05,
            "k_n = {k_n}: dips {light} (c = -1/750) and {strong} (c = -1/150)"
        );
    }
}

#[test]
fn reproduce_r2_dips_under_a_squeezed_bottom_only() {
    // R2 (paper 000 sec. 4.1, Fig. 3a), L1 = 19: the pile starts without overlaps and
    // S_zz(1) under the apex is the maximum for c = 0 (a hump), flat for c = −1/750, and
    // a dip of well over 10 % for c = −1/150.
    let (dir, report) = reproduce("reproduce-r2", &["R2"]);
    let variant = |name: &str| variant(&report, name);
    let (flat, light, strong) = (variant("c=0"), variant("c=-1_750"), variant("c=-1_150"));
    // The four profiles are drawn side by side, one line and legend entry each.
    let svg = std::fs::read_to_string(dir.join("profiles.svg")).unwrap();
    for name in ["c=1_15", "c=0", "c=-1_750", "c=-1_150"] {
        assert!(svg.contains(&format!("\n{name}\n")), "legend {name}");
    }
    for v in [&flat, &light, &strong] {
        assert_eq!(v["grains"], 92, "no grain is lost: {v}");
        // Each run's cost, from its summary (issue 40 item 6).
        let cost = &v["cost"];
        assert!(
            cost["steps"].as_u64().unwrap() > 1000
                && cost["wall_seconds"].as_f64().unwrap() > 0.0
                && cost["particle_steps_per_second"].as_f64().unwrap() > 0.0
                && cost["backend"] == "cpu",
            "{cost}"
        );
    }
    let f = |v: &Value, k: &str| v[k].as_f64().unwrap();
    assert_eq!(
        f(&flat, "row1_dip"),
        0.0,
        "c = 0 has its maximum under the apex"
    );
    assert!(f(&strong, "row1_dip") > 0.15, "c = −1/150: {strong}");
    assert!(
        f(&flat, "row1_szz_centre") > f(&light, "row1_szz_centre")
            && f(&light, "row1_szz_centre") > f(&strong, "row1_szz_centre"),
        "S_zz(1) under the apex falls with the squeeze"
    );
    // --reuse measures a finished run again without running it; --only picks it.
    let o = common::command([
        "reproduce",
        "R2",
        "--backend",
        "cpu",
        "--reuse",
        "--only",
        "c=0",
        "--out",
    ])
    .arg(&dir)
    .output()
    .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success() && err.contains("(finished run reused)"),
        "{err}"
    );
    assert!(!err.contains("step "), "no steps are run again: {err}");
    let again: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("reproduce.json")).unwrap())
            .unwrap();
    assert_eq!(again["variants"].as_array().unwrap().len(), 1);
    assert_eq!(
        again["variants"][0]["row1_szz_centre"],
        flat["row1_szz_centre"]
    );
}

/// The seed average of `setting` in a reproduce.json (`talus reproduce` of a variant
/// list with seeds in it, as R3's).
fn seed_average(report: &Value, setting: &str) -> Value {
    (report["seed_averages"].as_array().unwrap().iter())
        .find(|a| a["setting"] == setting)
        .unwrap_or_else(|| panic!("no seed average {setting}"))
        .clone()
}

/// Mean and standard error over seeds of `scalar` for `variant` in the reproduce.json of
/// `talus reproduce ID --seeds A..B` (each variant a sweep).
fn over_seeds(report: &Value, variant: &str, scalar: &str) -> (f64, f64) {
    let v = (report["variants"].as_array().unwrap().iter())
        .find(|v| v["variant"] == variant)
        .unwrap_or_else(|| panic!("no variant {variant}"));
    let s = &v["statistics"][scalar];
    (s["mean"].as_f64().unwrap(), s["se"].as_f64().unwrap())
}

#[test]
fn reproduce_r3_turns_the_hump_into_a_dip_with_size_disorder() {
    // R3 reduced (paper 000 sec. 4.4, Fig. 8): the R1 pile with diameters d0 (1 + r_d^i),
    // 5 seeds per r_d, S_zz(1) averaged over the seeds with each pile's apex at 0.
    let (_, report) = reproduce("reproduce-r3", &["R3", "--threads", "2"]);
    let (ordered, disordered) = (
        seed_average(&report, "rd=2_3000"),
        seed_average(&report, "rd=1_30"),
    );
    let f = |v: &Value, k: &str| v[k].as_f64().unwrap();
    for a in [&ordered, &disordered] {
        assert_eq!(a["seeds"], 5, "{}", a["setting"]);
    }
    // r_d = 2/3000 (ϱ ≈ 1, ordered): a hump, the maximum under the apex (measured: a dip
    // of 0.000; single seeds 0.00–0.01, so 0.01 bounds it).
    let dip = f(&ordered, "row1_dip");
    assert!(dip < 0.01, "r_d = 2/3000: a dip of {dip:.3}");
    // r_d = 1/30 (ϱ ≫ 1): a dip (measured 0.080 in the average; single seeds 0.05–0.26,
    // standard error of their mean 0.034: 0.03 is more than a standard error below),
    // and less load under the apex than the ordered pile carries there (1.030 against
    // 1.167; standard error of the single seeds under the apex 0.05).
    let dip = f(&disordered, "row1_dip");
    assert!(dip > 0.03, "r_d = 1/30: a dip of {dip:.3}");
    let (hump, dipped) = (
        f(&ordered, "row1_szz_apex"),
        f(&disordered, "row1_szz_apex"),
    );
    assert!(
        dipped < hump - 0.05,
        "S_zz(1) under the apex: {hump:.3} (r_d = 2/3000) against {dipped:.3} (1/30)"
    );
    // Coordination near the isostatic 4 in the disordered pile, as the paper's 3.96 for
    // M ≥ 1 (closer to 4 without the surface grains): single seeds 4.00–4.13 without
    // them; the ordered pile keeps its lattice's 5.
    let z = f(&disordered, "coordination_interior");
    assert!((z - 4.0).abs() < 0.2, "Z = {z}");
}

#[test]
fn reproduce_r4_builds_a_heap_at_the_papers_angle() {
    // R4 reduced (paper 001, the law as eq. 3–8 and 13 write it, leapfrog): 300 disks
    // poured from 30σ, 8 seeds (two minutes on two cores). Paper 001 gives 31° for
    // n = 36 in its text and 35° ± 5° over its heaps; the test takes the paper's 31° as
    // the target and the standard error of the 8-seed mean as the tolerance, twice over:
    // the band fit measured 30.3° ± 1.5°, the apex–toe line 31.1° ± 0.7°. The paper's M
    // under the heap is not reproduced at this size since eq. 13's torques (stop 53: dip
    // above noise z = 0.5, centre / side max 0.91 ± 0.07), so nothing here asserts it
    // (docs/REPRODUCTION.md).
    let (_, report) = reproduce(
        "reproduce-r4",
        &["R4", "--only", "pour", "--seeds", "1..8", "--jobs", "2"],
    );
    assert_eq!(
        report["variants"][0]["measured"], 8,
        "every seed ran: {}",
        report["failed"]
    );
    for reading in ["repose_mean_deg", "repose_apex_toe_deg"] {
        let (mean, se) = over_seeds(&report, "pour", reading);
        assert!(
            (mean - 31.0).abs() <= 2.0 * se && se < 2.0,
            "{reading}: {mean:.1}° ± {se:.1}° against paper 001's 31°"
        );
    }
}

#[test]
fn reproduce_r8_gives_the_same_stress_for_every_friction() {
    // R8 reduced (paper 000 sec. 5.2): the polygon pile settled with μ = 0, 0.3 and 0.6.
    // S_zz(1) of the three within 6 % of its maximum everywhere (measured: 4.4 % between
    // μ = 0 and the frictional two, 0.1 % between those), and no clear dip (under 5 % in
    // the base row and row 1 for every μ; measured 0). A stress that moved with μ as much
    // as R2's does with the bottom (18–28 % under the apex) fails both.
    // Built layer by layer as the paper builds it (issue 40 item 3), friction acts while
    // the rows land: the profiles differ more (measured: 6.9 % at most between μ = 0 and
    // 0.6, 1.1-1.8 % on average) but stay alike in magnitude and shape, the paper's
    // "similar in magnitude and shape" with "much stronger" fluctuations: within 10 % at
    // most and 3 % on average.
    let (_, report) = reproduce("reproduce-r8", &["R8", "--threads", "2"]);
    let comparisons = report["comparisons"].as_array().unwrap();
    assert_eq!(comparisons.len(), 6, "three pairs of μ per construction");
    for c in comparisons {
        let (most, mean) = (
            c["row1_szz_max_difference"].as_f64().unwrap(),
            c["row1_szz_mean_difference"].as_f64().unwrap(),
        );
        let layered = c["variants"][0].as_str().unwrap().starts_with("layered-");
        let bound = if layered { (0.10, 0.03) } else { (0.06, 0.03) };
        assert!(
            most < bound.0 && mean < bound.1,
            "{}: S_zz(1) differs by {most:.3} at most, {mean:.3} on average",
            c["variants"]
        );
    }
    for mu in [
        "mu-0",
        "mu-0.3",
        "mu-0.6",
        "layered-mu-0",
        "layered-mu-0.3",
        "layered-mu-0.6",
    ] {
        let v = variant(&report, mu);
        for dip in ["base_dip", "row1_dip"] {
            let d = v[dip].as_f64().unwrap();
            assert!(d < 0.05, "{mu}: {dip} {d:.3}");
        }
    }
}

/// How far variant `a`'s seed mean of `scalar` (in report `ra`) lies above variant `b`'s
/// (in `rb`), in standard errors of the difference.
fn above((ra, a): (&Value, &str), (rb, b): (&Value, &str), scalar: &str) -> f64 {
    let ((ma, sa), (mb, sb)) = (over_seeds(ra, a, scalar), over_seeds(rb, b, scalar));
    (ma - mb) / sa.hypot(sb)
}

#[test]
fn reproduce_r5_stands_steeper_with_a_short_tail_and_flatter_with_polydispersity() {
    // R5 reduced (paper 001 Fig. 6–8): R4's heap with the n = 144 law and the short tail
    // r0 = 1.047σ (4 seeds: the effect is large), and with 10 % polydispersity against
    // n = 36 (16 seeds each: the effect is about one seed spread), about four minutes on
    // two cores. The tolerance is two standard errors of the difference over the seeds.
    // The paper's other claim, the M lost with the Hooke law and the short tail, is not
    // tested: since eq. 13's torques (stop 53) the n = 36 reference has no M at this size
    // either (docs/REPRODUCTION.md).
    let (_, trend) = reproduce(
        "reproduce-r5",
        &[
            "R5",
            "--only",
            "continuous-n36,poly10",
            "--seeds",
            "1..16",
            "--jobs",
            "2",
        ],
    );
    let (_, short) = reproduce(
        "reproduce-r5-short",
        &[
            "R5",
            "--only",
            "n144-short",
            "--seeds",
            "1..4",
            "--jobs",
            "2",
        ],
    );
    // n = 144 with the short tail stands steeper than n = 36 on the apex–toe line
    // (paper 001: 35° against 31°; measured 37.2° ± 0.2° on 4 seeds against 29.7° ± 0.6°
    // on 16, 12 standard errors).
    let s = above(
        (&short, "n144-short"),
        (&trend, "continuous-n36"),
        "repose_apex_toe_deg",
    );
    assert!(s >= 2.0, "n144-short steeper than n = 36 by {s:.1} se");
    // Polydispersity flattens the heap: a lower band-fit slope and a lower heap from the
    // same grains (measured on 16 seeds: 25.5° ± 0.9° against 28.7° ± 1.0°, 2.6
    // standard errors; height 11.20σ ± 0.17σ against 11.77σ ± 0.13σ, 2.6). The apex–toe
    // line shows it less (28.0° ± 0.7° against 29.7° ± 0.6°, 2.0).
    for scalar in ["repose_mean_deg", "height_d"] {
        let s = above((&trend, "continuous-n36"), (&trend, "poly10"), scalar);
        assert!(s >= 2.0, "poly10 below n = 36 in {scalar} by {s:.1} se");
    }
}
