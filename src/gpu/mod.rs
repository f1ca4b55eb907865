//! The GPU path: the whole disk time step as WGSL compute kernels on wgpu (issue 3).
//!
//! Particle state lives in storage buffers for the whole run. The host encodes many
//! steps into one submission (every stage of every step is one dispatch, see
//! [`GpuSimulation::encode_step`]) and reads back only a few control words after each
//! submission (step, live count, lost count, halt flags), plus the full state when an
//! output needs it ([`GpuSimulation::download`]).
//!
//! The host keeps a CPU [`Simulation`] as a mirror: it holds the scene, the law and the
//! grid, and after `download` the state in f64, so snapshots, checkpoints, energies and
//! the settling rule are the CPU path's own code.

pub mod device;
pub mod kernels;
pub mod layout;
pub mod orientation;
pub mod position;

use crate::contacts::{Pair, WALL_BASE};
use crate::create::{
    self,
    source::{self, SourceState},
};
use crate::forces::ContactForce;
use crate::law::ContactLaw;
use crate::scene::{Creation, IntegratorKind, Layered, PointSource};
use crate::sim::{Divergence, Simulation};
use crate::springs::{SpringTable, pair_key};
use crate::state::{GEAR_VALUES, Particles};
use device::{DeviceError, Gpu};
use kernels::{Kernel, Pipelines};
use layout::*;
use wgpu::util::DeviceExt;

/// Steps encoded into one submission at most. Between submissions the host reads the
/// control words (divergence check, progress).
pub const STEPS_PER_SUBMIT: u64 = 64;

/// Workgroups of one dispatch at most (per dimension; the GPU path dispatches in one).
pub const MAX_WORKGROUPS: u64 = 65535;

/// Cells of a dense grid at most: one dispatch of `clear_cells` covers 65535 workgroups.
pub const MAX_CELLS: u64 = MAX_WORKGROUPS * WG as u64;

/// The spatial hash: the cell's coordinates times large primes (Teschner et al. 2003),
/// mixed by Wellons's lowbias32 so that every bit of the bucket depends on both.
pub const HASH_X: u32 = 73_856_093;
pub const HASH_Z: u32 = 19_349_663;
pub const HASH_MIX_1: u32 = 0x7feb_352d;
pub const HASH_MIX_2: u32 = 0x846c_a68b;

/// Buckets of a hashed grid at most (a power of two below MAX_CELLS).
pub const MAX_BUCKETS: u64 = 1 << 21;

/// Cells per side at most: anchors are i32 cell coordinates.
pub const MAX_CELLS_PER_SIDE: u32 = 1 << 30;

/// The bucket of cell (cx, cz) in a grid of `buckets` buckets (twin of `bucket` in
/// common.wgsl): the cell itself when the grid is dense (nx nz ≤ buckets), else a
/// spatial hash.
pub fn bucket(grid: &crate::cell_list::Grid, buckets: u32, cx: u32, cz: u32) -> u32 {
    if grid.nx > buckets / grid.nz {
        let mut h = cx.wrapping_mul(HASH_X) ^ cz.wrapping_mul(HASH_Z);
        h ^= h >> 16;
        h = h.wrapping_mul(HASH_MIX_1);
        h ^= h >> 15;
        h = h.wrapping_mul(HASH_MIX_2);
        h ^= h >> 16;
        h % buckets
    } else {
        cz * grid.nx + cx
    }
}

/// The buckets of the device's grid: about two per particle when the grid has more
/// than four times as many cells, or more than MAX_CELLS (a hashed grid: issue 13,
/// memory and rebuild time O(N) whatever the domain's area, and a pour 10⁵ d wide
/// runs); otherwise every cell (a dense grid, whose neighbouring cells are neighbours in
/// memory).
pub fn bucket_count(grid: &crate::cell_list::Grid, n_cap: u32) -> u64 {
    let cells = grid.nx as u64 * grid.nz as u64;
    let hashed = (2 * n_cap as u64)
        .next_power_of_two()
        .clamp(1024, MAX_BUCKETS);
    if cells > MAX_CELLS || cells > 4 * hashed {
        hashed
    } else {
        cells
    }
}

struct Buffers {
    params: wgpu::Buffer,
    state: wgpu::Buffer,
    props: wgpu::Buffer,
    cell_of: wgpu::Buffer,
    cell_count: wgpu::Buffer,
    cell_start: wgpu::Buffer,
    scan: wgpu::Buffer,
    sorted: wgpu::Buffer,
    contact_j: wgpu::Buffer,
    contact_count: wgpu::Buffer,
    down: wgpu::Buffer,
    down_count: wgpu::Buffer,
    hist_in: wgpu::Buffer,
    touching: wgpu::Buffer,
    /// Each candidate's result: what the reduction sums, and for outputs only.
    contact_ft: wgpu::Buffer,
    contact_info: wgpu::Buffer,
    contact_geo: wgpu::Buffer,
    force: wgpu::Buffer,
    walls: wgpu::Buffer,
    control: wgpu::Buffer,
    sources: wgpu::Buffer,
    candidates: wgpu::Buffer,
    corners: wgpu::Buffer,
    /// Each memory slot's particle id, and the particles on their way to a new order.
    ids: wgpu::Buffer,
    state_next: wgpu::Buffer,
    props_next: wgpu::Buffer,
    ids_next: wgpu::Buffer,
    table: wgpu::Buffer,
    /// The rebuild stages' indirect dispatch arguments (shaders/plan.wgsl).
    dispatch_args: wgpu::Buffer,
}

/// Per-slot values of the device put in id order (`ids`: each slot's id).
fn by_id<T: Copy>(ids: &[u32], slots: Vec<T>) -> Vec<T> {
    let mut out = slots.clone();
    for (&id, v) in ids.iter().zip(slots) {
        out[id as usize] = v;
    }
    out
}

/// Batches of steps in flight at most (`GpuSimulation::advance`): the host encodes and
/// submits one while the device runs the other.
pub const BATCHES_IN_FLIGHT: usize = 2;

/// A submitted batch of steps: its submission and the staging buffer its control words
/// are copied to.
struct Batch {
    staging: wgpu::Buffer,
    index: wgpu::SubmissionIndex,
    steps: u64,
}

/// The source bookkeeping of the host: where each source stood at upload.
struct SourceBase {
    spec: PointSource,
    state: SourceState,
}

/// A layer-by-layer block: its rows are laid by the host (`place_layered_rows`), which
/// reads the pile back to find its surface; its progress is `sim.sources[index]`.
struct LayeredBase {
    spec: Layered,
    material: u32,
    index: usize,
}

/// The stages of a rebuild of the neighbour lists, in order: the old lists' springs into
/// the table, the cell list, the new memory order, the new lists and their springs. A
/// step dispatches them indirectly (`plan_rebuild`, shaders/plan.wgsl).
pub const REBUILD_STAGES: [Kernel; 16] = {
    let c = GpuSimulation::CELL_LIST;
    [
        Kernel::ClearTable,
        Kernel::StoreHistory,
        c[0],
        c[1],
        c[2],
        c[3],
        c[4],
        c[5],
        c[6],
        c[7],
        c[8],
        c[9],
        Kernel::PermuteGather,
        Kernel::PermuteStore,
        Kernel::FindContacts,
        Kernel::GatherHistory,
    ]
};

/// What a step encodes besides its fixed stages.
#[derive(Clone, Copy, Debug)]
struct StepKind {
    /// Sources still have candidates: the insertion kernels run first.
    sources_left: bool,
    /// Store the contacts' outputs (the last step of an `advance`, which `download`
    /// reads).
    record: bool,
    /// Gear: the step before predicted this one already (`Kernel::CorrectAhead`).
    predicted: bool,
    /// Gear: predict the next step at the end of this one.
    ahead: bool,
}

/// One indirect dispatch's arguments in `dispatch_args`: x, y, z and a word of padding.
const DISPATCH_ARGS_BYTES: usize = 16;

/// The workgroups of one dispatch of kernel k.
pub fn workgroups(p: &Params, k: Kernel) -> u64 {
    match k {
        Kernel::InsertPlace | Kernel::ScanLevel2 | Kernel::AdvanceClock | Kernel::PlanRebuild => 1,
        // Grid-stride loops: as many workgroups as one dispatch takes.
        Kernel::ClearCells => ceil_div(p.cells.max(p.n_cap) as u64, WG as u64).min(MAX_WORKGROUPS),
        Kernel::ClearCursor => ceil_div(p.cells as u64, WG as u64),
        Kernel::ScanLevel0 | Kernel::ScanAdd0 => p.scan_blocks1 as u64,
        Kernel::ScanLevel1 | Kernel::ScanAdd1 => p.scan_blocks2 as u64,
        Kernel::ClearTable => ceil_div(p.table_mask as u64 + 1, WG as u64).min(MAX_WORKGROUPS),
        _ => ceil_div(p.n_cap as u64, WG as u64),
    }
    .max(1)
}

/// The contents of `dispatch_args` at the upload: each rebuild stage's workgroups, then
/// room for a step's arguments (shaders/plan.wgsl).
fn dispatch_args(p: &Params) -> Vec<u32> {
    let mut args: Vec<u32> = REBUILD_STAGES
        .iter()
        .flat_map(|&k| [workgroups(p, k) as u32, 1, 1, 0])
        .collect();
    args.resize(2 * args.len(), 0);
    args
}

pub struct GpuSimulation {
    /// The host mirror; its state is current after [`GpuSimulation::download`].
    pub sim: Simulation,
    gpu: Gpu,
    pipelines: Pipelines,
    buffers: Buffers,
    group0: wgpu::BindGroup,
    /// The spring table's group.
    group1: wgpu::BindGroup,
    /// The indirect dispatch arguments' group (`plan_rebuild` only).
    group2: wgpu::BindGroup,
    pub params: Params,
    /// The device's grid: cells of at least the law's range plus the neighbour lists'
    /// skin (positions are anchored to its cells, see `position`).
    pub grid: crate::cell_list::Grid,
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
}

/// What the GPU path has encoded and submitted since the upload (`talus bench`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counters {
    /// Dispatches with a workgroup count fixed when encoded.
    pub direct: u64,
    /// Indirect dispatches: the rebuild stages, which run workgroups only at a rebuild.
    pub indirect: u64,
    /// Submissions: batches of steps and readbacks.
    pub submissions: u64,
    /// Rebuilds of the neighbour lists (each runs the `REBUILD_STAGES.len()` indirect
    /// dispatches of its step).
    pub rebuilds: u64,
}

/// What a GPU checkpoint adds to the f64 state: the exact device state, so that a GPU
/// run resumes bitwise (f32 → f64 → f32 would round-trip, but the anchor split would not).
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceState {
    pub states: Vec<State>,
    pub props: Vec<Props>,
    pub springs: Vec<Entry>,
}

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error("GPU readback failed: {0}")]
    Readback(String),
    #[error("{0} (use --backend cpu)")]
    Unsupported(String),
}

/// The smallest buffer made: an empty array (a scene without walls or sources) must still
/// hold one element of the largest struct the shaders bind.
pub const MIN_BUFFER: u64 = 256;

/// The largest buffers that grow with the particle count n, and their sizes in bytes:
/// what an adapter's binding limit must hold (checked before a run).
pub fn particle_buffers(n: u64) -> [(&'static str, u64); 3] {
    let table_cap = table_capacity(n);
    [
        ("particle state", n * size_of::<State>() as u64),
        ("contact", n * MAX_CONTACTS as u64 * 16),
        ("spring table", table_cap * size_of::<Entry>() as u64),
    ]
}

/// Slots of the spring table for n particles: a power of two (the hash's mask), about
/// eight per particle (a dense packing has ~2 contacts per particle as the lower id: the
/// table stays about a quarter full, and probes stay short).
fn table_capacity(n: u64) -> u64 {
    (8 * n).next_power_of_two().max(64)
}

/// The most particles the GPU path holds where a buffer binds at most `binding` bytes:
/// every buffer of `particle_buffers` within it, and one thread per particle in a
/// dispatch of at most `MAX_WORKGROUPS` workgroups (`talus info` prints it).
pub fn max_particles(binding: u64) -> u64 {
    let fits = |n: u64| particle_buffers(n).iter().all(|&(_, b)| b <= binding);
    let (mut lo, mut hi) = (0, MAX_WORKGROUPS * WG as u64);
    if fits(hi) {
        return hi;
    }
    // fits(lo) and not fits(hi): the sizes grow with n.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) { lo = mid } else { hi = mid }
    }
    lo
}

fn ceil_div(a: u64, b: u64) -> u64 {
    a.div_ceil(b)
}

impl GpuSimulation {
    /// Opens the best adapter and uploads the simulation's state.
    pub fn new(sim: Simulation) -> Result<Self, GpuError> {
        Self::with_gpu(sim, Gpu::open()?)
    }

    pub fn with_gpu(mut sim: Simulation, gpu: Gpu) -> Result<Self, GpuError> {
        let (point_sources, layered_specs) = crate::sim::creators(&sim.scene);
        if !point_sources.is_empty() && !layered_specs.is_empty() {
            return Err(GpuError::Unsupported(
                "point sources together with layer-by-layer blocks are not on the GPU path yet"
                    .into(),
            ));
        }
        let device_state = sim.device_state.take();
        // Cells hold every candidate within range + skin of the lists (issue 13): the
        // law's grid with its cells doubled (the fixed-point unit scales by a power of
        // two; any other size loses the lattice piles' exact alignment, see
        // tests/gpu_scenes.rs `lattice_pile_agrees_with_the_cpu`).
        let skin = sim.skin();
        let grid = sim.grid.coarsened(sim.grid.cell_size + skin);
        if grid.nx >= MAX_CELLS_PER_SIDE || grid.nz >= MAX_CELLS_PER_SIDE {
            return Err(DeviceError::TooLarge {
                name: gpu.info.name.clone(),
                reason: format!(
                    "the cell grid has {} × {} cells, the GPU path handles at most {} per \
                     side; make the domain smaller",
                    grid.nx,
                    grid.nz,
                    MAX_CELLS_PER_SIDE - 1
                ),
            }
            .into());
        }
        // The anchor unit is the cell size, rounded to f32 (up, so cells stay ≥ range).
        let mut cell_size = grid.cell_size as f32;
        if (cell_size as f64) < grid.cell_size {
            cell_size = f32::from_bits(cell_size.to_bits() + 1);
        }
        let origin = grid.origin;

        // Sources: every candidate still to come, drawn now.
        let specs: Vec<PointSource> = sim
            .scene
            .particles
            .iter()
            .filter_map(|c| match c {
                Creation::PointSource(s) => Some(s.clone()),
                _ => None,
            })
            .collect();
        let mut sources = Vec::new();
        let mut source_rows = Vec::new();
        let mut candidates = Vec::new();
        // Polygon corners: every particle's in id order, then every candidate's.
        let mut corner_table: Vec<[f64; 2]> =
            sim.particles.shape.iter().flatten().copied().collect();
        let dt = sim.dt();
        for (spec, st) in specs.iter().zip(&sim.sources) {
            let list = source::upcoming(spec, st);
            source_rows.push(Source {
                first: candidates.len() as u32,
                count: list.len() as u32,
                inserted: 0,
                _pad: 0,
            });
            let material = crate::create::material_index(&sim.scene, &spec.material);
            for (k, drawn) in list.into_iter().enumerate() {
                let disk = source::particle(spec, &drawn, material);
                let x = drawn.x;
                let mut one = Particles::default();
                crate::create::push(&sim.scene, &mut one, &disk);
                let (anchor, frac, rem) =
                    position::split2(x - origin[0], spec.position[1] - origin[1], cell_size);
                let (radius_units, radius_rem) = position::length_units(one.radius[0], cell_size);
                let due = source::due_step(source::due_time(spec, st.inserted + k as u32), dt);
                let shape = [corner_table.len() as u32, one.shape[0].len() as u32];
                let (turn, turn_rem) = orientation::split_angle(drawn.theta);
                corner_table.extend_from_slice(&one.shape[0]);
                candidates.push(Candidate {
                    anchor,
                    frac,
                    rem,
                    velocity: [
                        (spec.velocity[0] * dt) as f32,
                        (spec.velocity[1] * dt) as f32,
                    ],
                    radius: one.radius[0] as f32,
                    mass: one.mass[0] as f32,
                    inv_inertia: (1.0 / one.inertia[0]) as f32,
                    due_step: due.min(u32::MAX as u64) as u32,
                    flags: ACTIVE | (material << 8),
                    radius_units,
                    radius_rem,
                    turn,
                    shape,
                    turn_rem,
                    _pad: 0,
                });
            }
            sources.push(SourceBase {
                spec: spec.clone(),
                state: st.clone(),
            });
        }
        // Layered rows still to come: the buffers are sized now for the most they can
        // hold (their corners go after the candidates').
        let mut layered = Vec::new();
        let mut layered_count = 0u32;
        let mut layered_corners = 0usize;
        for (m, spec) in layered_specs.iter().enumerate() {
            let index = specs.len() + m;
            let corners = spec.polygon.as_ref().map_or(0, |p| p.corners as usize);
            for k in sim.sources[index].inserted..create::layered::max_rows(spec) {
                let n = create::layered::row_capacity(spec, k);
                layered_count += n as u32;
                layered_corners += n * corners;
            }
            layered.push(LayeredBase {
                spec: spec.clone(),
                material: crate::create::material_index(&sim.scene, &spec.material),
                index,
            });
        }
        let n_now = sim.particles.len() as u32;
        let n_cap = (n_now + candidates.len() as u32 + layered_count).max(1);
        let table_cap = table_capacity(n_cap as u64);
        let cells = bucket_count(&grid, n_cap);

        let law = &sim.law;
        let g = sim.scene.gravity.g;
        let ramp = sim.scene.gravity.ramp_time;
        let d = &sim.scene.domain;
        let blocks1 = ceil_div(cells, SCAN_WG as u64) as u32;
        let blocks2 = ceil_div(blocks1 as u64, SCAN_WG as u64) as u32;
        let mut params = Params {
            n_cap,
            nx: grid.nx,
            nz: grid.nz,
            cells: cells as u32,
            n_walls: sim.walls.len() as u32,
            n_sources: sources.len() as u32,
            table_mask: (table_cap - 1) as u32,
            integrator: match sim.scene.integrator {
                IntegratorKind::Gear5 => 0,
                IntegratorKind::Leapfrog => 1,
            },
            cell_size,
            dt: dt as f32,
            max_overlap: sim.scene.limits.max_overlap as f32,
            range_factor: law.range_factor() as f32,
            gx: g[0] as f32,
            gz: g[1] as f32,
            ramp_steps: if ramp > 0.0 { (ramp / dt) as f32 } else { 0.0 },
            law: 0,
            dom_lo_x: (d.x[0] - origin[0]) as f32,
            dom_lo_z: (d.z[0] - origin[1]) as f32,
            dom_hi_x: (d.x[1] - origin[0]) as f32,
            dom_hi_z: (d.z[1] - origin[1]) as f32,
            scan_blocks1: blocks1,
            scan_blocks2: blocks2,
            scan_offset2: blocks1.next_multiple_of(SCAN_WG),
            unit: position::unit(cell_size) as f32,
            inv_unit: (1.0 / position::unit(cell_size)) as f32,
            skin: skin as f32,
            reorder: 1,
            ..Default::default()
        };
        law_params(law, &mut params);
        // Every dispatch is one-dimensional: at most 65535 workgroups. The clears of the
        // cells and of the spring table loop over what one dispatch does not cover; the
        // per-particle stages take one thread per particle.
        let widest = [ceil_div(n_cap as u64, WG as u64), blocks1 as u64];
        let most = widest.into_iter().max().unwrap_or(0);
        if most > MAX_WORKGROUPS {
            return Err(DeviceError::TooLarge {
                name: gpu.info.name.clone(),
                reason: format!(
                    "{n_cap} particles need {most} workgroups in one dispatch and the GPU \
                     path issues at most {MAX_WORKGROUPS} (about 4.19 million particles); \
                     use --backend cpu"
                ),
            }
            .into());
        }

        for (what, bytes) in particle_buffers(n_cap as u64) {
            gpu.check_buffer(what, bytes)?;
        }
        gpu.check_buffer("cell", cells * 4)?;
        let n = n_cap as u64;
        let m = MAX_CONTACTS as u64;

        let dev = &gpu.device;
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let zeroed = |label: &str, bytes: u64| {
            dev.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(MIN_BUFFER).next_multiple_of(16),
                usage: storage,
                mapped_at_creation: false,
            })
        };
        let init = |label: &str, bytes: &[u8]| {
            let mut v = bytes.to_vec();
            v.resize(v.len().max(MIN_BUFFER as usize).next_multiple_of(16), 0);
            dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &v,
                usage: storage,
            })
        };

        let walls: Vec<Wall> = sim
            .walls
            .iter()
            .map(|w| {
                let (a_anchor, a_frac, a_rem) =
                    position::split2(w.a[0] - origin[0], w.a[1] - origin[1], cell_size);
                let (b_anchor, b_frac, b_rem) =
                    position::split2(w.b[0] - origin[0], w.b[1] - origin[1], cell_size);
                let (nq, beta, alpha) = wall_normal(w);
                Wall {
                    a_anchor,
                    a_frac,
                    a_rem,
                    b_anchor,
                    b_frac,
                    b_rem,
                    ab: [(w.b[0] - w.a[0]) as f32, (w.b[1] - w.a[1]) as f32],
                    nq,
                    beta,
                    alpha,
                }
            })
            .collect();

        let mut control =
            vec![0u32; control::BLOCKED + (sources.len() * INSERT_WINDOW as usize).max(1)];
        control[control::STEP] = sim.step as u32;
        control[control::LIVE] = n_now;
        control[control::HALT_STEP] = u32::MAX;
        control[control::HALT_ID] = u32::MAX;
        // The first step builds the lists, with the springs of the table uploaded now.
        control[control::LISTS] = control::REBUILD | control::TABLE_CURRENT;

        let (states, props, entries) = match device_state {
            Some(mut ds) => {
                // The corner buffer is laid out afresh: point each particle at its corners.
                for (pr, start) in ds.props.iter_mut().zip(corner_starts(&sim.particles)) {
                    pr.shape[0] = start;
                }
                (ds.states, ds.props, ds.springs)
            }
            None => {
                let (s, p) = to_device(&sim.particles, origin, cell_size);
                let e = sim
                    .spring_table()
                    .entries()
                    .map(|(k, v)| Entry {
                        i: (k >> 32) as u32,
                        j: k as u32,
                        value: v as f32,
                        _pad: 0,
                    })
                    .collect();
                (s, p, e)
            }
        };
        let mut state_all = vec![State::default(); n_cap as usize];
        state_all[..states.len()].copy_from_slice(&states);
        let mut props_all = vec![Props::default(); n_cap as usize];
        props_all[..props.len()].copy_from_slice(&props);
        let table = build_table(&entries, table_cap as usize);

        let buffers = Buffers {
            params: dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            }),
            state: init("state", bytemuck::cast_slice(&state_all)),
            props: init("props", bytemuck::cast_slice(&props_all)),
            cell_of: zeroed("cell_of", n * 4),
            cell_count: zeroed("cell_count", cells * 4),
            cell_start: zeroed("cell_start", cells * 4),
            scan: zeroed("scan", (params.scan_offset2 as u64 + SCAN_WG as u64) * 4),
            sorted: zeroed("sorted", n * 4),
            contact_j: zeroed("contact_j", n * m * 4),
            contact_count: zeroed("contact_count", n * 4),
            down: zeroed("down", n * m * 4),
            down_count: zeroed("down_count", n * 4),
            hist_in: zeroed("hist_in", n * m * 4),
            touching: zeroed("touching", n * m * 4),
            contact_ft: zeroed("contact_ft", n * m * 16),
            contact_info: zeroed("contact_info", n * m * 16),
            contact_geo: zeroed("contact_geo", n * m * 16),
            force: zeroed("force", n * 16),
            walls: init("walls", bytemuck::cast_slice(&walls)),
            control: init("control", bytemuck::cast_slice(&control)),
            sources: init("sources", bytemuck::cast_slice(&source_rows)),
            candidates: init("candidates", bytemuck::cast_slice(&candidates)),
            corners: init(
                "corners",
                bytemuck::cast_slice(&{
                    let mut c = device_corners(
                        &corner_table,
                        &state_all,
                        &props_all,
                        position::unit(cell_size),
                    );
                    c.resize(c.len() + layered_corners, [0; 4]);
                    c
                }),
            ),
            ids: init(
                "ids",
                bytemuck::cast_slice(&(0..n_cap).collect::<Vec<u32>>()),
            ),
            state_next: zeroed("state_next", n * size_of::<State>() as u64),
            props_next: zeroed("props_next", n * size_of::<Props>() as u64),
            ids_next: zeroed("ids_next", n * 4),
            table: init("springs", bytemuck::cast_slice(&table)),
            dispatch_args: dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dispatch_args"),
                contents: bytemuck::cast_slice(&dispatch_args(&params)),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_SRC,
            }),
        };
        let pipelines = Pipelines::new(dev, matches!(sim.law, ContactLaw::OverlapArea(_)));
        let b = &buffers;
        let group0_buffers = [
            &b.params,
            &b.state,
            &b.props,
            &b.cell_of,
            &b.cell_count,
            &b.cell_start,
            &b.scan,
            &b.sorted,
            &b.contact_j,
            &b.contact_count,
            &b.down,
            &b.down_count,
            &b.hist_in,
            &b.touching,
            &b.contact_ft,
            &b.force,
            &b.walls,
            &b.control,
            &b.sources,
            &b.candidates,
            &b.corners,
            &b.ids,
            &b.state_next,
            &b.props_next,
            &b.ids_next,
            &b.contact_info,
            &b.contact_geo,
        ];
        let entries0: Vec<_> = group0_buffers
            .iter()
            .enumerate()
            .map(|(k, buf)| wgpu::BindGroupEntry {
                binding: k as u32,
                resource: buf.as_entire_binding(),
            })
            .collect();
        let group0 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("talus group 0"),
            layout: &pipelines.group0,
            entries: &entries0,
        });
        let group1 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("springs"),
            layout: &pipelines.group1,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: b.table.as_entire_binding(),
            }],
        });
        let group2 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dispatch arguments"),
            layout: &pipelines.group2,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: b.dispatch_args.as_entire_binding(),
            }],
        });
        let lost_base = sim.lost;
        let inactive_at_upload = (sim.particles.len() - sim.particles.active_count()) as u64;
        let step = sim.step;
        Ok(Self {
            sim,
            gpu,
            pipelines,
            buffers,
            group0,
            group1,
            group2,
            params,
            grid,
            n_cap,
            origin,
            corner_table,
            sources,
            layered,
            lost_base,
            inactive_at_upload,
            lost_now: 0,
            step,
            live: n_now,
            synced: true,
            dispatches: Default::default(),
            submissions: Default::default(),
            indirect: Default::default(),
        })
    }

    /// What has been encoded and submitted since the upload (reads the rebuild count
    /// back).
    pub fn counters(&self) -> Counters {
        Counters {
            direct: self.dispatches.get(),
            indirect: self.indirect.get(),
            submissions: self.submissions.get(),
            rebuilds: self.rebuilds(),
        }
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

    fn dispatch(&self, pass: &mut wgpu::ComputePass, k: Kernel, groups: u64) {
        self.dispatches.set(self.dispatches.get() + 1);
        pass.set_pipeline(&self.pipelines.pipelines[&k]);
        pass.dispatch_workgroups(groups.max(1) as u32, 1, 1);
    }

    /// Sets every bind group of the talus kernels on a pass.
    fn bind_groups(&self, pass: &mut wgpu::ComputePass) {
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, &self.group1, &[]);
        pass.set_bind_group(2, &self.group2, &[]);
    }

    /// Records the dispatches of one kernel (for tests of single stages).
    pub fn encode_kernel(&self, pass: &mut wgpu::ComputePass, k: Kernel) {
        self.dispatch(pass, k, workgroups(&self.params, k));
    }

    /// Records a rebuild stage (the `REBUILD_STAGES[stage]`), dispatched with the
    /// workgroups `plan_rebuild` wrote for this step: none between rebuilds.
    fn dispatch_rebuild_stage(&self, pass: &mut wgpu::ComputePass, stage: usize) {
        self.indirect.set(self.indirect.get() + 1);
        let k = REBUILD_STAGES[stage];
        pass.set_pipeline(&self.pipelines.pipelines[&k]);
        let offset = (REBUILD_STAGES.len() + stage) * DISPATCH_ARGS_BYTES;
        pass.dispatch_workgroups_indirect(&self.buffers.dispatch_args, offset as u64);
    }

    /// Runs one kernel with a given number of workgroups (tests of the grid-stride
    /// loops, which must cover everything from any number of workgroups).
    pub fn run_kernel_with_groups(&mut self, k: Kernel, groups: u64) {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.bind_groups(&mut pass);
            self.dispatch(&mut pass, k, groups);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.synced = false;
    }

    /// Runs some kernels once, in order, in one submission (tests of single stages).
    pub fn run_kernels(&mut self, ks: &[Kernel]) {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.bind_groups(&mut pass);
            for &k in ks {
                self.encode_kernel(&mut pass, k);
            }
        }
        self.gpu.queue.submit([enc.finish()]);
        self.synced = false;
    }

    /// The kernels of the cell list, in order.
    pub const CELL_LIST: [Kernel; 10] = [
        Kernel::ClearCells,
        Kernel::CellIndex,
        Kernel::CellHistogram,
        Kernel::ScanLevel0,
        Kernel::ScanLevel1,
        Kernel::ScanLevel2,
        Kernel::ScanAdd1,
        Kernel::ScanAdd0,
        Kernel::ClearCursor,
        Kernel::Scatter,
    ];

    /// One time step, stage by stage as in `Simulation::step`.
    fn encode_step(&self, pass: &mut wgpu::ComputePass, how: StepKind) {
        if how.sources_left {
            self.encode_kernel(pass, Kernel::InsertCheck);
            self.encode_kernel(pass, Kernel::InsertPlace);
        }
        let gear = self.params.integrator == 0;
        // The neighbour lists (issue 13): the survey decides whether this step rebuilds
        // them (the stages of a rebuild: the old lists' springs into the table, the cell
        // list, the memory order, the new lists, their springs from the table). Gear's
        // prediction surveys each particle it predicts; the step before may have run it
        // ahead.
        if !gear {
            self.encode_kernel(pass, Kernel::Survey);
        } else if !how.predicted {
            self.encode_kernel(pass, Kernel::Predict);
        }
        // Between rebuilds the rebuild stages are dispatched with no workgroups (issue 14
        // item 2): `plan_rebuild` writes their arguments once the survey has decided.
        self.encode_kernel(pass, Kernel::PlanRebuild);
        for stage in 0..REBUILD_STAGES.len() {
            self.dispatch_rebuild_stage(pass, stage);
        }
        self.encode_kernel(
            pass,
            if how.record {
                Kernel::ContactForces
            } else {
                Kernel::ContactForcesOnly
            },
        );
        self.encode_kernel(
            pass,
            match (gear, how.ahead) {
                (true, false) => Kernel::Correct,
                (true, true) => Kernel::CorrectAhead,
                (false, _) => Kernel::KickDrift,
            },
        );
        // (The integrators' kernels sum each particle's forces first and end with the
        // boundaries.)
        self.encode_kernel(pass, Kernel::AdvanceClock);
    }

    /// Whether candidates are still waiting: every particle created on the device comes
    /// from a source, and the buffers were sized for all of them.
    fn sources_left(&self) -> bool {
        self.live < self.n_cap && !self.sources.is_empty()
    }

    /// Advances `steps` steps, `STEPS_PER_SUBMIT` per submission. Submissions are
    /// pipelined (issue 14 item 3): each batch copies the control words into its own
    /// staging buffer, and the host reads them only once the next batch is submitted, so
    /// the device always has work queued and the host never waits on an idle device. A
    /// halt stops every later kernel on the device at once (each returns when `halted`),
    /// so a batch submitted after the halting one changes nothing, and the halt still
    /// names its step.
    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        let sources_left = self.sources_left();
        // Gear's prediction runs ahead at the end of the step before (`CorrectAhead`, as
        // the CPU path's `correct_ahead`) when the device goes on at once: not across an
        // insertion (new particles are predicted in their step), nor into a stop (the end
        // of the advance, a layered row: the host reads a corrected state).
        let can_run_ahead = self.params.integrator == 0 && !sources_left;
        let mut predicted = false;
        let mut left = steps;
        let mut in_flight: std::collections::VecDeque<Batch> = Default::default();
        // The step the device reaches once the batches in flight are done.
        let mut planned = self.step;
        while left > 0 || !in_flight.is_empty() {
            if left > 0 && in_flight.len() < BATCHES_IN_FLIGHT {
                let mut k = left.min(STEPS_PER_SUBMIT);
                // Submissions stop where a layered row is due; the host lays it once the
                // device has caught up.
                match self.next_layered_step(planned) {
                    Some(due) if due == planned && in_flight.is_empty() => {
                        self.place_layered_rows();
                        // The next row may be due within this batch.
                        continue;
                    }
                    Some(due) if due == planned => k = 0,
                    Some(due) => k = k.min(due - planned),
                    None => {}
                }
                if k > 0 {
                    let last = k == left;
                    let stops = last || self.next_layered_step(planned + k) == Some(planned + k);
                    let how = StepKind {
                        sources_left,
                        record: false,
                        predicted,
                        ahead: can_run_ahead,
                    };
                    in_flight.push_back(self.submit_batch(k, how, last, stops));
                    predicted = can_run_ahead && !stops;
                    planned += k;
                    left -= k;
                    continue;
                }
            }
            let batch = in_flight.pop_front().expect("a batch in flight");
            let done = batch.steps;
            let c = self.wait_for(batch);
            self.live = c[control::LIVE];
            self.lost_now = c[control::LOST] as u64;
            if c[control::HALT] != 0 {
                // The later batches ran as no-ops; let them finish first.
                for b in in_flight.drain(..) {
                    self.wait_for(b);
                }
                return Err(self.halt_cause(&c));
            }
            self.step += done;
        }
        Ok(())
    }

    /// Encodes and submits `k` steps, with a copy of the control words at their end.
    /// `how`: its first step (and whether steps may predict ahead); `last`: the batch
    /// ends the `advance`, its last step records the contacts; `stops`: the device stops
    /// after it (the end, a layered row), its last step does not predict ahead.
    fn submit_batch(&mut self, k: u64, first: StepKind, last: bool, stops: bool) -> Batch {
        let words = control::BLOCKED;
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("control readback"),
            size: (words * 4) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.bind_groups(&mut pass);
            let mut how = first;
            for step in 1..=k {
                let end = step == k;
                let ahead = first.ahead && !(end && stops);
                how.record = last && end;
                how.ahead = ahead;
                self.encode_step(&mut pass, how);
                how.predicted = ahead;
            }
        }
        enc.copy_buffer_to_buffer(&self.buffers.control, 0, &staging, 0, (words * 4) as u64);
        let index = self.gpu.queue.submit([enc.finish()]);
        staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, |r| r.expect("GPU readback failed"));
        self.submissions.set(self.submissions.get() + 1);
        self.synced = false;
        Batch {
            staging,
            index,
            steps: k,
        }
    }

    /// Waits until a batch is done and returns the control words it left.
    fn wait_for(&self, batch: Batch) -> Vec<u32> {
        self.gpu
            .device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(batch.index),
                timeout: None,
            })
            .expect("GPU device lost");
        let view = batch.staging.slice(..).get_mapped_range().expect("mapped");
        bytemuck::cast_slice::<u8, u32>(&view[..]).to_vec()
    }

    /// The first step from `from` on at which a layered block lays its next row (as the
    /// CPU path decides it: at the start of the first step with t ≥ its time).
    fn next_layered_step(&self, from: u64) -> Option<u64> {
        let dt = self.sim.scene.dt;
        self.layered
            .iter()
            .filter_map(|b| {
                let k = self.sim.sources[b.index].inserted;
                if k >= create::layered::max_rows(&b.spec) {
                    return None;
                }
                let due = b.spec.start_time + k as f64 * b.spec.interval;
                let mut s = ((due / dt).floor() as u64).saturating_sub(1).max(from);
                while (s as f64) * dt < due {
                    s += 1;
                }
                Some(s)
            })
            .min()
    }

    /// Lays the rows due at this step (`create::layered::emit` on the read-back pile) and
    /// appends them to the device, in the CPU path's order.
    fn place_layered_rows(&mut self) {
        let t = self.step as f64 * self.sim.scene.dt;
        self.download();
        let cell = self.params.cell_size;
        let unit = position::unit(cell);
        let gear = self.sim.scene.integrator == IntegratorKind::Gear5;
        let h = 0.5 * self.sim.scene.dt * self.sim.scene.dt;
        let g = self.sim.gravity(t);
        let mut live = self.live as usize;
        for b in &self.layered {
            let new = create::layered::emit(
                &b.spec,
                &mut self.sim.sources[b.index],
                t,
                b.material,
                &self.sim.particles,
            );
            for np in &new {
                let mut one = Particles::default();
                create::push(&self.sim.scene, &mut one, np);
                if gear {
                    one.q[2][0] = [h * g[0], h * g[1], 0.0];
                }
                let (st, mut pr) = to_device(&one, self.origin, cell);
                let first = self.corner_table.len();
                pr[0].shape[0] = first as u32;
                let corners = device_corners(&one.shape[0], &st, &pr_local(&pr[0]), unit);
                self.corner_table.extend_from_slice(&one.shape[0]);
                let q = &self.gpu.queue;
                q.write_buffer(
                    &self.buffers.state,
                    (live * size_of::<State>()) as u64,
                    bytemuck::cast_slice(&st[..]),
                );
                q.write_buffer(
                    &self.buffers.props,
                    (live * size_of::<Props>()) as u64,
                    bytemuck::cast_slice(&pr[..]),
                );
                // Ids are never reused: the new particle's is the number so far.
                q.write_buffer(
                    &self.buffers.ids,
                    (live * 4) as u64,
                    bytemuck::bytes_of(&(live as u32)),
                );
                if !corners.is_empty() {
                    q.write_buffer(
                        &self.buffers.corners,
                        (first * 16) as u64,
                        bytemuck::cast_slice(&corners),
                    );
                }
                live += 1;
            }
        }
        self.live = live as u32;
        self.gpu.queue.write_buffer(
            &self.buffers.control,
            (control::LIVE * 4) as u64,
            bytemuck::bytes_of(&self.live),
        );
        // New particles: the next step rebuilds the lists.
        let flags = self.read_control()[control::LISTS];
        self.write_lists_word(flags | control::REBUILD);
        self.synced = false;
    }

    fn halt_cause(&mut self, c: &[u32]) -> Divergence {
        // The device stopped inside the last submission, at the start of step
        // `halt_step`; the steps before it completed.
        let halt_step = c[control::HALT_STEP] as u64;
        self.step = halt_step;
        let id = c[control::HALT_ID];
        let flags = c[control::HALT];
        self.download();
        self.sim.step = halt_step;
        if flags & control::HALT_OVERLAP != 0 {
            let limit = self.sim.scene.limits.max_overlap;
            // The halting step recorded the diverging contacts (contact_forces.wgsl); the
            // others' records are older and within the limit.
            let mut worst: Option<(u32, f64)> = None;
            for (p, cf) in self.sim.pairs.iter().zip(&self.sim.contacts) {
                if p.i != id {
                    continue;
                }
                let ri = self.sim.particles.radius[p.i as usize];
                let rmin = if p.is_wall() {
                    ri
                } else {
                    ri.min(self.sim.particles.radius[p.j as usize])
                };
                let ratio = cf.overlap / rmin;
                if worst.is_none_or(|(_, r)| ratio > r) {
                    worst = Some((p.j, ratio));
                }
            }
            let (j, ratio) = worst.unwrap_or((u32::MAX, f64::NAN));
            let j = if j >= WALL_BASE && j != u32::MAX {
                format!("wall {}", j - WALL_BASE)
            } else {
                j.to_string()
            };
            return Divergence::Overlap {
                i: id,
                j,
                ratio,
                limit,
            };
        }
        if flags & control::HALT_NOT_FINITE != 0 {
            return Divergence::NotFinite {
                id,
                what: "force or position",
            };
        }
        if flags & control::HALT_CONTACTS_FULL != 0 {
            return Divergence::TooManyContacts {
                id,
                max: MAX_CONTACTS,
            };
        }
        Divergence::SpringTableFull { id }
    }

    fn read_control(&self) -> Vec<u32> {
        let words = control::BLOCKED;
        self.read_buffer::<u32>(&self.buffers.control, 0, words)
    }

    /// Copies `count` elements of type T from a buffer (blocking).
    fn read_buffer<T: bytemuck::Pod>(
        &self,
        buf: &wgpu::Buffer,
        first: usize,
        count: usize,
    ) -> Vec<T> {
        let size = size_of::<T>() as u64;
        let bytes = (count as u64 * size).next_multiple_of(4);
        if bytes == 0 {
            return Vec::new();
        }
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buf, first as u64 * size, &staging, 0, bytes);
        self.gpu.queue.submit([enc.finish()]);
        self.submissions.set(self.submissions.get() + 1);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| r.expect("GPU readback failed"));
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("GPU device lost");
        let view = slice.get_mapped_range().expect("mapped");
        let out = bytemuck::cast_slice::<u8, T>(&view[..count * size as usize]).to_vec();
        drop(view);
        staging.unmap();
        out
    }

    fn write_buffer<T: bytemuck::Pod>(&mut self, buf: &wgpu::Buffer, data: &[T]) {
        self.gpu
            .queue
            .write_buffer(buf, 0, bytemuck::cast_slice(data));
        self.synced = false;
    }

    /// Reads the device state into the host mirror `self.sim` (f64 particles, this step's
    /// contacts and forces, the spring table, source progress, step and losses).
    pub fn download(&mut self) -> &Simulation {
        if self.synced {
            return &self.sim;
        }
        let c = self.read_control();
        let live = c[control::LIVE] as usize;
        self.live = live as u32;
        let ds = self.device_state();
        let cell = self.params.cell_size;
        let p = from_device(&ds.states, &ds.props, self.origin, cell, &self.corner_table);
        self.sim.particles = p;
        self.sim.step = self.step;
        self.sim.lost = self.lost_base + c[control::LOST] as u64;
        let mut table = SpringTable::with_capacity_for(ds.springs.len());
        for e in &ds.springs {
            table.insert(pair_key(Pair { i: e.i, j: e.j }), e.value as f64);
        }
        self.sim.springs = table;
        let rows: Vec<Source> = self.read_buffer(&self.buffers.sources, 0, self.sources.len());
        // Point sources advance on the device; layered blocks (after them) on the host.
        for (k, (b, r)) in self.sources.iter().zip(&rows).enumerate() {
            self.sim.sources[k] = source::advanced(&b.spec, &b.state, r.inserted);
        }
        // This step's contacts, in the CPU's order (by i, then j, ids; walls last).
        let m = MAX_CONTACTS as usize;
        let ids: Vec<u32> = self.read_buffer(&self.buffers.ids, 0, live);
        let key = |j: u32| if j >= WALL_BASE { j } else { ids[j as usize] };
        let count: Vec<u32> = self.read_buffer(&self.buffers.contact_count, 0, live);
        let js: Vec<u32> = self.read_buffer(&self.buffers.contact_j, 0, live * m);
        let outs = self.read_contact_out(live * m);
        let touching: Vec<u32> = self.read_buffer(&self.buffers.touching, 0, live * m);
        let mut listed = Vec::new();
        // Every contact as the device computed it: its force, normal and contact point
        // (relative to i's centre), converted exactly from f32 (issue 19).
        let parts = &self.sim.particles;
        for s in 0..live {
            // The lists' candidates that touch: the contacts.
            for k in (0..count[s] as usize).filter(|&k| touching[s * m + k] != 0) {
                let (i, j) = (ids[s], key(js[s * m + k]));
                let o = outs[s * m + k];
                let p = parts.position(i as usize);
                let arm = [o.geo[2] as f64, o.geo[3] as f64];
                let pair = Pair { i, j };
                listed.push((
                    pair,
                    ContactForce {
                        force: [o.ft[0] as f64, o.ft[1] as f64],
                        // contact_out holds the torque on j; ContactForce the torque of F
                        // about j's centre.
                        torque: [o.ft[2] as f64, -(o.ft[3] as f64)],
                        point: [p[0] + arm[0], p[1] + arm[1]],
                        arm,
                        n: [o.geo[0] as f64, o.geo[1] as f64],
                        f_n: o.info[0] as f64,
                        f_t: o.info[1] as f64,
                        overlap: o.info[2] as f64,
                        energy: o.info[3] as f64,
                    },
                ));
            }
        }
        listed.sort_by_key(|(p, _)| (p.i, p.j));
        let (pairs, contacts) = listed.into_iter().unzip();
        self.sim.pairs = pairs;
        self.sim.contacts = contacts;
        self.sim.device_state = Some(ds);
        self.synced = true;
        &self.sim
    }

    /// The exact device state (for checkpoints).
    pub fn device_state(&self) -> DeviceState {
        let live = self.read_control()[control::LIVE] as usize;
        // In id order, whatever the memory order on the device.
        let ids: Vec<u32> = self.read_buffer(&self.buffers.ids, 0, live);
        let mut states: Vec<State> = by_id(&ids, self.read_buffer(&self.buffers.state, 0, live));
        // Where each particle was at the last rebuild belongs to the lists, not to the
        // state: an upload rebuilds them (and a resumed run may rebuild on other steps).
        for s in &mut states {
            s.listed_anchor = 0;
            s.listed_frac = [0; 2];
        }
        let props = by_id(&ids, self.read_buffer(&self.buffers.props, 0, live));
        let cap = self.params.table_mask as usize + 1;
        self.flush_table();
        let table: Vec<Entry> = self.read_buffer(&self.buffers.table, 0, cap);
        let mut springs: Vec<Entry> = table.into_iter().filter(|e| e.i != EMPTY).collect();
        springs.sort_by_key(|e| (e.i, e.j));
        DeviceState {
            states,
            props,
            springs,
        }
    }

    // ---- access for tests of single kernels ----

    /// Overwrites the particle state on the device (tests).
    pub fn upload_particles(&mut self, p: &Particles) {
        let (s, pr) = to_device(p, self.origin, self.params.cell_size);
        let s_buf = self.buffers.state.clone();
        let p_buf = self.buffers.props.clone();
        let ids_buf = self.buffers.ids.clone();
        self.write_buffer(&s_buf, &s);
        self.write_buffer(&p_buf, &pr);
        self.write_buffer(&ids_buf, &(0..s.len() as u32).collect::<Vec<_>>());
    }

    /// Whether rebuilds sort the particles in memory by cell (default: yes). No result
    /// depends on it (tests compare both).
    pub fn set_reorder(&mut self, reorder: bool) {
        self.params.reorder = reorder as u32;
        let params = self.params;
        self.gpu
            .queue
            .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(&params));
    }

    /// Makes the spring table hold the springs of the current lists (those of the
    /// candidates that touched at the last step), unless it already holds the springs
    /// (nothing has run since an upload). Between steps the springs live in the lists'
    /// slots; the table is written only at a rebuild (issue 13).
    fn flush_table(&self) {
        let flags = self.read_control()[control::LISTS];
        if flags & control::TABLE_CURRENT != 0 {
            return;
        }
        self.write_lists_word(control::FLUSH);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.bind_groups(&mut pass);
            self.encode_kernel(&mut pass, Kernel::ClearTable);
            self.encode_kernel(&mut pass, Kernel::StoreHistory);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.write_lists_word(flags);
    }

    fn write_lists_word(&self, flags: u32) {
        self.gpu.queue.write_buffer(
            &self.buffers.control,
            (control::LISTS * 4) as u64,
            bytemuck::bytes_of(&flags),
        );
    }

    /// Sets the neighbour lists' word (`control::REBUILD`, …; tests of single kernels).
    pub fn set_list_flags(&mut self, flags: u32) {
        self.write_lists_word(flags);
        self.synced = false;
    }

    /// Overwrites the spring table (tests); the next rebuild takes its springs from it.
    pub fn upload_springs(&mut self, entries: &[Entry]) {
        let table = build_table(entries, self.params.table_mask as usize + 1);
        let buf = self.buffers.table.clone();
        self.write_buffer(&buf, &table);
        self.set_list_flags(control::REBUILD | control::TABLE_CURRENT);
    }

    /// Overwrites the lists and their springs, every candidate touching (tests).
    pub fn upload_contacts(&mut self, count: &[u32], js: &[u32], history: &[f32]) {
        let (a, b, c, d) = (
            self.buffers.contact_count.clone(),
            self.buffers.contact_j.clone(),
            self.buffers.hist_in.clone(),
            self.buffers.touching.clone(),
        );
        self.write_buffer(&a, count);
        self.write_buffer(&b, js);
        self.write_buffer(&c, history);
        self.write_buffer(&d, &vec![1u32; js.len()]);
    }

    pub fn upload_cell_counts(&mut self, counts: &[u32]) {
        let buf = self.buffers.cell_count.clone();
        self.write_buffer(&buf, counts);
    }

    /// Reads a named per-step buffer as u32 words (tests).
    pub fn read_u32(&self, name: &str, count: usize) -> Vec<u32> {
        let b = &self.buffers;
        let buf = match name {
            "cell_of" => &b.cell_of,
            "cell_count" => &b.cell_count,
            "cell_start" => &b.cell_start,
            "sorted" => &b.sorted,
            "ids" => &b.ids,
            "contact_j" => &b.contact_j,
            "contact_count" => &b.contact_count,
            "touching" => &b.touching,
            "table" => &b.table,
            "control" => &b.control,
            "dispatch_args" => &b.dispatch_args,
            _ => panic!("unknown buffer {name}"),
        };
        self.read_buffer(buf, 0, count)
    }

    pub fn read_f32(&self, name: &str, count: usize) -> Vec<f32> {
        let b = &self.buffers;
        let buf = match name {
            "hist_in" => &b.hist_in,
            _ => panic!("unknown buffer {name}"),
        };
        self.read_buffer(buf, 0, count)
    }

    pub fn read_forces(&self, count: usize) -> Vec<[f32; 4]> {
        self.read_buffer(&self.buffers.force, 0, count)
    }

    pub fn read_contact_out(&self, count: usize) -> Vec<ContactOut> {
        let b = &self.buffers;
        let ft: Vec<[f32; 4]> = self.read_buffer(&b.contact_ft, 0, count);
        let info: Vec<[f32; 4]> = self.read_buffer(&b.contact_info, 0, count);
        let geo: Vec<[f32; 4]> = self.read_buffer(&b.contact_geo, 0, count);
        (ft.into_iter().zip(info).zip(geo))
            .map(|((ft, info), geo)| ContactOut { ft, info, geo })
            .collect()
    }
}

/// A wall's line normal n = (−t_z, t_x) (t along a → b) in Q30 integers q, and how q is
/// off n: q = (1 + α) n + β t, from the f64 end points. With them `wall_line`
/// (geometry.wgsl) measures distances from any line, long and inclined, exactly in
/// integers plus α (up to 2⁻³¹) times the distance and β times the distance along it.
fn wall_normal(w: &crate::geometry::WallSegment) -> ([i32; 2], f32, f32) {
    let ab = [w.b[0] - w.a[0], w.b[1] - w.a[1]];
    let len = ab[0].hypot(ab[1]).max(f64::MIN_POSITIVE);
    let t = [ab[0] / len, ab[1] / len];
    let n = [-t[1], t[0]];
    let q30 = (1u64 << 30) as f64;
    let nq = [(n[0] * q30).round() as i32, (n[1] * q30).round() as i32];
    let q = [nq[0] as f64 / q30, nq[1] as f64 / q30];
    let beta = q[0] * t[0] + q[1] * t[1];
    let alpha = q[0] * n[0] + q[1] * n[1] - 1.0;
    (nq, beta as f32, alpha as f32)
}

/// The device's corner buffer: every corner in whole position units, body frame in xy
/// and rotated to its particle's orientation in zw (as `rotate_corners` in
/// orientation.wgsl; a candidate's are rotated when it is placed).
fn device_corners(
    table: &[[f64; 2]],
    states: &[State],
    props: &[Props],
    unit: f64,
) -> Vec<[i32; 4]> {
    let mut out: Vec<[i32; 4]> = table
        .iter()
        .map(|&v| {
            let b = orientation::corner_units(v, unit);
            [b[0], b[1], b[0], b[1]]
        })
        .collect();
    for (s, p) in states.iter().zip(props) {
        let sc = orientation::turn_sin_cos(s.turn);
        let [start, count] = p.shape;
        for c in &mut out[start as usize..(start + count) as usize] {
            let w = orientation::rotate_units([c[0], c[1]], sc);
            c[2] = w[0];
            c[3] = w[1];
        }
    }
    out
}

/// One particle's props with its corners counted from 0 (for `device_corners` on a
/// table of its own corners).
fn pr_local(p: &Props) -> [Props; 1] {
    [Props {
        shape: [0, p.shape[1]],
        ..*p
    }]
}

/// Where each particle's corners start in the corner buffer: particles in id order.
pub fn corner_starts(p: &Particles) -> Vec<u32> {
    p.shape
        .iter()
        .scan(0u32, |next, c| {
            let start = *next;
            *next += c.len() as u32;
            Some(start)
        })
        .collect()
}

/// Host f64 particles → device layout.
pub fn to_device(p: &Particles, origin: [f64; 2], cell: f32) -> (Vec<State>, Vec<Props>) {
    let mut states = Vec::with_capacity(p.len());
    let mut props = Vec::with_capacity(p.len());
    let starts = corner_starts(p);
    for i in 0..p.len() {
        let q0 = p.q[0][i];
        let (anchor, frac, rem) = position::split2(q0[0] - origin[0], q0[1] - origin[1], cell);
        let mut s = State {
            anchor,
            frac,
            ..Default::default()
        };
        let (turn, turn_rem) = orientation::split_angle(q0[2]);
        s.turn = turn;
        s.q[0] = [rem[0], rem[1], turn_rem, 0.0];
        for k in 1..GEAR_VALUES {
            let v = p.q[k][i];
            s.q[k] = [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
        }
        states.push(s);
        let flags =
            ((p.active[i] as u32) * ACTIVE) | ((p.fixed[i] as u32) * FIXED) | (p.material[i] << 8);
        let (radius_units, radius_rem) = position::length_units(p.radius[i], cell);
        props.push(Props {
            radius: p.radius[i] as f32,
            mass: p.mass[i] as f32,
            inv_inertia: (1.0 / p.inertia[i]) as f32,
            flags,
            radius_units,
            radius_rem,
            shape: [starts[i], p.shape[i].len() as u32],
        });
    }
    (states, props)
}

/// Device layout → host f64 particles.
pub fn from_device(
    states: &[State],
    props: &[Props],
    origin: [f64; 2],
    cell: f32,
    corner_table: &[[f64; 2]],
) -> Particles {
    let mut p = Particles::default();
    for (s, pr) in states.iter().zip(props) {
        let coord = |k: usize| {
            let f = position::Fixed {
                anchor: s.anchor[k],
                frac: s.frac[k],
                rem: s.q[0][k],
            };
            origin[k] + position::join(f, cell)
        };
        let theta = orientation::join_angle(s.turn, s.q[0][2]);
        p.q[0].push([coord(0), coord(1), theta]);
        for k in 1..GEAR_VALUES {
            let v = s.q[k];
            p.q[k].push([v[0] as f64, v[1] as f64, v[2] as f64]);
        }
        p.radius
            .push((pr.radius_units as f64 + pr.radius_rem as f64) * position::unit(cell));
        p.mass.push(pr.mass as f64);
        p.inertia.push(if pr.inv_inertia == 0.0 {
            f64::INFINITY
        } else {
            1.0 / pr.inv_inertia as f64
        });
        p.fixed.push(pr.flags & FIXED != 0);
        p.active.push(pr.flags & ACTIVE != 0);
        p.material.push(pr.flags >> 8);
        let [start, count] = pr.shape;
        p.shape
            .push(corner_table[start as usize..(start + count) as usize].to_vec());
    }
    p
}

/// A spring table laid out as the kernels expect (host twin of `insert_new`).
pub fn build_table(entries: &[Entry], cap: usize) -> Vec<Entry> {
    let empty = Entry {
        i: EMPTY,
        ..Default::default()
    };
    let mut t = vec![empty; cap];
    let mask = cap - 1;
    for e in entries {
        let mut slot = hash_pair(e.i, e.j) as usize & mask;
        while t[slot].i != EMPTY {
            slot = (slot + 1) & mask;
        }
        t[slot] = *e;
    }
    t
}

/// Looks a pair up in a device-layout table (host twin of `lookup_old`).
pub fn table_lookup(table: &[Entry], i: u32, j: u32) -> Option<f32> {
    let mask = table.len() - 1;
    let mut slot = hash_pair(i, j) as usize & mask;
    for _ in 0..table.len() {
        let e = table[slot];
        if e.i == EMPTY {
            return None;
        }
        if e.i == i && e.j == j {
            return Some(e.value);
        }
        slot = (slot + 1) & mask;
    }
    None
}

/// Law coefficients into Params.
fn law_params(law: &ContactLaw, p: &mut Params) {
    match law {
        ContactLaw::SpringDashpot(l) => {
            p.law = LAW_SPRING_DASHPOT;
            p.k_n = l.k_n as f32;
            p.nu = l.nu as f32;
            p.psi = l.psi as f32;
            p.delta0 = l.delta0 as f32;
            p.gamma_n = l.gamma_n as f32;
            p.k_t = l.k_t as f32;
            p.gamma_t = l.gamma_t as f32;
            p.mu = l.mu as f32;
            p.clamp = l.clamp as u32;
        }
        ContactLaw::OverlapArea(l) => {
            // η^n and η^t travel in gamma_n and gamma_t (common.wgsl).
            p.law = LAW_AREA;
            p.k_n = l.k_n as f32;
            p.k_t = l.k_t as f32;
            p.mu = l.mu as f32;
            p.gamma_n = l.eta_n as f32;
            p.gamma_t = l.eta_t as f32;
            p.clamp = 1;
        }
        ContactLaw::Continuous(c) => {
            p.law = LAW_CONTINUOUS;
            match c.elastic {
                crate::law::continuous::Elastic::Power { n } => {
                    p.elastic = 0;
                    p.n_exp = n as f32;
                }
                crate::law::continuous::Elastic::Hooke { k } => {
                    p.elastic = 1;
                    p.hooke_k = k as f32;
                }
            }
            p.r0 = c.r0 as f32;
            p.mu = c.mu as f32;
            p.alpha = c.alpha as f32;
            p.damping_fraction = c.damping_fraction as f32;
            p.g_scale = c.g as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell_list::Grid;

    #[test]
    fn the_largest_scene_is_what_the_bindings_and_one_dispatch_hold() {
        // lavapipe binds 128 MiB: the candidates' result arrays (256 B per particle)
        // and the spring table (16 B per slot, a power of two) stop at 2^19.
        let lavapipe = 128 << 20;
        assert_eq!(max_particles(lavapipe), 1 << 19);
        assert!(
            particle_buffers(1 << 19)
                .iter()
                .all(|&(_, b)| b <= lavapipe)
        );
        assert!(
            particle_buffers((1 << 19) + 1)
                .iter()
                .any(|&(_, b)| b > lavapipe)
        );
        // NVIDIA-class 2 GiB bindings: one dispatch of 65 535 workgroups of 64 is the
        // limit, above the 4·10⁶ disks issue 14 asks for.
        assert_eq!(max_particles(2 << 30), MAX_WORKGROUPS * WG as u64);
        assert!(max_particles(2 << 30) >= 4_000_000);
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
