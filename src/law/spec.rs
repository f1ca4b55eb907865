//! The `contact` block of a scene: which law, and its coefficients as the scene gives
//! them (SPEC 2; resolved into a `ContactLaw` by `ContactLaw::from_spec`). The scene's
//! schema holds it (`scene::Scene::contact`); a parameter out of range is a
//! [`ParamError`] naming its key, which the scene reports as its own error.

use serde::{Deserialize, Serialize};

/// A contact parameter the law cannot take: its key path and the reason (the scene turns
/// it into `SceneError::Invalid`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct ParamError {
    pub path: String,
    pub reason: String,
}

impl ParamError {
    pub fn invalid(path: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            reason: reason.into(),
        }
    }
}

/// Serde's default for keys that are 1 unless given (here and in the scene's schema).
pub(crate) fn one() -> f64 {
    1.0
}

/// Serde's default for switches that are on unless given.
pub(crate) fn yes() -> bool {
    true
}

/// The contact law between all particles and walls (SPEC 2.1, 2.2).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case")]
pub enum ContactSpec {
    SpringDashpot(SpringDashpotSpec),
    OverlapArea(OverlapAreaSpec),
    Continuous(ContinuousSpec),
    HookeEquivalent(HookeEquivalentSpec),
    HertzCohesive(HertzCohesiveSpec),
}

/// Paper 004's law for spheropolygons (rods and disks): Hertz with viscous damping, a
/// Coulomb-capped tangential spring, and a constant cohesive pull within d_c (SPEC 2.4,
/// src/law/hertz_cohesive.rs).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzCohesiveSpec {
    /// Hertz stiffness k^N in F = k^N δ^{3/2} (paper 004: 10³ N/m^{3/2}).
    pub k_n: f64,
    /// Tangential spring k^T (paper 004: 0.1 k^N).
    #[serde(default)]
    pub k_t: f64,
    /// Damping rates γ^N, γ^T (1/time), multiplied by the reduced mass (paper 004: 300
    /// and 100 s⁻¹).
    #[serde(default)]
    pub gamma_n: f64,
    #[serde(default)]
    pub gamma_t: f64,
    #[serde(default)]
    pub mu: f64,
    /// Bond number Bo = F_c / (m g): the cohesive force in units of the weight of the
    /// pair's mass scale (the particle's mass for equal particles; 0: no cohesion).
    #[serde(default)]
    pub bond: f64,
    /// Cohesion range d_c, a gap in length units (paper 004: 10⁻⁴ widths).
    #[serde(default)]
    pub d_c: f64,
}

/// Power-law spring-dashpot, paper 000 eq. 2–5.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringDashpotSpec {
    /// Normal stiffness k_n (force/length for ν = 1). Either this (the stiffness form,
    /// with `gamma_n`, `k_t`, `gamma_t`) or `restitution` with `contact_time` (the
    /// material form, linear law only: src/law/restitution.rs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_n: Option<f64>,
    /// Coefficient of restitution of a head-on collision, the same for every pair of
    /// particles (resolved per contact from its reduced mass, a fixed partner or a wall
    /// counted as infinitely heavy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// How long the surfaces of a head-on collision overlap (time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_time: Option<f64>,
    /// Material form of a nonlinear law (ν ≠ 1 or ψ ≠ 0): the relative speed of the
    /// head-on collision whose restitution and contact time are given (they change with
    /// the speed: Hertz's t_c ∝ v^(−1/5)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impact_speed: Option<f64>,
    /// Material form: k_t/k_n (default 2/7) and γ_t/γ_n (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kt_ratio: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma_t_ratio: Option<f64>,
    /// Material form: other values for some pairs of materials (`"walls"` names the wall
    /// segments); the rest take the block's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<MaterialPair>,
    /// Material form: what talus resolved for every pair, written into the run's
    /// `scene.json` for the record; computed anew whenever a scene is read.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub resolved: Vec<ResolvedPair>,
    /// Elastic exponent ν: 1 Hooke, 1.5 Hertz, 2 conical.
    #[serde(default = "one")]
    pub nu: f64,
    /// Damping exponent ψ.
    #[serde(default)]
    pub psi: f64,
    /// Normalisation length δ0; required when ν ≠ 1 or ψ ≠ 0.
    #[serde(default)]
    pub delta0: Option<f64>,
    /// Normal damping γ_n (mass/time).
    #[serde(default)]
    pub gamma_n: f64,
    /// Tangential stiffness k_t; 0 disables the tangential spring.
    #[serde(default)]
    pub k_t: f64,
    /// Tangential damping γ_t.
    #[serde(default)]
    pub gamma_t: f64,
    /// Coulomb friction coefficient μ.
    #[serde(default)]
    pub mu: f64,
    /// Clamp f_n ≥ 0 after damping (SPEC 2). `false` gives the textbook linear
    /// spring-dashpot whose damping may pull at the end of a contact; it exists to
    /// compare with the analytic t_c = π/ω and r = exp(−η t_c) (paper 000 sec. 2.1).
    #[serde(default = "yes")]
    pub clamp: bool,
}

/// A pair of materials whose collisions differ from the contact block's (material form).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialPair {
    /// Two material names; `"walls"` for the wall segments.
    pub materials: [String; 2],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_time: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
}

/// One pair's resolved coefficients per unit of the contact's reduced mass m_eff: a
/// contact of that pair has k_n = m_eff · `k_n_per_mass` and so on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResolvedPair {
    pub materials: [String; 2],
    pub restitution: f64,
    pub contact_time: f64,
    pub mu: f64,
    pub k_n_per_mass: f64,
    pub k_t_per_mass: f64,
    /// The spring-dashpot's dampings per unit mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma_n_per_mass: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma_t_per_mass: Option<f64>,
    /// The overlap-area law's dimensionless dampings, γ = η sqrt(m_eff k).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta_n: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta_t: Option<f64>,
}

/// The name that stands for the wall segments in `contact.pairs`.
pub const WALLS: &str = "walls";

/// The overlap-area law of convex polygons, paper 000 eq. 6–7 (SPEC 2.3).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OverlapAreaSpec {
    /// k^n [force/length]: f_el = k^n A/l. Either this and `eta_n` (the stiffness form)
    /// or `restitution` and `contact_time` (the material form, calibrated on a
    /// face-to-face collision: src/law/overlap_area.rs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_n: Option<f64>,
    /// Material form: the restitution and contact time of a face-to-face collision.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_time: Option<f64>,
    /// Material form: pairs of materials with values of their own (`"walls"`: the walls).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<MaterialPair>,
    /// Material form: what talus resolved (a record, computed anew on reading).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub resolved: Vec<ResolvedPair>,
    /// Dimensionless normal damping η^n = γ^n/sqrt(m12 k^n).
    #[serde(default)]
    pub eta_n: f64,
    #[serde(default)]
    pub mu: f64,
    /// k^t/k^n (paper: 2/7).
    #[serde(default = "default_kt_ratio")]
    pub kt_ratio: f64,
    /// Dimensionless tangential damping η^t = γ^t/sqrt(m12 k^t) (paper: 0.01).
    #[serde(default = "default_eta_t")]
    pub eta_t: f64,
}

fn default_kt_ratio() -> f64 {
    2.0 / 7.0
}
fn default_eta_t() -> f64 {
    0.01
}

/// Continuous r^-(n+1) interaction with tapered friction, paper 001 eq. 3–8.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContinuousSpec {
    #[serde(default = "default_n")]
    pub n: f64,
    /// Cut-off r0 in units of σ.
    #[serde(default = "default_r0")]
    pub r0: f64,
    #[serde(default)]
    pub mu: f64,
    /// δ_max = α μ δ_N (paper 001 after eq. 6).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// Fraction of critical damping (paper 001: 0.5).
    #[serde(default = "default_damping_fraction")]
    pub damping_fraction: f64,
    /// Force scale g in F = m g (σ/r)^(n+1); defaults to |gravity.g|.
    #[serde(default)]
    pub g: Option<f64>,
    /// Clamp f_n ≥ 0 after the damping (SPEC 2): false, the default, follows paper 001
    /// eq. 3, where a separating pair in the tail σ < r < r0 is held back by its damping.
    #[serde(default)]
    pub clamp: bool,
    /// The velocity the tangential damping of eq. 4 acts on.
    #[serde(default)]
    pub tangential_damping: TangentialDamping,
    /// The arm of the disks' spins in eq. 6's slip and of f_t in eq. 13's torques.
    #[serde(default)]
    pub rolling_arm: RollingArm,
    /// What δ_F does beyond ±δ_max (eq. 5 is silent): held there, or accumulated.
    #[serde(default)]
    pub tangential_limit: TangentialLimit,
}

/// Hooke law equivalent to the continuous one by equal work (paper 001 eq. 14).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HookeEquivalentSpec {
    #[serde(default = "default_n")]
    pub n: f64,
    #[serde(default = "default_r0")]
    pub r0: f64,
    /// Minimum separation r_i / σ observed in the continuous run (paper 001 Fig. 4: 0.915).
    #[serde(default = "default_r_i")]
    pub r_i: f64,
    /// Spring constant in units of m g / σ; overrides the value from r_i when given.
    #[serde(default)]
    pub k: Option<f64>,
    #[serde(default)]
    pub mu: f64,
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    #[serde(default = "default_damping_fraction")]
    pub damping_fraction: f64,
    #[serde(default)]
    pub g: Option<f64>,
    /// Clamp f_n ≥ 0 after the damping (SPEC 2): false, the default, follows paper 001
    /// eq. 3, where a separating pair in the tail σ < r < r0 is held back by its damping.
    #[serde(default)]
    pub clamp: bool,
    /// The velocity the tangential damping of eq. 4 acts on.
    #[serde(default)]
    pub tangential_damping: TangentialDamping,
    /// The arm of the disks' spins in eq. 6's slip and of f_t in eq. 13's torques.
    #[serde(default)]
    pub rolling_arm: RollingArm,
    /// What δ_F does beyond ±δ_max (eq. 5 is silent): held there, or accumulated.
    #[serde(default)]
    pub tangential_limit: TangentialLimit,
}

/// What paper 001 eq. 4's tangential damping −C_T (ṙ_ij · t̂) acts on (SPEC 2.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TangentialDamping {
    /// ṙ_ij · t̂, the relative velocity of the centres, as eq. 4 writes it: the spins
    /// do not enter, so a disk spinning in place against its neighbour is not damped,
    /// and one rolling over it is.
    #[default]
    Centres,
    /// The slip of the two surfaces at the contact point, spins included (what talus
    /// did before issue 39).
    Slip,
}

/// The arm of the spins in paper 001 eq. 6's slip, δ_F = ∫ ṙ_ij · t̂ − (θ̇_i + θ̇_j) a,
/// and of the tangential force in eq. 13's torques, T_i = T_j = −a f_t: one lever for
/// both, so that the spring does the work δ_F stores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollingArm {
    /// a = r_ij, the centre distance, as eq. 6 and 13 write it: twice the physical arm
    /// (until stop 53 the torques stayed on the contact point, and the law was not
    /// conservative: `tests/laws.rs`).
    #[default]
    CentreDistance,
    /// Each disk's own distance to the contact point (σ/2 for equal disks): the surfaces'
    /// physical slip (what talus did before issue 39).
    ContactPoint,
}

/// What paper 001's δ_F (eq. 6) does once |δ_F| reaches δ_max = α μ δ_N: eq. 5 gives
/// F = μ F_N there and says no more (SPEC 2.2: "F_T = μ F_N once |δ_F| ≥ δ_max").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TangentialLimit {
    /// Held at ±δ_max while sliding (and cut to a shrinking δ_max), so that a reversal
    /// starts down eq. 5's curve at once: a spring that slides.
    #[default]
    Hold,
    /// Capped only by sliding: δ_F grows no further than the larger of δ_max and its
    /// last value, and a δ_max that shrinks (the pair easing apart) does not cut it, so
    /// that a contact whose normal load dips and comes back holds the same tangential
    /// force as before instead of slipping by what the dip cut.
    Slide,
    /// Accumulated by eq. 6's integral without bound: the force stays at μ F_N until the
    /// contact has slid back by all of its excess, pulling the way it slid from (a
    /// memory of the whole excursion; the plain reading of eq. 5 and 6 as code).
    Accumulate,
}

fn default_n() -> f64 {
    36.0
}
fn default_r0() -> f64 {
    1.2
}
fn default_r_i() -> f64 {
    0.915
}
fn default_alpha() -> f64 {
    1.214
}
fn default_damping_fraction() -> f64 {
    0.5
}
