//! Paper 004's law for spheropolygons (sec. 2, SPEC 2.4): Hertzian elasticity with
//! viscous damping, a Coulomb-capped tangential spring, and a constant cohesive pull
//! within a short range.
//!
//! - Normal: F_N = k^N δ^{3/2} + γ^N m12 δ̇ (paper 004 sec. 2; its γ^N is a rate in s⁻¹,
//!   hence the reduced mass m12, as SPEC 2.4 writes it), clamped at F_N ≥ 0: the
//!   non-cohesive part never pulls (SPEC 2).
//! - Tangential: ξ += v_t dt, F_T = −k^T ξ − γ^T m12 v_t, capped at μ F_N with F_N the
//!   repulsive part above (`tangential::coulomb_spring`). The paper writes
//!   min{k^T ξ + γ^T |v_t|, μ F_N} for the magnitude; the damping opposes v_t here, as
//!   the spring does. With units as the paper gives them, k^T = 0.1 k^N numerically.
//! - Cohesion: −F_c while the gap between the surfaces is below d_c, i.e. δ > −d_c
//!   (paper 004 sec. 2: "a constant attractive force F_c acting within a finite range
//!   d_c"), added after the clamp, so a cohesive contact pulls. Bo = F_c/(m g). The
//!   paper leaves the Coulomb cap of a cohesive contact open; the cap here is μ times the
//!   repulsive part, so a contact held only by cohesion (δ ≤ 0) has no friction.
//!
//! Issue 15, first step: the law as a function with its tests; not yet selectable in
//! scenes (docs/GUIDE.md, "Not done yet").

use super::tangential::{coulomb_spring, spring_energy};
use super::{ContactInput, ContactOutput};

/// Coefficients of paper 004's law (SI units in the paper: k^N = 10³ N/m^{3/2},
/// k^T/k^N = 0.1, γ^N/γ^T = 3, γ^T = 100 s⁻¹).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzCohesive {
    pub k_n: f64,
    pub k_t: f64,
    /// Damping rates (s⁻¹), multiplied by the reduced mass.
    pub gamma_n: f64,
    pub gamma_t: f64,
    pub mu: f64,
    /// Bo g: the cohesive force is F_c = Bo g m with m the contact's mass scale
    /// (`ContactInput::mass`: a particle's mass for two equal ones, the particle's for a
    /// wall), i.e. Bo = F_c / (m g) (paper 004 sec. 2).
    pub bond_g: f64,
    /// The cohesion range d_c (a gap, in length units).
    pub d_c: f64,
}

/// The largest cohesion range against the pair's σ = r_i + r_j of circumscribed radii:
/// the neighbour search takes circles within (1 + RANGE_MARGIN) σ, so d_c is limited to
/// that margin of the smallest particle (validated).
pub const RANGE_MARGIN: f64 = 1e-3;

impl HertzCohesive {
    /// Paper 004's values under gravity g, Bond number `bond`, friction μ and width w
    /// (d_c = 10⁻⁴ w).
    pub fn paper(g: f64, bond: f64, mu: f64, width: f64) -> Self {
        let k_n = 1e3;
        let gamma_t = 100.0;
        HertzCohesive {
            k_n,
            k_t: 0.1 * k_n,
            gamma_n: 3.0 * gamma_t,
            gamma_t,
            mu,
            bond_g: bond * g,
            d_c: 1e-4 * width,
        }
    }

    /// The scene's `contact` block; g = |gravity|.
    pub fn from_spec(
        s: &crate::law::spec::HertzCohesiveSpec,
        g: f64,
    ) -> Result<Self, crate::law::spec::ParamError> {
        use super::spec::ParamError;
        let check = |key: &str, v: f64, positive: bool| {
            if !v.is_finite() || v < 0.0 || (positive && v == 0.0) {
                let what = if positive {
                    "a positive"
                } else {
                    "a non-negative"
                };
                return Err(ParamError::invalid(
                    format!("contact.{key}"),
                    format!("must be {what} number, got {v}"),
                ));
            }
            Ok(v)
        };
        Ok(HertzCohesive {
            k_n: check("k_n", s.k_n, true)?,
            k_t: check("k_t", s.k_t, false)?,
            gamma_n: check("gamma_n", s.gamma_n, false)?,
            gamma_t: check("gamma_t", s.gamma_t, false)?,
            mu: check("mu", s.mu, false)?,
            bond_g: check("bond", s.bond, false)? * g,
            d_c: check("d_c", s.d_c, false)?,
        })
    }

    /// The cohesive force of a contact of mass scale m.
    pub fn cohesion(&self, mass: f64) -> f64 {
        self.bond_g * mass
    }

    /// Forces on particle 1 along n and t for a sub-contact of overlap δ (negative: a gap).
    /// WGSL twin: `hertz_cohesive` in shaders/laws.wgsl (its coefficients from `Params`).
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let delta = c.delta;
        if delta.is_nan() || delta <= -self.d_c {
            return ContactOutput::default();
        }
        let touching = delta > 0.0;
        let (f_rep, elastic) = if touching {
            let d32 = delta * delta.sqrt();
            let f = self.k_n * d32 + self.gamma_n * c.m12 * c.delta_dot;
            (f.max(0.0), 0.4 * self.k_n * d32 * delta)
        } else {
            (0.0, 0.0)
        };
        let f_c = self.cohesion(c.mass);
        let (f_t, history) = if touching {
            coulomb_spring(
                c.history,
                c.v_t,
                c.dt,
                self.k_t,
                self.gamma_t * c.m12,
                self.mu,
                f_rep,
            )
        } else {
            (0.0, 0.0)
        };
        ContactOutput {
            f_n: f_rep - f_c,
            f_t,
            history,
            // The cohesive pull's potential, −F_c (δ + d_c), counts with the rest.
            energy: elastic + spring_energy(self.k_t, history) - f_c * (delta + self.d_c),
            lever: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(delta: f64, delta_dot: f64, v_t: f64, history: f64) -> ContactInput {
        ContactInput {
            delta,
            delta_dot,
            v_t,
            m12: 0.5,
            mass: 1.0,
            history,
            dt: 5e-6,
            ..Default::default()
        }
    }

    #[test]
    fn a_static_overlap_carries_k_delta_to_the_three_halves() {
        // The overlap that carries a weight m g: k δ^{3/2} = m g.
        let law = HertzCohesive::paper(10.0, 0.0, 0.5, 1.0);
        let w = 0.785 * 10.0;
        let delta = (w / law.k_n).powf(2.0 / 3.0);
        let out = law.evaluate(&input(delta, 0.0, 0.0, 0.0));
        assert!((out.f_n - w).abs() < 1e-12 * w, "{} against {w}", out.f_n);
        assert_eq!(out.f_t, 0.0);
        // The elastic energy is the work ∫ k δ^{3/2} dδ = (2/5) k δ^{5/2}.
        assert!((out.energy - 0.4 * w * delta).abs() < 1e-12 * w * delta);
    }

    #[test]
    fn damping_never_pulls_but_cohesion_does() {
        let law = HertzCohesive::paper(10.0, 0.0, 0.5, 1.0);
        // Separating fast: the damped force would be negative; clamped at zero.
        assert_eq!(law.evaluate(&input(1e-4, -10.0, 0.0, 0.0)).f_n, 0.0);
        let sticky = HertzCohesive::paper(10.0, 1e3, 0.5, 1.0);
        // Bo = 10³ for a contact of mass scale 1 under g = 10.
        let f_c = 1e3 * 10.0;
        assert_eq!(sticky.evaluate(&input(1e-4, -10.0, 0.0, 0.0)).f_n, -f_c);
        // Within the range d_c = 1e-4 of a gap: pulled, no friction, no spring.
        let out = sticky.evaluate(&input(-0.5e-4, 0.0, 1.0, 3e-3));
        assert_eq!((out.f_n, out.f_t, out.history), (-f_c, 0.0, 0.0));
        // Beyond it: nothing.
        assert_eq!(
            sticky.evaluate(&input(-1.5e-4, 0.0, 1.0, 3e-3)),
            ContactOutput::default()
        );
        // Cohesion's potential rises linearly across the range to zero at its end.
        let e = |d: f64| sticky.evaluate(&input(d, 0.0, 0.0, 0.0)).energy;
        assert!((e(-0.5e-4) + f_c * 0.5e-4).abs() < 1e-12);
    }

    #[test]
    fn the_tangential_spring_sticks_below_the_cap_and_slides_at_mu_times_the_repulsion() {
        let law = HertzCohesive::paper(10.0, 1e3, 0.5, 1.0);
        let delta = 1e-3;
        let f_rep = law.k_n * delta * delta.sqrt();
        // A small spring sticks: −k_t ξ − γ_t m12 v_t.
        let xi = 1e-5;
        let out = law.evaluate(&input(delta, 0.0, 0.0, xi));
        assert!((out.f_t + law.k_t * xi).abs() < 1e-15);
        assert_eq!(out.history, xi);
        // A long one slides at μ times the repulsive part (not counting the cohesion).
        let out = law.evaluate(&input(delta, 0.0, 1.0, 1.0));
        assert!((out.f_t + 0.5 * f_rep).abs() < 1e-12 * f_rep);
        assert!((law.k_t * out.history - 0.5 * f_rep).abs() < 1e-12 * f_rep);
    }

    #[test]
    fn a_head_on_collision_loses_energy_to_damping_only() {
        // Two bodies (reduced mass m12) meet at speed v: integrated finely with the law,
        // the undamped law gives back the speed (Hertz is conservative), and the damped
        // one returns a smaller one that the time-reversed approach cannot exceed.
        let run = |gamma_n: f64| {
            let law = HertzCohesive {
                gamma_n,
                ..HertzCohesive::paper(10.0, 0.0, 0.0, 1.0)
            };
            let (m12, dt) = (0.5, 1e-7);
            let (mut delta, mut rate) = (0.0, 0.1);
            let mut t = 0.0;
            // Velocity Verlet on δ: m12 δ̈ = −F_N.
            let force = |d: f64, r: f64| {
                let c = ContactInput {
                    delta: d,
                    delta_dot: r,
                    m12,
                    dt,
                    ..Default::default()
                };
                law.evaluate(&c).f_n
            };
            loop {
                let a = -force(delta, rate) / m12;
                delta += rate * dt + 0.5 * a * dt * dt;
                let half = rate + 0.5 * a * dt;
                rate = half - 0.5 * force(delta, half) / m12 * dt;
                t += dt;
                if delta <= 0.0 || t > 1.0 {
                    break;
                }
            }
            (-rate / 0.1, t)
        };
        let (e, t_c) = run(0.0);
        assert!((e - 1.0).abs() < 1e-4, "undamped restitution {e}");
        // Hertz's contact time for the force k δ^{3/2}, mass m12 and speed v: 2.9432
        // δ_max / v with δ_max = (5 m12 v² / (4 k))^{2/5} (Landau & Lifshitz, Theory of
        // Elasticity, sec. 9).
        let delta_max = (5.0 * 0.5 * 0.1f64.powi(2) / (4.0 * 1e3)).powf(0.4);
        let hertz = 2.9432 * delta_max / 0.1;
        assert!(
            (t_c - hertz).abs() < 1e-3 * hertz,
            "contact time {t_c} against {hertz}"
        );
        let (e_damped, _) = run(300.0);
        assert!(
            e_damped > 0.0 && e_damped < 0.99 * e,
            "damped restitution {e_damped}"
        );
    }
}
