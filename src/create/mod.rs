//! Particle creation from the scene's `particles` blocks (SPEC 4): lattice piles, rows,
//! explicit lists at the start, and point sources during the run.

pub mod lattice;
pub mod source;

use crate::rng::Rng;
use crate::scene::{Creation, Scene};
use crate::state::{NewDisk, Particles};

/// Index of each material name (in the scene's sorted order).
pub fn material_index(scene: &Scene, name: &str) -> u32 {
    scene
        .materials
        .keys()
        .position(|k| k == name)
        .expect("validated material") as u32
}

/// Adds one disk with its material's density and thickness.
pub fn push(scene: &Scene, particles: &mut Particles, disk: &NewDisk) -> u32 {
    let m = scene
        .materials
        .values()
        .nth(disk.material as usize)
        .expect("validated material");
    particles.push_disk(disk, m.density, m.thickness, scene.dt)
}

/// Creates every particle that exists at t = 0, in block order; draws from `rng` in a
/// fixed order so the same seed gives the same particles.
pub fn initial_particles(scene: &Scene, rng: &mut Rng) -> Particles {
    let mut particles = Particles::default();
    for block in &scene.particles {
        match block {
            Creation::LatticePile(p) => {
                let material = material_index(scene, &p.material);
                for d in lattice::pile(p, material, rng) {
                    push(scene, &mut particles, &d);
                }
            }
            Creation::Row(r) => {
                let material = material_index(scene, &r.material);
                for k in 0..r.count {
                    let d = NewDisk {
                        position: [r.start[0] + k as f64 * r.spacing, r.start[1]],
                        theta: 0.0,
                        velocity: [0.0; 2],
                        omega: 0.0,
                        radius: 0.5 * r.diameter,
                        fixed: r.fixed,
                        fixed_rotation: false,
                        material,
                    };
                    push(scene, &mut particles, &d);
                }
            }
            Creation::List(l) => {
                let material = material_index(scene, &l.material);
                for p in &l.particles {
                    let d = NewDisk {
                        position: p.position,
                        theta: p.theta,
                        velocity: p.velocity,
                        omega: p.omega,
                        radius: 0.5 * p.diameter,
                        fixed: p.fixed,
                        fixed_rotation: p.fixed_rotation,
                        material,
                    };
                    push(scene, &mut particles, &d);
                }
            }
            Creation::PointSource(_) => {}
        }
    }
    particles
}
