//! Leapfrog, paper 001 eq. 9–12: v(t + dt/2) = v(t − dt/2) + a(t) dt,
//! r(t + dt) = r(t) + v(t + dt/2) dt, for x, z and θ alike.
//!
//! The state keeps q1 = dt · v(t − dt/2). Velocity-dependent forces at time t therefore
//! see the half-step-old velocity, as in the paper's scheme; this is first order in the
//! damping terms only.

use super::acceleration;
use crate::state::{Dof, Particles};

/// One kick–drift for one particle: q0 = r(t), q1 = dt · v(t − dt/2).
pub fn kick_drift_one(q0: &mut Dof, q1: &mut Dof, accel: Dof, dt: f64) {
    for d in 0..3 {
        q1[d] += accel[d] * dt * dt;
        q0[d] += q1[d];
    }
}

/// Stage: advance every integrated particle with the force at the current positions
/// (each on its own, on every thread).
/// `force(i)`: the force and torque (fx, fz, τ) on particle i.
pub fn kick_drift<F>(p: &mut Particles, force: F, gravity: [f64; 2], dt: f64)
where
    F: Fn(usize) -> Dof + Sync + Send,
{
    let (active, fixed, mass, inertia) = (&p.active, &p.fixed, &p.mass, &p.inertia);
    let [q0, q1, ..] = &mut p.q;
    crate::base::parallel::for_each2(q0, q1, |i, q0, q1| {
        if active[i] && !fixed[i] {
            let a = acceleration(force(i), mass[i], inertia[i], gravity);
            kick_drift_one(q0, q1, a, dt);
        }
    });
}
