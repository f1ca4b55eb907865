//! The scene's data model: the JSON keys, their types and their defaults (SPEC 4).
//!
//! Every struct denies unknown keys. Lengths, times and masses are in the scene's units;
//! `units` only labels them ("si" or "reduced", paper 001's σ, m, g).

use crate::law::spec::{ContactSpec, one, yes};
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
    /// Rolling resistance at disk contacts (src/law/rolling.rs); none unless given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolling: Option<crate::law::rolling::RollingSpec>,
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

/// The neighbour lists' skin when the scene gives none (`skin`), as a fraction of the
/// largest diameter.
pub const DEFAULT_SKIN: f64 = 0.3;

/// The simulation box. Particles whose centre leaves it are removed and counted as lost,
/// except across x under `periodic_x`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub x: [f64; 2],
    pub z: [f64; 2],
    /// Periodic in x (LAMMPS `boundary p`): a particle leaving through one side comes
    /// back through the other, and particles touch across the seam (the nearest image).
    /// Both paths.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub periodic_x: bool,
}

impl Domain {
    /// The period in x, 0 when not periodic.
    pub fn period_x(&self) -> f64 {
        if self.periodic_x {
            self.x[1] - self.x[0]
        } else {
            0.0
        }
    }
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

/// A rod (paper 004 sec. 2): a stadium of width the particle's `diameter` and length
/// `aspect` times that (a segment swept by half the width; src/shape/spheropolygon.rs).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RodSpec {
    pub aspect: f64,
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

/// A straight wall segment, fixed unless it has a `motion`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// The segment's ends at t = 0.
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// The velocity of the wall's surface, along the wall (a belt, or a wall shearing
    /// the material; LAMMPS `fix wall/gran ... shear`): it enters the relative velocity
    /// of the wall's contacts; the segment itself stays where it is.
    #[serde(default, skip_serializing_if = "at_rest")]
    pub velocity: [f64; 2],
    /// The segment's own motion, without turning (a piston, a pushing or an oscillating
    /// wall; LAMMPS `fix wall/gran ... wiggle`, `fix move linear`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<WallMotion>,
}

/// A wall's translation: by v t + A sin(2π t / T) at time t, so with the velocity
/// v + A (2π/T) cos(2π t / T), which its contacts see added to the surface's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallMotion {
    /// v, a constant velocity.
    #[serde(default)]
    pub velocity: [f64; 2],
    /// A, the amplitude of an oscillation (a displacement), with `period` T.
    #[serde(default)]
    pub amplitude: [f64; 2],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
}

impl WallMotion {
    /// 2π/T, 0 without an oscillation.
    pub fn omega(&self) -> f64 {
        match self.period {
            Some(p) if self.amplitude != [0.0; 2] => std::f64::consts::TAU / p,
            _ => 0.0,
        }
    }

    /// The displacement at time t from the segment at t = 0. Twin of
    /// `wall_displacement` in shaders/geometry.wgsl.
    pub fn displacement(&self, t: f64) -> [f64; 2] {
        let (v, a, s) = (self.velocity, self.amplitude, (self.omega() * t).sin());
        [v[0] * t + a[0] * s, v[1] * t + a[1] * s]
    }

    /// The segment's velocity at time t. Twin of `wall_motion_velocity` in
    /// shaders/geometry.wgsl.
    pub fn velocity_at(&self, t: f64) -> [f64; 2] {
        let w = self.omega();
        let (v, a, c) = (self.velocity, self.amplitude, w * (w * t).cos());
        [v[0] + a[0] * c, v[1] + a[1] * c]
    }

    /// Its largest speed.
    pub fn top_speed(&self) -> f64 {
        let w = self.omega();
        self.velocity[0].hypot(self.velocity[1]) + w * self.amplitude[0].hypot(self.amplitude[1])
    }
}

fn at_rest(v: &[f64; 2]) -> bool {
    *v == [0.0; 2]
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
    /// The most rows to lay (default: as many as the outline takes). With an outline
    /// steeper than the grains can stand, the rows stop here and the flanks take the
    /// slope the grains hold, not the outline's.
    #[serde(default)]
    pub rows: Option<u32>,
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
    /// Also write each snapshot as a LAMMPS-style text dump for OVITO
    /// (`snapshots/snap_SSSSSSSSSS_grains.dump`; `render::dump`).
    #[serde(default)]
    pub dump: bool,
}

impl Default for Output {
    fn default() -> Self {
        Self {
            snapshot_every: 0.0,
            checkpoint_every: None,
            log_every: 0.0,
            vtk: false,
            dump: false,
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
