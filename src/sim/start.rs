//! The checks and the set-up before the first step: what the blocks created, the
//! initial overlaps, the accelerations the integrator starts from.

use super::Simulation;
use crate::cpu::contacts::Pair;
use crate::cpu::forces::{overlap_ratio, reduce_candidate_forces};
use crate::cpu::neighbours::id_pair;
use crate::scene::{IntegratorKind, Scene, SceneError};
use crate::state::{Dof, Particles};

impl Simulation {
    /// The initial state's contacts: overlaps deeper than `limits.initial_overlap` are
    /// bad input (issue 16: particles placed into each other diverged at step 0 as a run
    /// failure); under Gear the forces also give q2 = a dt²/2, so that the first
    /// prediction knows them. The lists built here are the ones the first step would
    /// build (same positions): no result changes.
    pub(super) fn start(&mut self) -> Result<(), SceneError> {
        self.evaluate_contacts();
        self.check_initial_overlaps()?;
        if self.scene.integrator == IntegratorKind::Gear5 {
            self.seed_accelerations();
        }
        self.pairs.clear();
        self.contacts.clear();
        Ok(())
    }

    /// The pairs of the contacts just evaluated that overlap by more than
    /// `limits.initial_overlap` of the smaller radius, deepest first, as an error naming
    /// them.
    pub(super) fn check_initial_overlaps(&self) -> Result<(), SceneError> {
        let limit = self.scene.limits.initial_overlap;
        let mut deep: Vec<(f64, Pair)> = (self.pairs.iter().zip(&self.contacts))
            .map(|(&p, c)| (overlap_ratio(&self.particles, p, c), p))
            .filter(|(ratio, _)| ratio.is_nan() || *ratio > limit)
            .collect();
        if deep.is_empty() {
            return Ok(());
        }
        deep.sort_by(|a, b| b.0.total_cmp(&a.0));
        let name = |p: Pair| {
            let ids = id_pair(p, &self.ids);
            if p.is_wall() {
                format!(
                    "particle {} and wall {}",
                    ids.i,
                    p.j - crate::cpu::contacts::WALL_BASE
                )
            } else {
                format!("particles {} and {}", ids.i, ids.j)
            }
        };
        let listed: Vec<String> = (deep.iter().take(5))
            .map(|&(ratio, p)| format!("{} by {ratio:.3}", name(p)))
            .collect();
        let more = match deep.len() {
            n if n > listed.len() => format!(" ({n} pairs in all)"),
            _ => String::new(),
        };
        Err(SceneError::invalid(
            "limits.initial_overlap",
            format!(
                "the initial particles overlap deeper than {limit} of the smaller radius: \
                 {}{more}; move them apart (or raise limits.initial_overlap if you mean it)",
                listed.join(", ")
            ),
        ))
    }

    /// Gear's q2 from the forces of the contacts just evaluated and gravity.
    pub(super) fn seed_accelerations(&mut self) {
        reduce_candidate_forces(
            &self.particles,
            &self.neighbours,
            &self.candidates.kicks,
            &mut self.forces,
        );
        let g = self.gravity(0.0);
        let h = 0.5 * self.scene.dt * self.scene.dt;
        let p = &mut self.particles;
        for i in 0..p.len() {
            if p.fixed[i] {
                continue;
            }
            let f = self.forces[i];
            p.q[2][i] = [
                h * (f[0] / p.mass[i] + g[0]),
                h * (f[1] / p.mass[i] + g[1]),
                h * f[2] / p.inertia[i],
            ];
        }
    }
}

/// What the blocks created, checked before a run (issue 16): every particle inside the
/// domain (one outside would be lost at once, silently), and every point source with a
/// free spot at its outlet among the fixed particles (a source blocked by its own row
/// would pour nothing).
pub(super) fn check_created(
    scene: &Scene,
    p: &Particles,
    starts: &[usize],
) -> Result<(), SceneError> {
    let d = &scene.domain;
    for i in 0..p.len() {
        let q = p.position(i);
        if !(q[0] >= d.x[0] && q[0] <= d.x[1] && q[1] >= d.z[0] && q[1] <= d.z[1]) {
            let k = starts.iter().rposition(|&s| s <= i).unwrap_or(0);
            return Err(SceneError::invalid(
                format!("particles[{k}]"),
                format!(
                    "creates particle {i} at ({:.6}, {:.6}), outside the domain x {:?}, z {:?}",
                    q[0], q[1], d.x, d.z
                ),
            ));
        }
    }
    for (k, c) in scene.particles.iter().enumerate() {
        let crate::scene::Creation::PointSource(s) = c else {
            continue;
        };
        // The outlet: x in [x0 − spread, x0 + spread] at z0, for a particle of the
        // block's largest reach. Each fixed particle blocks an interval of x; the source
        // can never pour if their union covers the outlet.
        let r = 0.5
            * crate::scene::reach_bound_of(s.diameter.as_ref(), s.polygon.as_ref())
            * s.rod.as_ref().map_or(1.0, |rod| rod.aspect.max(1.0));
        let (lo, hi) = (s.position[0] - s.spread, s.position[0] + s.spread);
        let mut blocked: Vec<(f64, f64)> = (0..p.len())
            .filter(|&j| p.fixed[j] && p.active[j])
            .filter_map(|j| {
                let q = p.position(j);
                let reach = r + p.radius[j];
                let dz = q[1] - s.position[1];
                (dz.abs() < reach).then(|| {
                    let w = (reach * reach - dz * dz).sqrt();
                    (q[0] - w, q[0] + w)
                })
            })
            .collect();
        blocked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut covered = lo;
        for (a, b) in blocked {
            if a > covered {
                break;
            }
            covered = covered.max(b);
        }
        if covered > hi {
            return Err(SceneError::invalid(
                format!("particles[{k}].position"),
                format!(
                    "the source at ({}, {}) with spread {} is blocked everywhere by fixed \
                     particles: it could never pour (move it up or widen its spread)",
                    s.position[0], s.position[1], s.spread
                ),
            ));
        }
    }
    Ok(())
}

/// A position that left a domain periodic in x (`period` > 0) through one side, brought
/// back through the other.
#[inline(always)]
pub(super) fn wrap(x: [f64; 2], period: f64, p: &mut Dof) {
    if period > 0.0 {
        if p[0] < x[0] {
            p[0] += period;
        } else if p[0] >= x[1] {
            p[0] -= period;
        }
    }
}

/// Whether a position lies outside the domain [x0, x1] × [z0, z1] (a NaN does not).
#[inline(always)]
pub(super) fn outside(x: [f64; 2], z: [f64; 2], p: Dof) -> bool {
    p[0] < x[0] || p[0] > x[1] || p[1] < z[0] || p[1] > z[1]
}
