//! What a sweep keeps of each run's analysis (`measures.json`): the scalars its
//! statistics are taken over and the profiles it averages over seeds.

use super::{SweepError, io};
use crate::analyze::Analysis;
use crate::analyze::heap::Readings;
use crate::base::files::write_atomic;
use crate::reproduce::{self, Findings};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a run's analysis gives the sweep: the scalars its statistics are taken over and
/// the profiles it averages (`measures.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Measures {
    pub grains: usize,
    #[serde(deserialize_with = "nan_if_null")]
    pub time: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub repose_left_deg: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub repose_right_deg: f64,
    /// Both flanks' mean angle by the other readings (`analyze::heap::Readings`): the
    /// middle third of the height, apex to toe, the steepest stretch; None in a
    /// measures.json from before them (or null for a flank with nothing to fit).
    #[serde(default)]
    pub repose_middle_deg: Option<f64>,
    #[serde(default)]
    pub repose_apex_toe_deg: Option<f64>,
    #[serde(default)]
    pub repose_steepest_deg: Option<f64>,
    /// Height of the heap in mean diameters.
    #[serde(deserialize_with = "nan_if_null")]
    pub height_d: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub packing_fraction_lower_half: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub coordination_interior: f64,
    /// S_xx/S_zz in the middle of row 1 (`reproduce::Findings`).
    #[serde(deserialize_with = "nan_if_null")]
    pub stress_ratio_interior_row1: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub row1_szz_centre: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub row1_szz_max: f64,
    /// Paper 001's F_B/mg on the fixed base: under the apex and the largest on each side
    /// (None without a fixed base).
    pub base_load_centre_mg: Option<f64>,
    pub base_load_left_max_mg: Option<f64>,
    pub base_load_right_max_mg: Option<f64>,
    /// The base-load dip D = mean side maximum − centre in m g, its bootstrap se, and
    /// what noise alone gives on a plateau (`analyze::spread::DipSpread`), and the z
    /// of D against the latter; None without a fixed base, or in a measures.json from
    /// before them.
    #[serde(default)]
    pub base_load_dip_mg: Option<f64>,
    #[serde(default)]
    pub base_load_dip_se_mg: Option<f64>,
    #[serde(default)]
    pub base_load_dip_null_mg: Option<f64>,
    #[serde(default)]
    pub base_load_dip_z: Option<f64>,
    /// S_zz(1) against (x − x_apex)/width (paper 000 Fig. 3).
    pub szz_row1: Vec<(f64, f64)>,
    /// F_B/mg on each fixed base particle against (x − x_apex)/d (paper 001 Fig. 3b).
    pub base_force: Vec<(f64, f64)>,
    /// Packing fraction against depth below the top, in mean diameters.
    pub packing: Vec<(f64, f64)>,
}

/// JSON has no NaN: serde_json writes it as null (a flank too short to fit an angle),
/// and this reads null back as NaN.
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A profile's points where both coordinates are numbers, in increasing x (the layers
/// come top first, so their depths decrease).
fn finite(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p
}

impl Measures {
    pub fn of(a: &Analysis) -> Self {
        let f: Findings = reproduce::findings("", a);
        let s = &a.summary;
        let d = s.mean_diameter;
        let mg = s.base_load.as_ref().map_or(f64::NAN, |b| b.grain_weight);
        Measures {
            grains: f.grains,
            time: f.time,
            repose_left_deg: f.repose_left_deg,
            repose_right_deg: f.repose_right_deg,
            repose_middle_deg: Some(Readings::mean(&s.repose_readings.middle)),
            repose_apex_toe_deg: Some(Readings::mean(&s.repose_readings.apex_toe)),
            repose_steepest_deg: Some(Readings::mean(&s.repose_readings.steepest)),
            height_d: s.outline.height / d,
            packing_fraction_lower_half: f.packing_fraction_lower_half,
            coordination_interior: f.coordination_interior,
            stress_ratio_interior_row1: f.stress_ratio_interior_row1,
            row1_szz_centre: f.row1_szz_centre,
            row1_szz_max: f.row1_szz_max,
            base_load_centre_mg: f.base_load_centre_mg,
            base_load_left_max_mg: f.base_load_left_max_mg,
            base_load_right_max_mg: f.base_load_right_max_mg,
            base_load_dip_mg: s.base_load.as_ref().map(|b| b.spread.dip / mg),
            base_load_dip_se_mg: s.base_load.as_ref().map(|b| b.spread.dip_se / mg),
            base_load_dip_null_mg: s.base_load.as_ref().map(|b| b.spread.dip_null / mg),
            base_load_dip_z: s.base_load.as_ref().map(|b| b.spread.dip_z),
            szz_row1: finite(f.row1_profile.into_iter()),
            base_force: finite(
                (a.base_forces.iter()).map(|b| ((b.x - s.outline.apex_x) / d, b.load / mg)),
            ),
            packing: finite(a.layers.iter().map(|l| (l.depth / d, l.fraction))),
        }
    }

    /// The scalars, named, in the order of the tables.
    pub fn scalars(&self) -> Vec<(&'static str, f64)> {
        let opt = |v: Option<f64>| v.unwrap_or(f64::NAN);
        let side_max = opt(self.base_load_left_max_mg).max(opt(self.base_load_right_max_mg));
        vec![
            ("grains", self.grains as f64),
            ("time", self.time),
            ("repose_left_deg", self.repose_left_deg),
            ("repose_right_deg", self.repose_right_deg),
            (
                "repose_mean_deg",
                0.5 * (self.repose_left_deg + self.repose_right_deg),
            ),
            ("repose_middle_deg", opt(self.repose_middle_deg)),
            ("repose_apex_toe_deg", opt(self.repose_apex_toe_deg)),
            ("repose_steepest_deg", opt(self.repose_steepest_deg)),
            ("height_d", self.height_d),
            (
                "packing_fraction_lower_half",
                self.packing_fraction_lower_half,
            ),
            ("coordination_interior", self.coordination_interior),
            (
                "stress_ratio_interior_row1",
                self.stress_ratio_interior_row1,
            ),
            ("row1_szz_centre", self.row1_szz_centre),
            ("row1_szz_max", self.row1_szz_max),
            ("base_load_centre_mg", opt(self.base_load_centre_mg)),
            ("base_load_side_max_mg", side_max),
            (
                "base_load_centre_over_side_max",
                opt(self.base_load_centre_mg) / side_max,
            ),
            ("base_load_dip_mg", opt(self.base_load_dip_mg)),
            ("base_load_dip_se_mg", opt(self.base_load_dip_se_mg)),
            // D less what noise gives: its seed mean is the dip without the maxima's
            // upward bias, and its se over seeds says whether the M is real.
            (
                "base_load_dip_excess_mg",
                opt(self.base_load_dip_mg) - opt(self.base_load_dip_null_mg),
            ),
            ("base_load_dip_z", opt(self.base_load_dip_z)),
        ]
    }
}

pub fn write_measures(run_dir: &Path, m: &Measures) -> Result<(), SweepError> {
    let path = run_dir.join("measures.json");
    let text = serde_json::to_string_pretty(m).expect("serialises");
    write_atomic(&path, text.as_bytes()).map_err(io(&path))
}

pub fn read_measures(run_dir: &Path) -> Result<Measures, SweepError> {
    let path = run_dir.join("measures.json");
    let damaged = |reason: String| SweepError::Damaged {
        path: path.display().to_string(),
        reason,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| damaged(e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| damaged(e.to_string()))
}
