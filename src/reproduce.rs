//! `talus reproduce ID`: the scenes of SPEC 6 (R1–R8) with the measurements that decide
//! whether each reproduces its paper's result. The scene files are built in, so the
//! command runs anywhere; reduced forms by default, the paper's sizes with `--full`.

use crate::analyze::Analysis;
use serde::Serialize;

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

const R1: &str = include_str!("../scenes/r1_pile.json");
const R1_REDUCED: &str = include_str!("../scenes/r1_pile_reduced.json");
const R4: &str = include_str!("../scenes/r4_pour.json");
const R4_REDUCED: &str = include_str!("../scenes/r4_pour_reduced.json");
const R6: &str = include_str!("../scenes/r6_heap.json");
const R6_REDUCED: &str = include_str!("../scenes/r6_heap_reduced.json");
const R7_MONO: &str = include_str!("../scenes/r7_wedge_mono.json");
const R7_MEDIUM: &str = include_str!("../scenes/r7_wedge_medium.json");
const R7_POLY: &str = include_str!("../scenes/r7_wedge_poly.json");
const R7_LAYERED: &str = include_str!("../scenes/r7_layered_medium.json");
const R8: &str = include_str!("../scenes/r8_polygon_pile.json");
const R8_REDUCED: &str = include_str!("../scenes/r8_polygon_pile_reduced.json");

/// What R1–R9 reproduce (SPEC 6), in one line each.
pub fn claim(id: &str) -> &'static str {
    match id {
        "R1" => "S_xx/S_zz ≈ 1/3 in the interior of row M = 1",
        "R4" => {
            "stable heap, angle of repose 35° ± 5°, base normal force with an M profile (side maxima 20–30 % above the centre)"
        }
        "R6" => "a relaxed heap with a pressure dip visible in the principal stresses",
        "R7" => {
            "slopes near 23°, 24°, 28° (wedge) and 32° (layered); dip for polydisperse wedge heaps only"
        }
        "R8" => "stress independent of μ within fluctuations; no clear dip",
        _ => "",
    }
}

fn v(name: &str, scene: &'static str, overrides: &[&str], window: f64, row: f64) -> Variant {
    Variant {
        name: name.into(),
        scene,
        overrides: overrides.iter().map(|s| s.to_string()).collect(),
        window,
        row,
    }
}

/// The runs of reproduction `id` (R1, R4, R6, R7, R8).
pub fn variants(id: &str, full: bool) -> Result<Vec<Variant>, String> {
    // Reduced R7: the full scenes with fewer grains (a tenth), stopping accordingly.
    let r7 = |name: &str, scene: &'static str, count: u32, rate: f64| {
        let pour = count as f64 / rate;
        let o = if full {
            Vec::new()
        } else {
            vec![
                format!("particles[0].count={}", count / 10),
                format!("stop.time={}", pour / 10.0 + 10.0),
                format!("stop.not_before={}", pour / 10.0),
            ]
        };
        Variant {
            name: name.into(),
            scene,
            overrides: o,
            window: 14.0,
            row: 2.0,
        }
    };
    Ok(match id {
        "R1" => vec![v(
            "pile",
            if full { R1 } else { R1_REDUCED },
            &[],
            if full { 14.0 } else { 6.0 },
            1.0,
        )],
        "R4" => vec![v(
            "pour",
            if full { R4 } else { R4_REDUCED },
            &[],
            14.0,
            1.0,
        )],
        "R6" => vec![v(
            "heap",
            if full { R6 } else { R6_REDUCED },
            &[],
            14.0,
            2.0,
        )],
        "R7" if !full => {
            return Err(
                "R7 has no reduced form: with a tenth of the grains the wedge heaps spread \
                        into a layer a few grains high (tried); run `talus reproduce R7 --full`"
                    .into(),
            );
        }
        "R7" => vec![
            r7("wedge-mono", R7_MONO, 2600, 13.333333333333334),
            r7("wedge-medium", R7_MEDIUM, 3000, 13.333333333333334),
            r7("wedge-poly", R7_POLY, 3000, 13.333333333333334),
            {
                let mut l = v("layered-medium", R7_LAYERED, &[], 14.0, 2.0);
                if !full {
                    l.overrides = vec![
                        "particles[0].base_width=0.2".into(),
                        "stop.time=25".into(),
                        "stop.not_before=20".into(),
                    ];
                }
                l
            },
        ],
        "R8" => ["0", "0.3", "0.6"]
            .iter()
            .map(|mu| {
                let mut x = v(
                    &format!("mu-{mu}"),
                    if full { R8 } else { R8_REDUCED },
                    &[],
                    if full { 14.0 } else { 6.0 },
                    1.0,
                );
                x.overrides = vec![format!("contact.mu={mu}")];
                x
            })
            .collect(),
        "R2" | "R3" | "R5" | "R9" => {
            return Err(format!(
                "{id}: its scenes are not built yet (see the README's status)"
            ));
        }
        _ => return Err(format!("unknown reproduction `{id}`: R1, R4, R6, R7 or R8")),
    })
}

/// The numbers a reproduction is judged by, from one variant's analysis.
#[derive(Clone, Debug, Serialize)]
pub struct Findings {
    pub variant: String,
    pub grains: usize,
    pub time: f64,
    pub repose_left_deg: f64,
    pub repose_right_deg: f64,
    /// S_xx/S_zz averaged over the windows of row 1 with |X − 1/2| ≤ 0.2.
    pub stress_ratio_interior_row1: f64,
    /// The base row's S_zz: at the centre (X nearest 1/2), its maximum, and the dip
    /// (max − centre)/max (0 when the centre is the maximum).
    pub base_szz_centre: f64,
    pub base_szz_max: f64,
    pub base_dip: f64,
    pub coordination_interior: f64,
    pub packing_fraction_lower_half: f64,
    pub kinetic_over_elastic: Option<f64>,
}

pub fn findings(variant: &str, a: &Analysis) -> Findings {
    let s = &a.summary;
    let sc = s.stress_scale;
    let interior: Vec<f64> = a
        .windows
        .iter()
        .filter(|w| w.row == 1 && w.particles > 0)
        .filter(|w| ((w.x - s.outline.left) / s.outline.width - 0.5).abs() <= 0.2)
        .filter(|w| w.sigma.zz != 0.0)
        .map(|w| w.sigma.xx / w.sigma.zz)
        .collect();
    let base: Vec<(f64, f64)> = a
        .windows
        .iter()
        .filter(|w| w.row == 0)
        .map(|w| ((w.x - s.outline.left) / s.outline.width, w.sigma.zz / sc))
        .collect();
    let centre = base
        .iter()
        .min_by(|p, q| (p.0 - 0.5).abs().total_cmp(&(q.0 - 0.5).abs()))
        .map_or(f64::NAN, |p| p.1);
    let max = base.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    Findings {
        variant: variant.into(),
        grains: s.grains,
        time: s.time,
        repose_left_deg: s.repose_left.angle_deg,
        repose_right_deg: s.repose_right.angle_deg,
        stress_ratio_interior_row1: interior.iter().sum::<f64>() / interior.len().max(1) as f64,
        base_szz_centre: centre,
        base_szz_max: max,
        base_dip: if max > 0.0 {
            (max - centre) / max
        } else {
            f64::NAN
        },
        coordination_interior: s.coordination.interior,
        packing_fraction_lower_half: s.packing_fraction_lower_half,
        kinetic_over_elastic: s.energy.as_ref().map(|e| e.kinetic_over_elastic),
    }
}
