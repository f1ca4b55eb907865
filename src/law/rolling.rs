//! Rolling resistance at disk contacts (issue 43 item 1): a torque that opposes the
//! relative rolling of the two disks, the standard way to give round grains some of the
//! shape effects of real ones (LIGGGHTS `rolling_friction cdt`, LAMMPS `pair granular
//! ... rolling`).
//!
//! The constant directional torque (model A of Ai, Chen, Rotter and Ooi, Powder Technol.
//! 206 (2011) 269, their eq. 6): M_r = −μ_r R* f_n ω_r / |ω_r|, with ω_r = ω_i − ω_j the
//! relative spin (ω_i against a wall), R* = R_i R_j / (R_i + R_j) the rolling radius (R_i
//! against a wall) and f_n ≥ 0 the normal force. Applied as it stands, an explicit
//! integrator flips its sign every step once a contact stops rolling (Ai et al. sec.
//! 2.1): here it is limited near rest to a tenth of the torque that would bring ω_r to
//! rest within the step, 0.1 |ω_r| I*/dt with 1/I* = 1/I_i + 1/I_j (a fixed particle
//! or a wall counted as infinitely heavy; `AT_REST`), so a contact that has stopped
//! rolling comes to rest instead of chattering. What the model cannot do is hold a
//! torque below μ_r R* f_n still: there it acts as that viscous torque, and the
//! contact creeps at ω_r ≈ 10 τ dt / I*.
//!
//! The elastic–plastic spring–dashpot (model C of Ai et al., their eq. 9–16; LIGGGHTS
//! `epsd`/`epsd3`, LAMMPS `rolling sds`) holds such a torque: a rolling spring
//! M_k ← M_k − k_r ω_r dt kept in the contact's history like the tangential spring,
//! limited to the same μ_r R* f_n, with a dashpot −C_r ω_r while the spring holds
//! (none at full mobilisation, Ai et al.'s f = 0), C_r = η_r 2 sqrt(I_r k_r) and
//! 1/I_r = 1/(I_i + m_i R_i²) + 1/(I_j + m_j R_j²) (their eq. 16: each disk about the
//! contact point). The angular stiffness is k_r = k_roll R*², k_roll a stiffness per
//! unit of rolled length R* θ_r (LAMMPS `k_roll`); Ai et al.'s eq. 13 (and LIGGGHTS
//! `epsd`) take k_roll = 2.25 μ_r² k_n.

use serde::{Deserialize, Serialize};

/// The scene's `rolling` block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollingSpec {
    /// Which model: `constant_torque` (default) or `spring_dashpot`.
    #[serde(default)]
    pub model: RollingModel,
    /// The coefficient of rolling resistance μ_r (dimensionless: the lever of the normal
    /// force is μ_r R*).
    pub mu_r: f64,
    /// `spring_dashpot` only: k_roll, the rolling spring's force per unit of rolled
    /// length (N/m, like k_n; the angular stiffness is k_roll R*²). Default 2.25 μ_r² k_n
    /// (Ai et al. eq. 13) under a law with one k_n; required under the others.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// `spring_dashpot` only: η_r, the dashpot's fraction of critical damping
    /// (default 0.3, Ai et al.'s choice).
    #[serde(default)]
    pub damping: Option<f64>,
    /// Pairs of materials with values of their own (LIGGGHTS' per-type-pair
    /// `coefficientRollingFriction`): each key left out takes the block's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<RollingPair>,
}

/// A pair of materials whose rolling resistance differs from the block's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollingPair {
    /// Two material names; `"walls"` for the wall segments.
    pub materials: [String; 2],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_r: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
}

impl RollingSpec {
    /// The block's values with those a pair gives in their place (`pair` None: the
    /// block's own).
    pub fn with(&self, pair: Option<&RollingPair>) -> RollingSpec {
        let Some(p) = pair else {
            return RollingSpec {
                pairs: Vec::new(),
                ..self.clone()
            };
        };
        RollingSpec {
            model: self.model,
            mu_r: p.mu_r.unwrap_or(self.mu_r),
            stiffness: p.stiffness.or(self.stiffness),
            damping: p.damping.or(self.damping),
            pairs: Vec::new(),
        }
    }

    /// Each set of values the block gives with the key it is given at: the block's own,
    /// then each pair's.
    pub fn entries(&self) -> Vec<(String, RollingSpec)> {
        let mut out = vec![("rolling".to_string(), self.with(None))];
        for (k, p) in self.pairs.iter().enumerate() {
            out.push((format!("rolling.pairs[{k}]"), self.with(Some(p))));
        }
        out
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollingModel {
    /// Model A of Ai et al. (2011): |M_r| = μ_r R* f_n against the relative spin.
    #[default]
    ConstantTorque,
    /// Model C of Ai et al. (2011): a rolling spring and dashpot, plastic at μ_r R* f_n.
    SpringDashpot,
}

/// k_roll / (μ_r² k_n) when the scene does not give `stiffness` (Ai et al. eq. 13).
pub const DEFAULT_STIFFNESS_FACTOR: f64 = 2.25;

/// η_r when the scene does not give `damping` (Ai et al. sec. 2.3).
pub const DEFAULT_DAMPING: f64 = 0.3;

/// The resolved rolling resistance of a run: μ_r (0 for none), and for the spring model
/// k_roll > 0 and η_r (k_roll = 0: the constant torque).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rolling {
    pub mu_r: f64,
    pub k_roll: f64,
    pub eta_r: f64,
}

impl Rolling {
    pub const NONE: Rolling = Rolling {
        mu_r: 0.0,
        k_roll: 0.0,
        eta_r: 0.0,
    };

    /// The scene's block resolved; `k_n`: the law's one normal stiffness, if it has one
    /// (the spring's default). None: a spring without a stiffness to take (the scene's
    /// validation names the key).
    pub fn of(spec: Option<&RollingSpec>, k_n: Option<f64>) -> Option<Rolling> {
        let Some(s) = spec else {
            return Some(Rolling::NONE);
        };
        Some(match s.model {
            RollingModel::ConstantTorque => Rolling {
                mu_r: s.mu_r,
                ..Rolling::NONE
            },
            RollingModel::SpringDashpot => Rolling {
                mu_r: s.mu_r,
                k_roll: match s.stiffness {
                    Some(k) => k,
                    None => DEFAULT_STIFFNESS_FACTOR * s.mu_r * s.mu_r * k_n?,
                },
                eta_r: s.damping.unwrap_or(DEFAULT_DAMPING),
            },
        })
    }

    pub fn is_none(&self) -> bool {
        self.mu_r == 0.0
    }

    /// Whether contacts keep a rolling spring (the spring–dashpot model).
    pub fn has_spring(&self) -> bool {
        !self.is_none() && self.k_roll > 0.0
    }
}

/// The rolling resistance of every pair of materials, like the material form's
/// `PairTable` (src/law/restitution.rs): `side` = materials + 1, the last row and column
/// for the walls; side 1 when every pair has the same. Symmetric; one model for all
/// (the scene's `rolling.model`).
#[derive(Clone, Debug, PartialEq)]
pub struct RollingTable {
    pub side: usize,
    pub pairs: Vec<Rolling>,
    /// Whether no pair resists rolling, and whether some pair keeps a spring: asked at
    /// every contact, so kept.
    none: bool,
    spring: bool,
}

impl Default for RollingTable {
    fn default() -> Self {
        RollingTable::uniform(Rolling::NONE)
    }
}

impl RollingTable {
    pub fn uniform(r: Rolling) -> Self {
        RollingTable::new(1, vec![r])
    }

    fn new(side: usize, pairs: Vec<Rolling>) -> Self {
        RollingTable {
            side,
            none: pairs.iter().all(Rolling::is_none),
            spring: pairs.iter().any(Rolling::has_spring),
            pairs,
        }
    }

    /// The scene's block resolved for its materials (`materials`: their names in index
    /// order); `k_n` as in [`Rolling::of`]. None: a spring without a stiffness, or a
    /// pair naming an unknown material (the scene's validation names the key).
    pub fn of(
        spec: Option<&RollingSpec>,
        materials: &[String],
        k_n: Option<f64>,
    ) -> Option<RollingTable> {
        let Some(s) = spec else {
            return Some(RollingTable::default());
        };
        let all = Rolling::of(Some(&s.with(None)), k_n)?;
        if s.pairs.is_empty() {
            return Some(RollingTable::uniform(all));
        }
        let side = materials.len() + 1;
        let mut pairs = vec![all; side * side];
        for p in &s.pairs {
            let r = Rolling::of(Some(&s.with(Some(p))), k_n)?;
            let a = material_slot(materials, &p.materials[0])?;
            let b = material_slot(materials, &p.materials[1])?;
            pairs[a * side + b] = r;
            pairs[b * side + a] = r;
        }
        Some(RollingTable::new(side, pairs))
    }

    /// The values of a contact between materials a and b (b = `walls()`: a wall).
    #[inline(always)]
    pub fn get(&self, a: u32, b: u32) -> &Rolling {
        if self.side == 1 {
            &self.pairs[0]
        } else {
            &self.pairs[a as usize * self.side + b as usize]
        }
    }

    /// The index of the walls' row (the material index a wall contact looks up).
    pub fn walls(&self) -> u32 {
        self.side as u32 - 1
    }

    /// Whether no pair resists rolling.
    pub fn is_none(&self) -> bool {
        self.none
    }

    /// Whether contacts keep a rolling spring (some pair under the spring–dashpot model).
    pub fn has_spring(&self) -> bool {
        self.spring
    }

    /// What `talus check` says of it: the model, and the values of each pair of
    /// materials (`materials`: their names in index order); nothing without.
    pub fn describe(&self, materials: &[String]) -> Vec<String> {
        if self.is_none() {
            return Vec::new();
        }
        let values = |r: &Rolling| {
            if r.is_none() {
                "none".to_string()
            } else if self.has_spring() {
                format!(
                    "μ_r = {}, k_roll = {:.4e}, η_r = {}",
                    r.mu_r, r.k_roll, r.eta_r
                )
            } else {
                format!("μ_r = {}", r.mu_r)
            }
        };
        let model = if self.has_spring() {
            "a rolling spring k_roll R*² with a dashpot at η_r of critical, plastic at μ_r R* f_n (Ai et al. 2011 model C)"
        } else {
            "constant torque μ_r R* f_n against the relative spin (Ai et al. 2011 model A)"
        };
        let head = format!(
            "rolling resistance at disk contacts: {model} (R* = R_i R_j/(R_i + R_j), R_i at a wall; src/law/rolling.rs)"
        );
        if self.side == 1 {
            return vec![format!("{head}, {}", values(&self.pairs[0]))];
        }
        let name = |k: usize| {
            materials
                .get(k)
                .cloned()
                .unwrap_or_else(|| super::spec::WALLS.to_string())
        };
        let mut out = vec![format!("{head}, per pair of materials (rolling.pairs):")];
        for a in 0..self.side - 1 {
            for b in a..self.side {
                let r = self.get(a as u32, b as u32);
                out.push(format!("  {}–{}: {}", name(a), name(b), values(r)));
            }
        }
        out
    }
}

/// The index of a material named in `rolling.pairs` (`materials.len()` for "walls").
pub fn material_slot(materials: &[String], name: &str) -> Option<usize> {
    if name == super::spec::WALLS {
        return Some(materials.len());
    }
    materials.iter().position(|m| m == name)
}

/// The part of the torque that would stop the relative spin within one step which the
/// rolling torque may take at most: near rest it then acts as a viscous torque of
/// AT_REST I*/dt, which Gear's corrector (velocity-dependent forces are evaluated at the
/// predicted velocity) integrates stably only well below 1. Measured, a disk rolling to
/// a stop on a floor: at 1 (the whole torque that stops it) Gear locks into a two-step
/// cycle that creeps at 1.2·10⁻⁴ √(g d), as does the torque without any limit under
/// both integrators; at 0.1 it comes to rest (speed 10⁻²⁰ two time units later) and
/// stops 10⁻⁴ of the distance short of the unlimited torque's stop.
pub const AT_REST: f64 = 0.1;

/// The rolling torque on disk i (j takes its opposite), from the relative spin
/// `spin` = ω_i − ω_j, the rolling radius `r_roll` (R*), the normal force `f_n` (a pull
/// resists nothing), the inverse inertias (0 for a fixed particle or a wall) and dt.
/// Twin of `rolling_torque` in shaders/contact_forces.wgsl.
#[inline(always)]
pub fn rolling_torque(
    mu_r: f64,
    spin: f64,
    r_roll: f64,
    f_n: f64,
    inv_inertia_sum: f64,
    dt: f64,
) -> f64 {
    if !(inv_inertia_sum > 0.0) || spin == 0.0 {
        return 0.0;
    }
    // Ai et al. (2011) eq. 6, limited near rest (`AT_REST`).
    let full = mu_r * r_roll * f_n.max(0.0);
    let near_rest = AT_REST * spin.abs() / (inv_inertia_sum * dt);
    -full.min(near_rest).copysign(spin)
}

/// The spring–dashpot rolling torque on disk i (j takes its opposite) and the rolling
/// spring after the step (Ai et al. 2011 eq. 9–16), from the spring before it, the
/// relative spin `spin` = ω_i − ω_j, the rolling radius R*, the normal force (a pull
/// resists nothing) and 1/I_r (`rolling_inertia_inv` summed over the disks; 0: both
/// fixed, nothing to resist). Twin of `rolling_spring` in shaders/contact_forces.wgsl.
#[inline(always)]
pub fn rolling_spring(
    r: &Rolling,
    spring: f64,
    spin: f64,
    r_roll: f64,
    f_n: f64,
    inv_rolling_inertia: f64,
    dt: f64,
) -> (f64, f64) {
    if !(inv_rolling_inertia > 0.0) {
        return (0.0, 0.0);
    }
    let k_r = r.k_roll * r_roll * r_roll;
    // Eq. 11: the full mobilisation torque, the spring's plastic limit.
    let limit = r.mu_r * r_roll * f_n.max(0.0);
    // Eq. 9: the spring follows the relative rotation of the step.
    let m_k = spring - k_r * spin * dt;
    if m_k.abs() >= limit {
        // Full mobilisation: the spring slips at its limit, no damping (f = 0).
        let m_k = if m_k == 0.0 { 0.0 } else { limit.copysign(m_k) };
        return (m_k, m_k);
    }
    // Eq. 14–15: the dashpot at η_r of critical damping about the contact point.
    let c_r = r.eta_r * 2.0 * (k_r / inv_rolling_inertia).sqrt();
    (m_k - c_r * spin, m_k)
}

/// 1/(I + m R²): a disk's part of 1/I_r (its inertia about the contact point, Ai et al.
/// eq. 16); 0 for a fixed disk.
#[inline(always)]
pub fn rolling_inertia_inv(inertia: f64, mass: f64, radius: f64, fixed: bool) -> f64 {
    if fixed {
        0.0
    } else {
        1.0 / (inertia + mass * radius * radius)
    }
}

/// R* = R_i R_j / (R_i + R_j) of two disks, R_i against a wall (`r_j` None).
#[inline(always)]
pub fn rolling_radius(r_i: f64, r_j: Option<f64>) -> f64 {
    match r_j {
        Some(r_j) => r_i * r_j / (r_i + r_j),
        None => r_i,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_torque_opposes_the_spin_at_its_full_size_while_rolling() {
        let m = rolling_torque(0.1, 2.0, 0.5, 10.0, 1.0, 1e-4);
        assert_eq!(m, -0.1 * 0.5 * 10.0);
        let m = rolling_torque(0.1, -2.0, 0.5, 10.0, 1.0, 1e-4);
        assert_eq!(m, 0.1 * 0.5 * 10.0);
    }

    #[test]
    fn near_rest_it_only_stops_the_spin_and_a_pull_resists_nothing() {
        // 1e-6 rad/s stopped in one step of 1e-4 with 1/I* = 2 needs 5e-3, of which it
        // takes AT_REST.
        let m = rolling_torque(0.1, 1e-6, 0.5, 10.0, 2.0, 1e-4);
        assert!((m + AT_REST * 1e-6 / (2.0 * 1e-4)).abs() < 1e-18, "{m}");
        assert_eq!(rolling_torque(0.1, 1.0, 0.5, -3.0, 1.0, 1e-4), 0.0);
        assert_eq!(rolling_torque(0.1, 0.0, 0.5, 3.0, 1.0, 1e-4), 0.0);
        // Both fixed: nothing to resist.
        assert_eq!(rolling_torque(0.1, 1.0, 0.5, 3.0, 0.0, 1e-4), 0.0);
    }

    fn spring(k_roll: f64) -> Rolling {
        Rolling {
            mu_r: 0.1,
            k_roll,
            eta_r: 0.3,
        }
    }

    #[test]
    fn the_spring_winds_up_against_the_spin_and_slips_at_its_limit() {
        let r = spring(100.0);
        // k_r = 100 · 0.5² = 25; one step of spin 2 at dt 1e-3 winds it by −0.05.
        let (m, s) = rolling_spring(&r, 0.0, 2.0, 0.5, 10.0, 1.0, 1e-3);
        assert!((s + 25.0 * 2.0 * 1e-3).abs() < 1e-15, "{s}");
        // The dashpot 0.3 · 2 sqrt(25 / 1) = 3 against the spin of 2.
        assert!((m - (s - 3.0 * 2.0)).abs() < 1e-12, "{m}");
        // Beyond μ_r R* f_n = 0.5 the spring slips, without the dashpot.
        let (m, s) = rolling_spring(&r, -0.49, 2.0, 0.5, 10.0, 1.0, 1e-3);
        assert_eq!((m, s), (-0.5, -0.5));
        // A pull resists nothing; both disks fixed, nothing to resist.
        assert_eq!(
            rolling_spring(&r, -0.3, 2.0, 0.5, -1.0, 1.0, 1e-3),
            (0.0, 0.0)
        );
        assert_eq!(
            rolling_spring(&r, -0.3, 2.0, 0.5, 10.0, 0.0, 1e-3),
            (0.0, 0.0)
        );
    }

    #[test]
    fn the_default_stiffness_is_ai_et_al_and_needs_a_k_n() {
        let spec = RollingSpec {
            model: RollingModel::SpringDashpot,
            mu_r: 0.2,
            stiffness: None,
            damping: None,
            pairs: Vec::new(),
        };
        let r = Rolling::of(Some(&spec), Some(1e4)).unwrap();
        assert!((r.k_roll - 2.25 * 0.04 * 1e4).abs() < 1e-9);
        assert_eq!(r.eta_r, DEFAULT_DAMPING);
        assert!(r.has_spring());
        assert_eq!(Rolling::of(Some(&spec), None), None);
        let cdt = RollingSpec {
            model: RollingModel::ConstantTorque,
            ..spec
        };
        assert!(!Rolling::of(Some(&cdt), None).unwrap().has_spring());
    }

    #[test]
    fn the_rolling_radius_is_half_the_radius_for_equal_disks() {
        assert_eq!(rolling_radius(0.5, Some(0.5)), 0.25);
        assert_eq!(rolling_radius(0.5, None), 0.5);
    }
}
