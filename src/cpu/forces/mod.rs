//! Per-contact forces and their per-particle reduction.
//!
//! `contact_forces` evaluates each contact on its own (geometry → relative velocity →
//! law) and stores the force on particle i and the contact point. `reduce_forces` then
//! sums, for every particle, its contacts in contact-list order. On the CPU that is one
//! pass over the list adding +F to i and −F to j; it visits each particle's contacts in
//! increasing contact index, the same fixed order a per-particle GPU reduction uses, so
//! the sum never depends on thread timing (no float atomics).

use crate::base::geometry::{Geometry, WallSegment, tangent};
use crate::cpu::contacts::Pair;
use crate::cpu::orientation::RotatedCorners;
use crate::law::rolling::{
    RollingTable, rolling_inertia_inv, rolling_radius, rolling_spring, rolling_torque,
};
use crate::law::{ContactInput, ContactLaw, ContactOutput};
use crate::state::{Dof, Particles, offset};

mod candidates;
mod divergence;
mod kinematics;
mod reduce;
mod rods;

pub use candidates::{
    CandidateResults, Kick, candidate_force, candidate_force_hinted, candidate_forces,
};
pub use divergence::{diverges, overlap_ratio};
pub use kinematics::{area_contact, area_contact_hinted, contact_input};
pub use reduce::{kick_sum, reduce_candidate_forces, reduce_forces};

/// The result of one contact, kept for outputs and the reduction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    /// Total force on particle i (−force acts on j).
    pub force: [f64; 2],
    /// Its torques: about i's centre, arm × F, and about j's, (arm + r_i − r_j) × F (the
    /// torque on j is minus that; 0 for a wall).
    pub torque: [f64; 2],
    /// Contact point, where both forces act (world coordinates, for outputs).
    pub point: [f64; 2],
    /// The contact point relative to particle i's centre: the branch vector the torques
    /// use (relative to j's centre it is `arm + r_i − r_j`).
    pub arm: [f64; 2],
    /// Normal (from j to i) and the normal and tangential components.
    pub n: [f64; 2],
    pub f_n: f64,
    pub f_t: f64,
    /// Geometric overlap δ.
    pub overlap: f64,
    /// Elastic energy stored in the contact.
    pub energy: f64,
    /// The rolling spring after this step (rolling model `spring_dashpot`; else 0).
    pub rolling: f64,
}

/// What every contact of a step reads: the state, each particle's velocity (q1/dt,
/// computed once per step, `velocities`), the rotated corners and the walls.
#[derive(Clone, Copy)]
pub struct StepState<'a> {
    pub particles: &'a Particles,
    pub velocity: &'a [Dof],
    pub corners: &'a RotatedCorners,
    pub walls: &'a [WallSegment],
    /// Each wall's surface velocity.
    pub wall_velocity: &'a [[f64; 2]],
    pub dt: f64,
    /// The side of the material form's pair table (src/law/restitution.rs); 0 without.
    pub pair_side: usize,
    /// Rolling resistance at disk contacts, per pair of materials (scene `rolling`).
    pub rolling: &'a RollingTable,
}

/// Stage: the velocity (vx, vz, ω) = q1/dt of every particle.
pub fn velocities(particles: &Particles, dt: f64, out: &mut Vec<Dof>) {
    out.resize(particles.len(), [0.0; 3]);
    crate::base::parallel::for_each(out, |i, v| *v = particles.velocity(i, dt));
}

/// Stage: forces of every contact, and the updated tangential history. Each contact's
/// rolling spring (model `spring_dashpot`) starts afresh: this stage keeps no list
/// (the GPU kernels' tests use it on contacts that have just formed).
#[allow(clippy::too_many_arguments)]
pub fn contact_forces(
    particles: &Particles,
    corners: &RotatedCorners,
    walls: &[WallSegment],
    wall_velocity: &[[f64; 2]],
    law: &ContactLaw,
    rolling: &RollingTable,
    dt: f64,
    pairs: &[Pair],
    history_in: &[f64],
    out: &mut Vec<ContactForce>,
    history_out: &mut Vec<f64>,
) {
    let mut velocity = Vec::new();
    velocities(particles, dt, &mut velocity);
    let s = StepState {
        particles,
        velocity: &velocity,
        corners,
        walls,
        wall_velocity,
        dt,
        pair_side: law.pair_table().map_or(0, |t| t.side),
        rolling,
    };
    out.clear();
    history_out.clear();
    let area = matches!(law, ContactLaw::OverlapArea(_));
    for (&pair, &history) in pairs.iter().zip(history_in) {
        let (g, input) = contact_input(&s, area, pair, history);
        let (c, h) = contact_force(&s, |c| law.evaluate(c), pair, &g, &input, 0.0);
        out.push(c);
        history_out.push(h);
    }
}

/// The law applied to one contact's geometry and kinematics: the force on i and the
/// updated history. `rolling_spring`: the contact's rolling spring before the step
/// (model `spring_dashpot`; its update is `ContactForce::rolling`).
#[inline(always)]
pub(super) fn contact_force(
    s: &StepState,
    evaluate: impl Fn(&ContactInput) -> ContactOutput,
    pair: Pair,
    g: &Geometry,
    input: &ContactInput,
    rolling_spring: f64,
) -> (ContactForce, f64) {
    let particles = s.particles;
    let res = evaluate(input);
    let t = tangent(g.n);
    let force = [
        res.f_n * g.n[0] + res.f_t * t[0],
        res.f_n * g.n[1] + res.f_t * t[1],
    ];
    let i = pair.i as usize;
    let p = particles.position(i);
    let arm_j = (!pair.is_wall()).then(|| {
        let d = offset(particles, i, pair.j as usize);
        [g.arm[0] + d[0], g.arm[1] + d[1]]
    });
    let mut torque = res.torques(force, g.arm, arm_j);
    let mut spring = 0.0;
    if !s.rolling.is_none() {
        // On i, and its opposite on j (whose torque is −torque[1]).
        let m;
        (m, spring) = rolling(s, pair, res.f_n, rolling_spring);
        torque = [torque[0] + m, torque[1] + m];
    }
    let c = ContactForce {
        force,
        torque,
        point: [p[0] + g.arm[0], p[1] + g.arm[1]],
        arm: g.arm,
        n: g.n,
        f_n: res.f_n,
        f_t: res.f_t,
        overlap: g.delta,
        energy: res.energy,
        rolling: spring,
    };
    (c, res.history)
}

/// The rolling torque on disk i of a disk contact (src/law/rolling.rs), j taking its
/// opposite, and the rolling spring after the step (0 without one); f_n: the contact's
/// normal force, `spring`: the rolling spring before the step.
#[inline(always)]
fn rolling(s: &StepState, pair: Pair, f_n: f64, spring: f64) -> (f64, f64) {
    let p = s.particles;
    let i = pair.i as usize;
    let j = (!pair.is_wall()).then_some(pair.j as usize);
    let r = s.rolling.get(
        p.material[i],
        j.map_or(s.rolling.walls(), |j| p.material[j]),
    );
    let spin = s.velocity[i][2] - j.map_or(0.0, |j| s.velocity[j][2]);
    let r_roll = rolling_radius(p.radius[i], j.map(|j| p.radius[j]));
    if s.rolling.has_spring() {
        let inv = |k: usize| rolling_inertia_inv(p.inertia[k], p.mass[k], p.radius[k], p.fixed[k]);
        let inv_r = inv(i) + j.map_or(0.0, inv);
        return rolling_spring(r, spring, spin, r_roll, f_n, inv_r, s.dt);
    }
    let inv_inertia = |k: usize| if p.fixed[k] { 0.0 } else { 1.0 / p.inertia[k] };
    let inv = inv_inertia(i) + j.map_or(0.0, inv_inertia);
    let m = rolling_torque(r.mu_r, spin, r_roll, f_n, inv, s.dt);
    (m, 0.0)
}
