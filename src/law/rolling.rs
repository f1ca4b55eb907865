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
//! contact creeps at ω_r ≈ 10 τ dt / I*. The elastic–plastic spring–dashpot (model C),
//! which keeps a rolling spring in the contact history and holds, is not done yet.

use serde::{Deserialize, Serialize};

/// The scene's `rolling` block.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollingSpec {
    /// Which model (only `constant_torque` so far).
    #[serde(default)]
    pub model: RollingModel,
    /// The coefficient of rolling resistance μ_r (dimensionless: the lever of the normal
    /// force is μ_r R*).
    pub mu_r: f64,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollingModel {
    /// Model A of Ai et al. (2011): |M_r| = μ_r R* f_n against the relative spin.
    #[default]
    ConstantTorque,
}

/// The resolved rolling resistance of a run: μ_r, 0 for none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rolling {
    pub mu_r: f64,
}

impl Rolling {
    pub const NONE: Rolling = Rolling { mu_r: 0.0 };

    pub fn of(spec: Option<&RollingSpec>) -> Rolling {
        spec.map_or(Rolling::NONE, |s| Rolling { mu_r: s.mu_r })
    }

    pub fn is_none(&self) -> bool {
        self.mu_r == 0.0
    }
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

    #[test]
    fn the_rolling_radius_is_half_the_radius_for_equal_disks() {
        assert_eq!(rolling_radius(0.5, Some(0.5)), 0.25);
        assert_eq!(rolling_radius(0.5, None), 0.5);
    }
}
