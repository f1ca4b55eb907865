// Shared declarations of every talus kernel: constants, the data layouts and the
// bindings. The Rust twins of these structs are in src/gpu/layout.rs; a test checks the
// sizes and field offsets against naga's view of this file.
//
// Positions are fixed point (cell anchor + units + f32 remainder) for SPEC 3's
// precision; see position.wgsl, which every module includes after this file.

const WG: u32 = 64u;
// Workgroups of one dispatch in one dimension at most (src/gpu/mod.rs).
const MAX_WORKGROUPS: u32 = 65535u;
const WALL_BASE: u32 = 0xFFFF0000u;
const EMPTY: u32 = 0xFFFFFFFFu;
// A disk pair's rolling spring among its SubSprings (src/cpu/springs.rs ROLLING_KEY).
const ROLLING_KEY: u32 = 0xFFFFFFFEu;
// Params.law
const LAW_SPRING_DASHPOT: u32 = 0u;
const LAW_CONTINUOUS: u32 = 1u;
const LAW_AREA: u32 = 2u;
const LAW_HERTZ: u32 = 3u;
// Props.flags: ACTIVE | FIXED | material << MATERIAL_SHIFT | copy << COPY_SHIFT
const ACTIVE: u32 = 1u;
const FIXED: u32 = 2u;
const MATERIAL_SHIFT: u32 = 8u;
const COPY_SHIFT: u32 = 20u;
// control[] words
const C_STEP: u32 = 0u;
const C_LIVE: u32 = 1u;
const C_LOST: u32 = 2u;
const C_HALT: u32 = 3u;
const C_HALT_STEP: u32 = 4u;
const C_HALT_ID: u32 = 5u;
// Bits of the neighbour lists' word (src/cpu/neighbours.rs; issue 13).
const C_LISTS: u32 = 6u;
// How many times the lists were built.
const C_REBUILDS: u32 = 7u;
// 1 while the step in progress was recorded with the rebuild stages (`plan_rebuild`
// sets it, `advance_clock` clears it): a lean step, recorded without them (issue 38,
// src/gpu/step.rs), pauses when it would need them (`lists_stale`).
const C_STAGED: u32 = 8u;
// Inactive particles counted by cell_index at a rebuild (they go last in the new memory
// order, `permute_gather`).
const C_INACTIVE: u32 = 9u;
// The step whose lists were built last (`advance_clock`): moving walls ask for a
// rebuild once they have moved by half the skin since then (`walls_moved`).
const C_WALLS_LISTED: u32 = 10u;
const C_BLOCKED: u32 = 11u;
// control[C_LISTS]: REBUILD, the lists are rebuilt this step (a particle moved more
// than skin/2, or was inserted or removed, or the state was uploaded); TABLE_CURRENT,
// the spring table holds the springs (an upload: the first rebuild takes them from it
// instead of storing the lists' into it); FLUSH, the host asks for the table of the
// current lists (`GpuSimulation::device_state`); REMOVED, see below.
const REBUILD: u32 = 1u;
const TABLE_CURRENT: u32 = 2u;
const FLUSH: u32 = 4u;
// A particle was removed at the end of this step: the next step rebuilds the lists.
const REMOVED: u32 = 8u;
// The survey of the next step's prediction, run ahead at the end of this one (`correct`
// with AHEAD), asks for a rebuild: the next step rebuilds the lists.
const AHEAD_REBUILD: u32 = 16u;
// Halt reasons (bits of control[C_HALT]).
const HALT_OVERLAP: u32 = 1u;
const HALT_NOT_FINITE: u32 = 2u;
const HALT_CONTACTS_FULL: u32 = 4u;
const HALT_TABLE_FULL: u32 = 8u;
const HALT_TOO_FAST: u32 = 16u;
// Not a failure: a lean step found that it must rebuild the lists. Every kernel returns
// (`halted`) until the next step recorded with the rebuild stages, whose `plan_rebuild`
// lifts the pause and rebuilds from the paused, predicted state: the run goes on as if
// the stages had been recorded in the paused step (bitwise the same).
const HALT_PAUSED: u32 = 32u;
// Params.reading bits (src/gpu/layout.rs).
const READING_SLIP_DAMPING: u32 = 1u;
const READING_CONTACT_ARM: u32 = 2u;
const READING_ACCUMULATE: u32 = 4u;
const READING_SLIDE: u32 = 8u;
// Candidates of one source looked at per step.
const INSERT_WINDOW: u32 = 4u;
// Gear values per degree of freedom (State.q; src/state.rs).
const GEAR_VALUES: u32 = 6u;
// Slots of the spring-dashpot law's table per pair of materials (Params.pair_law holds
// two vec4 per slot).
const MAX_PAIR_SLOTS: u32 = 64u;

struct Params {
    n_cap: u32,
    nx: u32,
    nz: u32,
    cells: u32,
    n_walls: u32,
    n_sources: u32,
    table_mask: u32,
    integrator: u32,   // 0 Gear, 1 leapfrog
    cell_size: f32,
    dt: f32,
    max_overlap: f32,
    range_factor: f32,
    gx: f32,
    gz: f32,
    ramp_steps: f32,   // gravity ramp in steps; 0: none
    law: u32,          // 0 spring-dashpot, 1 continuous, 2 overlap area (polygons)
    dom_lo_x: f32,     // domain, relative to the grid origin
    dom_lo_z: f32,
    dom_hi_x: f32,
    dom_hi_z: f32,
    // spring-dashpot (paper 000 eq. 2-5); the overlap-area law (paper 000 eq. 6-7)
    // uses k_n, k_t, mu, and gamma_n, gamma_t for its dimensionless eta_n, eta_t
    k_n: f32,
    nu: f32,
    psi: f32,
    delta0: f32,
    gamma_n: f32,
    k_t: f32,
    gamma_t: f32,
    mu: f32,
    clamp: u32,
    // continuous (paper 001 eq. 3-8)
    elastic: u32,      // 0 power law, 1 Hooke
    n_exp: f32,
    hooke_k: f32,
    r0: f32,
    alpha: f32,
    damping_fraction: f32,
    g_scale: f32,
    // prefix sum: blocks of level 1 and where level 2 starts in `scan`
    scan_blocks1: u32,
    scan_blocks2: u32,
    scan_offset2: u32,
    // fixed-point positions (position.wgsl): unit = cell_size / 2^30, and its inverse
    unit: f32,
    inv_unit: f32,
    // the neighbour lists' skin (length units)
    skin: f32,
    // 1: sort the particles in memory by cell at every rebuild (permute.wgsl); 0: keep
    // them where they are (tests: the results must not depend on it)
    reorder: u32,
    // Candidates per particle as the lower id (its own list, slots i list_cap + k) and
    // as the higher id (its down list): 16, more for long rods (src/gpu/mod.rs
    // `list_capacity`)
    list_cap: u32,
    // hertz_cohesive (paper 004 sec. 2): Bo g, the cohesive pull per unit of the
    // contact's mass scale, and the cohesion range d_c (length)
    bond_g: f32,
    d_c: f32,
    // limits.max_step_displacement, squared (0: no bound): the most a particle may move
    // in one step, as a fraction of its radius (survey.wgsl `survey_one_at`)
    max_step2: f32,
    // The spring-dashpot law's coefficients per pair of materials (src/law/restitution.rs,
    // src/gpu/layout.rs): slot s = a pair_side + b (b = pair_side - 1: a wall) has
    // pair_law[2s] = (k_n, gamma_n, k_t, gamma_t) and pair_law[2s + 1] = (mu, mu_r,
    // k_roll, eta_r), the first four per unit of the contact's effective mass when
    // per_mass is 1; the rolling resistance's table (src/law/rolling.rs RollingTable)
    // shares the slots.
    pair_side: u32,
    per_mass: u32,
    // The continuous law's readings of paper 001 (src/law/continuous.rs `Reading`):
    // READING_SLIP_DAMPING | READING_CONTACT_ARM | READING_ACCUMULATE | READING_SLIDE, 0 for the
    // default readings; its clamp
    // is `clamp`.
    reading: u32,
    // rolling resistance at disk contacts (src/law/rolling.rs), whose values per pair
    // ride in pair_law[2s + 1].yzw (`rolling_of`): here the largest mu_r of any pair (0:
    // none) and the largest k_roll (0: the constant torque), which choose the branches
    rolling_mu: f32,
    rolling_k: f32,
    pad_roll0: u32,
    // a domain periodic in x: its period in whole cells (src/gpu/mod.rs `device_grid`), 0
    // when not periodic
    period_cells: u32,
    pad_roll1: u32,
    pad_roll2: u32,
    pair_law: array<vec4<f32>, 2u * MAX_PAIR_SLOTS>,
};

// Dynamic state: q[0] = (rem_x, rem_z, rem_theta, 0) with the position's remainder in
// units (position.wgsl) and the orientation's in turn units (orientation.wgsl),
// q[k] = (dt^k/k!) d^k/dt^k in length units and radians.
struct State {
    q: array<vec4<f32>, GEAR_VALUES>,
    anchor: vec2<i32>,
    frac: vec2<u32>,
    turn: u32,
    // Where the particle was when the lists were built: its anchor (two i16 in one word)
    // and frac (src/cpu/neighbours.rs `moved`; the survey kernel).
    listed_anchor: u32,
    listed_frac: vec2<u32>,
    // q1's whole units: position units along x and z, turn units of the rotation
    // (position.wgsl `renormalize_q1`); q[1].xyz holds the rest.
    q1_whole: vec4<i32>,
};

struct Props {
    radius: f32,
    mass: f32,
    inv_inertia: f32,   // 0 for fixed rotation
    flags: u32,         // ACTIVE | FIXED | material << 8 | copy << 20
    radius_units: u32,  // the radius in fixed point (position.wgsl)
    radius_rem: f32,
    shape: vec2<u32>,   // polygon corners: first index in `corners`, count (0: disk)
};

// A segment a-b; both end points in fixed point, ab = b - a in length units.
struct Wall {
    a_anchor: vec2<i32>,
    a_frac: vec2<u32>,
    a_rem: vec2<f32>,
    b_anchor: vec2<i32>,
    b_frac: vec2<u32>,
    b_rem: vec2<f32>,
    ab: vec2<f32>,
    nq: vec2<i32>,      // the line's unit normal (-t.y, t.x) in Q30 (host: gpu/mod.rs)
    beta: f32,          // nq/2^30 = (1 + alpha) n + beta t: its turn off the true normal
    alpha: f32,         // and its stretch
    velocity: vec2<f32>, // the surface's velocity, along the wall (scene walls[k].velocity)
    // The segment's own motion (scene walls[k].motion): a constant velocity, and an
    // oscillation's amplitude and 2 pi / T (0: none); the ends above are at t = 0.
    motion_v: vec2<f32>,
    amplitude: vec2<f32>,
    omega: f32,
    pad: u32,
};

struct Entry {
    i: atomic<u32>,
    j: u32,
    value: f32,
    _pad: u32,
};

// A pair's springs beyond its tangential one (src/cpu/springs.rs `SubSprings`;
// MAX_SUB = 4): a spheropolygon pair's, one per sub-contact (`SubContact::key`), or a
// disk pair's rolling spring (key ROLLING_KEY); EMPTY for none. Per candidate slot
// (`sub_hist`) and per entry of the spring table (`table_sub`, beside `table`), in the
// scenes that keep them (`sub_springs_kept`).
struct SubSprings {
    key: vec4<u32>,
    xi: vec4<f32>,
};

struct Source {
    first: u32,      // index of its first candidate
    count: u32,
    inserted: u32,
    _pad: u32,
};

struct Candidate {
    anchor: vec2<i32>,
    frac: vec2<u32>,
    rem: vec2<f32>,
    velocity: vec2<f32>,  // scaled: dt * v
    radius: f32,
    mass: f32,
    inv_inertia: f32,
    due_step: u32,
    flags: u32,
    radius_units: u32,
    radius_rem: f32,
    turn: u32,           // orientation: whole turn units and remainder
    shape: vec2<u32>,
    turn_rem: f32,
    _pad: u32,
};

// The bindings are declared after this file, generated from src/gpu/bindings.rs
// BINDINGS: `read` where no entry point of the module writes the buffer.

// Every candidate of the lists as one compact list of `count` slots (i list_cap +
// k), written by find_contacts at a rebuild, for contact_forces under the overlap-area
// law, which takes one thread per pair (issue 14 item 5). clear_cells empties it.
struct PairList {
    count: atomic<u32>,
    slot: array<u32>,
};

fn is_active(i: u32) -> bool {
    return (props[i].flags & ACTIVE) != 0u;
}

fn is_fixed(i: u32) -> bool {
    return (props[i].flags & FIXED) != 0u;
}

// A contact's slot in Params.pair_law: materials a and b of i and j, b = pair_side - 1
// for a wall (src/law/restitution.rs `PairTable::slot`).
fn pair_slot(i: u32, j: u32, wall: bool) -> u32 {
    let side = params.pair_side;
    if (side <= 1u) { return 0u; }
    let a = (props[i].flags >> MATERIAL_SHIFT) & ((1u << (COPY_SHIFT - MATERIAL_SHIFT)) - 1u);
    var b = side - 1u;
    if (!wall) {
        b = (props[j].flags >> MATERIAL_SHIFT) & ((1u << (COPY_SHIFT - MATERIAL_SHIFT)) - 1u);
    }
    return a * side + b;
}

// A contact's effective mass: the reduced mass with a fixed partner or a wall infinitely
// heavy (src/law/restitution.rs `effective_mass`).
fn effective_mass(i: u32, j: u32, wall: bool, m1: f32) -> f32 {
    if (wall) { return m1; }
    let m2 = props[j].mass;
    let fixed_i = is_fixed(i);
    let fixed_j = is_fixed(j);
    if (fixed_j && !fixed_i) { return m1; }
    if (fixed_i && !fixed_j) { return m2; }
    return m1 * m2 / (m1 + m2);
}

// The copy of the scene particle i belongs to (`replicas`): it touches only its own.
fn copy_of(flags: u32) -> u32 {
    return flags >> COPY_SHIFT;
}

fn is_integrated(i: u32) -> bool {
    return (props[i].flags & (ACTIVE | FIXED)) == ACTIVE;
}

// Whether the scene keeps SubSprings per candidate and table entry (src/gpu/mod.rs
// `keeps_sub_springs`): spheropolygons' sub-contact springs, or rolling springs.
fn sub_springs_kept() -> bool {
    return params.law == LAW_HERTZ || params.rolling_k > 0.0;
}

// --- Walls that move (scene walls[k].motion; src/sim/walls.rs) ---

// The time of the contacts evaluated in step `step`: Gear evaluates them at the
// predicted state, t + dt, leapfrog at t (src/sim/mod.rs `step_with`).
fn contact_time_of(step: u32) -> f32 {
    return f32(step + select(0u, 1u, params.integrator == 0u)) * params.dt;
}

// The time of this step's contacts.
fn contact_time() -> f32 {
    return contact_time_of(atomicLoad(&control[C_STEP]));
}

fn wall_moves(w: u32) -> bool {
    return any(walls[w].motion_v != vec2<f32>(0.0)) || walls[w].omega != 0.0;
}

// Twin of src/scene/schema.rs `WallMotion::displacement`: wall w's displacement at time
// t from its ends at t = 0, v t + A sin(omega t).
fn wall_displacement(w: u32, t: f32) -> vec2<f32> {
    let m = walls[w];
    return m.motion_v * t + m.amplitude * sin(m.omega * t);
}

// Twin of src/scene/schema.rs `WallMotion::velocity_at`.
fn wall_motion_velocity(w: u32, t: f32) -> vec2<f32> {
    let m = walls[w];
    return m.motion_v + m.amplitude * (m.omega * cos(m.omega * t));
}

// The velocity wall w's contacts see in this step: its surface's along it, plus the
// segment's own.
fn wall_velocity(w: u32) -> vec2<f32> {
    if (!wall_moves(w)) { return walls[w].velocity; }
    return walls[w].velocity + wall_motion_velocity(w, contact_time());
}

// Twin of src/sim/walls.rs `walls_moved`: whether at the contacts of step `step` a wall
// has moved by more than skin/2 since the lists were built (control[C_WALLS_LISTED]);
// a hair less than skin/2 for f32's rounding, so never later than the CPU path.
fn walls_moved(step: u32) -> bool {
    let listed = contact_time_of(atomicLoad(&control[C_WALLS_LISTED]));
    let now = contact_time_of(step);
    let half = 0.5 * params.skin * (1.0 - 1.0e-4);
    for (var w = 0u; w < params.n_walls; w++) {
        if (!wall_moves(w)) { continue; }
        let d = wall_displacement(w, now) - wall_displacement(w, listed);
        if (dot(d, d) > half * half) { return true; }
    }
    return false;
}

fn halted() -> bool {
    return atomicLoad(&control[C_HALT]) != 0u;
}

fn lists_word() -> u32 {
    return atomicLoad(&control[C_LISTS]);
}

// Whether this step rebuilds the neighbour lists.
fn rebuilding() -> bool {
    return (lists_word() & REBUILD) != 0u;
}

// This step must rebuild the lists but was recorded without the rebuild stages.
fn lists_stale() -> bool {
    return rebuilding() && atomicLoad(&control[C_STAGED]) == 0u;
}

fn request_rebuild() {
    atomicOr(&control[C_LISTS], REBUILD);
}

fn live() -> u32 {
    return atomicLoad(&control[C_LIVE]);
}

// Stops the run because of the particle in memory slot i: the first step and the lowest
// particle id are kept (atomic min, so the report depends neither on thread timing nor
// on the memory order).
fn halt(reason: u32, i: u32) {
    atomicOr(&control[C_HALT], reason);
    atomicMin(&control[C_HALT_STEP], atomicLoad(&control[C_STEP]));
    atomicMin(&control[C_HALT_ID], ids[i]);
}

// The spring table's key for partner j of a candidate: its id, or the wall's code.
fn partner_key(j: u32) -> u32 {
    if (j >= WALL_BASE) { return j; }
    return ids[j];
}

// Gravity at the given step (ramped linearly, paper 000 sec. 4).
fn gravity_at(step: f32) -> vec2<f32> {
    var s = 1.0;
    if (params.ramp_steps > 0.0) {
        s = min(step / params.ramp_steps, 1.0);
    }
    return vec2<f32>(params.gx, params.gz) * s;
}

// Cell coordinates of an anchor, clamped into the grid (as Grid::cell_coords).
fn cell_coords(a: vec2<i32>) -> vec2<u32> {
    let cx = clamp(a.x, 0, i32(params.nx) - 1);
    let cz = clamp(a.y, 0, i32(params.nz) - 1);
    return vec2<u32>(u32(cx), u32(cz));
}

// Whether the grid is hashed into `params.cells` buckets (issue 13: a grid with more
// cells than that, a wide domain, takes memory O(N) whatever its area) or dense
// (nx nz <= cells: bucket = cell). Written without the product, which may overflow.
fn hashed_grid() -> bool {
    return params.nx > params.cells / params.nz;
}

// The spatial hash: the cell's coordinates times large primes (Teschner et al. 2003),
// mixed by Wellons's lowbias32 so that every bit of the bucket depends on both.
const HASH_X: u32 = 73856093u;
const HASH_Z: u32 = 19349663u;
const HASH_MIX_1: u32 = 0x7feb352du;
const HASH_MIX_2: u32 = 0x846ca68bu;

// The bucket of cell c (twin of `gpu::bucket`): the cell itself on a dense grid, else a
// spatial hash; cells that share a bucket are told apart by their particles' anchors.
fn bucket(c: vec2<u32>) -> u32 {
    if (!hashed_grid()) { return c.y * params.nx + c.x; }
    var h = (c.x * HASH_X) ^ (c.y * HASH_Z);
    h ^= h >> 16u;
    h *= HASH_MIX_1;
    h ^= h >> 15u;
    h *= HASH_MIX_2;
    h ^= h >> 16u;
    return h % params.cells;
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

fn tangent(n: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(-n.y, n.x);
}

// Slot hash of a pair for the spring table (host twin src/gpu/layout.rs `hash_pair`):
// both ids multiplied by odd constants, mixed by the buckets' finaliser.
const PAIR_HASH_I: u32 = 0x9E3779B1u;
const PAIR_HASH_J_ADD: u32 = 0x7F4A7C15u;
const PAIR_HASH_J: u32 = 0x85EBCA77u;
fn hash_pair(i: u32, j: u32) -> u32 {
    var h = (i * PAIR_HASH_I) ^ ((j + PAIR_HASH_J_ADD) * PAIR_HASH_J);
    h ^= h >> 16u;
    h *= HASH_MIX_1;
    h ^= h >> 15u;
    h *= HASH_MIX_2;
    h ^= h >> 16u;
    return h;
}
