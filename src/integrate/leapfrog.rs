//! Leapfrog, paper 001 eq. 9–12: v(t + dt/2) = v(t − dt/2) + a(t) dt,
//! r(t + dt) = r(t) + v(t + dt/2) dt, for x, z and θ alike.
//!
//! The state keeps q1 = dt · v(t − dt/2). Velocity-dependent forces at time t therefore
//! see the half-step-old velocity, as in the paper's scheme; this is first order in the
//! damping terms only.

use super::{acceleration, is_integrated};
use crate::state::{Dof, Particles};

/// One kick–drift for one particle: q0 = r(t), q1 = dt · v(t − dt/2).
pub fn kick_drift_one(q0: &mut Dof, q1: &mut Dof, accel: Dof, dt: f64) {
    for d in 0..3 {
        q1[d] += accel[d] * dt * dt;
        q0[d] += q1[d];
    }
}

/// Stage: advance every integrated particle with the force at the current positions.
pub fn kick_drift(p: &mut Particles, forces: &[Dof], gravity: [f64; 2], dt: f64) {
    for i in 0..p.len() {
        if is_integrated(p, i) {
            let a = acceleration(p, i, forces[i], gravity);
            let (mut q0, mut q1) = (p.q[0][i], p.q[1][i]);
            kick_drift_one(&mut q0, &mut q1, a, dt);
            p.q[0][i] = q0;
            p.q[1][i] = q1;
        }
    }
}
