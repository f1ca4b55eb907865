// Stage: boundaries (src/sim/insert.rs `remove_escaped`): a particle whose centre left the
// domain is deactivated and counted as lost. Also the divergence check on positions,
// and the step counter that closes every step. `leave_domain` runs at the end of the
// integrators' kernels (`correct`, `kick_drift`), for each active particle once it has
// moved: one dispatch fewer per step.

// Particle i at state s (the integrator's copy, as it will store it).
fn leave_domain(i: u32, s: State) {
    if (!is_active(i)) { return; }
    let p = position(s);
    let ok = abs(s.q[0].x) <= 3.0e38 && abs(s.q[0].y) <= 3.0e38 && abs(s.q[0].z) <= 3.0e38;
    if (!ok) { halt(HALT_NOT_FINITE, i); return; }
    // Across a periodic x the centre has come back through the other side (its anchor
    // wrapped in `renormalize`): only z can be left.
    let left_x = params.period_cells == 0u && (p.x < params.dom_lo_x || p.x > params.dom_hi_x);
    if (left_x || p.y < params.dom_lo_z || p.y > params.dom_hi_z) {
        props[i].flags &= ~ACTIVE;
        atomicAdd(&control[C_LOST], 1u);
        // Its candidates leave the lists at the next step (as on the CPU path).
        atomicOr(&control[C_LISTS], REMOVED);
    }
}

@compute @workgroup_size(1)
fn advance_clock() {
    if (!halted()) {
        let step = atomicAdd(&control[C_STEP], 1u);
        // The lists are current; what the next step needs is asked for again, but a
        // removal at the end of this one, or the survey of its prediction run ahead,
        // already asks for a rebuild.
        if (rebuilding()) {
            atomicAdd(&control[C_REBUILDS], 1u);
            atomicStore(&control[C_WALLS_LISTED], step);
        }
        let next = (lists_word() & (REMOVED | AHEAD_REBUILD)) != 0u;
        atomicStore(&control[C_LISTS], select(0u, REBUILD, next));
        atomicStore(&control[C_STAGED], 0u);
    }
}
