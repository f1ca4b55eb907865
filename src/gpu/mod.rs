//! The GPU path: the whole time step as WGSL compute kernels on wgpu (issue 3).
//!
//! Particle state lives in storage buffers for the whole run. The host encodes many
//! steps into one submission (`step.rs`: each stage one dispatch, the rebuild stages
//! indirect, see [`GpuSimulation::advance`]) and reads back only a few control words
//! after each submission (step, live count, lost count, halt flags), plus the full state
//! when an output needs it ([`GpuSimulation::download`], `transfer.rs`).
//!
//! The host keeps a CPU [`Simulation`] as a mirror: it holds the scene, the law and the
//! grid, and after `download` the state in f64, so snapshots, checkpoints, energies and
//! the settling rule are the CPU path's own code.
//!
//! | file | concern |
//! |---|---|
//! | `mod.rs` | `GpuSimulation`: the upload (`with_gpu`), sizes and limits |
//! | `params.rs` | `Params`, the uniform every kernel reads |
//! | `bindings.rs` | every binding, and which kernel reads or writes it |
//! | `buffers.rs` | the buffers and their bind groups |
//! | `step.rs` | encoding steps, pipelined batches, halts |
//! | `insert.rs` | point sources' candidates, layered rows |
//! | `transfer.rs` | host ↔ device layouts, download, access for tests |
//! | `profile.rs` | device time per kernel, from timestamps (`talus bench --kernels`) |
//! | `buckets.rs` | the hashed grid |
//! | `device.rs`, `kernels.rs`, `layout.rs`, `position.rs`, `orientation.rs` | adapters, pipelines, shared layouts, fixed point |

pub mod bindings;
mod buckets;
mod buffers;
pub mod constants;
pub mod footprint;
pub use bindings::{BINDINGS, Binding};
pub use footprint::{Footprint, footprint, max_particles};
pub mod device;
mod insert;
pub mod kernels;
pub mod layout;
pub mod modules;
pub mod orientation;
mod params;
pub mod position;
mod probe;
mod profile;
mod readback;
mod step;
mod transfer;

pub use buckets::{HASH_MIX_1, HASH_MIX_2, HASH_X, HASH_Z, MAX_BUCKETS, bucket, bucket_count};
use buffers::{Buffers, Initial};
use insert::{LayeredBase, SourceBase};
pub use params::{gpu_pair_side, law_params};
pub use profile::{KernelTime, KernelTimes, kernel_times};
pub use step::{BATCHES_IN_FLIGHT, Counters, REBUILD_STAGES, STEPS_PER_SUBMIT, workgroups};
use step::{dispatch_args, initial_control};
pub use transfer::{build_table, corner_starts, from_device, table_lookup, to_device};
use transfer::{device_corners, device_walls, initial_state, pr_local};

use crate::cpu::contacts::{Pair, WALL_BASE};
use crate::cpu::forces::ContactForce;
use crate::cpu::springs::{SpringTable, pair_key};
use crate::create::{
    self,
    source::{self, SourceState},
};
use crate::law::ContactLaw;
use crate::scene::{Creation, IntegratorKind, Layered, PointSource};
use crate::sim::{Divergence, Simulation};
use crate::state::{GEAR_VALUES, Particles};
use device::{DeviceError, Gpu};
use kernels::Pipelines;
use layout::*;
use modules::Kernel;
use wgpu::util::DeviceExt;

/// Workgroups of one dispatch at most (per dimension; the GPU path dispatches in one).
pub const MAX_WORKGROUPS: u64 = 65535;

/// Cells of a dense grid at most: one dispatch of `clear_cells` covers 65535 workgroups.
pub const MAX_CELLS: u64 = MAX_WORKGROUPS * WG as u64;

/// Cells per side at most: anchors are i32 cell coordinates.
pub const MAX_CELLS_PER_SIDE: u32 = 1 << 30;

pub struct GpuSimulation {
    /// The host mirror; its state is current after [`GpuSimulation::download`].
    pub sim: Simulation,
    gpu: Gpu,
    pipelines: Pipelines,
    buffers: Buffers,
    /// One bind group per shape of `pipelines.groups`.
    bind_groups: Vec<wgpu::BindGroup>,
    pub params: Params,
    /// The device's grid: cells of at least the law's range plus the neighbour lists'
    /// skin (positions are anchored to its cells, see `position`).
    pub grid: crate::cpu::cell_list::Grid,
    n_cap: u32,
    origin: [f64; 2],
    /// The corners in the device's corner buffer, in f64 (shapes of downloaded particles).
    corner_table: Vec<[f64; 2]>,
    sources: Vec<SourceBase>,
    layered: Vec<LayeredBase>,
    /// Loss count at upload (the GPU counts from there), inactive particles at upload,
    /// and losses on the device after the last submission.
    lost_base: u64,
    inactive_at_upload: u64,
    /// Fixed particles at the upload: they never move, so never leave, and a source
    /// inserts none.
    fixed_at_upload: u64,
    lost_now: u64,
    /// The step the device is at (known on the host without a readback).
    step: u64,
    live: u32,
    synced: bool,
    /// Dispatches encoded (direct, and indirect: the rebuild stages) and submissions
    /// made (compute and readback) since the upload: what `talus bench` reports per step.
    dispatches: std::cell::Cell<u64>,
    indirect: std::cell::Cell<u64>,
    submissions: std::cell::Cell<u64>,
    /// Batches in which a lean step paused for a rebuild (`step::STAGE_EVERY`); how often
    /// a step carries the rebuild stages now (`step::stage_interval`), unless a test
    /// forces it (1: every step, the reference); the rebuild count last read back.
    pauses: u64,
    stage_every: u64,
    forced_stage_every: Option<u64>,
    rebuilds_read: Option<u32>,
    /// The exact device state read by the last `download`: what a checkpoint of `sim`
    /// carries (`checkpoint_state`).
    downloaded: Option<DeviceState>,
    /// The timestamps of a profiled run (`profile.rs`), while one is encoded.
    recorder: std::cell::RefCell<Option<profile::Recorder>>,
}

/// What a GPU checkpoint adds to the f64 state: the exact device state, so that a GPU
/// run resumes bitwise (f32 → f64 → f32 would round-trip, but the anchor split would not).
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceState {
    pub states: Vec<State>,
    pub props: Vec<Props>,
    pub springs: Vec<Entry>,
    /// Spheropolygons: each entry of `springs`' sub-contact springs (empty otherwise).
    pub sub: Vec<SubSprings>,
}

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error("GPU readback failed: {0}")]
    Readback(String),
    #[error("{0} (use --backend cpu)")]
    Unsupported(String),
    /// `profile` (talus bench --kernels): the adapter cannot time single kernels, or the
    /// profiled steps stopped.
    #[error("kernel times: {0}")]
    Profile(String),
}

/// The smallest buffer made: an empty array (a scene without walls or sources) must still
/// hold one element of the largest struct the shaders bind.
pub const MIN_BUFFER: u64 = 256;

/// Candidates per particle the lists hold (`Params::list_cap`): `MAX_CONTACTS` (16)
/// for disks and polygons, whose circumscribed circles hold few neighbours; for long
/// rods, whose circles (d widths across) each meet ~d others, twice the number expected
/// as the lower id in a packing of 0.9 plus 8, in steps of 16: the circles within range
/// plus the skin, π (σ + skin)² · 0.9 / A_min, halved. (Rods of d = 5 with the default
/// skin: 48; d = 10: 64.)
pub fn list_capacity(sim: &Simulation) -> u32 {
    if !matches!(sim.law, ContactLaw::HertzCohesive(_)) {
        return MAX_CONTACTS;
    }
    let p = &sim.particles;
    let widest = (crate::scene::max_diameter(&sim.scene)).max(2.0 * p.max_radius());
    let reach = sim.law.range_factor() * widest + sim.skin();
    // The smallest area, of the blocks still to create and of the particles there are.
    let mut area = crate::scene::smallest_particle_area(&sim.scene);
    for i in 0..p.len() {
        let a = if p.is_swept(i) {
            crate::shape::spheropolygon::Spheropolygon {
                core: p.shape[i].clone(),
                radius: p.sweep[i],
            }
            .area()
        } else {
            std::f64::consts::PI * p.radius[i] * p.radius[i]
        };
        area = area.min(a);
    }
    if !(area > 0.0 && area.is_finite()) {
        return MAX_CONTACTS;
    }
    let expected = 0.5 * std::f64::consts::PI * reach * reach * 0.9 / area;
    let cap = (2.0 * expected + 8.0).min(1024.0) as u32;
    cap.next_multiple_of(16).max(MAX_CONTACTS)
}

/// What the GPU path cannot take of a scene, or `None` (checked at the upload and by
/// `talus check --backend gpu`).
pub fn unsupported(sim: &Simulation) -> Option<String> {
    if let Some(reason) = unsupported_spheropolygons(sim) {
        return Some(reason);
    }
    // Props.flags holds material and copy in 12 bits each.
    let field = 1usize << (layout::COPY_SHIFT - layout::MATERIAL_SHIFT);
    if sim.scene.materials.len() > field || sim.scene.replicas as usize > field {
        return Some(format!(
            "the GPU path holds at most {field} materials and {field} copies of a scene"
        ));
    }
    if params::gpu_pair_side(&sim.law).is_none()
        || sim.rolling.side * sim.rolling.side > layout::MAX_PAIR_SLOTS
    {
        return Some(format!(
            "the GPU path holds contact.pairs and rolling.pairs for at most {} materials (and the walls); the scene has {}",
            layout::MAX_PAIR_SLOTS.isqrt() - 1,
            sim.scene.materials.len()
        ));
    }
    let (point_sources, layered_specs) = crate::sim::creators(&sim.scene);
    if !point_sources.is_empty() && !layered_specs.is_empty() {
        return Some(
            "point sources together with layer-by-layer blocks are not on the GPU path yet".into(),
        );
    }
    None
}

/// What the GPU path cannot take of a spheropolygon scene (law hertz_cohesive): cores
/// of more than two corners (spheropolygon.wgsl takes disks and rods, at most four
/// sub-contacts a pair), and polygons without a sweep (the CPU path takes them as
/// disks of their circumscribed radius).
fn unsupported_spheropolygons(sim: &Simulation) -> Option<String> {
    if !matches!(sim.law, ContactLaw::HertzCohesive(_)) {
        return None;
    }
    let p = &sim.particles;
    let mut wide =
        (0..p.len()).filter(|&i| p.shape[i].len() > 2 || (p.is_polygon(i) && !p.is_swept(i)));
    if let Some(i) = wide.next() {
        return Some(format!(
            "particle {i} is a spheropolygon with a core of {} corners; the GPU path takes \
             disks and rods (cores of at most two corners) under law hertz_cohesive",
            p.shape[i].len()
        ));
    }
    let polygon_source = sim.scene.particles.iter().any(|c| match c {
        Creation::PointSource(s) => s.polygon.is_some(),
        Creation::LatticePile(l) => l.polygon.is_some(),
        Creation::Row(r) => r.polygon.is_some(),
        Creation::Layered(l) => l.polygon.is_some(),
        Creation::List(l) => l.polygon.is_some(),
    });
    polygon_source.then(|| {
        "polygons under law hertz_cohesive are not on the GPU path; it takes disks and rods"
            .to_string()
    })
}

/// The grid of the device's cell list and fixed-point positions: the law's grid with
/// its cells doubled until they hold range + skin (the fixed-point unit scales by a
/// power of two, which keeps lattice piles exactly aligned); in a domain periodic in x,
/// cells of at least range + skin whose columns fill the period exactly, so that a
/// centre crossing the seam moves by whole cells (`Params::period_cells`).
pub(crate) fn device_grid(sim: &Simulation) -> crate::cpu::cell_list::Grid {
    let skin = sim.skin();
    let d = &sim.scene.domain;
    if d.periodic_x {
        let max_d = crate::scene::max_diameter(&sim.scene).max(2.0 * sim.particles.max_radius());
        let reach = sim.law.range_factor() * max_d + skin;
        return crate::cpu::cell_list::Grid::periodic(d.x, d.z, reach);
    }
    sim.grid.coarsened(sim.grid.cell_size + skin)
}

/// Whether the scene keeps `SubSprings` per candidate slot and table entry (`sub_hist`,
/// `table_sub`): spheropolygons' sub-contact springs, or disk pairs' rolling springs
/// (rolling model `spring_dashpot`). WGSL twin: `sub_springs_kept` in common.wgsl.
pub(crate) fn keeps_sub_springs(sim: &crate::sim::Simulation) -> bool {
    matches!(sim.law, ContactLaw::HertzCohesive(_)) || sim.rolling.has_spring()
}

/// `keeps_sub_springs` from the device's parameters.
pub(crate) fn params_keep_sub_springs(params: &Params) -> bool {
    params.law == LAW_HERTZ || params.rolling_k > 0.0
}

/// Whether `contact_forces` takes a thread per pair (the overlap-area law and
/// spheropolygons: `POLYGONS`, `SPHEROPOLYGONS`) rather than one per particle.
pub(crate) fn per_pair(params: &Params) -> bool {
    params.law == LAW_AREA || params.law == LAW_HERTZ
}

fn ceil_div(a: u64, b: u64) -> u64 {
    a.div_ceil(b)
}

impl GpuSimulation {
    /// Opens the best adapter and uploads the simulation's state.
    pub fn new(sim: Simulation) -> Result<Self, GpuError> {
        Self::with_gpu(sim, Gpu::open()?)
    }

    /// Uploads the simulation's state to an opened adapter.
    pub fn with_gpu(sim: Simulation, gpu: Gpu) -> Result<Self, GpuError> {
        Self::resume_with_gpu(sim, None, gpu)
    }

    /// Opens the best adapter and uploads a simulation resumed from a checkpoint
    /// (`io::checkpoint::Checkpoint`'s two parts): its exact device state when it has one
    /// (a GPU run resumes bitwise), else its f64 state.
    pub fn resume(sim: Simulation, device_state: Option<DeviceState>) -> Result<Self, GpuError> {
        Self::resume_with_gpu(sim, device_state, Gpu::open()?)
    }

    /// [`GpuSimulation::resume`] on an opened adapter.
    pub fn resume_with_gpu(
        sim: Simulation,
        device_state: Option<DeviceState>,
        gpu: Gpu,
    ) -> Result<Self, GpuError> {
        if let Some(reason) = unsupported(&sim) {
            return Err(GpuError::Unsupported(reason));
        }
        let (_, layered_specs) = crate::sim::creators(&sim.scene);
        // Cells hold every candidate within range + skin of the lists (issue 13; see
        // `device_grid`, and tests/gpu_scenes.rs `lattice_pile_agrees_with_the_cpu`).
        let skin = sim.skin();
        let grid = device_grid(&sim);
        // Every particle the point sources will still insert is drawn below, on the
        // host, and every buffer is sized for them: check that they and the grid fit the
        // adapter first (a count of 4·10⁹ would otherwise abort on allocation; issue 16).
        let needs = footprint(&sim);
        if let Some(reason) = needs.misfit(gpu.binding_limit()) {
            return Err(DeviceError::TooLarge {
                name: gpu.info.name.clone(),
                reason,
            }
            .into());
        }
        // The anchor unit is the cell size, rounded to f32 (up, so cells stay ≥ range).
        let mut cell_size = grid.cell_size as f32;
        if (cell_size as f64) < grid.cell_size {
            cell_size = f32::from_bits(cell_size.to_bits() + 1);
        }
        let origin = grid.origin;

        let up = insert::upcoming(&sim, &layered_specs, origin, cell_size);
        let n_now = sim.particles.len() as u32;
        let n_cap = (n_now + up.candidates.len() as u32 + up.layered_count).max(1);
        let table_cap = footprint::table_capacity(n_cap as u64);
        let cells = bucket_count(&grid, n_cap);

        let params =
            params::step_params(&sim, &grid, n_cap, cells, up.sources.len(), cell_size, skin);
        let blocks1 = params.scan_blocks1;
        // Every dispatch is one-dimensional: at most 65535 workgroups. The clears of the
        // cells and of the spring table loop over what one dispatch does not cover; the
        // per-particle stages take one thread per particle (`Footprint::misfit`).
        debug_assert_eq!(
            needs.particles, n_cap as u64,
            "the footprint counts the upload"
        );
        if blocks1 as u64 > MAX_WORKGROUPS {
            return Err(DeviceError::TooLarge {
                name: gpu.info.name.clone(),
                reason: format!(
                    "the prefix sum over {cells} cells needs {blocks1} workgroups and the GPU \
                     path issues at most {MAX_WORKGROUPS}; make the domain smaller"
                ),
            }
            .into());
        }
        debug_assert_eq!(needs.list_cap, params.list_cap);
        let walls = device_walls(&sim.scene.walls, origin, cell_size);

        let control = initial_control(sim.step, n_now, up.sources.len());
        let (states, props, entries, subs) = initial_state(&sim, device_state, origin, cell_size);
        let mut state_all = vec![State::default(); n_cap as usize];
        state_all[..states.len()].copy_from_slice(&states);
        let mut props_all = vec![Props::default(); n_cap as usize];
        props_all[..props.len()].copy_from_slice(&props);
        let kept = keeps_sub_springs(&sim);
        let (table, table_sub) =
            transfer::build_tables(&entries, kept.then_some(&subs[..]), table_cap as usize);

        let mut corners = device_corners(
            &up.corner_table,
            &state_all,
            &props_all,
            position::unit(cell_size),
        );
        corners.resize(corners.len() + up.layered_corners, [0; 4]);
        let initial = Initial {
            state: &state_all,
            props: &props_all,
            walls: &walls,
            control: &control,
            sources: &up.source_rows,
            candidates: &up.candidates,
            corners: &corners,
            table: &table,
            table_sub: &table_sub,
        };
        let dev = &gpu.device;
        let buffers = Buffers::new(dev, &params, cells, &initial);
        let pipelines = Pipelines::new(dev, kernels::Build::of(&sim, &gpu.info));
        let bind_groups = buffers.bind_groups(dev, &pipelines);
        let lost_base = sim.lost;
        let inactive_at_upload = (sim.particles.len() - sim.particles.active_count()) as u64;
        let fixed_at_upload = (sim.particles.active_count() - sim.particles.mobile_count()) as u64;
        let step = sim.step;
        Ok(Self {
            sim,
            gpu,
            pipelines,
            buffers,
            bind_groups,
            params,
            grid,
            n_cap,
            origin,
            corner_table: up.corner_table,
            sources: up.sources,
            layered: up.layered,
            lost_base,
            inactive_at_upload,
            fixed_at_upload,
            lost_now: 0,
            step,
            live: n_now,
            synced: true,
            dispatches: Default::default(),
            submissions: Default::default(),
            pauses: 0,
            stage_every: step::STAGE_EVERY,
            forced_stage_every: None,
            rebuilds_read: None,
            indirect: Default::default(),
            downloaded: None,
            recorder: Default::default(),
        })
    }

    pub fn adapter_name(&self) -> &str {
        &self.gpu.info.name
    }

    /// The step the device has reached.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Particles created so far (active or lost).
    pub fn live(&self) -> u32 {
        self.live
    }

    /// How many times the device has built the neighbour lists since the upload.
    pub fn rebuilds(&self) -> u64 {
        self.read_control()[control::REBUILDS] as u64
    }

    /// Active particles after the last submission (from the control words).
    pub fn active_count(&self) -> u64 {
        (self.live as u64).saturating_sub(self.inactive_at_upload + self.lost_now)
    }

    /// Active particles that move (not fixed), no readback.
    pub fn mobile_count(&self) -> u64 {
        self.active_count().saturating_sub(self.fixed_at_upload)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::cell_list::Grid;

    #[test]
    fn the_largest_scene_is_what_the_bindings_and_one_dispatch_hold() {
        // lavapipe binds 128 MiB: the candidates' result arrays (256 B per particle)
        // and the spring table (16 B per slot, a power of two) stop at 2^19.
        let lavapipe = 128 << 20;
        assert_eq!(max_particles(lavapipe, MAX_CONTACTS, false), 1 << 19);
        // NVIDIA-class 2 GiB bindings: one dispatch of 65 535 workgroups of 64 is the
        // limit, above the 4·10⁶ disks issue 14 asks for.
        let nvidia = max_particles(2 << 30, MAX_CONTACTS, false);
        assert_eq!(nvidia, MAX_WORKGROUPS * WG as u64);
        assert!(nvidia >= 4_000_000);
    }

    #[test]
    fn a_dense_grid_is_its_own_buckets_and_a_wide_one_spreads_over_them() {
        // 100 × 50 cells for 1000 particles: dense; for 100, hashed (2¹⁰ buckets).
        let small = Grid::new([0.0, 100.0], [0.0, 50.0], 1.0);
        assert_eq!(bucket_count(&small, 100), 1024);
        let b = bucket_count(&small, 1000) as u32;
        assert_eq!(b as usize, small.cell_count());
        assert_eq!(bucket(&small, b, 7, 3), 3 * small.nx + 7);
        // 10⁵ × 10⁵ cells, 10⁴ particles: 2¹⁵ buckets.
        let wide = Grid::new([0.0, 1e5], [0.0, 1e5], 1.0);
        let b = bucket_count(&wide, 10_000) as u32;
        assert_eq!(b, 1 << 15);
        // A block of 256 × 256 cells spreads over the buckets like random draws (two
        // per bucket: e⁻² = 13.5 % of them empty, none with more than a dozen), so a
        // bucket holds few particles of other cells; and the 3 × 3 cells around a cell
        // rarely share one.
        let mut count = vec![0u32; b as usize];
        let mut shared = 0;
        for cz in 40_000..40_256 {
            for cx in 10_000..10_256 {
                let k = bucket(&wide, b, cx, cz);
                assert!(k < b);
                count[k as usize] += 1;
                let mut around: Vec<u32> = (0..9)
                    .map(|m| bucket(&wide, b, cx + m % 3 - 1, cz + m / 3 - 1))
                    .collect();
                around.sort();
                around.dedup();
                shared += 9 - around.len();
            }
        }
        let empty = count.iter().filter(|&&c| c == 0).count() as f64 / b as f64;
        let most = *count.iter().max().unwrap();
        assert!(
            (0.11..0.16).contains(&empty) && most <= 12,
            "{:.3} of the buckets empty, the fullest holds {most} cells",
            empty
        );
        // Random draws: 36/2¹⁵ of the neighbourhoods share a bucket.
        assert!(
            shared < 200,
            "{shared} of 65536 neighbourhoods share a bucket"
        );
    }
}
