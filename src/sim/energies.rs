//! The energies at the end of a step (kinetic, elastic, potential).

use super::Simulation;

/// Energies at the end of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energies {
    pub kinetic_translational: f64,
    pub kinetic_rotational: f64,
    /// Stored in contacts at the last force evaluation.
    pub elastic: f64,
    /// Gravitational potential −m g·r of mobile particles (full g, relative to z = 0).
    pub potential: f64,
}

impl Energies {
    pub fn kinetic(&self) -> f64 {
        self.kinetic_translational + self.kinetic_rotational
    }
}

impl Simulation {
    /// Kinetic, elastic and potential energy now.
    pub fn energies(&self) -> Energies {
        let dt = self.scene.dt;
        let g = self.scene.gravity.g;
        let mut e = Energies::default();
        for i in 0..self.particles.len() {
            if !crate::integrate::is_integrated(&self.particles, i) {
                continue;
            }
            let v = self.particles.velocity(i, dt);
            let m = self.particles.mass[i];
            e.kinetic_translational += 0.5 * m * (v[0] * v[0] + v[1] * v[1]);
            if self.particles.inertia[i].is_finite() {
                e.kinetic_rotational += 0.5 * self.particles.inertia[i] * v[2] * v[2];
            }
            let p = self.particles.q[0][i];
            e.potential -= m * (g[0] * p[0] + g[1] * p[1]);
        }
        e.elastic = self.contacts.iter().map(|c| c.energy).sum();
        e
    }
}
