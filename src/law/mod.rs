//! Contact laws, assembled from parts (STYLE 3): geometry once per contact, then a normal
//! law, its damping, the non-negative clamp, and a tangential law with its cap.
//!
//! [`ContactLaw`] holds coefficients computed once on the host in f64 from the scene
//! ([`ContactLaw::from_spec`]); [`ContactLaw::evaluate`] is the per-contact pure function
//! that the force stage calls. Each formula lives in a small module with the paper's
//! equation next to it, so a WGSL twin can be written line for line.

pub mod continuous;
pub mod hertz_cohesive;
pub mod overlap_area;
pub mod restitution;
pub mod rolling;
pub mod spec;
pub mod spring_dashpot;
pub mod tangential;

use spec::{ContactSpec, ParamError};

/// What the force stage knows about one contact before applying a law.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactInput {
    /// Geometric overlap δ (SPEC 2.1): (d1 + d2)/2 − r for disks, R − distance for walls.
    pub delta: f64,
    /// Centre distance r and mean diameter σ seen by the continuous law (paper 001); for
    /// a wall the mirror image: r = 2·distance, σ = d. For area contacts δ is A/l and r
    /// the penetration depth A/L (SPEC 2.3, src/law/overlap_area.rs).
    pub r: f64,
    pub sigma: f64,
    /// Rate of overlap dδ/dt = −v12·n.
    pub delta_dot: f64,
    /// Tangential relative velocity at the contact point, v12·t (the surfaces' slip,
    /// spins included).
    pub v_t: f64,
    /// The continuous law's other readings of it (paper 001 eq. 4 and 6): the centres'
    /// relative velocity along t, and the sum of the spins θ̇_1 + θ̇_2 (θ̇_1 against a
    /// wall). Other laws ignore them.
    pub v_centres: f64,
    pub spin: f64,
    /// Reduced mass m12 = m1 m2 / (m1 + m2) (m1 for a wall).
    pub m12: f64,
    /// Mass scale m of the continuous law: 2 m12 for two disks (the particle mass for
    /// equal disks, SPEC 2.2), m1 for a wall (the mirror disk's mass).
    pub mass: f64,
    /// Tangential history (spring ξ or paper 001's δ_F) from the previous step.
    pub history: f64,
    pub dt: f64,
    /// The material form (src/law/restitution.rs): the reduced mass with a fixed partner
    /// or a wall counted as infinitely heavy, and the pair of materials' slot in the
    /// law's table. Other laws ignore them.
    pub m_eff: f64,
    pub pair: u32,
}

/// What a law returns for one contact: forces on particle 1 along n and t.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOutput {
    pub f_n: f64,
    pub f_t: f64,
    /// Updated tangential history to store for the next step.
    pub history: f64,
    /// Elastic energy stored in the contact (normal + tangential).
    pub energy: f64,
    /// The lever of f_t in both torques where the law sets one (paper 001 eq. 13: the
    /// centre distance r_ij); 0: the contact point's arms.
    pub lever: f64,
}

impl ContactOutput {
    /// The torques about i's centre and about j's (`forces::ContactForce::torque`): F at
    /// the contact point, whose arms from the centres are `arm_i` and `arm_j` (none for a
    /// wall), or f_t on the law's lever, the same on both disks (paper 001 eq. 13; the
    /// normal force of two disks is central).
    pub fn torques(&self, force: [f64; 2], arm_i: [f64; 2], arm_j: Option<[f64; 2]>) -> [f64; 2] {
        use crate::base::geometry::cross;
        if self.lever > 0.0 {
            return [-self.lever * self.f_t, self.lever * self.f_t];
        }
        [cross(arm_i, force), arm_j.map_or(0.0, |a| cross(a, force))]
    }
}

/// One contact law's per-contact function, for loops specialised to the law (the force
/// stage dispatches on [`ContactLaw`] once per step, not once per contact).
pub trait Law: Sync {
    /// The overlap-area law sees every pair by its overlap area (SPEC 2.3).
    const AREA: bool;
    fn evaluate(&self, c: &ContactInput) -> ContactOutput;
    /// Interaction range in units of σ = r_i + r_j.
    fn range_factor(&self) -> f64;
}

impl Law for spring_dashpot::SpringDashpot {
    const AREA: bool = false;
    #[inline(always)]
    fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        spring_dashpot::SpringDashpot::evaluate(self, c)
    }
    fn range_factor(&self) -> f64 {
        1.0
    }
}

impl Law for overlap_area::OverlapArea {
    const AREA: bool = true;
    #[inline(always)]
    fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        overlap_area::OverlapArea::evaluate(self, c)
    }
    fn range_factor(&self) -> f64 {
        1.0
    }
}

impl Law for continuous::Continuous {
    const AREA: bool = false;
    #[inline(always)]
    fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        continuous::Continuous::evaluate(self, c)
    }
    fn range_factor(&self) -> f64 {
        continuous::Continuous::range_factor(self)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ContactLaw {
    SpringDashpot(spring_dashpot::SpringDashpot),
    OverlapArea(overlap_area::OverlapArea),
    Continuous(continuous::Continuous),
    /// Spheropolygons (rods, and disks as point cores): paper 004's law per sub-contact
    /// (src/shape/spheropolygon.rs).
    HertzCohesive(hertz_cohesive::HertzCohesive),
}

impl ContactLaw {
    /// Turns the scene's contact block into coefficients, checking each parameter.
    /// `g` is |gravity|, the default force scale of the continuous laws.
    /// `materials`: the scene's material names in index order; `corners`: each
    /// material's polygons' corner count (0: disks), for the overlap-area law's material
    /// form.
    pub fn from_spec(
        spec: &ContactSpec,
        g: f64,
        materials: &[String],
        corners: &[u32],
    ) -> Result<Self, ParamError> {
        match spec {
            ContactSpec::SpringDashpot(s) => Ok(Self::SpringDashpot(
                spring_dashpot::SpringDashpot::from_spec(s, materials)?,
            )),
            ContactSpec::OverlapArea(s) => Ok(Self::OverlapArea(
                overlap_area::OverlapArea::from_spec(s, materials, corners)?,
            )),
            ContactSpec::Continuous(s) => {
                Ok(Self::Continuous(continuous::Continuous::from_spec(s, g)?))
            }
            ContactSpec::HookeEquivalent(s) => Ok(Self::Continuous(
                continuous::Continuous::from_hooke_spec(s, g)?,
            )),
            ContactSpec::HertzCohesive(s) => Ok(Self::HertzCohesive(
                hertz_cohesive::HertzCohesive::from_spec(s, g)?,
            )),
        }
    }

    /// The material form's pair table, if the law has one.
    pub fn pair_table(&self) -> Option<&restitution::PairTable> {
        match self {
            Self::SpringDashpot(l) => l.pairs.as_ref(),
            Self::OverlapArea(l) => l.pairs.as_ref(),
            _ => None,
        }
    }

    /// Largest centre distance, in units of σ = (d1 + d2)/2, at which two disks interact.
    pub fn range_factor(&self) -> f64 {
        match self {
            Self::SpringDashpot(_) | Self::OverlapArea(_) => 1.0,
            Self::Continuous(c) => c.range_factor(),
            // Circumscribed circles within d_c (validated below this margin of σ).
            Self::HertzCohesive(_) => 1.0 + hertz_cohesive::RANGE_MARGIN,
        }
    }

    /// Whether a contact with this input interacts at all (it then has a history entry).
    pub fn in_contact(&self, input_r: f64, sigma: f64) -> bool {
        input_r < self.range_factor() * sigma
    }

    /// The scene's law on one contact. WGSL twin: `evaluate` in shaders/laws.wgsl.
    #[inline(always)]
    pub fn evaluate(&self, c: &ContactInput) -> ContactOutput {
        match self {
            Self::SpringDashpot(l) => l.evaluate(c),
            Self::OverlapArea(l) => l.evaluate(c),
            Self::Continuous(l) => l.evaluate(c),
            Self::HertzCohesive(l) => l.evaluate(c),
        }
    }

    /// Stiffness scale k/m12 of the stiffest contact expected, for the time-step check:
    /// returns ω0² for a contact of two particles with reduced mass m12 and diameter σ.
    pub fn omega0_squared(&self, m12: f64, sigma: f64) -> f64 {
        match self {
            Self::SpringDashpot(l) => l.omega0_squared(m12, sigma),
            Self::OverlapArea(l) => l.omega0_squared(m12),
            Self::Continuous(l) => l.omega0_squared(m12, sigma),
            // Hertz's stiffness dF/dδ = 3/2 k δ^{1/2} at an overlap of 1 % of σ.
            Self::HertzCohesive(l) => 1.5 * l.k_n * (0.01 * sigma).sqrt() / m12,
        }
    }

    /// The law's one linear normal stiffness k_n (N/m): the spring–dashpot's stiffness
    /// form with ν = 1. None where the stiffness varies by pair, with the overlap or with
    /// the distance (the default of a rolling spring's stiffness, src/law/rolling.rs).
    pub fn linear_k_n(&self) -> Option<f64> {
        match self {
            Self::SpringDashpot(l) if l.pairs.is_none() && l.nu == 1.0 => Some(l.k_n),
            _ => None,
        }
    }

    pub fn mu(&self) -> f64 {
        match self {
            Self::SpringDashpot(l) => l.mu,
            Self::OverlapArea(l) => l.mu,
            Self::Continuous(l) => l.mu,
            Self::HertzCohesive(l) => l.mu,
        }
    }
}

/// Clamps a normal force to be non-negative: a non-cohesive contact never attracts
/// (SPEC 2). Applied after damping is added, so a fast-separating contact carries zero
/// force instead of pulling the grains together.
#[inline]
pub fn clamp_non_negative(f_n: f64) -> f64 {
    f_n.max(0.0)
}
