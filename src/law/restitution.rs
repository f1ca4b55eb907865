//! Materials given as a restitution coefficient e and a contact time t_c instead of a
//! stiffness and a damping (issue 20): the linear spring-dashpot's closed forms, and the
//! table of coefficients per pair of materials.
//!
//! The head-on collision of the linear law, m δ̈ = −k δ − γ δ̇ with m the pair's reduced
//! mass, depends on k and γ only through ω0² = k/m and β = γ/(2m) (paper 000 sec. 2.1).
//! So the coefficients are resolved *per unit of reduced mass*, κ = k/m and c = γ/m, and
//! each contact multiplies them by its own reduced mass m_eff (a fixed particle or a wall
//! counted as infinitely heavy: m_eff is then the moving particle's mass). Every pair,
//! moving or resting on the base, light or heavy, then collides with the e and t_c asked
//! for; this is how LIGGGHTS resolves its `coefficientRestitution` per contact from the
//! effective mass. The price: a heavier pair is stiffer (k ∝ m_eff).
//!
//! With δ(t) = (v0/ω) e^(−βt) sin ωt, ω² = ω0² − β², η = β/ω:
//! - unclamped (the textbook law, `clamp: false`): the contact lasts t_c = π/ω and
//!   e = exp(−η π);
//! - clamped (SPEC 2's f_n ≥ 0, the default): the force k δ + γ δ̇ vanishes at ω t* = φ(η)
//!   = π − 2 arctan η, where δ̇ = −v0 e^(−βt*), so e = exp(−η φ(η)) (Schwager & Pöschel,
//!   Granular Matter 9, 465 (2007)); the disks then fly apart with δ(t*) = (v0/ω) e^(−βt*)
//!   sin φ still to close, which takes sin φ / ω more. `contact_time` is the whole time
//!   the surfaces overlap, t_c = (φ + sin φ)/ω: what the head-on test measures, and π/ω
//!   again as η → 0. Under the clamp e > e^(−2) ≈ 0.135 (η → ∞).

use super::spec::ParamError;
use std::f64::consts::PI;

/// φ(η) = ω t*, the phase at which the clamped law's force vanishes.
fn clamped_phase(eta: f64) -> f64 {
    PI - 2.0 * eta.atan()
}

/// The smallest restitution the clamped linear law reaches (η → ∞): e^(−2).
pub const CLAMPED_MIN_RESTITUTION: f64 = 0.135_335_283_236_612_7;

/// η = β/ω of the linear law with restitution e; None when no damping gives it.
pub fn eta_for(e: f64, clamp: bool) -> Option<f64> {
    if !(e > 0.0 && e <= 1.0) {
        return None;
    }
    let target = -e.ln();
    if !clamp {
        return Some(target / PI);
    }
    if e <= CLAMPED_MIN_RESTITUTION {
        return None;
    }
    // η φ(η) rises monotonically from 0 to 2: bisect (60 halvings of a bracket that
    // doubles until it holds the root give η to the last bits).
    let f = |eta: f64| eta * clamped_phase(eta) - target;
    let mut hi = 1.0;
    while f(hi) < 0.0 {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= f64::EPSILON * hi {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The restitution and overlap time of the linear law with ω0² = κ and β = c/2 (the
/// inverse of [`per_mass`]); None when it does not bounce (β ≥ ω0).
pub fn collision(kappa: f64, c: f64, clamp: bool) -> Option<(f64, f64)> {
    let beta = 0.5 * c;
    let w2 = kappa - beta * beta;
    if w2.is_nan() || w2 <= 0.0 {
        return None;
    }
    let omega = w2.sqrt();
    let eta = beta / omega;
    Some(if clamp {
        let phi = clamped_phase(eta);
        ((-eta * phi).exp(), (phi + phi.sin()) / omega)
    } else {
        ((-eta * PI).exp(), PI / omega)
    })
}

/// The normal coefficients per unit of reduced mass, (κ = k_n/m, c = γ_n/m), that give
/// restitution e and contact time t_c (module docs); None when e is out of reach.
pub fn per_mass(e: f64, t_c: f64, clamp: bool) -> Option<(f64, f64)> {
    let eta = eta_for(e, clamp)?;
    let phase = if clamp {
        let phi = clamped_phase(eta);
        phi + phi.sin()
    } else {
        PI
    };
    let omega = phase / t_c;
    let beta = eta * omega;
    Some((omega * omega + beta * beta, 2.0 * beta))
}

/// The power law's head-on collision in its own units (the nonlinear spring-dashpot,
/// paper 000 eq. 2–3): x'' = −x^ν − D x^ψ x' from x = 0, x' = 1 (the force clamped at 0
/// when `clamp`), with δ = X x, t = (X/v) τ (below). Returns (e, τ_c): the rebound
/// speed and the time x > 0; None when the pair does not come apart within τ = 10³.
/// Fourth-order Runge–Kutta at dτ = 10⁻⁴, the crossing of x = 0 interpolated.
fn power_collision(nu: f64, psi: f64, d: f64, clamp: bool) -> Option<(f64, f64)> {
    let accel = |x: f64, u: f64| {
        let x = x.max(0.0);
        let f = x.powf(nu) + d * x.powf(psi) * u;
        -(if clamp { f.max(0.0) } else { f })
    };
    let h = 1e-4;
    let (mut x, mut u, mut tau) = (0.0f64, 1.0f64, 0.0f64);
    while tau < 1e3 {
        let (k1x, k1u) = (u, accel(x, u));
        let (k2x, k2u) = (
            u + 0.5 * h * k1u,
            accel(x + 0.5 * h * k1x, u + 0.5 * h * k1u),
        );
        let (k3x, k3u) = (
            u + 0.5 * h * k2u,
            accel(x + 0.5 * h * k2x, u + 0.5 * h * k2u),
        );
        let (k4x, k4u) = (u + h * k3u, accel(x + h * k3x, u + h * k3u));
        let nx = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        let nu_ = u + h / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u);
        if tau > 0.0 && nx <= 0.0 {
            let f = x / (x - nx);
            return Some((-(u + f * (nu_ - u)), tau + f * h));
        }
        (x, u, tau) = (nx, nu_, tau + h);
    }
    None
}

/// The nonlinear law's coefficients per unit of reduced mass, (κ, c) with k_n = m κ and
/// γ_n = m c in f = k_n δ0 (δ/δ0)^ν + γ_n (δ/δ0)^ψ δ̇, that give restitution e and
/// overlap time t_c in a head-on collision at the relative speed v. Per unit mass the
/// collision is δ̈ = −κ' δ^ν − c' δ^ψ δ̇ (κ' = κ δ0^(1−ν), c' = c δ0^(−ψ)); with X =
/// (v²/κ')^(1/(ν+1)) and T = X/v it is [`power_collision`] with D = c' X^(ψ+1)/v. So D
/// follows from e alone (bisection: e falls as D grows), then T = t_c/τ_c. Unlike the
/// linear law's, e and t_c then hold at that speed only (Hertz: t_c ∝ v^(−1/5)).
pub fn per_mass_power(
    e: f64,
    t_c: f64,
    v: f64,
    (nu, psi, delta0): (f64, f64, f64),
    clamp: bool,
) -> Option<(f64, f64)> {
    if !(e > 0.0 && e <= 1.0 && t_c > 0.0 && v > 0.0) {
        return None;
    }
    let e_of = |d: f64| power_collision(nu, psi, d, clamp).map_or(0.0, |r| r.0);
    let mut hi = 1.0;
    while e_of(hi) > e {
        hi *= 2.0;
        if hi > 1e4 {
            return None;
        }
    }
    let mut lo = 0.0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if e_of(mid) > e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let d = 0.5 * (lo + hi);
    let (_, tau) = power_collision(nu, psi, d, clamp)?;
    let x = v * t_c / tau;
    let kappa = v * v / x.powf(nu + 1.0) * delta0.powf(nu - 1.0);
    let c = d * v / x.powf(psi + 1.0) * delta0.powf(psi);
    Some((kappa, c))
}

/// The restitution and overlap time the nonlinear law's (κ, c) give at speed v (the
/// inverse of [`per_mass_power`]).
pub fn collision_power(
    kappa: f64,
    c: f64,
    v: f64,
    (nu, psi, delta0): (f64, f64, f64),
    clamp: bool,
) -> Option<(f64, f64)> {
    let k1 = kappa * delta0.powf(1.0 - nu);
    let c1 = c * delta0.powf(-psi);
    let x = (v * v / k1).powf(1.0 / (nu + 1.0));
    let (e, tau) = power_collision(nu, psi, c1 * x.powf(psi + 1.0) / v, clamp)?;
    Some((e, tau * x / v))
}

/// The first of `keys` given, as the error `contact.KEY: reason`.
pub fn refuse(keys: &[(&str, bool)], reason: &str) -> Result<(), ParamError> {
    match keys.iter().find(|(_, given)| *given) {
        Some((key, _)) => Err(ParamError::invalid(format!("contact.{key}"), reason)),
        None => Ok(()),
    }
}

/// The material form's (e, t_c), both required once either is given.
pub fn given_pair(e: Option<f64>, t_c: Option<f64>) -> Result<(f64, f64), ParamError> {
    match (e, t_c) {
        (Some(e), Some(t_c)) => Ok((e, t_c)),
        (None, _) => Err(missing("restitution")),
        (_, None) => Err(missing("contact_time")),
    }
}

fn missing(key: &str) -> ParamError {
    ParamError::invalid(
        format!("contact.{key}"),
        "is required with the other of restitution and contact_time (the material form)",
    )
}

/// One pair of materials' coefficients per unit of the contact's reduced mass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PerMass {
    /// k_n/m (1/time²), γ_n/m (1/time), k_t/m, γ_t/m; for the overlap-area law γ_n and
    /// γ_t hold its dimensionless η^n and η^t (src/law/overlap_area.rs).
    pub k_n: f64,
    pub gamma_n: f64,
    pub k_t: f64,
    pub gamma_t: f64,
    pub mu: f64,
}

/// The material form of a contact block: e, t_c and μ for every pair, and the pairs with
/// values of their own.
pub struct MaterialForm<'a> {
    pub restitution: f64,
    pub contact_time: f64,
    pub mu: f64,
    pub pairs: &'a [crate::law::spec::MaterialPair],
}

/// The pair table of a material form: `resolve(at, e, t_c, μ, a, b)` gives the
/// coefficients of materials a and b (b = materials: the walls) from the values that
/// apply to them, `at` naming the key they come from (for its errors).
pub fn pair_table(
    form: &MaterialForm,
    materials: &[String],
    resolve: impl Fn(&str, f64, f64, f64, usize, usize) -> Result<PerMass, ParamError>,
) -> Result<PairTable, ParamError> {
    use super::spec::WALLS;
    if !form.pairs.is_empty() && materials.iter().any(|m| m == WALLS) {
        return Err(ParamError::invalid(
            format!("materials.{WALLS}"),
            format!("\"{WALLS}\" names the wall segments in contact.pairs: rename the material"),
        ));
    }
    let side = materials.len() + 1;
    // Which entry of `pairs` each unordered pair takes its values from.
    let mut own = std::collections::BTreeMap::new();
    for (k, p) in form.pairs.iter().enumerate() {
        let at = format!("contact.pairs[{k}]");
        let index = |name: &str| -> Result<usize, ParamError> {
            if name == WALLS {
                return Ok(side - 1);
            }
            materials.iter().position(|m| m == name).ok_or_else(|| {
                ParamError::invalid(
                    format!("{at}.materials"),
                    format!(
                        "unknown material \"{name}\" (known: {}, and \"{WALLS}\")",
                        materials.join(", ")
                    ),
                )
            })
        };
        let (a, b) = (index(&p.materials[0])?, index(&p.materials[1])?);
        if a == side - 1 && b == side - 1 {
            return Err(ParamError::invalid(
                format!("{at}.materials"),
                "walls do not touch walls",
            ));
        }
        if own.insert((a.min(b), a.max(b)), k).is_some() {
            return Err(ParamError::invalid(
                format!("{at}.materials"),
                "this pair is listed twice",
            ));
        }
    }
    let mut coeffs = vec![PerMass::default(); side * side];
    for a in 0..side {
        for b in a..side {
            let (at, e, t_c, mu) = match own.get(&(a, b)) {
                Some(&k) => {
                    let p = &form.pairs[k];
                    (
                        format!("contact.pairs[{k}]"),
                        p.restitution.unwrap_or(form.restitution),
                        p.contact_time.unwrap_or(form.contact_time),
                        p.mu.unwrap_or(form.mu),
                    )
                }
                None => (
                    "contact".to_string(),
                    form.restitution,
                    form.contact_time,
                    form.mu,
                ),
            };
            if a == side - 1 {
                continue;
            }
            let c = resolve(&at, e, t_c, mu, a, b)?;
            coeffs[a * side + b] = c;
            coeffs[b * side + a] = c;
        }
    }
    Ok(PairTable { side, coeffs })
}

/// (κ, c) of [`per_mass`] or the key's error: e out of reach, t_c not positive.
pub fn resolve_linear(at: &str, e: f64, t_c: f64, clamp: bool) -> Result<(f64, f64), ParamError> {
    if !(t_c.is_finite() && t_c > 0.0) {
        return Err(ParamError::invalid(
            format!("{at}.contact_time"),
            format!("must be positive, got {t_c}"),
        ));
    }
    per_mass(e, t_c, clamp).ok_or_else(|| {
        let range = if clamp {
            format!(
                "in ({:.4}, 1] under the clamp f_n ≥ 0 (set clamp: false for less)",
                CLAMPED_MIN_RESTITUTION
            )
        } else {
            "in (0, 1]".to_string()
        };
        ParamError::invalid(
            format!("{at}.restitution"),
            format!("must be {range}, got {e}"),
        )
    })
}

/// The table as the scene records it (`contact.resolved`): each unordered pair once,
/// walls last; `collide` gives the (e, t_c) a pair's coefficients give.
pub fn resolved(
    table: &PairTable,
    materials: &[String],
    collide: impl Fn(usize, usize, &PerMass) -> Option<(f64, f64)>,
    eta: bool,
) -> Vec<crate::law::spec::ResolvedPair> {
    let name = |k: usize| {
        materials
            .get(k)
            .cloned()
            .unwrap_or_else(|| crate::law::spec::WALLS.to_string())
    };
    let mut out = Vec::new();
    for a in 0..table.side - 1 {
        for b in a..table.side {
            let c = table.coeffs[a * table.side + b];
            let (e, t_c) = collide(a, b, &c).unwrap_or((f64::NAN, f64::NAN));
            let (rates, etas) = if eta {
                (None, Some((c.gamma_n, c.gamma_t)))
            } else {
                (Some((c.gamma_n, c.gamma_t)), None)
            };
            out.push(crate::law::spec::ResolvedPair {
                materials: [name(a), name(b)],
                restitution: e,
                contact_time: t_c,
                mu: c.mu,
                k_n_per_mass: c.k_n,
                k_t_per_mass: c.k_t,
                gamma_n_per_mass: rates.map(|r| r.0),
                gamma_t_per_mass: rates.map(|r| r.1),
                eta_n: etas.map(|r| r.0),
                eta_t: etas.map(|r| r.1),
            });
        }
    }
    out
}

/// The coefficients of every pair of materials: `side` = materials + 1, the last row and
/// column for the walls. Symmetric; a contact looks its pair up by [`PairTable::slot`].
#[derive(Clone, Debug, PartialEq)]
pub struct PairTable {
    pub side: usize,
    pub coeffs: Vec<PerMass>,
}

impl PairTable {
    /// The table's index of a contact between materials a and b (b = `side − 1`: a wall).
    #[inline(always)]
    pub fn slot(side: usize, a: u32, b: u32) -> u32 {
        a * side as u32 + b
    }

    #[inline(always)]
    pub fn get(&self, slot: u32) -> &PerMass {
        &self.coeffs[slot as usize]
    }

    /// The index of the walls' row.
    pub fn walls(&self) -> u32 {
        self.side as u32 - 1
    }
}

/// The effective mass of a contact: the reduced mass, with a fixed partner (or a wall,
/// `j = None`) infinitely heavy.
#[inline(always)]
pub fn effective_mass(mi: f64, fixed_i: bool, j: Option<(f64, bool)>) -> f64 {
    match j {
        None => mi,
        Some((_, true)) if !fixed_i => mi,
        Some((mj, false)) if fixed_i => mj,
        Some((mj, _)) => mi * mj / (mi + mj),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_mass_and_collision_are_inverse() {
        for clamp in [false, true] {
            for e in [0.2, 0.5, 0.6, 0.9, 0.999, 1.0] {
                let (kappa, c) = per_mass(e, 0.05, clamp).unwrap();
                let (e2, t2) = collision(kappa, c, clamp).unwrap();
                assert!((e2 - e).abs() < 1e-12, "{clamp} {e}: {e2}");
                assert!((t2 - 0.05).abs() < 1e-12, "{clamp} {e}: {t2}");
            }
        }
    }

    #[test]
    fn the_power_law_solver_gives_the_linear_closed_forms() {
        // ν = 1, ψ = 0 is the linear law: the numerical route must land on its closed
        // forms, whatever the speed and δ0.
        for clamp in [false, true] {
            for e in [0.3, 0.75, 0.95] {
                let (kappa, c) = per_mass(e, 0.05, clamp).unwrap();
                let (k2, c2) = per_mass_power(e, 0.05, 3.0, (1.0, 0.0, 0.2), clamp).unwrap();
                assert!(
                    (k2 / kappa - 1.0).abs() < 1e-6,
                    "{clamp} {e}: κ {k2} vs {kappa}"
                );
                assert!((c2 / c - 1.0).abs() < 1e-6, "{clamp} {e}: c {c2} vs {c}");
            }
        }
        // Hertz round trip, and the speed dependence: t_c ∝ v^(−1/5) without damping.
        let law = (1.5, 0.5, 0.01);
        let (k, c) = per_mass_power(0.6, 0.02, 1.0, law, true).unwrap();
        let (e, t) = collision_power(k, c, 1.0, law, true).unwrap();
        assert!((e - 0.6).abs() < 1e-9 && (t - 0.02).abs() < 1e-9, "{e} {t}");
        let (k, _) = per_mass_power(1.0, 0.02, 1.0, law, true).unwrap();
        let (_, t2) = collision_power(k, 0.0, 32.0, law, true).unwrap();
        assert!((t2 / 0.02 - 0.5).abs() < 1e-6, "{t2}");
    }

    #[test]
    fn clamped_restitution_has_a_floor() {
        assert!(eta_for(0.13, true).is_none());
        assert!(eta_for(0.14, true).is_some());
        assert!(eta_for(0.13, false).is_some());
        assert!(eta_for(0.0, false).is_none());
        assert!(eta_for(1.5, false).is_none());
        assert_eq!(CLAMPED_MIN_RESTITUTION, (-2.0f64).exp());
    }

    #[test]
    fn effective_mass_counts_fixed_partners_as_infinitely_heavy() {
        assert_eq!(effective_mass(2.0, false, None), 2.0);
        assert_eq!(effective_mass(2.0, false, Some((2.0, false))), 1.0);
        assert_eq!(effective_mass(2.0, false, Some((5.0, true))), 2.0);
        assert_eq!(effective_mass(2.0, true, Some((3.0, false))), 3.0);
    }
}
