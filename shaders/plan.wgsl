// Stage: whether this step's rebuild stages run (issue 14 item 2). After the prediction
// and its survey, the neighbour lists' word says whether the lists are rebuilt this step
// (src/sim.rs `step`: the survey, an insertion, a removal). The rebuild stages (the old
// lists' springs into the table, the cell list, the memory order, the new lists and
// their springs) are dispatched indirectly with the arguments written here: their
// workgroup counts at a rebuild, none between rebuilds or after a halt. A step between
// rebuilds then runs only predict, plan_rebuild, contact_forces, correct and
// advance_clock.
//
// dispatch_args holds, per rebuild stage k, four words at 4k (x, y, z, unused): the
// host's workgroup counts (written once at the upload); and the same at 4(R + k): this
// step's arguments, R the number of rebuild stages.

@group(2) @binding(0) var<storage, read_write> dispatch_args: array<u32>;

@compute @workgroup_size(WG)
fn plan_rebuild(@builtin(local_invocation_index) l: u32) {
    let stages = arrayLength(&dispatch_args) / 8u;
    let go = rebuilding() && !halted();
    for (var k = l; k < stages; k += WG) {
        let full = 4u * k;
        let now = 4u * (stages + k);
        dispatch_args[now] = select(0u, dispatch_args[full], go);
        dispatch_args[now + 1u] = 1u;
        dispatch_args[now + 2u] = 1u;
    }
}
