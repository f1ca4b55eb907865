//! The scene's data model: the JSON keys, their types and their defaults (SPEC 4).
//!
//! Every struct denies unknown keys. Lengths, times and masses are in the scene's units;
//! `units` only labels them ("si" or "reduced", paper 001's σ, m, g).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default = "default_name")]
    pub name: String,
    #[serde(default)]
    pub units: Units,
    #[serde(default)]
    pub seed: u64,
    /// Time step.
    pub dt: f64,
    pub stop: Stop,
    #[serde(default)]
    pub integrator: IntegratorKind,
    pub gravity: Gravity,
    pub domain: Domain,
    pub materials: BTreeMap<String, Material>,
    pub contact: ContactSpec,
    #[serde(default)]
    pub walls: Vec<Wall>,
    pub particles: Vec<Creation>,
    #[serde(default)]
    pub output: Output,
    #[serde(default)]
    pub limits: Limits,
    /// The neighbour list's skin (a length): candidate pairs are listed within the
    /// interaction range plus this, and relisted once a particle has moved by half of it.
    /// Default: 0.3 of the largest diameter; 0 relists every step. It changes only the
    /// speed, never the results.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin: Option<f64>,
    /// Independent copies of the scene in one simulation (default 1): copy c has the
    /// seed `seed + c`, its own particles, sources and random streams, and touches only
    /// its own particles (and the walls). Written out and analysed as one run each
    /// (`copies/copy_CCCC/`). Not written when 1, so a scene without copies reads and
    /// writes as before.
    #[serde(default = "one_copy", skip_serializing_if = "is_one_copy")]
    pub replicas: u32,
}

fn one_copy() -> u32 {
    1
}

fn is_one_copy(k: &u32) -> bool {
    *k == 1
}

fn default_name() -> String {
    "unnamed".into()
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    Si,
    #[default]
    Reduced,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorKind {
    /// 5th-order Gear predictor–corrector, six values (SPEC 3).
    #[default]
    Gear5,
    /// Leapfrog with half-step velocities (paper 001 eq. 9–12).
    Leapfrog,
}

/// When the run ends: at `time`, or earlier once it has settled.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stop {
    /// End time (always applies).
    pub time: f64,
    /// Stop early when kinetic energy < this fraction of the elastic energy (paper 000
    /// sec. 3: "kinetic energy orders of magnitude smaller than the elastic energy").
    #[serde(default)]
    pub kinetic_fraction: Option<f64>,
    /// Stop early when the mean kinetic energy per particle falls below this fraction of
    /// its value at the first check after the sources are done (paper 004 sec. 2:
    /// "relaxed until the particles' mean kinetic energy is several orders of magnitude
    /// smaller than its initial value"; unlike `kinetic_fraction` it works for cohesive
    /// packings, whose elastic energy may be tiny or negative).
    #[serde(default)]
    pub kinetic_drop: Option<f64>,
    /// Simulated time between checks of the settling rule.
    #[serde(default = "default_check_every")]
    pub check_every: f64,
    /// The settling rule is not checked before this time (nor while sources still pour
    /// or gravity still ramps).
    #[serde(default)]
    pub not_before: f64,
}

fn default_check_every() -> f64 {
    1.0
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    /// Acceleration vector (x, z).
    pub g: [f64; 2],
    /// Gravity grows linearly from zero to `g` over this time (paper 000 sec. 4).
    #[serde(default)]
    pub ramp_time: f64,
}

/// The simulation box. Particles whose centre leaves it are removed and counted as lost.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub x: [f64; 2],
    pub z: [f64; 2],
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Mass density; mass = density · area · thickness (SPEC 1).
    pub density: f64,
    /// Extent along the third axis (2D particles are rods; 1 m in paper 000).
    #[serde(default = "one")]
    pub thickness: f64,
}

fn one() -> f64 {
    1.0
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

/// A rod (paper 004 sec. 2): a stadium of width the particle's `diameter` and length
/// `aspect` times that (a segment swept by half the width; src/spheropolygon.rs).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RodSpec {
    pub aspect: f64,
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

/// Convex polygons instead of disks (paper 000 sec. 2.2, 5): `corners` corners on an
/// ellipse with full axes (a, b) at angles φ0 + 2πk/C. Without `axes` they are regular:
/// in lists and point sources inscribed in the circle of the block's diameter; on
/// lattice piles and rows the diameter is the face-to-face one and a face points along
/// +x, so that lattice neighbours touch face to face (C divisible by 6).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolygonSpec {
    pub corners: u32,
    /// Full axes (a, b), each a fixed size or {"uniform": [lo, hi]}, drawn independently
    /// (point sources only).
    #[serde(default)]
    pub axes: Option<[Size; 2]>,
    /// Random start angle φ0 on the ellipse (irregular polygons, paper 000 sec. 5.4);
    /// otherwise φ0 = 0.
    #[serde(default)]
    pub irregular: bool,
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
    /// The arm of the disks' spin in eq. 6's slip.
    #[serde(default)]
    pub rolling_arm: RollingArm,
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
    /// The arm of the disks' spin in eq. 6's slip.
    #[serde(default)]
    pub rolling_arm: RollingArm,
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

/// The arm of the spins in paper 001 eq. 6's slip, δ_F = ∫ ṙ_ij · t̂ − (θ̇_i + θ̇_j) a.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RollingArm {
    /// a = r_ij, the centre distance, as eq. 6 writes it: twice the physical arm.
    #[default]
    CentreDistance,
    /// Each disk's own distance to the contact point (σ/2 for equal disks): the surfaces'
    /// physical slip (what talus did before issue 39).
    ContactPoint,
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

/// A fixed straight wall segment.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    pub from: [f64; 2],
    pub to: [f64; 2],
}

/// A size: a fixed diameter or a uniform distribution of diameters.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Size {
    Fixed(f64),
    Uniform(UniformSize),
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UniformSize {
    pub uniform: [f64; 2],
}

impl Size {
    pub fn bounds(&self) -> (f64, f64) {
        match self {
            Size::Fixed(d) => (*d, *d),
            Size::Uniform(u) => (u.uniform[0], u.uniform[1]),
        }
    }
}

/// How particles are created (SPEC 4).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Creation {
    LatticePile(LatticePile),
    Row(Row),
    PointSource(PointSource),
    Layered(Layered),
    List(ParticleList),
}

/// A triangular-lattice pile (paper 000 sec. 4, Fig. 2): row M holds L − M (60°) or
/// L − 3M (30°) disks.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticePile {
    pub material: String,
    /// 30 or 60 degrees.
    pub slope: f64,
    /// L, the number of disks in the bottom row M = 0.
    pub bottom_row: u32,
    /// d0.
    pub diameter: f64,
    /// c in the bottom-row spacing d0 (1 + c) (paper 000 sec. 4.1).
    #[serde(default)]
    pub spacing_c: f64,
    /// r_d: mobile diameters d0 (1 + u), u uniform in [−r_d/2, r_d/2] (paper 000 sec. 4.4).
    #[serde(default)]
    pub size_disorder: f64,
    /// Whether the bottom row is fixed (a bumpy base).
    #[serde(default = "yes")]
    pub fixed_bottom: bool,
    /// x of the pile's centre line.
    #[serde(default)]
    pub center_x: f64,
    /// z of the bottom of the lowest row.
    #[serde(default)]
    pub base_z: f64,
    /// Convex polygons instead of disks.
    #[serde(default)]
    pub polygon: Option<PolygonSpec>,
}

fn yes() -> bool {
    true
}

/// A straight horizontal row of equal disks, e.g. a bumpy substrate (paper 001).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Row {
    pub material: String,
    pub count: u32,
    pub diameter: f64,
    /// Centre-to-centre spacing.
    pub spacing: f64,
    /// Centre of the first disk.
    pub start: [f64; 2],
    #[serde(default = "yes")]
    pub fixed: bool,
    /// Convex polygons instead of disks.
    #[serde(default)]
    pub polygon: Option<PolygonSpec>,
}

/// Layer-by-layer construction (paper 000 sec. 5.4.2): every `interval` a row of
/// particles is dropped from `gap` (in units of the largest particle) above the surface
/// below each of them, where the pile is still below the outline (`base_width`, `slope`);
/// or, with `row_height`, rows narrowing by 2 h / tan(slope). See `create::layered`.
/// Particles are drawn as by a point source.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layered {
    pub material: String,
    /// Disk diameter, or the circle of regular polygons; absent with `polygon.axes`.
    #[serde(default)]
    pub diameter: Option<Size>,
    /// Convex polygons instead of disks.
    #[serde(default)]
    pub polygon: Option<PolygonSpec>,
    /// x of the pile's centre line and z of its floor.
    #[serde(default)]
    pub center_x: f64,
    #[serde(default)]
    pub base_z: f64,
    /// Width of the first row.
    pub base_width: f64,
    /// Angle of the outline, degrees.
    pub slope: f64,
    /// Time between rows.
    pub interval: f64,
    /// Drop height above the surface, in units of the largest particle (< 1: "smoothly").
    #[serde(default = "default_gap")]
    pub gap: f64,
    #[serde(default)]
    pub start_time: f64,
    /// Rows of this fixed height (in units of the largest particle) instead of rows that
    /// follow the pile's measured height (the default).
    #[serde(default)]
    pub row_height: Option<f64>,
}

fn default_gap() -> f64 {
    0.5
}

/// A point source pouring disks (paper 001 sec. II; paper 000 sec. 5.3).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSource {
    pub material: String,
    /// Outlet position (x, z); z is the drop height.
    pub position: [f64; 2],
    /// x is drawn uniformly in ±spread around the outlet.
    #[serde(default)]
    pub spread: f64,
    /// Particles per unit time.
    pub rate: f64,
    /// Total number to pour.
    pub count: u32,
    #[serde(default)]
    pub diameter: Option<Size>,
    /// Initial velocity (x, z).
    #[serde(default)]
    pub velocity: [f64; 2],
    #[serde(default)]
    pub start_time: f64,
    /// Convex polygons instead of disks.
    #[serde(default)]
    pub polygon: Option<PolygonSpec>,
    /// Rods instead of disks, of width `diameter`, each at a random orientation (paper
    /// 004's deposition; law `hertz_cohesive` only).
    #[serde(default)]
    pub rod: Option<RodSpec>,
    /// Rods only: a random speed up to this added to `velocity` in a random direction
    /// (paper 004: "a random initial velocity and orientation").
    #[serde(default)]
    pub velocity_spread: f64,
}

/// Particles given one by one (small test scenes).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleList {
    pub material: String,
    pub particles: Vec<ListedParticle>,
    /// Convex polygons instead of disks.
    #[serde(default)]
    pub polygon: Option<PolygonSpec>,
    /// Rods (spheropolygons) instead of disks: `diameter` is their width (law
    /// `hertz_cohesive` only).
    #[serde(default)]
    pub rod: Option<RodSpec>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListedParticle {
    pub position: [f64; 2],
    pub diameter: f64,
    #[serde(default)]
    pub velocity: [f64; 2],
    #[serde(default)]
    pub theta: f64,
    #[serde(default)]
    pub omega: f64,
    #[serde(default)]
    pub fixed: bool,
    /// Never rotates (infinite moment of inertia): a sliding block rather than a roller.
    #[serde(default)]
    pub fixed_rotation: bool,
}

/// What is written and how often (in simulated time; 0 disables).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    #[serde(default)]
    pub snapshot_every: f64,
    /// Default: a tenth of `stop.time`; 0 disables checkpoints.
    #[serde(default)]
    pub checkpoint_every: Option<f64>,
    /// Interval of the energy log (log.csv).
    #[serde(default)]
    pub log_every: f64,
    /// Also write each snapshot as VTK PolyData for ParaView (grains and contacts, with
    /// `snapshots.pvd` listing them in time).
    #[serde(default)]
    pub vtk: bool,
}

impl Default for Output {
    fn default() -> Self {
        Self {
            snapshot_every: 0.0,
            checkpoint_every: None,
            log_every: 0.0,
            vtk: false,
        }
    }
}

/// Divergence guards.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// A run stops when an overlap exceeds this fraction of the smaller radius.
    #[serde(default = "default_max_overlap")]
    pub max_overlap: f64,
    /// The most particles a scene may create (checked before anything is allocated;
    /// about 1 kB of memory each): raise it for a larger scene on a larger machine.
    #[serde(default = "default_max_particles")]
    pub max_particles: f64,
    /// The deepest overlap the initial particles may have, as a fraction of the smaller
    /// radius: deeper is bad input (particles placed into each other), not a run to
    /// start (issue 16).
    #[serde(default = "default_initial_overlap")]
    pub initial_overlap: f64,
    /// A run stops when a particle moves by more than this fraction of its radius in one
    /// step (it would pass through thin neighbours and fixed rows without meeting them:
    /// tunnelling); 0 switches the guard off.
    #[serde(default = "default_max_step_displacement")]
    pub max_step_displacement: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_overlap: default_max_overlap(),
            max_particles: default_max_particles(),
            initial_overlap: default_initial_overlap(),
            max_step_displacement: default_max_step_displacement(),
        }
    }
}

fn default_max_particles() -> f64 {
    2e7
}

fn default_max_step_displacement() -> f64 {
    0.5
}

fn default_initial_overlap() -> f64 {
    0.05
}

fn default_max_overlap() -> f64 {
    0.5
}
