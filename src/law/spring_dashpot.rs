//! Power-law spring-dashpot for disks, paper 000 eq. 2–5 (SPEC 2.1).

use super::tangential::{coulomb_spring, spring_energy};
use super::{ContactInput, ContactOutput, clamp_non_negative};
use crate::scene::{SceneError, SpringDashpotSpec};

#[derive(Clone, Debug, PartialEq)]
pub struct SpringDashpot {
    pub k_n: f64,
    pub nu: f64,
    pub psi: f64,
    pub delta0: f64,
    pub gamma_n: f64,
    pub k_t: f64,
    pub gamma_t: f64,
    pub mu: f64,
    pub clamp: bool,
}

/// Reference overlap, as a fraction of the diameter, at which the stiffness of a
/// nonlinear (ν ≠ 1) law is taken for the time-step check: a large overlap for DEM.
pub const REFERENCE_OVERLAP: f64 = 0.05;

impl SpringDashpot {
    pub fn from_spec(s: &SpringDashpotSpec) -> Result<Self, SceneError> {
        positive("contact.k_n", s.k_n)?;
        if !(s.nu >= 1.0 && s.nu <= 3.0) {
            return Err(SceneError::invalid(
                "contact.nu",
                format!(
                    "must be in [1, 3] (1 Hooke, 1.5 Hertz, 2 conical), got {}",
                    s.nu
                ),
            ));
        }
        if !(s.psi >= 0.0 && s.psi <= 3.0) {
            return Err(SceneError::invalid(
                "contact.psi",
                format!("must be in [0, 3], got {}", s.psi),
            ));
        }
        let delta0 = match s.delta0 {
            Some(d) => positive("contact.delta0", d)?,
            None if s.nu != 1.0 || s.psi != 0.0 => {
                return Err(SceneError::invalid(
                    "contact.delta0",
                    "is required when nu ≠ 1 or psi ≠ 0",
                ));
            }
            None => 1.0,
        };
        non_negative("contact.gamma_n", s.gamma_n)?;
        non_negative("contact.k_t", s.k_t)?;
        non_negative("contact.gamma_t", s.gamma_t)?;
        non_negative("contact.mu", s.mu)?;
        Ok(Self {
            k_n: s.k_n,
            nu: s.nu,
            psi: s.psi,
            delta0,
            gamma_n: s.gamma_n,
            k_t: s.k_t,
            gamma_t: s.gamma_t,
            mu: s.mu,
            clamp: s.clamp,
        })
    }

    #[inline(always)]
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let f_el = elastic_force(self.k_n, self.delta0, self.nu, c.delta);
        let f_diss = dissipative_force(self.gamma_n, self.delta0, self.psi, c.delta, c.delta_dot);
        let f_n = if self.clamp {
            clamp_non_negative(f_el + f_diss)
        } else {
            f_el + f_diss
        };
        let (f_t, xi) =
            coulomb_spring(c.history, c.v_t, c.dt, self.k_t, self.gamma_t, self.mu, f_n);
        let energy =
            elastic_energy(self.k_n, self.delta0, self.nu, c.delta) + spring_energy(self.k_t, xi);
        ContactOutput {
            f_n,
            f_t,
            history: xi,
            energy,
        }
    }

    /// ω0² = k/m12 with k the stiffness dF/dδ: k_n for ν = 1, else taken at an overlap of
    /// [`REFERENCE_OVERLAP`] of the diameter σ.
    pub fn omega0_squared(&self, m12: f64, sigma: f64) -> f64 {
        let k = if self.nu == 1.0 {
            self.k_n
        } else {
            self.nu * self.k_n * (REFERENCE_OVERLAP * sigma / self.delta0).powf(self.nu - 1.0)
        };
        k / m12
    }
}

/// f_el = k_n δ0 (δ/δ0)^ν, paper 000 eq. 2.
#[inline(always)]
pub fn elastic_force(k_n: f64, delta0: f64, nu: f64, delta: f64) -> f64 {
    if nu == 1.0 {
        k_n * delta
    } else {
        k_n * delta0 * (delta / delta0).powf(nu)
    }
}

/// f_diss = γ_n δ̇ (δ/δ0)^ψ, paper 000 eq. 3.
#[inline(always)]
pub fn dissipative_force(gamma_n: f64, delta0: f64, psi: f64, delta: f64, delta_dot: f64) -> f64 {
    if psi == 0.0 {
        gamma_n * delta_dot
    } else {
        gamma_n * delta_dot * (delta / delta0).powf(psi)
    }
}

/// ∫0^δ f_el = k_n δ0² (δ/δ0)^(ν+1) / (ν+1).
#[inline(always)]
pub fn elastic_energy(k_n: f64, delta0: f64, nu: f64, delta: f64) -> f64 {
    let x = delta / delta0;
    // The linear law without powf and the division: x² is what powf(x, 2) gives (both
    // correctly rounded), and halving is exact, so the value is the same to the bit.
    if nu == 1.0 {
        return k_n * delta0 * delta0 * (x * x) * 0.5;
    }
    k_n * delta0 * delta0 * x.powf(nu + 1.0) / (nu + 1.0)
}

pub(crate) fn positive(path: &str, v: f64) -> Result<f64, SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be positive, got {v}"),
        ))
    }
}

pub(crate) fn non_negative(path: &str, v: f64) -> Result<f64, SceneError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(SceneError::invalid(
            path,
            format!("must be zero or positive, got {v}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertz_energy_is_integral_of_force() {
        let (k, d0, nu, d) = (1e5, 1e-3, 1.5, 2e-5);
        let h = 1e-9;
        let fd = (elastic_energy(k, d0, nu, d + h) - elastic_energy(k, d0, nu, d - h)) / (2.0 * h);
        assert!((fd - elastic_force(k, d0, nu, d)).abs() < 1e-6 * fd);
    }

    #[test]
    fn normal_force_never_attracts() {
        let law = SpringDashpot {
            k_n: 100.0,
            nu: 1.0,
            psi: 0.0,
            delta0: 1.0,
            gamma_n: 10.0,
            k_t: 0.0,
            gamma_t: 0.0,
            mu: 0.0,
            clamp: true,
        };
        let c = ContactInput {
            delta: 0.01,
            delta_dot: -10.0,
            dt: 1e-3,
            ..Default::default()
        };
        assert_eq!(law.evaluate(&c).f_n, 0.0);
        let c = ContactInput {
            delta: 0.01,
            delta_dot: 0.0,
            dt: 1e-3,
            ..Default::default()
        };
        assert_eq!(law.evaluate(&c).f_n, 1.0);
    }
}
