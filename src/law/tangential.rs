//! Tangential laws: the Coulomb-capped spring (paper 000 eq. 4–5, SPEC 2.1) and the
//! tapered friction of paper 001 (eq. 5–8, SPEC 2.2).
//!
//! In 2D the tangent t = (−n_z, n_x) is one direction, so the history is a scalar along
//! the current t. Storing it as a scalar *is* rotating the spring with the contact frame
//! each step: it stays tangential exactly, with its length unchanged.

/// Coulomb-capped linear spring: ξ += v_t dt; f_t = −k_t ξ − γ_t v_t, capped at μ f_n.
/// When the cap is reached the contact slides and the spring is shortened so that
/// k_t |ξ| = μ f_n (paper 000 after eq. 5). With k_t = 0 it is pure viscous friction,
/// still capped. Returns (f_t, new ξ).
#[inline(always)]
pub fn coulomb_spring(
    xi: f64,
    v_t: f64,
    dt: f64,
    k_t: f64,
    gamma_t: f64,
    mu: f64,
    f_n: f64,
) -> (f64, f64) {
    let xi = xi + v_t * dt;
    let trial = -k_t * xi - gamma_t * v_t;
    let cap = mu * f_n;
    if trial.abs() <= cap {
        return (trial, xi);
    }
    let f_t = cap.copysign(trial);
    let xi = if k_t > 0.0 { -f_t / k_t } else { 0.0 };
    (f_t, xi)
}

/// Elastic energy of the tangential spring, k_t ξ² / 2.
#[inline(always)]
pub fn spring_energy(k_t: f64, xi: f64) -> f64 {
    0.5 * k_t * xi * xi
}

/// Tapered friction force magnitude, paper 001 eq. 5:
/// F = μ F_N [1 − (1 − |δ_F|/δ_max)^(3/2)], and μ F_N once |δ_F| ≥ δ_max.
pub fn tapered_friction(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    if delta_max <= 0.0 {
        return 0.0;
    }
    let u = (delta_f.abs() / delta_max).min(1.0);
    mu_f_n * (1.0 - (1.0 - u).powf(1.5))
}

/// Tangential stiffness k_T = dF/dδ_F, paper 001 eq. 7.
pub fn tapered_stiffness(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    if delta_max <= 0.0 {
        return 0.0;
    }
    let u = (delta_f.abs() / delta_max).min(1.0);
    1.5 * mu_f_n / delta_max * (1.0 - u).sqrt()
}

/// Work stored in the tapered spring, ∫0^|δ_F| F dδ = μF_N (x + (2/5) D ((1 − x/D)^(5/2) − 1)).
pub fn tapered_energy(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    if delta_max <= 0.0 {
        return 0.0;
    }
    let x = delta_f.abs().min(delta_max);
    mu_f_n * (x + 0.4 * delta_max * ((1.0 - x / delta_max).powf(2.5) - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coulomb_spring_sticks_below_cap_and_slides_at_it() {
        let (f, xi) = coulomb_spring(0.0, 1.0, 0.1, 10.0, 0.0, 0.5, 10.0);
        assert_eq!((f, xi), (-1.0, 0.1));
        let (f, xi) = coulomb_spring(0.0, 10.0, 0.1, 10.0, 0.0, 0.5, 1.0);
        assert_eq!(f, -0.5);
        assert!(
            (10.0 * xi.abs() - 0.5).abs() < 1e-15,
            "spring shortened to the cap"
        );
    }

    #[test]
    fn tapered_friction_is_continuous_and_saturates() {
        let (d, m) = (0.1, 2.0);
        assert_eq!(tapered_friction(0.0, d, m), 0.0);
        assert!((tapered_friction(d, d, m) - m).abs() < 1e-15);
        assert_eq!(tapered_friction(2.0 * d, d, m), m);
        // k_T is the derivative of F (central difference).
        let x = 0.03;
        let fd = (tapered_friction(x + 1e-7, d, m) - tapered_friction(x - 1e-7, d, m)) / 2e-7;
        assert!((fd - tapered_stiffness(x, d, m)).abs() < 1e-5 * fd);
        // energy is the integral of F.
        let ed = (tapered_energy(x + 1e-7, d, m) - tapered_energy(x - 1e-7, d, m)) / 2e-7;
        assert!((ed - tapered_friction(x, d, m)).abs() < 1e-6);
    }
}
