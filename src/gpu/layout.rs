//! The data layouts shared with the kernels: `#[repr(C)]` twins of the structs in
//! `shaders/common.wgsl`. `tests/gpu_layout.rs` checks each size and field offset
//! against naga's layout of the WGSL, so the two cannot drift apart.

use bytemuck::{Pod, Zeroable};

use crate::cpu::springs::MAX_SUB;
use crate::state::GEAR_VALUES;

/// Candidates per particle as the lower id, and as the higher id, of disks and polygons
/// (`Params::list_cap`; more for long rods, `gpu::list_capacity`).
pub const MAX_CONTACTS: u32 = 16;
/// Candidates of one source looked at per step (`INSERT_WINDOW`); the CPU path uses the
/// same cap so that both insert on the same steps.
pub const INSERT_WINDOW: u32 = 4;
pub const EMPTY: u32 = u32::MAX;
pub const ACTIVE: u32 = 1;
pub const FIXED: u32 = 2;
/// `Props.flags`: ACTIVE | FIXED | material << MATERIAL_SHIFT | copy << COPY_SHIFT
/// (the copy of the scene, `replicas`; materials below 2¹², copies below 2¹²).
pub const MATERIAL_SHIFT: u32 = 8;
pub const COPY_SHIFT: u32 = 20;

/// A particle's `Props.flags`.
pub fn flags(active: bool, fixed: bool, material: u32, copy: u32) -> u32 {
    ((active as u32) * ACTIVE)
        | ((fixed as u32) * FIXED)
        | (material << MATERIAL_SHIFT)
        | (copy << COPY_SHIFT)
}
/// Workgroup size of the per-particle kernels (`WG`).
pub const WG: u32 = 64;
/// Workgroup size of the prefix sum, and the elements one workgroup scans (`SCAN_WG`).
pub const SCAN_WG: u32 = 256;

/// 1.0 of a unit vector in Q30 integers (`Q30` in geometry.wgsl): a wall's normal
/// (`Wall::nq`).
pub const Q30: f64 = (1u64 << 30) as f64;

/// `Params::law` (`LAW_*` in common.wgsl).
pub const LAW_SPRING_DASHPOT: u32 = 0;
pub const LAW_CONTINUOUS: u32 = 1;
pub const LAW_AREA: u32 = 2;
pub const LAW_HERTZ: u32 = 3;
/// `LAW` of a pipeline that reads `Params::law` at run time (`LAW_ANY` in laws.wgsl).
pub const LAW_ANY: u32 = 0xFFFF_FFFF;

/// Words of the control buffer (`C_*` in common.wgsl).
pub mod control {
    pub const STEP: usize = 0;
    pub const LIVE: usize = 1;
    pub const LOST: usize = 2;
    pub const HALT: usize = 3;
    pub const HALT_STEP: usize = 4;
    pub const HALT_ID: usize = 5;
    /// The neighbour lists' word, and its bits (`C_LISTS`, `REBUILD`, … in common.wgsl).
    pub const LISTS: usize = 6;
    pub const REBUILD: u32 = 1;
    pub const TABLE_CURRENT: u32 = 2;
    pub const FLUSH: u32 = 4;
    pub const REMOVED: u32 = 8;
    /// The next step rebuilds: asked for by the survey of Gear's prediction run ahead in
    /// `correct` (`Kernel::CorrectAhead`).
    pub const AHEAD_REBUILD: u32 = 16;
    /// How many times the device built the lists (`C_REBUILDS`).
    pub const REBUILDS: usize = 7;
    /// 1 while the step in progress was recorded with the rebuild stages (`C_STAGED`).
    pub const STAGED: usize = 8;
    /// Inactive particles counted at a rebuild (`C_INACTIVE`).
    pub const INACTIVE: usize = 9;
    /// The step whose lists were built last (`C_WALLS_LISTED`): moving walls ask for a
    /// rebuild once they have moved by half the skin since then.
    pub const WALLS_LISTED: usize = 10;
    pub const BLOCKED: usize = 11;
    pub const HALT_OVERLAP: u32 = 1;
    pub const HALT_NOT_FINITE: u32 = 2;
    pub const HALT_CONTACTS_FULL: u32 = 4;
    pub const HALT_TABLE_FULL: u32 = 8;
    pub const HALT_TOO_FAST: u32 = 16;
    /// Not a failure: a lean step paused until the next step with the rebuild stages
    /// (`HALT_PAUSED`; src/gpu/step.rs).
    pub const HALT_PAUSED: u32 = 32;
}

/// `Params::reading` bits: the continuous law's tangential damping on the surfaces'
/// slip (not the centres' velocity), eq. 6's spins on each disk's own arm (not the
/// centre distance), and δ_F accumulated beyond ±δ_max or capped by sliding only (not
/// held within ±δ_max).
pub const READING_SLIP_DAMPING: u32 = 1;
pub const READING_CONTACT_ARM: u32 = 2;
pub const READING_ACCUMULATE: u32 = 4;
pub const READING_SLIDE: u32 = 8;

#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub n_cap: u32,
    pub nx: u32,
    pub nz: u32,
    pub cells: u32,
    pub n_walls: u32,
    pub n_sources: u32,
    pub table_mask: u32,
    pub integrator: u32,
    pub cell_size: f32,
    pub dt: f32,
    pub max_overlap: f32,
    pub range_factor: f32,
    pub gx: f32,
    pub gz: f32,
    pub ramp_steps: f32,
    pub law: u32,
    pub dom_lo_x: f32,
    pub dom_lo_z: f32,
    pub dom_hi_x: f32,
    pub dom_hi_z: f32,
    pub k_n: f32,
    pub nu: f32,
    pub psi: f32,
    pub delta0: f32,
    pub gamma_n: f32,
    pub k_t: f32,
    pub gamma_t: f32,
    pub mu: f32,
    pub clamp: u32,
    pub elastic: u32,
    pub n_exp: f32,
    pub hooke_k: f32,
    pub r0: f32,
    pub alpha: f32,
    pub damping_fraction: f32,
    pub g_scale: f32,
    pub scan_blocks1: u32,
    pub scan_blocks2: u32,
    pub scan_offset2: u32,
    /// Fixed-point unit, cell_size / 2^30 (`position.wgsl`), and its inverse.
    pub unit: f32,
    pub inv_unit: f32,
    /// The neighbour lists' skin (length units).
    pub skin: f32,
    /// 1: sort the particles in memory by cell at every rebuild (permute.wgsl).
    pub reorder: u32,
    pub list_cap: u32,
    pub bond_g: f32,
    pub d_c: f32,
    /// `limits.max_step_displacement`² (0: no bound).
    pub max_step2: f32,
    /// The spring-dashpot law's coefficients per pair of materials (src/law/restitution.rs):
    /// the table's side (1: one entry for every contact) and whether they are per unit
    /// of the contact's effective mass (the material form) or absolute.
    pub pair_side: u32,
    pub per_mass: u32,
    /// The continuous law's readings of paper 001 (src/law/continuous.rs `Reading`):
    /// `READING_SLIP_DAMPING` | `READING_CONTACT_ARM` | `READING_ACCUMULATE` |
    /// `READING_SLIDE`, 0 for the default readings.
    pub reading: u32,
    /// Rolling resistance at disk contacts (src/law/rolling.rs), whose values per pair
    /// ride in `pair_law[2s + 1].yzw`: here the largest μ_r of any pair (0: none) and
    /// the largest k_roll (0: the constant torque), which choose the kernels' branches.
    pub rolling_mu: f32,
    pub rolling_k: f32,
    pub pad_roll0: u32,
    /// A domain periodic in x (scene `domain.periodic_x`): its period in whole cells of
    /// the grid, whose columns fill it exactly (`gpu::device_grid`); 0 when not periodic.
    pub period_cells: u32,
    pub pad_roll1: u32,
    pub pad_roll2: u32,
    /// Slot s = a · pair_side + b of materials a and b (b = pair_side − 1: a wall):
    /// `pair_law[2s]` = (k_n, γ_n, k_t, γ_t), `pair_law[2s + 1]` = (μ, μ_r, k_roll, η_r).
    pub pair_law: [[f32; 4]; 2 * MAX_PAIR_SLOTS],
}

/// The most slots of the pair table the GPU path holds: 7 materials and the walls.
pub const MAX_PAIR_SLOTS: usize = 64;

impl Default for Params {
    // `Default` is not derived for arrays longer than 32.
    fn default() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

/// Dynamic state of one particle: q[0] = (rem_x, rem_z, rem_θ, 0) and the scaled Gear
/// derivatives q[1..6]; the position from the grid origin is
/// `anchor · cell_size + (frac + rem) · unit` (see `position`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct State {
    pub q: [[f32; 4]; GEAR_VALUES],
    pub anchor: [i32; 2],
    pub frac: [u32; 2],
    /// Orientation in whole turn units of 2π/2³² (see `orientation`); the remainder is
    /// q[0][2].
    pub turn: u32,
    /// Where the particle was when the lists were built: its anchor as two i16 halves,
    /// and its frac (the survey kernel's displacement test).
    pub listed_anchor: u32,
    pub listed_frac: [u32; 2],
    /// q1 = v dt in fixed point: whole position units (x, z) and turn units (rotation);
    /// q[1] holds the rest, at most half a unit (issue 14 item 5; position.wgsl
    /// `renormalize_q1`).
    pub q1_whole: [i32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Props {
    pub radius: f32,
    pub mass: f32,
    pub inv_inertia: f32,
    pub flags: u32,
    /// The radius in fixed point: `radius_units + radius_rem` units.
    pub radius_units: u32,
    pub radius_rem: f32,
    /// Polygon corners: first index into the corner buffer and count (0 for a disk).
    pub shape: [u32; 2],
}

/// One candidate's result as the host reads it: its slot of the three arrays
/// `contact_ft`, `contact_info` and `contact_geo` (common.wgsl), 16 bytes each.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ContactOut {
    /// (f_x, f_z) on i, torque on i, torque on j.
    pub ft: [f32; 4],
    /// f_n, f_t, overlap, elastic energy.
    pub info: [f32; 4],
    /// The geometry the device used: the normal (n_x, n_z) from j to i and the contact
    /// point relative to i's centre (written for outputs, not read by the kernels).
    pub geo: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Wall {
    pub a_anchor: [i32; 2],
    pub a_frac: [u32; 2],
    pub a_rem: [f32; 2],
    pub b_anchor: [i32; 2],
    pub b_frac: [u32; 2],
    pub b_rem: [f32; 2],
    pub ab: [f32; 2],
    /// The line's unit normal n = (−t_z, t_x), t = (b − a)/|b − a|, in Q30 integers
    /// (`wall_line` in geometry.wgsl measures distances from the line with it exactly).
    pub nq: [i32; 2],
    /// How far that Q30 normal q is turned off n and stretched: q = (1 + α) n + β t,
    /// β = q·t, α = q·n − 1 (both up to ~2⁻³¹).
    pub beta: f32,
    pub alpha: f32,
    /// The surface's velocity, along the wall (scene `walls[k].velocity`).
    pub velocity: [f32; 2],
    /// The segment's own motion (scene `walls[k].motion`, src/scene/schema.rs
    /// `WallMotion`): its constant velocity, and its oscillation's amplitude and 2π/T
    /// (0: none). The ends above are the segment's at t = 0 (`wall_at` in geometry.wgsl
    /// places it).
    pub motion_v: [f32; 2],
    pub amplitude: [f32; 2],
    pub omega: f32,
    pub pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Entry {
    pub i: u32,
    pub j: u32,
    pub value: f32,
    pub _pad: u32,
}

/// A spheropolygon pair's sub-contact springs on the device (`SubSprings` in
/// common.wgsl; `spheropolygon::SubSprings` in f64): keys EMPTY past the last.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct SubSprings {
    pub key: [u32; MAX_SUB],
    pub xi: [f32; MAX_SUB],
}

impl Default for SubSprings {
    fn default() -> Self {
        Self {
            key: [EMPTY; MAX_SUB],
            xi: [0.0; MAX_SUB],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Source {
    pub first: u32,
    pub count: u32,
    pub inserted: u32,
    pub _pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Candidate {
    pub anchor: [i32; 2],
    pub frac: [u32; 2],
    pub rem: [f32; 2],
    pub velocity: [f32; 2],
    pub radius: f32,
    pub mass: f32,
    pub inv_inertia: f32,
    pub due_step: u32,
    pub flags: u32,
    pub radius_units: u32,
    pub radius_rem: f32,
    /// Orientation (see `State::turn`) and polygon corners (see `Props::shape`).
    pub turn: u32,
    pub shape: [u32; 2],
    pub turn_rem: f32,
    pub _pad: u32,
}

/// Field offsets of each struct, by WGSL member name, for the layout test.
pub fn offsets() -> Vec<(&'static str, usize, Vec<(&'static str, usize)>)> {
    use std::mem::{offset_of, size_of};
    macro_rules! fields {
        ($t:ty, $name:literal, [$($f:ident),*]) => {
            ($name, size_of::<$t>(), vec![$((stringify!($f), offset_of!($t, $f))),*])
        };
    }
    vec![
        fields!(
            Params,
            "Params",
            [
                n_cap,
                nx,
                nz,
                cells,
                n_walls,
                n_sources,
                table_mask,
                integrator,
                cell_size,
                dt,
                max_overlap,
                range_factor,
                gx,
                gz,
                ramp_steps,
                law,
                dom_lo_x,
                dom_lo_z,
                dom_hi_x,
                dom_hi_z,
                k_n,
                nu,
                psi,
                delta0,
                gamma_n,
                k_t,
                gamma_t,
                mu,
                clamp,
                elastic,
                n_exp,
                hooke_k,
                r0,
                alpha,
                damping_fraction,
                g_scale,
                scan_blocks1,
                scan_blocks2,
                scan_offset2,
                unit,
                inv_unit,
                skin,
                reorder,
                list_cap,
                bond_g,
                d_c,
                max_step2,
                pair_side,
                per_mass,
                reading,
                rolling_mu,
                rolling_k,
                pad_roll0,
                period_cells,
                pad_roll1,
                pad_roll2,
                pair_law
            ]
        ),
        fields!(
            State,
            "State",
            [q, anchor, frac, turn, listed_anchor, listed_frac, q1_whole]
        ),
        fields!(
            Props,
            "Props",
            [
                radius,
                mass,
                inv_inertia,
                flags,
                radius_units,
                radius_rem,
                shape
            ]
        ),
        fields!(
            Wall,
            "Wall",
            [
                a_anchor, a_frac, a_rem, b_anchor, b_frac, b_rem, ab, nq, beta, alpha, velocity,
                motion_v, amplitude, omega, pad
            ]
        ),
        fields!(Entry, "Entry", [i, j, value, _pad]),
        fields!(Source, "Source", [first, count, inserted, _pad]),
        fields!(SubSprings, "SubSprings", [key, xi]),
        fields!(
            Candidate,
            "Candidate",
            [
                anchor,
                frac,
                rem,
                velocity,
                radius,
                mass,
                inv_inertia,
                due_step,
                flags,
                radius_units,
                radius_rem,
                turn,
                shape,
                turn_rem,
                _pad
            ]
        ),
    ]
}

/// `hash_pair`'s multipliers of the ids and the offset of j (`PAIR_HASH_*` in
/// common.wgsl); its finaliser is the buckets' (`HASH_MIX_1`, `HASH_MIX_2`).
pub const PAIR_HASH_I: u32 = 0x9E37_79B1;
pub const PAIR_HASH_J_ADD: u32 = 0x7F4A_7C15;
pub const PAIR_HASH_J: u32 = 0x85EB_CA77;

/// The spring table's slot hash, twin of `hash_pair` in common.wgsl (used on the host
/// to rebuild a table from a checkpoint).
pub fn hash_pair(i: u32, j: u32) -> u32 {
    use super::{HASH_MIX_1, HASH_MIX_2};
    let mut h =
        i.wrapping_mul(PAIR_HASH_I) ^ j.wrapping_add(PAIR_HASH_J_ADD).wrapping_mul(PAIR_HASH_J);
    h ^= h >> 16;
    h = h.wrapping_mul(HASH_MIX_1);
    h ^= h >> 15;
    h = h.wrapping_mul(HASH_MIX_2);
    h ^= h >> 16;
    h
}
