//! Power-law spring-dashpot for disks, paper 000 eq. 2–5 (SPEC 2.1).

use super::restitution::{PairTable, PerMass};
use super::spec::{ParamError, ResolvedPair, SpringDashpotSpec};
use super::tangential::{coulomb_spring, spring_energy};
use super::{ContactInput, ContactOutput, clamp_non_negative};

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
    /// The material form (`restitution` and `contact_time`): coefficients per pair of
    /// materials per unit of the contact's reduced mass (src/law/restitution.rs); the
    /// absolute ones above are then unused. None: the stiffness form.
    pub pairs: Option<PairTable>,
    /// The material form of a nonlinear law: the relative speed at which e and t_c hold.
    pub impact_speed: Option<f64>,
}

/// k_t/k_n of the material form when the scene does not say (the ratio of a
/// homogeneous elastic disk's tangential and normal stiffness, as in paper 000).
pub const DEFAULT_KT_RATIO: f64 = 2.0 / 7.0;

/// Reference overlap, as a fraction of the diameter, at which the stiffness of a
/// nonlinear (ν ≠ 1) law is taken for the time-step check: a large overlap for DEM.
pub const REFERENCE_OVERLAP: f64 = 0.05;

impl SpringDashpot {
    /// `materials`: the scene's material names in index order (the pair table's rows).
    pub fn from_spec(s: &SpringDashpotSpec, materials: &[String]) -> Result<Self, ParamError> {
        if s.restitution.is_some() || s.contact_time.is_some() {
            return Self::from_material_form(s, materials);
        }
        super::restitution::refuse(
            &[
                ("kt_ratio", s.kt_ratio.is_some()),
                ("gamma_t_ratio", s.gamma_t_ratio.is_some()),
                ("pairs", !s.pairs.is_empty()),
            ],
            "belongs to the material form: give restitution and contact_time instead of k_n",
        )?;
        let Some(k_n) = s.k_n else {
            return Err(ParamError::invalid(
                "contact.k_n",
                "is required (or give restitution and contact_time, the material form)",
            ));
        };
        positive("contact.k_n", k_n)?;
        if !(s.nu >= 1.0 && s.nu <= 3.0) {
            return Err(ParamError::invalid(
                "contact.nu",
                format!(
                    "must be in [1, 3] (1 Hooke, 1.5 Hertz, 2 conical), got {}",
                    s.nu
                ),
            ));
        }
        if !(s.psi >= 0.0 && s.psi <= 3.0) {
            return Err(ParamError::invalid(
                "contact.psi",
                format!("must be in [0, 3], got {}", s.psi),
            ));
        }
        let delta0 = match s.delta0 {
            Some(d) => positive("contact.delta0", d)?,
            None if s.nu != 1.0 || s.psi != 0.0 => {
                return Err(ParamError::invalid(
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
            k_n,
            nu: s.nu,
            psi: s.psi,
            delta0,
            gamma_n: s.gamma_n,
            k_t: s.k_t,
            gamma_t: s.gamma_t,
            mu: s.mu,
            clamp: s.clamp,
            pairs: None,
            impact_speed: None,
        })
    }

    /// The material form: e and t_c (and μ) for every pair of materials, resolved into
    /// coefficients per unit of reduced mass (src/law/restitution.rs).
    fn from_material_form(s: &SpringDashpotSpec, materials: &[String]) -> Result<Self, ParamError> {
        let (e, t_c) = super::restitution::given_pair(s.restitution, s.contact_time)?;
        super::restitution::refuse(
            &[
                ("k_n", s.k_n.is_some()),
                ("gamma_n", s.gamma_n != 0.0),
                ("k_t", s.k_t != 0.0),
                ("gamma_t", s.gamma_t != 0.0),
            ],
            "belongs to the stiffness form: with restitution and contact_time the law resolves it (use kt_ratio and gamma_t_ratio for the tangential spring)",
        )?;
        // The linear law's e and t_c hold at every speed (closed forms); a nonlinear
        // law's only at the speed they are asked for, which must then be given.
        let linear = s.nu == 1.0 && s.psi == 0.0;
        let power = if linear {
            super::restitution::refuse(
                &[
                    ("delta0", s.delta0.is_some()),
                    ("impact_speed", s.impact_speed.is_some()),
                ],
                "is for a nonlinear law (nu ≠ 1 or psi ≠ 0): the linear law's restitution and contact time hold at every speed",
            )?;
            None
        } else {
            if !(s.nu >= 1.0 && s.nu <= 3.0 && s.psi >= 0.0 && s.psi <= 3.0) {
                return Err(ParamError::invalid(
                    "contact.nu",
                    format!(
                        "must be in [1, 3] with psi in [0, 3], got nu = {}, psi = {}",
                        s.nu, s.psi
                    ),
                ));
            }
            let Some(delta0) = s.delta0 else {
                return Err(ParamError::invalid(
                    "contact.delta0",
                    "is required when nu ≠ 1 or psi ≠ 0",
                ));
            };
            let Some(v) = s.impact_speed else {
                return Err(ParamError::invalid(
                    "contact.impact_speed",
                    "is required for restitution and contact_time with a nonlinear law (nu ≠ 1 or psi ≠ 0): they hold at that relative speed of a head-on collision only",
                ));
            };
            Some((
                positive("contact.delta0", delta0)?,
                positive("contact.impact_speed", v)?,
            ))
        };
        let kt_ratio = non_negative("contact.kt_ratio", s.kt_ratio.unwrap_or(DEFAULT_KT_RATIO))?;
        let gt_ratio = non_negative("contact.gamma_t_ratio", s.gamma_t_ratio.unwrap_or(0.0))?;
        let form = super::restitution::MaterialForm {
            restitution: e,
            contact_time: t_c,
            mu: s.mu,
            pairs: &s.pairs,
        };
        let table = super::restitution::pair_table(&form, materials, |at, e, t_c, mu, _, _| {
            let mu = non_negative(&format!("{at}.mu"), mu)?;
            let (k_n, gamma_n) = match power {
                None => super::restitution::resolve_linear(at, e, t_c, s.clamp)?,
                Some((delta0, v)) => {
                    positive(&format!("{at}.contact_time"), t_c)?;
                    super::restitution::per_mass_power(e, t_c, v, (s.nu, s.psi, delta0), s.clamp)
                        .ok_or_else(|| {
                            ParamError::invalid(
                                format!("{at}.restitution"),
                                format!(
                                    "must be in (0, 1] and reachable by damping the law (got {e})"
                                ),
                            )
                        })?
                }
            };
            Ok(PerMass {
                k_n,
                gamma_n,
                k_t: kt_ratio * k_n,
                gamma_t: gt_ratio * gamma_n,
                mu,
            })
        })?;
        let base = table.coeffs[0];
        Ok(Self {
            k_n: base.k_n,
            nu: s.nu,
            psi: s.psi,
            delta0: power.map_or(1.0, |p| p.0),
            impact_speed: power.map(|p| p.1),
            gamma_n: base.gamma_n,
            k_t: base.k_t,
            gamma_t: base.gamma_t,
            mu: s.mu,
            clamp: s.clamp,
            pairs: Some(table),
        })
    }

    /// The restitution and overlap time of a head-on collision under a pair's
    /// coefficients (at `impact_speed` for a nonlinear law).
    pub fn collision(&self, c: &PerMass) -> Option<(f64, f64)> {
        match self.impact_speed {
            None => super::restitution::collision(c.k_n, c.gamma_n, self.clamp),
            Some(v) => super::restitution::collision_power(
                c.k_n,
                c.gamma_n,
                v,
                (self.nu, self.psi, self.delta0),
                self.clamp,
            ),
        }
    }

    /// The material form's table as the scene records it (`contact.resolved`).
    pub fn resolved(&self, materials: &[String]) -> Vec<ResolvedPair> {
        let Some(t) = &self.pairs else {
            return Vec::new();
        };
        super::restitution::resolved(t, materials, |_, _, c| self.collision(c), false)
    }

    /// The coefficients of one contact: (k_n, γ_n, k_t, γ_t, μ).
    #[inline(always)]
    fn coefficients(&self, c: &ContactInput) -> (f64, f64, f64, f64, f64) {
        match &self.pairs {
            None => (self.k_n, self.gamma_n, self.k_t, self.gamma_t, self.mu),
            Some(t) => {
                let p = t.get(c.pair);
                let m = c.m_eff;
                (p.k_n * m, p.gamma_n * m, p.k_t * m, p.gamma_t * m, p.mu)
            }
        }
    }

    /// WGSL twin: `spring_dashpot` in shaders/laws.wgsl (its coefficients from `Params`).
    #[inline(always)]
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let (k_n, gamma_n, k_t, gamma_t, mu) = self.coefficients(c);
        let f_el = elastic_force(k_n, self.delta0, self.nu, c.delta);
        let f_diss = dissipative_force(gamma_n, self.delta0, self.psi, c.delta, c.delta_dot);
        let f_n = if self.clamp {
            clamp_non_negative(f_el + f_diss)
        } else {
            f_el + f_diss
        };
        let (f_t, xi) = coulomb_spring(c.history, c.v_t, c.dt, k_t, gamma_t, mu, f_n);
        let energy = elastic_energy(k_n, self.delta0, self.nu, c.delta) + spring_energy(k_t, xi);
        ContactOutput {
            f_n,
            f_t,
            history: xi,
            energy,
            lever: 0.0,
        }
    }

    /// ω0² = k/m12 with k the stiffness dF/dδ: k_n for ν = 1, else taken at an overlap of
    /// [`REFERENCE_OVERLAP`] of the diameter σ.
    /// In the material form ω0² is the pair's k_n per unit mass, whatever the masses:
    /// the stiffest pair's.
    pub fn omega0_squared(&self, m12: f64, sigma: f64) -> f64 {
        if let Some(t) = &self.pairs {
            return t.coeffs.iter().map(|c| c.k_n).fold(0.0, f64::max);
        }
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

pub(crate) fn positive(path: &str, v: f64) -> Result<f64, ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ParamError::invalid(
            path,
            format!("must be positive, got {v}"),
        ))
    }
}

pub(crate) fn non_negative(path: &str, v: f64) -> Result<f64, ParamError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(ParamError::invalid(
            path,
            format!("must be zero or positive, got {v}"),
        ))
    }
}

impl SpringDashpot {
    /// `talus check`'s table of the spring-dashpot law per pair of materials: the
    /// coefficients, and the restitution and contact time they give, for typical particles
    /// (`masses`, by material: `scene::typical_masses`) colliding with a moving one and with
    /// a fixed one or a wall (infinitely heavy).
    pub fn describe(&self, materials: &[String], masses: &[Option<f64>]) -> Vec<String> {
        let law = self;
        let clamp = if law.clamp {
            "clamped f_n ≥ 0"
        } else {
            "unclamped"
        };
        let mut out = Vec::new();
        let linear = law.nu == 1.0 && law.psi == 0.0;
        match &law.pairs {
            Some(_) => out.push(format!(
                "contact: material form ({clamp}{}): every contact has k = m_eff · k/m of its pair, m_eff its reduced mass (a fixed partner or a wall infinitely heavy)",
                match law.impact_speed {
                    Some(v) => format!(", ν = {}, ψ = {}: e and t_c at the impact speed {v}", law.nu, law.psi),
                    None => String::new(),
                }
            )),
            None if linear => out.push(format!(
                "contact: stiffness form ({clamp}): k_n = {}, γ_n = {}, k_t = {}, γ_t = {}, μ = {}; what they give:",
                law.k_n, law.gamma_n, law.k_t, law.gamma_t, law.mu
            )),
            None => {
                out.push(format!(
                    "contact: nonlinear spring-dashpot (ν = {}, ψ = {}): restitution and contact time depend on the impact speed, not tabulated",
                    law.nu, law.psi
                ));
                return out;
            }
        }
        let side = materials.len() + 1;
        let name = |k: usize| {
            materials
                .get(k)
                .map_or(crate::law::spec::WALLS, |s| s.as_str())
        };
        // One line per pair and per kind of partner: (m_eff, what it is).
        let collide = |kappa: f64, c: f64| match super::restitution::collision(kappa, c, law.clamp)
        {
            Some((e, t_c)) => format!("e {e:.3}, t_c {t_c:.3e}"),
            None => "no bounce (overdamped)".to_string(),
        };
        for a in 0..materials.len() {
            let Some(ma) = masses[a] else { continue };
            for b in a..side {
                let partners: Vec<(f64, String)> = if b == side - 1 {
                    vec![(ma, "a wall".to_string())]
                } else {
                    let Some(mb) = masses[b] else { continue };
                    vec![
                        (ma * mb / (ma + mb), "two moving".to_string()),
                        (ma, format!("a moving {} on a fixed {}", name(a), name(b))),
                    ]
                };
                let pair = format!("  {}–{}:", name(a), name(b));
                match &law.pairs {
                    Some(t) => {
                        let p = t.coeffs[a * t.side + b];
                        let bounce = match law.collision(&p) {
                            Some((e, t_c)) => format!("e {e:.3}, t_c {t_c:.3e}"),
                            None => "no bounce (overdamped)".to_string(),
                        };
                        let mut line = format!(
                            "{pair} {bounce}, μ {}; per unit mass k_n {:.4e}, γ_n {:.4e}, k_t {:.4e}, γ_t {:.4e}",
                            p.mu, p.k_n, p.gamma_n, p.k_t, p.gamma_t
                        );
                        for (m, what) in partners {
                            line += &format!(
                                "; {what} (m_eff {m:.4}): k_n {:.4e}, γ_n {:.4e}",
                                p.k_n * m,
                                p.gamma_n * m
                            );
                        }
                        out.push(line);
                    }
                    None => {
                        let parts: Vec<String> = (partners.iter())
                            .map(|(m, what)| {
                                format!(
                                    "{what} (m_eff {m:.4}): {}",
                                    collide(law.k_n / m, law.gamma_n / m)
                                )
                            })
                            .collect();
                        out.push(format!("{pair} {}", parts.join("; ")));
                    }
                }
            }
        }
        out
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
            pairs: None,
            impact_speed: None,
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
