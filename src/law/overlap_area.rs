//! The overlap-area law of convex polygons, paper 000 eq. 6–7 and sec. 2.2.2 (SPEC 2.3).
//!
//! The geometry (src/overlap.rs) gives the overlap area A, the reduced arm l and the
//! chord L. The force stage passes δ = A/l (the length that plays the role of the disk
//! overlap) and its rate d(A/l)/dt ≈ L v_n / l: for a relative translation the overlap
//! area changes at exactly L v_n (v_n the approach speed across the chord), and the
//! slow change of l is neglected. Relative velocities rather than the previous step's
//! A/l keep the damping at the predicted state, where Gear evaluates every force.

use super::tangential::{coulomb_spring, spring_energy};
use super::{ContactInput, ContactOutput, clamp_non_negative};
use crate::scene::{OverlapAreaSpec, SceneError};

#[derive(Clone, Debug, PartialEq)]
pub struct OverlapArea {
    pub k_n: f64,
    /// η^n = γ^n/sqrt(m12 k^n).
    pub eta_n: f64,
    pub mu: f64,
    /// k^t = kt_ratio · k^n (paper: 2/7).
    pub k_t: f64,
    /// η^t = γ^t/sqrt(m12 k^t) (paper: 0.01).
    pub eta_t: f64,
}

/// Stiffness of a flat face-to-face contact relative to k^n for the time-step check:
/// f = k^n A/l = (k^n L/l) δ, and L/l is about 2 for the faces of polygons with 6 or
/// more corners (L ≈ the side, l ≈ half the inradius).
pub const FACE_STIFFNESS: f64 = 2.0;

impl OverlapArea {
    pub fn from_spec(s: &OverlapAreaSpec) -> Result<Self, SceneError> {
        super::spring_dashpot::positive("contact.k_n", s.k_n)?;
        super::spring_dashpot::non_negative("contact.eta_n", s.eta_n)?;
        super::spring_dashpot::non_negative("contact.mu", s.mu)?;
        super::spring_dashpot::non_negative("contact.kt_ratio", s.kt_ratio)?;
        super::spring_dashpot::non_negative("contact.eta_t", s.eta_t)?;
        Ok(Self {
            k_n: s.k_n,
            eta_n: s.eta_n,
            mu: s.mu,
            k_t: s.kt_ratio * s.k_n,
            eta_t: s.eta_t,
        })
    }

    /// c.delta = A/l, c.delta_dot = d(A/l)/dt, c.r = the penetration depth A/L (for the
    /// energy; 0 when the chord vanishes).
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let gamma_n = self.eta_n * (c.m12 * self.k_n).sqrt();
        let gamma_t = self.eta_t * (c.m12 * self.k_t).sqrt();
        let f_el = self.k_n * c.delta; // eq. 6
        let f_n = clamp_non_negative(f_el + gamma_n * c.delta_dot); // eq. 7
        let (f_t, xi) = coulomb_spring(c.history, c.v_t, c.dt, self.k_t, gamma_t, self.mu, f_n);
        // For a flat contact f_el = (k^n L/l) δ with the depth δ = A/L: energy f_el δ / 2.
        let energy = 0.5 * f_el * c.r + spring_energy(self.k_t, xi);
        ContactOutput {
            f_n,
            f_t,
            history: xi,
            energy,
        }
    }

    pub fn omega0_squared(&self, m12: f64) -> f64 {
        FACE_STIFFNESS * self.k_n / m12
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_and_friction_scale_with_the_reduced_mass() {
        let law = OverlapArea {
            k_n: 100.0,
            eta_n: 0.5,
            mu: 0.5,
            k_t: 100.0 * 2.0 / 7.0,
            eta_t: 0.01,
        };
        let c = ContactInput {
            delta: 0.01,
            delta_dot: 0.2,
            m12: 4.0,
            dt: 1e-3,
            ..Default::default()
        };
        let out = law.evaluate(&c);
        // γ^n = 0.5 sqrt(4 · 100) = 10: f = 100 · 0.01 + 10 · 0.2.
        assert!((out.f_n - 3.0).abs() < 1e-12);
        assert_eq!(out.f_t, 0.0);
    }
}
