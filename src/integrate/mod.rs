//! Time integration: the Gear predictor–corrector (default) and leapfrog (SPEC 3).
//!
//! Each integrator has a per-particle pure function and a stage over all particles that
//! skips fixed and inactive ones. Accelerations are contact force / mass plus gravity.

pub mod gear;
pub mod leapfrog;

use crate::state::{Dof, Particles};

/// Acceleration (ẍ, z̈, θ̈) of a particle of this mass and moment of inertia from its
/// summed contact force and torque.
pub fn acceleration(force: Dof, mass: f64, inertia: f64, gravity: [f64; 2]) -> Dof {
    [
        force[0] / mass + gravity[0],
        force[1] / mass + gravity[1],
        force[2] / inertia,
    ]
}

/// Whether the integrators move particle i.
pub fn is_integrated(particles: &Particles, i: usize) -> bool {
    particles.active[i] && !particles.fixed[i]
}
