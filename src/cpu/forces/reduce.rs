//! Stages `reduce_candidate_forces` and `reduce_forces` (twins of kick_sum and
//! reduce_forces in the WGSL): each particle's total force and torque, summed in a fixed
//! order so that the sums never depend on thread timing.

use super::ContactForce;
use super::candidates::Kick;
use crate::cpu::contacts::Pair;
use crate::cpu::neighbours::NeighbourList;
use crate::state::{Dof, Particles};

/// Stage: total contact force and torque (fx, fz, τ) on every particle from the
/// candidates' results, each particle on its own (in parallel): first the contacts in
/// which it is the higher id (by increasing partner id), then its own (by increasing
/// partner, walls last). That is the order in which `reduce_forces` adds them, so the
/// sums are bitwise the same, whatever the thread count.
pub fn reduce_candidate_forces(
    particles: &Particles,
    list: &NeighbourList,
    kicks: &[Kick],
    out: &mut Vec<Dof>,
) {
    out.clear();
    out.resize(particles.len(), [0.0; 3]);
    crate::base::parallel::for_each(out, |p, acc| *acc = kick_sum(list, kicks, p));
}

/// The total contact force and torque on particle p: its candidates as the higher id
/// (−F, in increasing partner id), then as the lower id (+F, in increasing partner id,
/// walls last). The integrators call it for each particle they move, so that the sum
/// and the update are one pass.
#[inline(always)]
pub fn kick_sum(list: &NeighbourList, kicks: &[Kick], p: usize) -> Dof {
    let mut acc = [0.0; 3];
    let down = &list.down[list.down_start[p] as usize..list.down_start[p + 1] as usize];
    // A candidate out of contact has a zero kick (`settle`): summed without a branch,
    // the same bits as skipping it (the sums start at +0 and never become −0).
    for &k in down {
        let c = &kicks[k as usize];
        acc[0] -= c.force[0];
        acc[1] -= c.force[1];
        acc[2] -= c.torque[1];
    }
    let own = &kicks[list.start[p] as usize..list.start[p + 1] as usize];
    for c in own {
        acc[0] += c.force[0];
        acc[1] += c.force[1];
        acc[2] += c.torque[0];
    }
    acc
}

/// Stage: total contact force and torque (fx, fz, τ) on every particle.
pub fn reduce_forces(
    particles: &Particles,
    pairs: &[Pair],
    contacts: &[ContactForce],
    out: &mut Vec<Dof>,
) {
    out.clear();
    out.resize(particles.len(), [0.0; 3]);
    for (pair, c) in pairs.iter().zip(contacts) {
        let i = pair.i as usize;
        let acc = &mut out[i];
        acc[0] += c.force[0];
        acc[1] += c.force[1];
        acc[2] += c.torque[0];
        if !pair.is_wall() {
            let acc = &mut out[pair.j as usize];
            acc[0] -= c.force[0];
            acc[1] -= c.force[1];
            acc[2] -= c.torque[1];
        }
    }
}
