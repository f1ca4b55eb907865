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

/// Paper 001's tapered spring at δ_F: the friction force magnitude (eq. 5), its
/// stiffness k_T = dF/dδ_F (eq. 7) and the work it stores, from one square root: with
/// w = 1 − min(|δ_F|/δ_max, 1),
/// F = μ F_N (1 − w^(3/2)), k_T = (3 μ F_N / 2 δ_max) w^(1/2), and
/// ∫0^|δ_F| F dδ = μ F_N (x + (2/5) δ_max (w^(5/2) − 1)) with x = min(|δ_F|, δ_max).
/// (`powf` for the half-integer powers cost several times the square root.)
/// All zero for δ_max ≤ 0. WGSL: `tapered_friction`, `tapered_stiffness`,
/// `tapered_energy`.
#[inline]
pub fn tapered(delta_f: f64, delta_max: f64, mu_f_n: f64) -> (f64, f64, f64) {
    if delta_max <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    // x / δ_max is exactly 1 at the limit (w = 0: a sliding contact has k_T = 0 and no
    // tangential damping, eq. 8), which x · (1/δ_max) need not be.
    let x = delta_f.abs().min(delta_max);
    let w = 1.0 - x / delta_max;
    let root = w.sqrt();
    (
        mu_f_n * (1.0 - w * root),
        1.5 * mu_f_n / delta_max * root,
        mu_f_n * (x + 0.4 * delta_max * (w * w * root - 1.0)),
    )
}

/// Tapered friction force magnitude, paper 001 eq. 5:
/// F = μ F_N [1 − (1 − |δ_F|/δ_max)^(3/2)], and μ F_N once |δ_F| ≥ δ_max.
pub fn tapered_friction(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    tapered(delta_f, delta_max, mu_f_n).0
}

/// Tangential stiffness k_T = dF/dδ_F, paper 001 eq. 7.
pub fn tapered_stiffness(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    tapered(delta_f, delta_max, mu_f_n).1
}

/// Work stored in the tapered spring, ∫0^|δ_F| F dδ = μF_N (x + (2/5) D ((1 − x/D)^(5/2) − 1)).
pub fn tapered_energy(delta_f: f64, delta_max: f64, mu_f_n: f64) -> f64 {
    tapered(delta_f, delta_max, mu_f_n).2
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

    #[test]
    fn tapered_spring_from_one_root_is_eq_5_and_7_and_stops_damping_at_the_limit() {
        let (d, m) = (0.12, 3.0);
        for k in 0..=1000 {
            let x = d * k as f64 / 1000.0;
            let (f, k_t, w) = tapered(-x, d, m);
            let u = 1.0 - x / d;
            let f_pow = m * (1.0 - u.powf(1.5));
            let k_pow = 1.5 * m / d * u.powf(0.5);
            let w_pow = m * (x + 0.4 * d * (u.powf(2.5) - 1.0));
            assert!((f - f_pow).abs() <= 1e-15 * m, "F at {x}: {f} {f_pow}");
            assert!(
                (k_t - k_pow).abs() <= 1e-14 * m / d,
                "k_T at {x}: {k_t} {k_pow}"
            );
            assert!((w - w_pow).abs() <= 1e-15 * m * d, "W at {x}: {w} {w_pow}");
        }
        // At and beyond the limit k_T is exactly 0, so eq. 8's damping C_T = sqrt(m k_T)
        // vanishes for a sliding contact (the GPU twin gets 0 there too).
        for x in [d, -d, 1.5 * d, 10.0 * d] {
            assert_eq!(tapered(x, d, m).1, 0.0);
            assert_eq!(tapered(x, d, m).0, m);
        }
        assert_eq!(tapered(0.01, 0.0, m), (0.0, 0.0, 0.0));
    }
}
