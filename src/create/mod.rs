//! Particle creation from the scene's `particles` blocks (SPEC 4): lattice piles, rows,
//! explicit lists at the start, and point sources during the run.

pub mod lattice;
pub mod layered;
pub mod source;

use crate::base::rng::Rng;
use crate::scene::{Creation, PolygonSpec, Scene};
use crate::shape::{self, P2};
pub use crate::state::NewParticle;
use crate::state::Particles;

/// Index of each material name (in the scene's sorted order).
pub fn material_index(scene: &Scene, name: &str) -> u32 {
    scene
        .materials
        .keys()
        .position(|k| k == name)
        .expect("validated material") as u32
}

/// The reach (radius, circumscribed for a polygon) and corners of a particle with full
/// axes (a, b) and start angle φ0 on the ellipse: a disk of diameter a without a
/// polygon spec.
pub fn shape_of(polygon: Option<&PolygonSpec>, a: f64, b: f64, start: f64) -> (f64, Vec<P2>) {
    match polygon {
        None => (0.5 * a, Vec::new()),
        Some(p) => {
            let corners = shape::ellipse_polygon(p.corners, a, b, start);
            (shape::circumradius(&corners), corners)
        }
    }
}

/// A regular polygon (or a disk) of `diameter`. Free particles (lists, sources) are
/// inscribed in the circle of that diameter with a corner at φ0 = 0. On a lattice or a
/// row (`lattice`) the diameter is the inscribed, face-to-face one and a face points
/// along +x (φ0 = π/C), so that neighbours one diameter apart touch face to face when C
/// is divisible by 6.
pub fn regular_shape(
    polygon: Option<&PolygonSpec>,
    diameter: f64,
    lattice: bool,
) -> (f64, Vec<P2>) {
    match polygon {
        Some(p) if lattice => {
            let half_angle = std::f64::consts::PI / p.corners as f64;
            let d = diameter / half_angle.cos();
            shape_of(polygon, d, d, half_angle)
        }
        _ => shape_of(polygon, diameter, diameter, 0.0),
    }
}

/// Adds one particle with its material's density and thickness.
pub fn push(scene: &Scene, particles: &mut Particles, disk: &NewParticle) -> u32 {
    let m = scene
        .materials
        .values()
        .nth(disk.material as usize)
        .expect("validated material");
    particles.push_particle(disk, m.density, m.thickness, scene.dt)
}

/// Creates every particle that exists at t = 0, in block order; draws from `rng` in a
/// fixed order so the same seed gives the same particles.
pub fn initial_particles(scene: &Scene, rng: &mut Rng) -> Particles {
    initial_particles_by_block(scene, rng).0
}

/// `initial_particles`, and where each block's particles start (blocks in scene order).
pub fn initial_particles_by_block(scene: &Scene, rng: &mut Rng) -> (Particles, Vec<usize>) {
    let mut particles = Particles::default();
    let mut starts = Vec::new();
    for block in &scene.particles {
        starts.push(particles.len());
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
                    let (radius, corners) = regular_shape(r.polygon.as_ref(), r.diameter, true);
                    let d = NewParticle {
                        position: [r.start[0] + k as f64 * r.spacing, r.start[1]],
                        theta: 0.0,
                        velocity: [0.0; 2],
                        omega: 0.0,
                        radius,
                        fixed: r.fixed,
                        fixed_rotation: false,
                        material,
                        corners,
                        sweep: 0.0,
                    };
                    push(scene, &mut particles, &d);
                }
            }
            Creation::List(l) => {
                let material = material_index(scene, &l.material);
                for p in &l.particles {
                    let (mut radius, mut corners) =
                        regular_shape(l.polygon.as_ref(), p.diameter, false);
                    let mut sweep = 0.0;
                    if let Some(rod) = &l.rod {
                        // Paper 004's rod: width `diameter`, length `aspect` widths.
                        let s =
                            crate::shape::spheropolygon::Spheropolygon::rod(rod.aspect, p.diameter);
                        radius = s.circumradius();
                        sweep = s.radius;
                        corners = s.core;
                    }
                    let d = NewParticle {
                        position: p.position,
                        theta: p.theta,
                        velocity: p.velocity,
                        omega: p.omega,
                        radius,
                        fixed: p.fixed,
                        fixed_rotation: p.fixed_rotation,
                        material,
                        corners,
                        sweep,
                    };
                    push(scene, &mut particles, &d);
                }
            }
            Creation::PointSource(_) | Creation::Layered(_) => {}
        }
    }
    (particles, starts)
}
