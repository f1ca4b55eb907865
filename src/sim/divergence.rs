//! Why a step could not be completed, and the checks that find it: a diverging contact,
//! a lost position, a particle too fast for its neighbours (issue 16).

use super::Simulation;
use crate::cpu::forces::overlap_ratio;
use crate::cpu::neighbours::{NeighbourList, id_pair};
use crate::scene::Scene;
use crate::state::{Dof, Particles};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Why a step could not be completed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Divergence {
    #[error("particle {id} has a non-finite {what}")]
    NotFinite { id: u32, what: &'static str },
    #[error(
        "particle {id} has more than {max} neighbour-list candidates on the GPU path (pairs within the law's range plus the skin; a buffer limit): a smaller `skin` lists fewer, and if the overlaps are large the run is diverging"
    )]
    TooManyContacts { id: u32, max: u32 },
    #[error("the GPU spring table is full (particle {id})")]
    SpringTableFull { id: u32 },
    #[error(
        "particles {i} and {j} overlap by {ratio:.3} of the smaller radius (limits.max_overlap = {limit})"
    )]
    Overlap {
        i: u32,
        j: String,
        ratio: f64,
        limit: f64,
    },
    #[error(
        "particle {id} moves by {ratio:.3} of its radius in one step (limits.max_step_displacement = {limit}): it would pass through its neighbours without meeting them; a smaller dt, or a softer start"
    )]
    TooFast { id: u32, ratio: f64, limit: f64 },
    /// Not the physics: the GPU could not be read back (the device was lost).
    #[error("{0}")]
    Device(String),
}

impl Simulation {
    pub(super) fn check_divergence(&self) -> Result<(), Divergence> {
        let limit = self.scene.limits.max_overlap;
        if let Some((k, c)) = &self.candidates.diverging {
            let pair = self.neighbours.pairs[*k];
            let ids = id_pair(pair, &self.ids);
            if !(c.force[0].is_finite() && c.force[1].is_finite()) {
                return Err(Divergence::NotFinite {
                    id: ids.i,
                    what: "contact force",
                });
            }
            let j = if pair.is_wall() {
                format!("wall {}", pair.j - crate::cpu::contacts::WALL_BASE)
            } else {
                ids.j.to_string()
            };
            return Err(Divergence::Overlap {
                i: ids.i,
                j,
                ratio: overlap_ratio(&self.particles, pair, c),
                limit,
            });
        }
        if let Some(i) = self.lost_position {
            return Err(Divergence::NotFinite {
                id: i as u32,
                what: "position",
            });
        }
        if let Some(id) = self.too_fast {
            return Err(self.too_fast_report(id as u32));
        }
        Ok(())
    }

    /// The report of particle `id` moving too far in one step: by how much, from its
    /// state now (q1 = v dt).
    pub fn too_fast_report(&self, id: u32) -> Divergence {
        let p = &self.particles;
        // Inside an advance the particles may be in cell order; outside, slot = id.
        let slot = match self.ids.iter().position(|&k| k == id) {
            Some(i) => Some(i),
            None => (self.ids.is_empty() && (id as usize) < p.len()).then_some(id as usize),
        };
        let ratio = slot.map_or(f64::NAN, |i| p.q[1][i][0].hypot(p.q[1][i][1]) / p.radius[i]);
        Divergence::TooFast {
            id,
            ratio,
            limit: self.scene.limits.max_step_displacement,
        }
    }
}

/// What the survey of the particles watches for (`Simulation::survey_with`): motion
/// beyond the skin of the neighbour list, positions that are not finite, and particles
/// moving too far in one step.
pub(super) struct SurveyWatch<'a> {
    list: &'a NeighbourList,
    ids: &'a [u32],
    dt: f64,
    /// Whether the list is not stale anyway (then each particle's motion is checked).
    check_moves: bool,
    /// (limits.max_step_displacement)², or infinity when the guard is off.
    max_step2: f64,
    moved: AtomicBool,
    /// The smallest id of an active particle whose position is not finite.
    lost: AtomicUsize,
    /// The smallest id of an active particle moving too far in one step.
    fast: AtomicUsize,
}

impl<'a> SurveyWatch<'a> {
    pub(super) fn new(
        list: &'a NeighbourList,
        ids: &'a [u32],
        particles: &Particles,
        scene: &Scene,
    ) -> Self {
        let f = scene.limits.max_step_displacement;
        SurveyWatch {
            list,
            ids,
            dt: scene.dt,
            check_moves: !list.stale(particles),
            max_step2: if f > 0.0 { f * f } else { f64::INFINITY },
            moved: AtomicBool::new(false),
            lost: AtomicUsize::new(usize::MAX),
            fast: AtomicUsize::new(usize::MAX),
        }
    }

    /// Particle i (of radius r) at the state about to be evaluated: its velocity q1/dt
    /// (what every contact reads), whether it has moved beyond the skin, whether it is
    /// lost, whether this step's displacement q1 = v dt exceeds the bound (issue 16:
    /// a grain faster than that tunnels through fixed rows with no contact seen).
    #[inline(always)]
    pub(super) fn survey_one(
        &self,
        i: usize,
        q0: Dof,
        q1: Dof,
        active: bool,
        r: f64,
        velocity: &mut Dof,
    ) {
        let dt = self.dt;
        *velocity = [q1[0] / dt, q1[1] / dt, q1[2] / dt];
        if self.check_moves && self.list.moved_to(i, q0, active) {
            self.moved.store(true, Ordering::Relaxed);
        }
        if active && !q0.iter().all(|v| v.is_finite()) {
            self.lost.fetch_min(self.ids[i] as usize, Ordering::Relaxed);
        }
        if active && q1[0] * q1[0] + q1[1] * q1[1] > self.max_step2 * r * r {
            self.fast.fetch_min(self.ids[i] as usize, Ordering::Relaxed);
        }
    }

    /// Notes the first lost position and the first particle too fast; returns whether
    /// a particle moved beyond the skin.
    pub(super) fn finish(
        self,
        lost_position: &mut Option<usize>,
        too_fast: &mut Option<usize>,
    ) -> bool {
        let lost = self.lost.into_inner();
        *lost_position = (lost != usize::MAX).then_some(lost);
        let fast = self.fast.into_inner();
        *too_fast = (fast != usize::MAX).then_some(fast);
        self.moved.into_inner()
    }
}
