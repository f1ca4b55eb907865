// Stage (src/cpu/forces/candidates.rs `candidate_forces`): each candidate of the lists on its own:
// whether it touches (`touches`: the test of src/cpu/forces/candidates.rs `candidate_force`), and if it
// does, its geometry, the relative velocity at the contact point and the law. Stores
// the force on i, both torques, the normal and contact point it used, and the updated
// history in the candidate's slot; a candidate that does not touch gets zero force and
// history. Flags a diverging contact.

// Whether to store what only outputs read (`contact_info`, `contact_geo`): the host
// builds the step that ends an `advance` with it, the others without (32 bytes per
// candidate and step less; `Kernel::ContactForcesOnly`).
override RECORD: bool = true;

// Whether disks i and j at offset o interact (r < range_factor * sigma). The f32
// distance is right to ~1e-7 relative, so only pairs within 1e-5 of the boundary need
// the exact geometry `g` (disk_disk(i, j), computed by the caller anyway).
fn disks_touch(o: Offset, i: u32, j: u32, g: Geometry) -> bool {
    if (!o.near) { return false; }
    let v = offset_vector(o);
    let reach = params.range_factor * (props[i].radius + props[j].radius);
    let r2 = dot(v, v);
    let margin = 2.0e-5 * reach * reach;
    if (r2 > reach * reach + margin) { return false; }
    if (r2 < reach * reach - margin) { return true; }
    return g.r < params.range_factor * g.sigma;
}

// Polygons (and disks under the area law) first by their circumscribed circles, with
// f32 slack; then they touch when the overlap area `a` is found.
fn circles_near(i: u32, j: u32) -> bool {
    let o = offset_ij(i, j);
    if (!o.near) { return false; }
    let v = offset_vector(o);
    let reach = params.range_factor * (props[i].radius + props[j].radius);
    return dot(v, v) <= reach * reach + 2.0e-5 * reach * reach;
}

fn wall_circle_near(i: u32, w: u32) -> bool {
    return disk_wall(i, w).delta >= -1.0e-5 * props[i].radius;
}

fn velocity(i: u32) -> vec3<f32> {
    return q1_total(state[i].q1_whole, state[i].q[1]) / params.dt;
}

// Disks: a thread per particle, over its own list (its state read once for all its
// candidates). The overlap-area law and spheropolygons: a thread per pair of the compact list find_contacts
// wrote (`pairs`), dispatched with the workgroups `plan_pairs` wrote (striding over any
// beyond them): a polygon pair costs far more than a disk pair, and a thread per
// particle would run a third as many threads, each keeping the others of its group
// waiting for its longest list.
@compute @workgroup_size(WG)
fn contact_forces(@builtin(global_invocation_id) gid: vec3<u32>,
                  @builtin(num_workgroups) groups: vec3<u32>) {
    if (halted()) { return; }
    // A lean step whose survey asks for a rebuild pauses here (HALT_PAUSED): its
    // candidates are stale. Every thread sees the same words, set by earlier dispatches.
    if (lists_stale()) {
        atomicOr(&control[C_HALT], HALT_PAUSED);
        return;
    }
    if (POLYGONS || SPHEROPOLYGONS) {
        let total = atomicLoad(&pairs.count);
        for (var t = gid.x; t < total; t += groups.x * WG) {
            let slot = pairs.slot[t];
            let i = slot / params.list_cap;
            if (SPHEROPOLYGONS) {
                spheropolygon_force(i, slot, props[i].mass, velocity(i));
            } else {
                candidate_force(i, slot, props[i].radius, props[i].mass, velocity(i));
            }
        }
        return;
    }
    let i = gid.x;
    if (i >= live()) { return; }
    // Particle i's own values once for all its candidates.
    let ri = props[i].radius;
    let m1 = props[i].mass;
    let v1 = velocity(i);
    for (var k = 0u; k < contact_count[i]; k++) {
        candidate_force(i, i * params.list_cap + k, ri, m1, v1);
    }
}

// src/law/rolling.rs AT_REST (checked by tests/gpu_constants.rs).
const ROLLING_AT_REST: f32 = 0.1;

// Twin of src/law/rolling.rs `rolling_torque`: the constant directional torque of Ai et
// al. (2011) eq. 6 against the relative spin, limited near rest to ROLLING_AT_REST of
// what stops it in one step.
fn rolling_torque(mu_r: f32, spin: f32, r_roll: f32, f_n: f32, inv_inertia_sum: f32,
                  dt: f32) -> f32 {
    if (!(inv_inertia_sum > 0.0) || spin == 0.0) { return 0.0; }
    let full = mu_r * r_roll * max(f_n, 0.0);
    let near_rest = ROLLING_AT_REST * abs(spin) / (inv_inertia_sum * dt);
    return -sign(spin) * min(full, near_rest);
}

// Twin of src/law/rolling.rs `Rolling`: one pair of materials' rolling resistance.
struct Rolling {
    mu_r: f32,
    k_roll: f32,
    eta_r: f32,
};

// Twin of src/law/rolling.rs `RollingTable::get`: the rolling resistance of the pair of
// materials in slot `pair` of Params.pair_law (`pair_slot`), in its second vec4's yzw.
fn rolling_of(pair: u32) -> Rolling {
    let r = params.pair_law[2u * pair + 1u];
    return Rolling(r.y, r.z, r.w);
}

// Twin of src/law/rolling.rs `rolling_spring`: the spring-dashpot rolling torque of Ai
// et al. (2011) eq. 9-16 on i (x) and the rolling spring after the step (y).
fn rolling_spring(r: Rolling, spring: f32, spin: f32, r_roll: f32, f_n: f32,
                  inv_rolling_inertia: f32, dt: f32) -> vec2<f32> {
    if (!(inv_rolling_inertia > 0.0)) { return vec2<f32>(0.0); }
    let k_r = r.k_roll * r_roll * r_roll;
    let limit = r.mu_r * r_roll * max(f_n, 0.0);
    let m_k = spring - k_r * spin * dt;
    if (abs(m_k) >= limit) {
        // Full mobilisation: the spring slips at its limit, no damping.
        var held = 0.0;
        if (m_k != 0.0) { held = sign(m_k) * limit; }
        return vec2<f32>(held, held);
    }
    let c_r = r.eta_r * 2.0 * sqrt(k_r / inv_rolling_inertia);
    return vec2<f32>(m_k - c_r * spin, m_k);
}

// Twin of src/law/rolling.rs `rolling_inertia_inv`: 1/(I + m R^2) of disk k, 0 fixed.
fn rolling_inertia_inv(k: u32) -> f32 {
    if (is_fixed(k) || !(props[k].inv_inertia > 0.0)) { return 0.0; }
    let r = props[k].radius;
    return 1.0 / (1.0 / props[k].inv_inertia + props[k].mass * r * r);
}

// Candidate `slot` of particle i's list; i's radius, mass and velocity.
fn candidate_force(i: u32, slot: u32, ri: f32, m1: f32, v1: vec3<f32>) {
    let j = contact_j[slot];
    let wall = j >= WALL_BASE;
    var g: Geometry;
    var v2 = vec3<f32>(0.0);
    var d_ij = vec2<f32>(0.0);   // centre i minus centre j
    var rmin = ri;
    var m12 = m1;
    var mass = m1;
    var o: Offset;
    if (!wall) {
        o = offset_ij(i, j);
        d_ij = offset_vector(o);
        v2 = velocity(j);
        rmin = min(ri, props[j].radius);
        let m2 = props[j].mass;
        m12 = m1 * m2 / (m1 + m2);
        mass = 2.0 * m12;
    } else if (WALLS) {
        // A wall's surface moves along it (scene walls[k].velocity).
        v2 = vec3<f32>(wall_velocity(j - WALL_BASE), 0.0);
    }
    // The law sees the rate of delta: the overlap's for disks, L v_n / l for the
    // overlap area (delta = A/l; src/cpu/forces/kinematics.rs `area_kinematics`).
    var rate = 1.0;
    var touches = false;
    if (POLYGONS) {
        var a: AreaContact;
        if (WALLS && wall) {
            touches = wall_circle_near(i, j - WALL_BASE);
            if (touches) { a = area_contact_wall(i, j - WALL_BASE); }
        } else {
            touches = circles_near(i, j);
            if (touches) { a = area_contact(i, j); }
        }
        touches = touches && a.found;
        var delta = 0.0;
        var depth = 0.0;
        rate = 0.0;
        if (a.found && a.l > 0.0) {
            delta = a.area / a.l;
            if (a.chord > 0.0) { depth = a.area / a.chord; }
            rate = a.chord / a.l;
        }
        g = Geometry(a.n, delta, depth, 0.0, a.point, true);
    } else if (WALLS && wall) {
        g = disk_wall(i, j - WALL_BASE);
        touches = g.r < params.range_factor * g.sigma;
    } else {
        g = disk_disk_at(o, i, j);
        touches = disks_touch(o, i, j, g);
    }
    if (!touches) {
        contact_ft[slot] = vec4<f32>(0.0);
        hist_in[slot] = 0.0;
        if (!POLYGONS && params.rolling_k > 0.0) {
            sub_hist[slot] = SubSprings(vec4<u32>(EMPTY), vec4<f32>(0.0));
        }
        touching[slot] = 0u;
        return;
    }
    touching[slot] = 1u;
    let l1 = g.arm;
    let l2 = d_ij + l1;
    let s1 = v1.z * vec2<f32>(-l1.y, l1.x);
    var s2 = vec2<f32>(0.0);
    if (!wall) { s2 = v2.z * vec2<f32>(-l2.y, l2.x); }
    // Relative velocity of the two surfaces at the contact point.
    let v12 = v1.xy + s1 - v2.xy - s2;
    let t = tangent(g.n);
    var m_eff = m12;
    var pair = 0u;
    if (params.per_mass != 0u) {
        m_eff = effective_mass(i, j, wall, m1);
        pair = pair_slot(i, j, wall);
    }
    // The centres' velocity and the spins, for the continuous law's readings (v2 of a
    // wall is its surface's velocity, with no spin).
    let v_centres = dot(v1.xy - v2.xy, t);
    let input = ContactInput(g.delta, g.r, g.sigma, -dot(v12, g.n) * rate, dot(v12, t),
                             m12, mass, hist_in[slot], params.dt, m_eff, pair,
                             v_centres, v1.z + v2.z);
    let res = evaluate(input);
    let f = res.f_n * g.n + res.f_t * t;
    // Paper 001 eq. 13 (src/cpu/forces/mod.rs `contact_force`): both torques on the law's lever.
    var torques = vec2<f32>(cross2(l1, f), -cross2(l2, f));
    if (res.lever > 0.0) { torques = vec2<f32>(-res.lever * res.f_t); }
    if (!POLYGONS && params.rolling_mu > 0.0) {
        // src/cpu/forces/mod.rs `rolling`: on i, and its opposite on j.
        let roll = rolling_of(pair_slot(i, j, wall));
        var spin = v1.z;
        var r_roll = ri;
        var inv_inertia = select(props[i].inv_inertia, 0.0, is_fixed(i));
        var inv_rolling = rolling_inertia_inv(i);
        if (!wall) {
            spin = v1.z - v2.z;
            let rj = props[j].radius;
            r_roll = ri * rj / (ri + rj);
            inv_inertia += select(props[j].inv_inertia, 0.0, is_fixed(j));
            inv_rolling += rolling_inertia_inv(j);
        }
        var m = 0.0;
        if (params.rolling_k > 0.0) {
            // The rolling spring, kept among the slot's SubSprings (ROLLING_KEY).
            let old = sub_hist[slot];
            var spring = 0.0;
            if (old.key.x == ROLLING_KEY) { spring = old.xi.x; }
            let r = rolling_spring(roll, spring, spin, r_roll, res.f_n, inv_rolling, params.dt);
            m = r.x;
            sub_hist[slot] = SubSprings(vec4<u32>(ROLLING_KEY, EMPTY, EMPTY, EMPTY),
                                        vec4<f32>(r.y, 0.0, 0.0, 0.0));
        } else {
            m = rolling_torque(roll.mu_r, spin, r_roll, res.f_n, inv_inertia, params.dt);
        }
        torques += vec2<f32>(m, -m);
    }
    contact_ft[slot] = vec4<f32>(f, torques);
    // In place: the slot's spring is the list's history from step to step.
    hist_in[slot] = res.history;
    let finite = abs(f.x) <= 3.0e38 && abs(f.y) <= 3.0e38;
    let too_deep = g.delta / rmin > params.max_overlap;
    if (!finite) { halt(HALT_NOT_FINITE, i); }
    if (too_deep) { halt(HALT_OVERLAP, i); }
    // A diverging contact is recorded whatever the step: the halt report names the
    // deepest overlap of the particle (`GpuSimulation::halt_cause`), and older
    // records of its slots are all within the limit, or their step would have halted.
    if (RECORD || !finite || too_deep) {
        contact_info[slot] = vec4<f32>(res.f_n, res.f_t, g.delta, res.energy);
        contact_geo[slot] = vec4<f32>(g.n, l1);
    }
}
