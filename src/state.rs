//! Particle state: structure-of-arrays in f64, indexed by particle id (creation order).
//!
//! Positions and orientations carry their Gear derivatives: `q[k][i]` holds
//! (dt^k / k!) d^k(x, z, θ)/dt^k of particle i (Allen & Tildesley's scaled derivatives),
//! so q[0] is the configuration and q[1]/dt the velocity. Leapfrog keeps
//! q[1] = dt · v(t − dt/2) and leaves q[2..] at zero. These arrays are the whole dynamic
//! state; forces are recomputed every step.

/// (x, z, θ) or its derivatives.
pub type Dof = [f64; 3];

use crate::shape::{self, P2};

/// Gear order + 1: the number of stored values per degree of freedom.
pub const GEAR_VALUES: usize = 6;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    pub q: [Vec<Dof>; GEAR_VALUES],
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    pub inertia: Vec<f64>,
    /// Fixed particles take part in contacts but are never integrated (SPEC 1).
    pub fixed: Vec<bool>,
    /// Cleared when a particle leaves the domain; its id is never reused.
    pub active: Vec<bool>,
    pub material: Vec<u32>,
    /// Polygon corners in the body frame (counter-clockwise, centroid at the origin);
    /// empty for a disk. `radius` is then the circumscribed radius.
    pub shape: Vec<Vec<P2>>,
    /// A spheropolygon's sweep radius (src/shape/spheropolygon.rs: `shape` is then its core,
    /// two corners for a rod); 0 for disks and polygons.
    pub sweep: Vec<f64>,
    /// The copy of the scene a particle belongs to (`replicas`; 0 without copies): it
    /// touches only particles of its own copy.
    pub copy: Vec<u32>,
    /// The domain's period in x (scene `domain.periodic_x`), 0 when not periodic: the
    /// positions are then taken modulo it (`offset`). Set from the scene with the state.
    pub period_x: f64,
}

/// A new particle before it joins the state.
#[derive(Clone, Debug, PartialEq)]
pub struct NewParticle {
    pub position: [f64; 2],
    pub theta: f64,
    pub velocity: [f64; 2],
    pub omega: f64,
    pub radius: f64,
    pub fixed: bool,
    /// Infinite moment of inertia: the particle never turns.
    pub fixed_rotation: bool,
    pub material: u32,
    /// Polygon corners in the body frame (see `shape`); empty for a disk.
    pub corners: Vec<P2>,
    /// Sweep radius of a spheropolygon whose core is `corners` (0: a disk or polygon).
    pub sweep: f64,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.radius.len()
    }

    pub fn is_empty(&self) -> bool {
        self.radius.is_empty()
    }

    /// Appends a particle; mass = density · area · thickness. A disk has I = m r²/2 (SPEC
    /// 1; paper 001's I = m σ²/8 for a disk of diameter σ), a polygon the moment of its
    /// actual area, density · thickness · ∫ r² dA about the centroid.
    pub fn push_particle(&mut self, d: &NewParticle, density: f64, thickness: f64, dt: f64) -> u32 {
        let id = self.len() as u32;
        let (mass, inertia) = if d.sweep > 0.0 {
            // A spheropolygon: the exact area and moment of the swept shape.
            let s = crate::shape::spheropolygon::Spheropolygon {
                core: d.corners.clone(),
                radius: d.sweep,
            };
            let rho = density * thickness;
            (rho * s.area(), rho * s.polar_moment())
        } else if d.corners.is_empty() {
            let mass = density * std::f64::consts::PI * d.radius * d.radius * thickness;
            (mass, 0.5 * mass * d.radius * d.radius)
        } else {
            let rho = density * thickness;
            (
                rho * shape::area(&d.corners),
                rho * shape::polar_moment(&d.corners),
            )
        };
        self.q[0].push([d.position[0], d.position[1], d.theta]);
        self.q[1].push([d.velocity[0] * dt, d.velocity[1] * dt, d.omega * dt]);
        for k in 2..GEAR_VALUES {
            self.q[k].push([0.0; 3]);
        }
        self.radius.push(d.radius);
        self.mass.push(mass);
        self.inertia.push(if d.fixed_rotation {
            f64::INFINITY
        } else {
            inertia
        });
        self.fixed.push(d.fixed);
        self.active.push(true);
        self.material.push(d.material);
        self.shape.push(d.corners.clone());
        self.sweep.push(d.sweep);
        self.copy.push(0);
        id
    }

    #[inline]
    pub fn position(&self, i: usize) -> [f64; 2] {
        [self.q[0][i][0], self.q[0][i][1]]
    }

    /// Velocity (vx, vz, ω) from the scaled first derivative.
    #[inline]
    pub fn velocity(&self, i: usize, dt: f64) -> Dof {
        let q = self.q[1][i];
        [q[0] / dt, q[1] / dt, q[2] / dt]
    }

    pub fn active_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }

    pub fn mobile_count(&self) -> usize {
        (0..self.len())
            .filter(|&i| self.active[i] && !self.fixed[i])
            .count()
    }

    pub fn is_polygon(&self, i: usize) -> bool {
        !self.shape[i].is_empty()
    }

    /// Whether particle i is a spheropolygon (a rod).
    pub fn is_swept(&self, i: usize) -> bool {
        self.sweep[i] > 0.0
    }

    /// Puts the particles in a new memory order: `order[new] = old` index (a
    /// permutation of 0..len).
    pub fn permute(&mut self, order: &[u32]) {
        assert_eq!(order.len(), self.len());
        for q in &mut self.q {
            *q = gather(q, order);
        }
        self.radius = gather(&self.radius, order);
        self.mass = gather(&self.mass, order);
        self.inertia = gather(&self.inertia, order);
        self.fixed = gather(&self.fixed, order);
        self.active = gather(&self.active, order);
        self.material = gather(&self.material, order);
        self.sweep = gather(&self.sweep, order);
        self.copy = gather(&self.copy, order);
        let mut shape = std::mem::take(&mut self.shape);
        self.shape = order
            .iter()
            .map(|&k| std::mem::take(&mut shape[k as usize]))
            .collect();
    }

    /// Whether particle j is active and of copy `copy` (what a copy's sources and
    /// layered blocks see).
    #[inline]
    pub fn present_in(&self, j: usize, copy: u32) -> bool {
        self.active[j] && self.copy[j] == copy
    }

    /// Appends all of `other`'s particles, as copy `copy`.
    pub fn append(&mut self, other: &Particles, copy: u32) {
        for k in 0..GEAR_VALUES {
            self.q[k].extend_from_slice(&other.q[k]);
        }
        self.radius.extend_from_slice(&other.radius);
        self.mass.extend_from_slice(&other.mass);
        self.inertia.extend_from_slice(&other.inertia);
        self.fixed.extend_from_slice(&other.fixed);
        self.active.extend_from_slice(&other.active);
        self.material.extend_from_slice(&other.material);
        self.shape.extend(other.shape.iter().cloned());
        self.sweep.extend_from_slice(&other.sweep);
        self.copy.extend(std::iter::repeat_n(copy, other.len()));
    }

    /// The particles of copy `copy`, in their order, and for each its index here.
    pub fn of_copy(&self, copy: u32) -> (Particles, Vec<usize>) {
        let index: Vec<usize> = (0..self.len()).filter(|&i| self.copy[i] == copy).collect();
        let pick = |v: &[f64]| index.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let mut p = Particles {
            q: std::array::from_fn(|k| index.iter().map(|&i| self.q[k][i]).collect()),
            radius: pick(&self.radius),
            mass: pick(&self.mass),
            inertia: pick(&self.inertia),
            fixed: index.iter().map(|&i| self.fixed[i]).collect(),
            active: index.iter().map(|&i| self.active[i]).collect(),
            material: index.iter().map(|&i| self.material[i]).collect(),
            shape: index.iter().map(|&i| self.shape[i].clone()).collect(),
            sweep: pick(&self.sweep),
            copy: Vec::new(),
            period_x: self.period_x,
        };
        p.copy = vec![0; index.len()];
        (p, index)
    }

    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }
}

/// r_i − r_j: the offset of the pair, the only way positions enter a contact's geometry
/// (issue 18); in a domain periodic in x, to j's nearest image.
#[inline]
pub fn offset(particles: &Particles, i: usize, j: usize) -> [f64; 2] {
    let (pi, pj) = (particles.position(i), particles.position(j));
    [
        nearest_image(pi[0] - pj[0], particles.period_x),
        pi[1] - pj[1],
    ]
}

/// A difference of x coordinates to its nearest image under the period `period` (0: not
/// periodic, `dx` as it is). Positions lie in the domain (within a step of it), so
/// |dx| < 1.5 period and one period either way suffices: compares only, no rounding
/// call in the contacts' hot loop, behind a branch that a run never changes.
#[inline(always)]
pub fn nearest_image(dx: f64, period: f64) -> f64 {
    if period > 0.0 {
        if dx > 0.5 * period {
            return dx - period;
        }
        if dx < -0.5 * period {
            return dx + period;
        }
    }
    dx
}

/// `v` in a new order: `out[k] = v[from[k]]`.
pub fn gather<T: Copy>(v: &[T], from: &[u32]) -> Vec<T> {
    from.iter().map(|&k| v[k as usize]).collect()
}
