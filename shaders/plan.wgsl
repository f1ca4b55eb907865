// Stage: whether this step's rebuild stages run (issue 14 item 2). After the prediction
// and its survey, the neighbour lists' word says whether the lists are rebuilt this step
// (src/sim/mod.rs `step`: the survey, an insertion, a removal). The rebuild stages (the old
// lists' springs into the table, the cell list, the memory order, the new lists and
// their springs) are dispatched indirectly with the arguments written here: their
// workgroup counts at a rebuild, none between rebuilds or after a halt. A step between
// rebuilds then runs only predict, plan_rebuild, contact_forces, correct and
// advance_clock.
//
// dispatch_args holds, per rebuild stage k, four words at 4k (x, y, z, unused): the
// host's workgroup counts (written once at the upload); and the same at 4(R + k): this
// step's arguments, R the number of rebuild stages.

// dispatch_args: group 2 (src/gpu/bindings.rs).

@compute @workgroup_size(WG)
fn plan_rebuild(@builtin(local_invocation_index) l: u32) {
    let stages = arrayLength(&dispatch_args) / 8u;
    // A pause (a lean step before that needed the rebuild) ends here: the state is the
    // paused step's, predicted and surveyed, and its rebuild runs now. Each thread
    // decides from the word as it was; the first lifts the pause and notes the stages.
    let h = atomicLoad(&control[C_HALT]);
    let go = rebuilding() && (h & ~HALT_PAUSED) == 0u;
    if (l == 0u) {
        if (h == HALT_PAUSED) { atomicStore(&control[C_HALT], 0u); }
        atomicStore(&control[C_STAGED], 1u);
    }
    for (var k = l; k < stages; k += WG) {
        let full = 4u * k;
        let now = 4u * (stages + k);
        dispatch_args[now] = select(0u, dispatch_args[full], go);
        dispatch_args[now + 1u] = 1u;
        dispatch_args[now + 2u] = 1u;
    }
}

// Stage: the workgroups of contact_forces under the overlap-area law, which takes a
// thread per pair (issue 14 item 5): at a rebuild, from the pairs find_contacts listed
// (`pairs`), PAIRS_PER_THREAD to a thread; the same until the next rebuild. At most
// MAX_WORKGROUPS: contact_forces strides over the rest. Its arguments follow the
// rebuild stages' two sets in dispatch_args (`PAIR_ARGS_OFFSET` in src/gpu/step.rs).
// A hardware adapter takes one pair per thread, for as many threads as it can run; a
// software one (lavapipe) runs every thread of a group through every branch, and takes
// four, so that a group's threads share out the pairs evenly (src/gpu/kernels.rs).
override PAIRS_PER_THREAD: u32 = 1u;

@compute @workgroup_size(1)
fn plan_pairs() {
    if (!rebuilding()) { return; }
    let at = 8u * (arrayLength(&dispatch_args) / 8u);
    let per_group = WG * PAIRS_PER_THREAD;
    let groups = (atomicLoad(&pairs.count) + per_group - 1u) / per_group;
    dispatch_args[at] = min(groups, MAX_WORKGROUPS);
}
