// Stage (src/cpu/forces/reduce.rs `reduce_candidate_forces`, `kick_sum`): each particle sums its own
// contacts' forces in a fixed order, with no float atomics: first the contacts where it
// is the higher id (sorted by the lower id, as they come in the CPU's contact list,
// whatever the memory order), then its own. The integrators' kernels (`correct`,
// `kick_drift`) sum each particle's forces as they move it, through `acceleration`: no
// dispatch and no force buffer between them (issue 14 items 2 and 4). The kernel below
// writes the sums out for the tests of single stages.

// The total contact force and torque (fx, fz, τ) on particle p.
fn kick_sum(p: u32) -> vec3<f32> {
    var acc = vec3<f32>(0.0);
    // The down list is in id order since the rebuild (gather_history.wgsl).
    let nd = min(atomicLoad(&down_count[p]), params.list_cap);
    for (var a = 0u; a < nd; a++) {
        let ft = contact_ft[down[p * params.list_cap + a]];
        acc -= vec3<f32>(ft.xy, 0.0);
        acc.z += ft.w;
    }
    for (var k = 0u; k < contact_count[p]; k++) {
        let ft = contact_ft[p * params.list_cap + k];
        acc += ft.xyz;
    }
    return acc;
}

// Particle i's acceleration (ax, az, α) under its contacts and gravity g.
fn acceleration(i: u32, g: vec2<f32>) -> vec4<f32> {
    let f = kick_sum(i);
    return vec4<f32>(f.xy / props[i].mass + g, f.z * props[i].inv_inertia, 0.0);
}

@compute @workgroup_size(WG)
fn reduce_forces(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = gid.x;
    if (p >= live() || halted()) { return; }
    force[p] = vec4<f32>(kick_sum(p), 0.0);
}
