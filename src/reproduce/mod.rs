//! `talus reproduce ID`: the scenes of SPEC 6 (R1–R9) with the measurements that decide
//! whether each reproduces its paper's result. The scene files are built in, so the
//! command runs anywhere; reduced forms by default, the paper's sizes with `--full`.

use serde::Serialize;

mod findings;
pub mod paper;
mod variants;
pub use findings::{
    Comparison, Findings, Q_PAIRS, RunCost, SeedAverage, comparisons, findings, seed_averages,
};
pub use variants::variants;

/// One run of a reproduction: a scene, its overrides, and the analysis sizes.
#[derive(Clone, Debug)]
pub struct Variant {
    pub name: String,
    pub scene: &'static str,
    pub overrides: Vec<String>,
    /// Moving-average window and row height, in mean diameters.
    pub window: f64,
    pub row: f64,
}

/// What R1–R9 reproduce (SPEC 6), in one line each.
pub fn claim(id: &str) -> &'static str {
    match id {
        "R1" => "S_xx/S_zz ≈ 1/3 in the interior of row M = 1; the same stress for ν = 1 and 3/2",
        "R2" => {
            "dip of S_zz(1) under the apex for c < 0, deepening with |c|; no dip (zig-zag) for c = 1/15"
        }
        "R3" => {
            "averaged over seeds, the hump of S_zz(1) at small r_d turns into a dip at r_d = 1/30; coordination ≈ 3.96 for M ≥ 1"
        }
        "R5" => {
            "M profile lost for Hooke and short-tail n = 144; flatter, more compacted heaps with polydispersity"
        }
        "R4" => {
            "stable heap, angle of repose 35° ± 5°, base normal force with an M profile (side maxima 20–30 % above the centre)"
        }
        "R6" => "a relaxed heap with a pressure dip visible in the principal stresses",
        "R7" => {
            "slopes near 23°, 24°, 28° (wedge) and 32° (layered); dip for polydisperse wedge heaps only"
        }
        "R8" => "stress independent of μ within fluctuations; no clear dip",
        "R9" => {
            "the packing fraction of deposited rods falls with the aspect ratio d and with the Bond number"
        }
        _ => "",
    }
}

/// A reproduction that does not exist, or a size it does not have.
#[derive(Debug, thiserror::Error)]
pub enum ReproductionError {
    #[error("unknown reproduction `{0}`: R1 to R9")]
    Unknown(String),
    #[error("--rods: {0} has no rod count (only R9 has)")]
    NotRods(String),
    #[error("--rods {0}: R9 needs at least 10 rods")]
    TooFewRods(usize),
}

/// How large the runs of a reproduction are.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Size {
    Reduced,
    /// The paper's.
    Full,
    /// The paper's layout with this many rods, the box and the run sized for them (R9).
    Rods(usize),
}

/// The variants `only` picks: each of its comma-separated parts picks the variant of
/// that name, or, when no variant has that name, those whose name contains it
/// (`d5-bo1000` is one run, not also `d5-bo10000`; `seed3` every variant of seed 3).
pub fn pick(variants: Vec<Variant>, only: &str) -> Vec<Variant> {
    let parts: Vec<&str> = (only.split(',').map(str::trim))
        .filter(|p| !p.is_empty())
        .collect();
    let named = |p: &str| variants.iter().any(|v| v.name == p);
    let exact: Vec<bool> = parts.iter().map(|p| named(p)).collect();
    (variants.iter())
        .filter(|v| {
            (parts.iter().zip(&exact)).any(|(p, &exact)| {
                if exact {
                    v.name == *p
                } else {
                    v.name.contains(p)
                }
            })
        })
        .cloned()
        .collect()
}

/// R9's trends (runs named `dD-boB`), each with whether it falls as paper 004 finds:
/// the packing fraction against d at Bo = 0 and against Bo at d = 5 (Fig. 2b); the
/// strength of Q(r)'s maxima and minima against Bo at d = 2 and 5 (Fig. 4); the share of
/// vertical principal stress directions against Bo at d = 10 (Fig. 5).
pub fn r9_trends(found: &[Findings]) -> Vec<String> {
    let get = |name: &str, value: &dyn Fn(&Findings) -> Option<f64>| {
        found.iter().find(|f| f.variant == name).and_then(value)
    };
    // The runs of `names` (variant, label) that ran, at least two, and whether the
    // value falls along them.
    let trend = |quantity: &str,
                 value: &dyn Fn(&Findings) -> Option<f64>,
                 what: &str,
                 names: Vec<(String, String)>| {
        let ran: Vec<(String, f64)> = (names.into_iter())
            .filter_map(|(n, label)| get(&n, value).map(|v| (label, v)))
            .collect();
        (ran.len() >= 2).then(|| {
            let falls = ran.windows(2).all(|w| w[1].1 < w[0].1);
            let listed: Vec<String> = ran.iter().map(|(l, v)| format!("{l}: {v:.3}")).collect();
            format!(
                "{quantity} against {what}: {} ({})",
                listed.join(", "),
                if falls {
                    "falls, as in paper 004"
                } else {
                    "does not fall throughout"
                }
            )
        })
    };
    let phi = |f: &Findings| Some(f.packing_fraction_lower_half);
    let order = |f: &Findings| f.q_order;
    let vertical = |f: &Findings| Some(f.vertical_stress_fraction);
    // Reduced: Bo = 0, 10², 10³, 10⁴ at d = 5; full: 0, 10³, 10⁴ (those that ran).
    let bonds = |d: u32, list: &[u32]| -> Vec<(String, String)> {
        (list.iter())
            .map(|b| (format!("d{d}-bo{b}"), format!("Bo = {b}")))
            .collect()
    };
    let aspects =
        (([2, 5, 10].iter()).map(|d| (format!("d{d}-bo0"), format!("d = {d}")))).collect();
    let mut out: Vec<String> = [
        trend("packing fraction", &phi, "d at Bo = 0", aspects),
        trend(
            "packing fraction",
            &phi,
            "Bo at d = 5",
            bonds(5, &[0, 100, 1000, 10000]),
        ),
        trend(
            "mean |Q(r)|",
            &order,
            "Bo at d = 2",
            bonds(2, &[0, 1000, 10000]),
        ),
        trend(
            "mean |Q(r)|",
            &order,
            "Bo at d = 5",
            bonds(5, &[0, 100, 1000, 10000]),
        ),
        trend(
            "share of principal stress directions within 20° of the vertical",
            &vertical,
            "Bo at d = 10",
            bonds(10, &[0, 1000, 10000]),
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    // f(θ): without cohesion long rods lie flat; cohesion makes f(θ) flatter (paper 004
    // Fig. 3): fewer lying, more standing.
    for f in found.iter().filter(|f| f.variant.starts_with('d')) {
        let deepest = f.stress_depth.last().map_or(0.0, |p| p.0);
        let fit = match f.janssen {
            Some(j) => format!(
                "sigma_m = {:.3} rho g W, h_s = {:.2} W (slabs to {deepest:.2} W deep)",
                j.sigma_m, j.h_s
            ),
            None => format!("none (slabs to {deepest:.2} W deep; the fit needs 0.5 W)"),
        };
        let q = match (f.q_contact, f.q_order) {
            (Some(c), Some(o)) => format!("{c:.2} at contact, mean |Q| {o:.3}"),
            _ => "none".to_string(),
        };
        out.push(format!(
            "{}: {:.0} % of the rods lie within 20° of the horizontal, {:.0} % stand within 20° of the vertical (uniform: 22 % each); principal stress within 20° of the vertical: {:.0} % of the rods; Q(r): {q}; Janssen fit of the mean stress: {fit}",
            f.variant,
            100.0 * f.lying_fraction,
            100.0 * f.standing_fraction,
            100.0 * f.vertical_stress_fraction,
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::findings::{orientation_fraction, q_bins};
    use super::*;
    use std::f64::consts::PI;

    fn run(name: &str, profile: Vec<(f64, f64)>) -> Findings {
        Findings {
            variant: name.into(),
            grains: 1,
            time: 0.0,
            repose_left_deg: 0.0,
            repose_right_deg: 0.0,
            stress_ratio_interior_row1: 0.0,
            base_szz_centre: 0.0,
            base_szz_max: 0.0,
            base_dip: 0.0,
            row1_szz_centre: 0.0,
            row1_szz_max: 0.0,
            row1_dip: 0.0,
            row1_profile: profile,
            coordination_interior: 4.0,
            packing_fraction_lower_half: 0.0,
            kinetic_over_elastic: None,
            base_load_centre_mg: None,
            base_load_left_max_mg: None,
            base_load_right_max_mg: None,
            lying_fraction: 0.0,
            standing_fraction: 0.0,
            stress_depth: Vec::new(),
            janssen: None,
            vertical_stress_fraction: 0.0,
            q_contact: None,
            q_order: None,
            cost: None,
        }
    }

    #[test]
    fn only_picks_a_name_exactly_or_else_every_name_containing_it() {
        let names = |only: &str| -> Vec<String> {
            let all = variants("R9", Size::Full).unwrap();
            pick(all, only).into_iter().map(|v| v.name).collect()
        };
        assert_eq!(names("d5-bo1000"), ["d5-bo1000"]);
        assert_eq!(names("d10"), ["d10-bo0", "d10-bo1000", "d10-bo10000"]);
        assert_eq!(names(" d2-bo0, d5-bo1000 ,"), ["d2-bo0", "d5-bo1000"]);
        // A part that names no variant matches by containment: Bo = 10³ and 10⁴.
        assert_eq!(names("bo1000").len(), 6);
        assert!(names("d7").is_empty() && names(",").is_empty());
    }

    #[test]
    fn r9_with_fewer_rods_sizes_the_box_and_the_run_for_them() {
        let set = |v: &Variant, key: &str| -> String {
            let hit = v.overrides.iter().rev().find(|o| o.starts_with(key));
            hit.unwrap_or_else(|| panic!("{}: no {key}", v.name))[key.len()..].to_string()
        };
        let find = |all: &[Variant], name: &str| all.iter().find(|v| v.name == name).cloned();
        let full = variants("R9", Size::Full).unwrap();
        let some = variants("R9", Size::Rods(1000)).unwrap();
        assert_eq!(some.len(), full.len());
        for (name, top) in [("d10-bo0", "130]"), ("d10-bo10000", "256]")] {
            let v = find(&some, name).unwrap();
            assert_eq!(set(&v, "particles[0].count="), "1000");
            // Fed at ~20 a second, then 50 time units to settle.
            assert_eq!(set(&v, "stop.time="), "100");
            // 1000 rods of area 9 + π/4 over 200 widths at a packing fraction of 0.7
            // (0.25 with cohesion), plus 4 d + 20 above them.
            assert_eq!(set(&v, "walls[1].to="), format!("[-100,{top}"));
        }
        let v = find(&full, "d10-bo0").unwrap();
        assert_eq!(set(&v, "particles[0].count="), "6000");
        assert_eq!(set(&v, "stop.time="), "800");
        assert!(matches!(
            variants("R4", Size::Rods(1000)),
            Err(ReproductionError::NotRods(..))
        ));
        assert!(variants("R9", Size::Rods(9)).is_err());
    }

    #[test]
    fn r9_trends_say_whether_the_packing_fraction_falls() {
        let phi = |name: &str, p: f64| Findings {
            packing_fraction_lower_half: p,
            ..run(name, Vec::new())
        };
        let found = [
            phi("d2-bo0", 0.85),
            phi("d5-bo0", 0.82),
            phi("d10-bo0", 0.74),
            phi("d5-bo100", 0.78),
            phi("d5-bo1000", 0.80),
        ];
        let t = r9_trends(&found);
        assert_eq!(t.len(), 2 + found.len());
        assert!(t[0].contains("d = 10: 0.740") && t[0].contains("falls, as in paper 004"));
        assert!(t[1].contains("does not fall throughout"), "{}", t[1]);
        // A run that is missing leaves its trend out.
        assert_eq!(r9_trends(&found[..3]).len(), 1 + 3);
        // f(θ) uniform over 18 bins: 4 of them lie within 20° of the horizontal.
        let uniform: Vec<(f64, f64)> = (0..18)
            .map(|k| ((k as f64 + 0.5) * PI / 18.0, 1.0 / PI))
            .collect();
        let lying = orientation_fraction(&uniform, |t| t.min(PI - t) < 20f64.to_radians());
        assert!((lying - 4.0 / 18.0).abs() < 1e-12, "{lying}");
        assert!(
            variants("R9", Size::Reduced).unwrap().len() == 8
                && variants("R9", Size::Full).unwrap().len() == 9
        );
    }

    #[test]
    fn r9_trends_follow_q_and_the_principal_directions() {
        let f = |name: &str, q: Option<f64>, vertical: f64| Findings {
            q_contact: q,
            q_order: q,
            vertical_stress_fraction: vertical,
            ..run(name, Vec::new())
        };
        let found = [
            f("d2-bo0", Some(0.30), 0.5),
            f("d2-bo1000", Some(0.12), 0.3),
            f("d5-bo0", Some(0.20), 0.4),
            f("d5-bo10000", Some(0.25), 0.4),
            f("d10-bo0", None, 0.6),
            f("d10-bo10000", None, 0.25),
        ];
        let t = r9_trends(&found);
        let line = |start: &str| {
            (t.iter().find(|l| l.starts_with(start)))
                .unwrap_or_else(|| panic!("no {start}: {t:?}"))
                .clone()
        };
        let d2 = line("mean |Q(r)| against Bo at d = 2");
        assert!(
            d2.contains("Bo = 1000: 0.120") && d2.contains("falls, as in"),
            "{d2}"
        );
        let d5 = line("mean |Q(r)| against Bo at d = 5");
        assert!(d5.contains("does not fall throughout"), "{d5}");
        let d10 = line("share of principal stress directions within 20° of the vertical");
        assert!(
            d10.contains("Bo = 10000: 0.250") && d10.contains("falls, as in"),
            "{d10}"
        );
        let one = line("d2-bo0:");
        assert!(
            one.contains("vertical: 50 %") && one.contains("0.30 at contact, mean |Q| 0.300"),
            "{one}"
        );
        assert!(line("d10-bo0:").contains("Q(r): none"));
        // Q(r)'s bins with too few pairs do not count.
        let q = [
            (0.5, 0.9, Q_PAIRS - 1),
            (1.0, 0.4, Q_PAIRS),
            (1.5, -0.2, 500),
        ];
        assert_eq!(q_bins(&q).collect::<Vec<_>>(), vec![0.4, -0.2]);
    }

    #[test]
    fn comparisons_measure_profiles_against_each_other() {
        // b is a 10 % lower and shifted by half a window: compared at a's windows it
        // differs by 0.1 of a's maximum at the top, and by the interpolation between.
        let a = run("a", vec![(-0.2, 0.5), (0.0, 1.0), (0.2, 0.5)]);
        let b = run(
            "b",
            vec![(-0.3, 0.45), (-0.1, 0.9), (0.1, 0.9), (0.3, 0.45)],
        );
        assert!(comparisons("R4", &[a.clone(), b.clone()]).is_empty());
        let c = comparisons("R1", &[a, b]);
        assert_eq!(c.len(), 1);
        // At −0.2 b is 0.675, at 0 0.9, at 0.2 0.675: differences 0.175, 0.1, 0.175.
        assert!(
            (c[0].row1_szz_max_difference - 0.175).abs() < 1e-12,
            "{c:?}"
        );
        assert!(
            (c[0].row1_szz_mean_difference - 0.15).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn seeds_average_into_one_profile_per_setting() {
        // Two seeds whose slopes run opposite ways average into a flat profile; the other
        // setting's single seed is its own average.
        let found = vec![
            run("a-seed1", vec![(-0.2, 1.0), (0.0, 0.5), (0.2, 0.0)]),
            run("a-seed2", vec![(-0.2, 0.0), (0.0, 0.5), (0.2, 1.0)]),
            run("b-seed1", vec![(-0.2, 0.2), (0.0, 1.0), (0.2, 0.2)]),
        ];
        let av = seed_averages(&found);
        assert_eq!(av.len(), 2);
        assert_eq!((av[0].setting.as_str(), av[0].seeds), ("a", 2));
        for (p, x) in av[0].profile.iter().zip([-0.2, 0.0, 0.2]) {
            assert!(
                (p.0 - x).abs() < 1e-15 && (p.1 - 0.5).abs() < 1e-12,
                "{p:?}"
            );
        }
        assert!((av[1].row1_szz_apex - 1.0).abs() < 1e-12 && av[1].row1_dip.abs() < 1e-12);
    }
}
