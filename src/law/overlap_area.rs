//! The overlap-area law of convex polygons, paper 000 eq. 6–7 and sec. 2.2.2 (SPEC 2.3).
//!
//! The geometry (src/overlap/) gives the overlap area A, the reduced arm l and the
//! chord L. The force stage passes δ = A/l (the length that plays the role of the disk
//! overlap) and its rate d(A/l)/dt ≈ L v_n / l: for a relative translation the overlap
//! area changes at exactly L v_n (v_n the approach speed across the chord), and the
//! slow change of l is neglected. Relative velocities rather than the previous step's
//! A/l keep the damping at the predicted state, where Gear evaluates every force.

use super::restitution::{PairTable, PerMass};
use super::spec::{OverlapAreaSpec, ParamError, ResolvedPair};
use super::tangential::{coulomb_spring, spring_energy};
use super::{ContactInput, ContactOutput, clamp_non_negative};

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
    /// The material form (`restitution` and `contact_time`): per pair of materials k^n
    /// and k^t per unit of the contact's effective mass m_eff, and η^n, η^t (in the
    /// table's γ fields), with γ = η sqrt(m_eff k). None: the stiffness form above.
    pub pairs: Option<PairTable>,
    /// The material form's calibration: L/l of a face-to-face contact per pair of
    /// materials (`face_factor`), by the table's slots.
    pub faces: Vec<f64>,
}

/// Stiffness of a flat face-to-face contact relative to k^n for the time-step check:
/// f = k^n A/l = (k^n L/l) δ, and L/l is about 2 for the faces of polygons with 6 or
/// more corners (L ≈ the side, l ≈ half the inradius).
pub const FACE_STIFFNESS: f64 = 2.0;

/// L/l of a face-to-face contact of regular polygons of equal inradius a with `ci` and
/// `cj` corners (`cj` None: a wall), which calibrates the material form. The faces
/// overlap along the shorter side, L = 2a tan(π/C) with C the larger corner count; l =
/// 1/(1/l_i + 1/l_j) with l_i ≈ a (the force point on the face), so L/l = 4 tan(π/C), and
/// 2 tan(π/C_i) against a wall (l = l_i). A disk (`ci` or `cj` 0) has no flat face: its
/// overlap area grows as δ^{3/2}, and [`FACE_STIFFNESS`] stands in.
pub fn face_factor(ci: u32, cj: Option<u32>) -> f64 {
    use std::f64::consts::PI;
    match cj {
        _ if ci == 0 => FACE_STIFFNESS,
        Some(0) => FACE_STIFFNESS,
        None => 2.0 * (PI / ci as f64).tan(),
        Some(cj) => 4.0 * (PI / ci.max(cj) as f64).tan(),
    }
}

impl OverlapArea {
    /// `materials`: the scene's material names in index order; `corners`: each
    /// material's polygons' corner count (0 for disks), for the material form.
    pub fn from_spec(
        s: &OverlapAreaSpec,
        materials: &[String],
        corners: &[u32],
    ) -> Result<Self, ParamError> {
        use super::spring_dashpot::{non_negative, positive};
        non_negative("contact.mu", s.mu)?;
        non_negative("contact.kt_ratio", s.kt_ratio)?;
        non_negative("contact.eta_t", s.eta_t)?;
        if s.restitution.is_some() || s.contact_time.is_some() {
            return Self::from_material_form(s, materials, corners);
        }
        if !s.pairs.is_empty() {
            return Err(ParamError::invalid(
                "contact.pairs",
                "belongs to the material form: give restitution and contact_time instead of k_n",
            ));
        }
        let Some(k_n) = s.k_n else {
            return Err(ParamError::invalid(
                "contact.k_n",
                "is required (or give restitution and contact_time, the material form)",
            ));
        };
        positive("contact.k_n", k_n)?;
        non_negative("contact.eta_n", s.eta_n)?;
        Ok(Self {
            k_n,
            eta_n: s.eta_n,
            mu: s.mu,
            k_t: s.kt_ratio * k_n,
            eta_t: s.eta_t,
            pairs: None,
            faces: Vec::new(),
        })
    }

    /// The material form, calibrated on the head-on collision of two faces: there
    /// f = k^n (L/l) p in the penetration p and the damping acts on p with γ L/l, so with
    /// g = L/l the contact is the linear law with ω0² = g k^n/m_eff and damping ratio
    /// β/ω0 = η^n sqrt(g)/2 (the law is always clamped). k^n/m_eff = κ/g and η^n = c/sqrt(κ g)
    /// with (κ, c) the linear law's (src/law/restitution.rs). Corner impacts, unequal
    /// sizes and irregular polygons have other L/l: for them e and t_c are approximate.
    fn from_material_form(
        s: &OverlapAreaSpec,
        materials: &[String],
        corners: &[u32],
    ) -> Result<Self, ParamError> {
        let (e, t_c) = super::restitution::given_pair(s.restitution, s.contact_time)?;
        super::restitution::refuse(
            &[("k_n", s.k_n.is_some()), ("eta_n", s.eta_n != 0.0)],
            "belongs to the stiffness form: with restitution and contact_time the law resolves it",
        )?;
        let side = materials.len() + 1;
        let form = super::restitution::MaterialForm {
            restitution: e,
            contact_time: t_c,
            mu: s.mu,
            pairs: &s.pairs,
        };
        let walls = side - 1;
        let face = |a: usize, b: usize| match (a.min(b), a.max(b)) {
            (w, _) if w == walls => FACE_STIFFNESS, // walls on walls: never used
            (a, b) => face_factor(corners[a], (b < walls).then(|| corners[b])),
        };
        let table = super::restitution::pair_table(&form, materials, |at, e, t_c, mu, a, b| {
            let mu = super::spring_dashpot::non_negative(&format!("{at}.mu"), mu)?;
            let (kappa, c) = super::restitution::resolve_linear(at, e, t_c, true)?;
            let g = face(a, b);
            Ok(PerMass {
                k_n: kappa / g,
                gamma_n: c / (kappa * g).sqrt(),
                k_t: s.kt_ratio * kappa / g,
                gamma_t: s.eta_t,
                mu,
            })
        })?;
        let faces = (0..side * side).map(|k| face(k / side, k % side)).collect();
        let base = table.coeffs[0];
        Ok(Self {
            k_n: base.k_n,
            eta_n: base.gamma_n,
            mu: s.mu,
            k_t: base.k_t,
            eta_t: s.eta_t,
            pairs: Some(table),
            faces,
        })
    }

    /// The material form's table as the scene records it (`contact.resolved`): the
    /// e and t_c of each pair's face-to-face collision.
    pub fn resolved(&self, materials: &[String]) -> Vec<ResolvedPair> {
        let Some(t) = &self.pairs else {
            return Vec::new();
        };
        super::restitution::resolved(
            t,
            materials,
            |a, b, c| {
                let g = self.faces[a * t.side + b];
                let kappa = c.k_n * g;
                super::restitution::collision(kappa, c.gamma_n * (kappa * g).sqrt(), true)
            },
            true,
        )
    }

    /// `talus check`'s lines on the material form: per pair of materials the face-to-face
    /// e and t_c, the L/l they were calibrated with, and the coefficients.
    pub fn describe(&self, materials: &[String]) -> Vec<String> {
        let Some(t) = &self.pairs else {
            return Vec::new();
        };
        let mut out = vec![
            "contact: overlap-area law, material form: per pair, k^n = m_eff · k^n/m and γ = η sqrt(m_eff k) (m_eff the reduced mass, a fixed partner or a wall infinitely heavy), calibrated on a face-to-face collision with the pair's L/l (src/law/overlap_area.rs)".to_string(),
        ];
        for r in self.resolved(materials) {
            let a = materials
                .iter()
                .position(|m| *m == r.materials[0])
                .unwrap_or(t.side - 1);
            let b = materials
                .iter()
                .position(|m| *m == r.materials[1])
                .unwrap_or(t.side - 1);
            out.push(format!(
                "  {}–{}: e {:.3}, t_c {:.3e} face to face (L/l {:.3}), μ {}; k^n/m {:.4e}, η^n {:.4}, k^t/m {:.4e}, η^t {}",
                r.materials[0],
                r.materials[1],
                r.restitution,
                r.contact_time,
                self.faces[a * t.side + b],
                r.mu,
                r.k_n_per_mass,
                r.eta_n.unwrap_or(f64::NAN),
                r.k_t_per_mass,
                r.eta_t.unwrap_or(f64::NAN),
            ));
        }
        out
    }

    /// c.delta = A/l, c.delta_dot = d(A/l)/dt, c.r = the penetration depth A/L (for the
    /// energy; 0 when the chord vanishes).
    /// WGSL twin: `overlap_area` in shaders/laws.wgsl (its coefficients from `Params`).
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        let (k_n, eta_n, k_t, eta_t, mu, m) = match &self.pairs {
            None => (self.k_n, self.eta_n, self.k_t, self.eta_t, self.mu, c.m12),
            Some(t) => {
                let p = t.get(c.pair);
                let m = c.m_eff;
                (p.k_n * m, p.gamma_n, p.k_t * m, p.gamma_t, p.mu, m)
            }
        };
        let gamma_n = eta_n * (m * k_n).sqrt();
        let gamma_t = eta_t * (m * k_t).sqrt();
        let f_el = k_n * c.delta; // eq. 6
        let f_n = clamp_non_negative(f_el + gamma_n * c.delta_dot); // eq. 7
        let (f_t, xi) = coulomb_spring(c.history, c.v_t, c.dt, k_t, gamma_t, mu, f_n);
        // For a flat contact f_el = (k^n L/l) δ with the depth δ = A/L: energy f_el δ / 2.
        let energy = 0.5 * f_el * c.r + spring_energy(k_t, xi);
        ContactOutput {
            f_n,
            f_t,
            history: xi,
            energy,
            lever: 0.0,
        }
    }

    /// In the material form ω0² is the stiffest pair's face stiffness per unit mass,
    /// whatever the masses.
    pub fn omega0_squared(&self, m12: f64) -> f64 {
        if let Some(t) = &self.pairs {
            let faces = t.coeffs.iter().zip(&self.faces);
            return faces
                .map(|(c, g)| c.k_n * g.max(FACE_STIFFNESS))
                .fold(0.0, f64::max);
        }
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
            pairs: None,
            faces: Vec::new(),
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
