//! Continuous interaction with tapered friction for disks, paper 001 eq. 3–8 (SPEC 2.2),
//! and its equivalent Hooke law (paper 001 eq. 14).
//!
//! Lengths enter through σ = (d1 + d2)/2 and forces through m g with m = 2 m12, so the
//! law is the paper's reduced-unit law for any units and for unequal disks.

use super::spec::{
    ContinuousSpec, HookeEquivalentSpec, ParamError, RollingArm, TangentialDamping, TangentialLimit,
};
use super::spring_dashpot::{non_negative, positive};
use super::tangential::tapered;
use super::{ContactInput, ContactOutput, clamp_non_negative};

/// The elastic part of the normal force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Elastic {
    /// F_e = m g (σ/r)^(n+1) for r < r0 σ (paper 001 sec. II).
    Power { n: f64 },
    /// F_e = k (m g/σ)(σ − r) for r < σ; k in units of m g/σ (paper 001 eq. 14).
    Hooke { k: f64 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Continuous {
    pub elastic: Elastic,
    /// Cut-off r0/σ of the power law (and the engagement distance for δ_N).
    pub r0: f64,
    pub mu: f64,
    pub alpha: f64,
    pub damping_fraction: f64,
    /// Force scale g.
    pub g: f64,
    /// How eq. 3, 4 and 6 are read where the text leaves a choice (SPEC 2.2).
    pub reading: Reading,
}

/// The readings of paper 001's law that a scene chooses (issue 39); the defaults are
/// the paper's text taken literally.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Reading {
    /// f_n ≥ 0 after the damping (not in eq. 3).
    pub clamp: bool,
    pub damping: TangentialDamping,
    pub arm: RollingArm,
    pub limit: TangentialLimit,
}

impl Continuous {
    pub fn from_spec(s: &ContinuousSpec, g: f64) -> Result<Self, ParamError> {
        positive("contact.n", s.n)?;
        if !(s.r0 > 1.0 && s.r0.is_finite()) {
            return Err(ParamError::invalid(
                "contact.r0",
                format!("must be greater than 1 (in units of σ), got {}", s.r0),
            ));
        }
        let g = force_scale(s.g, g)?;
        check_friction(s.mu, s.alpha, s.damping_fraction)?;
        Ok(Self {
            elastic: Elastic::Power { n: s.n },
            r0: s.r0,
            mu: s.mu,
            alpha: s.alpha,
            damping_fraction: s.damping_fraction,
            g,
            reading: Reading {
                clamp: s.clamp,
                damping: s.tangential_damping,
                arm: s.rolling_arm,
                limit: s.tangential_limit,
            },
        })
    }

    pub fn from_hooke_spec(s: &HookeEquivalentSpec, g: f64) -> Result<Self, ParamError> {
        positive("contact.n", s.n)?;
        if !(s.r0 > 1.0 && s.r0.is_finite()) {
            return Err(ParamError::invalid(
                "contact.r0",
                format!("must be greater than 1, got {}", s.r0),
            ));
        }
        let k = match s.k {
            Some(k) => positive("contact.k", k)?,
            None => {
                if !(s.r_i > 0.0 && s.r_i < 1.0) {
                    return Err(ParamError::invalid(
                        "contact.r_i",
                        format!("must be in (0, 1) (units of σ), got {}", s.r_i),
                    ));
                }
                equivalent_hooke_constant(s.n, s.r0, s.r_i)
            }
        };
        let g = force_scale(s.g, g)?;
        check_friction(s.mu, s.alpha, s.damping_fraction)?;
        // The Hooke law engages at r = σ: range and δ_N use r0 = 1.
        Ok(Self {
            elastic: Elastic::Hooke { k },
            r0: 1.0,
            mu: s.mu,
            alpha: s.alpha,
            damping_fraction: s.damping_fraction,
            g,
            reading: Reading {
                clamp: s.clamp,
                damping: s.tangential_damping,
                arm: s.rolling_arm,
                limit: s.tangential_limit,
            },
        })
    }

    pub fn range_factor(&self) -> f64 {
        self.r0
    }

    /// WGSL twin: `continuous` in shaders/laws.wgsl (its coefficients from `Params`).
    #[inline(always)]
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let m = c.mass;
        let (f_e, k, elastic_energy) = self.elastic(m, c.sigma, c.r);
        // Paper 001 eq. 3: C_N = 50 % of critical damping 2 sqrt(m k(r)), added to F_e
        // without a clamp unless the scene asks for one: in the tail σ < r < r0 a
        // separating pair is pulled back by its damping (the paper's "endurance").
        let c_n = self.damping_fraction * 2.0 * (m * k).sqrt();
        let f_n = f_e + c_n * c.delta_dot;
        let f_n = if self.reading.clamp {
            clamp_non_negative(f_n)
        } else {
            f_n
        };

        // δ_N = r0 − r; δ_max = α μ δ_N (paper 001 after eq. 6).
        let delta_n = (self.r0 * c.sigma - c.r).max(0.0);
        let delta_max = self.alpha * self.mu * delta_n;
        // Eq. 6: δ_F accumulates ṙ_ij · t̂ − (θ̇_i + θ̇_j) r_ij, the spins' arm the centre
        // distance as written, or each disk's own (the surfaces' slip, `v_t`). By default
        // it is held at ±δ_max while sliding so that a reversal starts from the Coulomb
        // limit rather than unwinding a long excursion (the paper leaves this open:
        // `TangentialLimit`).
        let slip = match self.reading.arm {
            RollingArm::CentreDistance => c.v_centres - c.spin * c.r,
            RollingArm::ContactPoint => c.v_t,
        };
        let delta_f = c.history + slip * c.dt;
        let delta_f = match self.reading.limit {
            TangentialLimit::Hold => delta_f.clamp(-delta_max, delta_max),
            TangentialLimit::Slide => {
                let bound = delta_max.max(c.history.abs());
                delta_f.clamp(-bound, bound)
            }
            TangentialLimit::Accumulate => delta_f,
        };
        let mu_f_e = self.mu * f_e;
        let (spring, k_t, tangential_energy) = tapered(delta_f, delta_max, mu_f_e);
        // Eq. 8: C_T = 50 % of critical, sqrt(m k_T), on the velocity eq. 4 names, the
        // centres' ṙ_ij · t̂, or on the surfaces' slip.
        let c_t = self.damping_fraction * 2.0 * (m * k_t).sqrt();
        let v_damped = match self.reading.damping {
            TangentialDamping::Centres => c.v_centres,
            TangentialDamping::Slip => c.v_t,
        };
        let f_t = -spring.copysign(delta_f) - c_t * v_damped;
        let f_t = if delta_f == 0.0 { -c_t * v_damped } else { f_t };

        let energy = elastic_energy + tangential_energy;
        ContactOutput {
            f_n,
            f_t,
            history: delta_f,
            energy,
            // Eq. 13: the torques on the lever eq. 6 gives the spins, so that the spring's
            // work is what δ_F stores (tests/laws.rs, the pocket).
            lever: match self.reading.arm {
                RollingArm::CentreDistance => c.r,
                RollingArm::ContactPoint => 0.0,
            },
        }
    }

    /// F_e(r), k(r) = −dF_e/dr and the work stored ∫_r^{range} F_e, zero beyond the
    /// range: the power law's three from one power (σ/r)^n. (WGSL: `continuous_force`,
    /// `continuous_stiffness`, `continuous_energy`.)
    #[inline]
    pub fn elastic(&self, m: f64, sigma: f64, r: f64) -> (f64, f64, f64) {
        match self.elastic {
            Elastic::Power { n } if r < self.r0 * sigma => {
                let x = sigma / r;
                let p = power(x, n);
                let f = m * self.g * p * x;
                let tail = power(1.0 / self.r0, n);
                (
                    f,
                    (n + 1.0) * f * x / sigma,
                    m * self.g * sigma / n * (p - tail),
                )
            }
            Elastic::Hooke { k } if r < sigma => {
                let k = k * m * self.g / sigma;
                (k * (sigma - r), k, 0.5 * k * (sigma - r) * (sigma - r))
            }
            _ => (0.0, 0.0, 0.0),
        }
    }

    /// F_e(r), zero beyond the range.
    pub fn elastic_force(&self, m: f64, sigma: f64, r: f64) -> f64 {
        self.elastic(m, sigma, r).0
    }

    /// k(r) = −dF_e/dr.
    pub fn elastic_stiffness(&self, m: f64, sigma: f64, r: f64) -> f64 {
        self.elastic(m, sigma, r).1
    }

    /// Work stored, ∫_r^{range} F_e.
    pub fn elastic_energy(&self, m: f64, sigma: f64, r: f64) -> f64 {
        self.elastic(m, sigma, r).2
    }

    /// The normal damping rate C_N/m12 (per unit time, on the pair's relative motion) at
    /// the closest approach of a head-on impact at speed `v`: of a grain of diameter
    /// `sigma` on a fixed one (m12 = m) and of two such grains (m12 = m/2), the larger.
    /// C_N = ζ 2 sqrt(m k(r)) grows with k(r), and k(r) of the power law grows as
    /// (σ/r)^(n+2): a fast impact meets a damping hundreds of times the resting one.
    /// The stored work is `elastic_energy`, so the closest approach solves
    /// E(r) = m12 v²/2 (bisection; beyond the law's hardest point the last r tried).
    pub fn impact_damping_rate(&self, sigma: f64, v: f64) -> f64 {
        let m = 1.0; // every term scales with m: the rate does not depend on it
        [m, 0.5 * m]
            .into_iter()
            .map(|m12| {
                let work = 0.5 * m12 * v * v;
                let (mut lo, mut hi) = (1e-3 * sigma, self.r0.max(1.0) * sigma);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if self.elastic_energy(m, sigma, mid) > work {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let k = self.elastic_stiffness(m, sigma, hi);
                self.damping_fraction * 2.0 * (m * k).sqrt() / m12
            })
            .fold(0.0, f64::max)
    }

    /// ω0² at r = σ, where a resting pair sits under its own weight (paper 001 sec. II).
    pub fn omega0_squared(&self, m12: f64, sigma: f64) -> f64 {
        self.elastic_stiffness(2.0 * m12, sigma, sigma) / m12
    }
}

/// x^n, by repeated multiplication when n is a whole number (paper 001's n = 36 and
/// 144): `powf` took two thirds of a poured heap's time (three powers per contact and
/// step), repeated squaring takes a few multiplications, within a few ulps of it.
#[inline]
fn power(x: f64, n: f64) -> f64 {
    let k = n as i32;
    if k as f64 == n { x.powi(k) } else { x.powf(n) }
}

/// Paper 001 eq. 14, in units of m g/σ: k = 2 ∫_{r_i}^{r0} F dr / (σ − r_i)², with
/// ∫ (1/r)^(n+1) dr = (r_i^−n − r0^−n)/n (σ = 1).
pub fn equivalent_hooke_constant(n: f64, r0: f64, r_i: f64) -> f64 {
    2.0 * (r_i.powf(-n) - r0.powf(-n)) / n / ((1.0 - r_i) * (1.0 - r_i))
}

fn force_scale(given: Option<f64>, gravity: f64) -> Result<f64, ParamError> {
    match given {
        Some(g) => positive("contact.g", g),
        None if gravity > 0.0 => Ok(gravity),
        None => Err(ParamError::invalid(
            "contact.g",
            "is required when gravity is zero (it sets the force scale m g)",
        )),
    }
}

fn check_friction(mu: f64, alpha: f64, damping: f64) -> Result<(), ParamError> {
    non_negative("contact.mu", mu)?;
    positive("contact.alpha", alpha)?;
    non_negative("contact.damping_fraction", damping)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::tangential::{tapered_friction, tapered_stiffness};

    #[test]
    fn the_power_law_from_one_power_matches_powf() {
        // Whole n by repeated multiplication, any other n by powf: F_e, k and the stored
        // work as the closed forms with powf, across the range and for unequal disks
        // (σ = 0.8) with m g ≠ 1. Repeated squaring raises its roundings to powers up to
        // n/2: a few ε times n (6e-14 for n = 144), far inside the f64 path's 1e-6.
        for n in [36.0, 144.0, 36.5] {
            let l = Continuous {
                elastic: Elastic::Power { n },
                r0: 1.2,
                g: 9.81,
                ..law()
            };
            let (m, sigma) = (1.7, 0.8);
            for k in 0..200 {
                let r = sigma * (0.85 + 0.35 * k as f64 / 200.0);
                let (f, stiff, e) = l.elastic(m, sigma, r);
                let x = sigma / r;
                let f_pow = m * 9.81 * x.powf(n + 1.0);
                let k_pow = (n + 1.0) * m * 9.81 / sigma * x.powf(n + 2.0);
                let e_pow = m * 9.81 * sigma / n * (x.powf(n) - (1.0 / 1.2f64).powf(n));
                let tol = 4e-16 * (n + 2.0);
                assert!(
                    (f - f_pow).abs() <= tol * f_pow,
                    "n {n}, r {r}: {f} {f_pow}"
                );
                assert!((stiff - k_pow).abs() <= tol * k_pow, "n {n}, r {r}");
                assert!(
                    (e - e_pow).abs() <= tol * e_pow.abs().max(1e-3),
                    "n {n}, r {r}"
                );
            }
            assert_eq!(l.elastic(m, sigma, 1.2 * sigma), (0.0, 0.0, 0.0));
        }
    }

    fn law() -> Continuous {
        Continuous {
            elastic: Elastic::Power { n: 36.0 },
            r0: 1.2,
            mu: 0.5,
            alpha: 1.214,
            damping_fraction: 0.5,
            g: 1.0,
            reading: Reading::default(),
        }
    }

    /// A pair of unit disks at r in the tail, separating at 0.5 √(gσ), with the
    /// surfaces slipping at `v_t`, the centres at `v_centres` and the spins summing to
    /// `spin`.
    fn tail_input(v_t: f64, v_centres: f64, spin: f64) -> ContactInput {
        ContactInput {
            delta: -0.1,
            r: 1.1,
            sigma: 1.0,
            delta_dot: -0.5,
            v_t,
            v_centres,
            spin,
            m12: 0.5,
            mass: 1.0,
            history: 0.0,
            dt: 1e-3,
            ..Default::default()
        }
    }

    #[test]
    fn eq_3_holds_a_separating_pair_back_unless_clamped() {
        // Paper 001 eq. 3: F_N = F_e − C_N ṙ·n̂, no clamp: in the tail a pair separating
        // faster than F_e / C_N is pulled together.
        let mut l = law();
        let c = tail_input(0.0, 0.0, 0.0);
        let (f_e, k) = (
            l.elastic_force(1.0, 1.0, 1.1),
            l.elastic_stiffness(1.0, 1.0, 1.1),
        );
        let want = f_e - 0.5 * 2.0 * k.sqrt() * 0.5;
        assert!(want < 0.0, "the damping outweighs F_e here ({want})");
        assert!((l.evaluate(&c).f_n - want).abs() < 1e-15);
        l.reading.clamp = true;
        assert_eq!(l.evaluate(&c).f_n, 0.0);
    }

    #[test]
    fn eq_4_damps_the_centres_and_eq_6_turns_the_spins_on_the_centre_distance() {
        let mut l = law();
        // Two disks spinning the same way at ω = 2 with still centres: their surfaces
        // slip at −ω (a_1 + a_2) = −ω r, the arms meeting at the contact point.
        let (omega, r, dt) = (2.0, 1.1, 1e-3);
        let v_t = -omega * r; // the physical slip with arms summing to r
        let c = tail_input(v_t, 0.0, 2.0 * omega);
        let out = l.evaluate(&c);
        // Eq. 6 as written: δ_F = −(θ̇_i + θ̇_j) r_ij dt = −2 ω r dt, twice the slip.
        assert!((out.history - (-2.0 * omega * r * dt)).abs() < 1e-15);
        // Eq. 4: the centres do not move, so no damping: f_t is the spring alone.
        let delta_max = l.alpha * l.mu * (l.r0 - r);
        let spring = tapered_friction(out.history, delta_max, l.mu * l.elastic_force(1.0, 1.0, r));
        assert!(
            (out.f_t - spring).abs() < 1e-15,
            "{} against {spring}",
            out.f_t
        );
        // The other readings: δ_F from the slip, and the slip damped.
        l.reading.arm = RollingArm::ContactPoint;
        l.reading.damping = TangentialDamping::Slip;
        let out = l.evaluate(&c);
        assert!((out.history - v_t * dt).abs() < 1e-15);
        let mu_f_e = l.mu * l.elastic_force(1.0, 1.0, r);
        let k_t = tapered_stiffness(out.history, delta_max, mu_f_e);
        let c_t = 0.5 * 2.0 * k_t.sqrt();
        let want = tapered_friction(out.history, delta_max, mu_f_e) - c_t * v_t;
        assert!((out.f_t - want).abs() < 1e-12, "{} against {want}", out.f_t);
    }

    #[test]
    fn delta_f_is_held_at_its_limit_or_accumulates_beyond_it() {
        // A resting pair (r = σ, δ_max = α μ 0.2σ) whose δ_F already stands at 2 δ_max.
        let mut l = law();
        let delta_max = l.alpha * l.mu * (l.r0 - 1.0);
        let mu_f_e = l.mu * l.elastic_force(1.0, 1.0, 1.0);
        let input = |v: f64| ContactInput {
            r: 1.0,
            sigma: 1.0,
            v_centres: v,
            m12: 0.5,
            mass: 1.0,
            history: 2.0 * delta_max,
            dt: 1e-3,
            ..Default::default()
        };
        // Sliding on: held at δ_max (a spring that slides), or carried on; μ F_e either
        // way, undamped (k_T = 0 at the limit).
        let held = l.evaluate(&input(0.5));
        assert_eq!(held.history, delta_max);
        assert!((held.f_t + mu_f_e).abs() < 1e-15, "{}", held.f_t);
        l.reading.limit = TangentialLimit::Accumulate;
        let carried = l.evaluate(&input(0.5));
        assert_eq!(carried.history, 2.0 * delta_max + 0.5e-3);
        assert!((carried.f_t + mu_f_e).abs() < 1e-15, "{}", carried.f_t);
        // Turning back by 0.1 δ_max: the held spring comes down eq. 5's curve at once,
        // the accumulated one stays at μ F_e, pulling the new way until δ_F is back
        // under δ_max (no sliding dissipation).
        let back = -0.1 * delta_max / 1e-3;
        let carried = l.evaluate(&input(back));
        assert!((carried.f_t + mu_f_e).abs() < 1e-15, "{}", carried.f_t);
        l.reading.limit = TangentialLimit::Hold;
        let mut c = input(back);
        c.history = delta_max;
        let held = l.evaluate(&c);
        let spring = tapered_friction(0.9 * delta_max, delta_max, mu_f_e);
        assert!(spring < 0.97 * mu_f_e);
        let c_t = 0.5 * 2.0 * tapered_stiffness(0.9 * delta_max, delta_max, mu_f_e).sqrt();
        assert!(
            (held.f_t - (-spring - c_t * back)).abs() < 1e-12,
            "{}",
            held.f_t
        );
    }

    #[test]
    fn sliding_caps_delta_f_and_a_shrinking_limit_does_not_cut_it() {
        // A pair eased apart to r = 1.1σ (δ_max = α μ 0.1σ) with δ_F = 0.08σ from when
        // it was pressed closer: `hold` cuts δ_F to the new δ_max, `slide` keeps it.
        let mut l = law();
        let delta_max = l.alpha * l.mu * (l.r0 - 1.1);
        let input = |v: f64, history: f64| ContactInput {
            r: 1.1,
            sigma: 1.0,
            v_centres: v,
            m12: 0.5,
            mass: 1.0,
            history,
            dt: 1e-3,
            ..Default::default()
        };
        assert!(0.08 > delta_max);
        assert_eq!(l.evaluate(&input(0.0, 0.08)).history, delta_max);
        l.reading.limit = TangentialLimit::Slide;
        assert_eq!(l.evaluate(&input(0.0, 0.08)).history, 0.08);
        // Sliding on does not take it further; sliding back unwinds it.
        assert_eq!(l.evaluate(&input(1.0, 0.08)).history, 0.08);
        assert_eq!(l.evaluate(&input(-1.0, 0.08)).history, 0.08 - 1e-3);
        // Within δ_max it is the held spring's.
        let inside = input(1.0, 0.5 * delta_max);
        assert_eq!(l.evaluate(&inside).history, 0.5 * delta_max + 1e-3);
        assert_eq!(l.evaluate(&input(1.0, delta_max)).history, delta_max);
    }

    #[test]
    fn force_is_m_g_at_contact_and_about_a_thousandth_at_cutoff() {
        let l = law();
        assert!((l.elastic_force(1.0, 1.0, 1.0) - 1.0).abs() < 1e-15);
        let cut = l.elastic_force(1.0, 1.0, 1.2 - 1e-12);
        assert!((cut / 1.2e-3 - 1.0).abs() < 0.05, "cut-off force {cut}"); // SPEC 2.2: ≈1.2e-3 mg
        assert_eq!(l.elastic_force(1.0, 1.0, 1.2), 0.0);
    }

    #[test]
    fn stiffness_and_energy_are_derivatives() {
        let l = law();
        let (m, s, r, h) = (1.3, 0.9, 0.95, 1e-7);
        let dfdr = (l.elastic_force(m, s, r + h) - l.elastic_force(m, s, r - h)) / (2.0 * h);
        assert!((-dfdr - l.elastic_stiffness(m, s, r)).abs() < 1e-6 * dfdr.abs());
        let dedr = (l.elastic_energy(m, s, r + h) - l.elastic_energy(m, s, r - h)) / (2.0 * h);
        assert!((-dedr - l.elastic_force(m, s, r)).abs() < 1e-6);
    }

    #[test]
    fn an_impact_meets_the_damping_of_its_closest_approach() {
        // Paper 001's drop from 100σ: v² = 2 g h. Closed form with g = σ = m = 1: the
        // work m g σ/n ((σ/r)^n − r0^−n) = m12 v²/2 gives (σ/r)^n; k/m = (n+1)(σ/r)^(n+2);
        // C_N/m12 = ζ 2 sqrt(k/m) · m/m12.
        let (l, n) = (law(), 36.0);
        let v2 = 2.0 * 100.0;
        let rate = |m12: f64| {
            let x = n * 0.5 * m12 * v2 + 1.2f64.powf(-n); // (σ/r)^n
            0.5 * 2.0 * ((n + 1.0) * x.powf((n + 2.0) / n)).sqrt() / m12
        };
        let want = rate(1.0).max(rate(0.5));
        let got = l.impact_damping_rate(1.0, v2.sqrt());
        assert!((got - want).abs() < 1e-9 * want, "{got} against {want}");
        // Two grains meeting (m12 = m/2) are the harder case: C_N/m12 ≈ 640 per unit
        // time, 0.64 per step of 0.001, where Gear diverged (issue 39).
        assert!((got - rate(0.5)).abs() < 1e-9 * want && (600.0..700.0).contains(&got));
        // At rest the damping is the resting pair's, sqrt(37) per unit time.
        let resting = l.impact_damping_rate(1.0, 1e-6);
        assert!(resting < 2.0 * 37f64.sqrt() * 1.01, "{resting}");
    }

    #[test]
    fn equivalent_hooke_constant_equates_work() {
        let (n, r0, ri) = (36.0, 1.2, 0.915);
        let k = equivalent_hooke_constant(n, r0, ri);
        // trapezoid integral of the power law from r_i to r0
        let steps = 200_000;
        let h = (r0 - ri) / steps as f64;
        let w: f64 = (0..steps)
            .map(|i| {
                let a = ri + i as f64 * h;
                0.5 * h * (a.powf(-37.0) + (a + h).powf(-37.0))
            })
            .sum();
        assert!((0.5 * k * (1.0 - ri) * (1.0 - ri) - w).abs() < 1e-6 * w);
    }
}
