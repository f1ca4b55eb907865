//! The simulation on the CPU reference path (f64): state, and one time step that reads
//! like the algorithm. Each stage is a function with a GPU twin of the same name
//! (ARCHITECTURE.md).

use crate::base::geometry::WallSegment;
use crate::base::rng::Rng;
use crate::cpu::cell_list::Grid;
use crate::cpu::contacts::Pair;
use crate::cpu::forces::{CandidateResults, ContactForce, StepState, candidate_forces, kick_sum};
use crate::cpu::neighbours::{DEFAULT_SKIN, NeighbourList, cell_order};
use crate::cpu::orientation::{RotatedCorners, rotate_corners};
use crate::cpu::springs::SpringTable;
use crate::create::{self, source::SourceState};
use crate::integrate::{gear, leapfrog};
use crate::law::ContactLaw;
use crate::law::rolling::RollingTable;
use crate::scene::{IntegratorKind, Scene, SceneError};
use crate::state::{Dof, Particles};
use std::sync::atomic::{AtomicUsize, Ordering};

mod divergence;
mod energies;
mod insert;
mod order;
mod start;
mod walls;

pub use divergence::Divergence;
pub use energies::Energies;
pub use insert::{copy_seed, creators};

use divergence::SurveyWatch;
use insert::source_count;
use start::{check_created, outside, wrap};

/// The shortest `Simulation::advance` that sorts the particles in memory: sorting and
/// putting back cost a few steps' time (measured: 1–3 steps at 10⁵ disks).
pub const SORTED_ADVANCE: u64 = 64;

#[derive(Clone)]
pub struct Simulation {
    pub scene: Scene,
    pub law: ContactLaw,
    pub walls: Vec<WallSegment>,
    /// Each wall's surface velocity (scene `walls[k].velocity`, along the wall).
    pub wall_velocity: Vec<[f64; 2]>,
    /// Rolling resistance at disk contacts, per pair of materials (scene `rolling`).
    pub rolling: RollingTable,
    pub grid: Grid,
    pub particles: Particles,
    /// The tangential springs the state was created with (a checkpoint's, or the GPU
    /// path's at its last download); once the CPU path has stepped, they live in the
    /// neighbour list (`spring_table` gives them as a table).
    pub springs: SpringTable,
    pub sources: Vec<SourceState>,
    pub rng: Rng,
    pub step: u64,
    /// Particles removed for leaving the domain.
    pub lost: u64,
    // Per-step buffers, rebuilt every step (not part of the state).
    /// The polygons' corners turned to their orientations at the current step.
    pub corners: RotatedCorners,
    pub pairs: Vec<Pair>,
    pub contacts: Vec<ContactForce>,
    forces: Vec<Dof>,
    /// The candidate pairs and their springs (issue 13), and this evaluation's result of
    /// each candidate.
    pub neighbours: NeighbourList,
    candidates: CandidateResults,
    /// Whether a step lists its contacts in `pairs` and `contacts` (default; a run
    /// turns it off for the steps between its outputs).
    pub record_contacts: bool,
    /// Whether polygon pairs start from their hint of the last step (default): off, every
    /// evaluation starts from none, for the tests that the hints change nothing.
    pub use_hints: bool,
    /// Every particle's velocity q1/dt at the evaluated state.
    velocity: Vec<Dof>,
    /// The first active particle whose position at the evaluated state is not finite.
    lost_position: Option<usize>,
    /// The first active particle that moves by more than `limits.max_step_displacement`
    /// of its radius in the step about to be evaluated.
    too_fast: Option<usize>,
    /// Whether a step has moved the springs into the neighbour list.
    committed: bool,
    /// Each memory slot's particle id. The identity, except inside `advance`, which
    /// sorts the particles by cell at every rebuild (issue 13 item 4) and puts them back
    /// in id order before it returns: outside it, index = id everywhere.
    ids: Vec<u32>,
    /// Whether a rebuild sorts the particles by cell (inside `advance`).
    reorder: bool,
    /// How many rebuilds have changed the particles' memory order.
    pub reorders: u64,
    /// The cell order of the last sort (each slot's id then) and the neighbour list
    /// it was made for (its rebuild count): the next `advance` starts from it.
    sorted: (Vec<u32>, u64),
    /// Whether the next evaluation rebuilds the list whatever the motion.
    force_rebuild: bool,
    /// The time the moving walls are placed at (`place_walls`), and the one they were
    /// at when the neighbour list was built.
    wall_time: f64,
    walls_listed_at: f64,
    /// Inside `advance`: the state is already predicted for the next step and surveyed
    /// (`correct_ahead`); the survey's answer.
    predicted: Option<bool>,
}

impl Simulation {
    /// Builds the initial state of a validated scene.
    ///
    /// With `replicas` K, copy c is the scene made with the seed `seed + c`: its initial
    /// particles (ids of copy c after those of copy c − 1) and its sources, in the same
    /// order as a run of that seed alone; the generator kept is copy 0's.
    pub fn new(scene: Scene) -> Result<Self, SceneError> {
        let mut particles = Particles::default();
        let mut sources = Vec::new();
        let mut rng = Rng::new(scene.seed);
        for c in 0..scene.replicas {
            let seed = copy_seed(&scene, c);
            let mut copy_rng = Rng::new(seed);
            let (created, starts) = create::initial_particles_by_block(&scene, &mut copy_rng);
            check_created(&scene, &created, &starts)?;
            if c == 0 {
                particles = created;
                rng = copy_rng;
            } else {
                particles.append(&created, c);
            }
            // Point sources first (the GPU path indexes them so), then layered blocks.
            sources.extend((0..source_count(&scene)).map(|k| SourceState::new(seed, k)));
        }
        let mut sim =
            Self::from_parts(scene, particles, SpringTable::default(), sources, rng, 0, 0)?;
        sim.start()?;
        Ok(sim)
    }

    /// Reassembles a simulation from its state (used by `new` and by checkpoints).
    pub fn from_parts(
        scene: Scene,
        particles: Particles,
        springs: SpringTable,
        sources: Vec<SourceState>,
        rng: Rng,
        step: u64,
        lost: u64,
    ) -> Result<Self, SceneError> {
        let law = ContactLaw::of_scene(&scene)?;
        let mut particles = particles;
        particles.period_x = scene.domain.period_x();
        let copies = scene.replicas as usize;
        if sources.len() != copies * source_count(&scene) {
            return Err(SceneError::invalid(
                "particles",
                format!(
                    "the state has {} source states for {} point sources and layered blocks \
                     in {copies} copies",
                    sources.len(),
                    source_count(&scene)
                ),
            ));
        }
        if particles.copy.len() != particles.len()
            || particles.copy.iter().any(|&c| c >= scene.replicas)
        {
            return Err(SceneError::invalid(
                "replicas",
                format!("the state's particles are not all of its {copies} copies"),
            ));
        }
        let walls = scene
            .walls
            .iter()
            .map(|w| WallSegment { a: w.from, b: w.to })
            .collect();
        let wall_velocity = scene.walls.iter().map(|w| w.velocity).collect();
        let max_d = crate::scene::max_diameter(&scene).max(2.0 * particles.max_radius());
        let grid = Grid::new(scene.domain.x, scene.domain.z, law.range_factor() * max_d);
        Ok(Self {
            // Validated: a spring has its stiffness (`scene::validate`).
            rolling: RollingTable::of(
                scene.rolling.as_ref(),
                &scene.materials.keys().cloned().collect::<Vec<_>>(),
                law.linear_k_n(),
            )
            .unwrap_or_default(),
            scene,
            law,
            walls,
            wall_velocity,
            grid,
            particles,
            springs,
            sources,
            rng,
            step,
            lost,
            corners: RotatedCorners::default(),
            use_hints: true,
            pairs: Vec::new(),
            contacts: Vec::new(),
            forces: Vec::new(),
            neighbours: NeighbourList::default(),
            candidates: CandidateResults::default(),
            record_contacts: true,
            velocity: Vec::new(),
            lost_position: None,
            too_fast: None,
            committed: false,
            ids: Vec::new(),
            reorder: false,
            reorders: 0,
            sorted: (Vec::new(), 0),
            force_rebuild: false,
            wall_time: 0.0,
            walls_listed_at: 0.0,
            predicted: None,
        })
    }

    pub fn dt(&self) -> f64 {
        self.scene.dt
    }

    /// Simulated time, computed from the step count so it never drifts.
    pub fn time(&self) -> f64 {
        self.step as f64 * self.scene.dt
    }

    /// Gravity at time t, ramped linearly over `gravity.ramp_time` (paper 000 sec. 4).
    pub fn gravity(&self, t: f64) -> [f64; 2] {
        let g = self.scene.gravity.g;
        let ramp = self.scene.gravity.ramp_time;
        let s = if ramp > 0.0 { (t / ramp).min(1.0) } else { 1.0 };
        [g[0] * s, g[1] * s]
    }

    /// Whether every source has poured all its particles, every layered block has laid
    /// all its rows, and gravity is at full strength.
    pub fn feeding_done(&self) -> bool {
        let (sources, layered) = creators(&self.scene);
        let (p, n) = (sources.len(), sources.len() + layered.len());
        (self.sources.chunks(n.max(1))).all(|copy| {
            (sources.iter().zip(copy)).all(|(spec, st)| st.done(spec))
                && (layered.iter().zip(&copy[p..]))
                    .all(|(spec, st)| st.inserted >= crate::scene::rows::max_rows(spec))
        }) && self.time() >= self.scene.gravity.ramp_time
    }

    /// The skin of the neighbour list: the scene's, or DEFAULT_SKIN of the largest
    /// diameter.
    pub fn skin(&self) -> f64 {
        self.scene
            .skin
            .unwrap_or_else(|| DEFAULT_SKIN * self.largest_diameter())
    }

    fn largest_diameter(&self) -> f64 {
        crate::scene::max_diameter(&self.scene).max(2.0 * self.particles.max_radius())
    }

    /// Stage: one pass over the particles at the state about to be evaluated: each
    /// one's velocity q1/dt (what every contact reads), whether one has moved beyond the
    /// neighbour list's skin (returned), and the first whose position is not finite.
    fn survey(&mut self) -> bool {
        self.survey_with(false)
    }

    /// With `predict`, each particle is first predicted (Gear) in the same pass: one
    /// read and write of the Gear values instead of two (bitwise the same as
    /// `gear::predict` followed by `survey`).
    fn survey_with(&mut self, predict: bool) -> bool {
        let watch = SurveyWatch::new(&self.neighbours, &self.ids, &self.particles, &self.scene);
        let p = &mut self.particles;
        self.velocity.resize(p.len(), [0.0; 3]);
        let (q, active, fixed, radius) = (&mut p.q, &p.active, &p.fixed, &p.radius);
        crate::base::parallel::for_each6_with(q, &mut self.velocity, |i, v, velocity| {
            let [q0, q1, q2, q3, q4, q5] = v;
            if predict && active[i] && !fixed[i] {
                gear::predict_in_place([&mut *q0, &mut *q1, q2, q3, q4, q5]);
            }
            watch.survey_one(i, *q0, *q1, active[i], radius[i], velocity);
        });
        watch.finish(&mut self.lost_position, &mut self.too_fast)
    }

    /// Gear's correction of this step, the boundaries, and the prediction and survey
    /// of the next step in one pass over the particles, for a step that another follows
    /// at once with no insertion due: bitwise the same as `gear::correct`,
    /// `remove_escaped`, then the next step's `survey_with(true)`, with one read and
    /// write of the Gear values instead of two. Returns the survey's answer.
    fn correct_ahead(&mut self, gravity: [f64; 2]) -> bool {
        let (dt, d) = (self.scene.dt, &self.scene.domain);
        let (x, z, period) = (d.x, d.z, d.period_x());
        let escaped = AtomicUsize::new(0);
        let (list, kicks) = (&self.neighbours, &self.candidates.kicks);
        let watch = SurveyWatch::new(list, &self.ids, &self.particles, &self.scene);
        let p = &mut self.particles;
        let (q, active, fixed, mass, inertia, radius) = (
            &mut p.q,
            &mut p.active,
            &p.fixed,
            &p.mass,
            &p.inertia,
            &p.radius,
        );
        crate::base::parallel::for_each6_with2(
            q,
            &mut self.velocity,
            active,
            |i, v, velocity, on| {
                let [q0, q1, q2, q3, q4, q5] = v;
                let integrated = *on && !fixed[i];
                if integrated {
                    let a = crate::integrate::acceleration(
                        kick_sum(list, kicks, i),
                        mass[i],
                        inertia[i],
                        gravity,
                    );
                    gear::correct_in_place([&mut *q0, &mut *q1, q2, q3, q4, q5], a, dt);
                }
                if *on {
                    wrap(x, period, q0);
                }
                if *on && outside(x, z, *q0) {
                    *on = false;
                    escaped.fetch_add(1, Ordering::Relaxed);
                }
                if integrated && *on {
                    gear::predict_in_place([&mut *q0, &mut *q1, q2, q3, q4, q5]);
                }
                watch.survey_one(i, *q0, *q1, *on, radius[i], velocity);
            },
        );
        self.lost += escaped.into_inner() as u64;
        watch.finish(&mut self.lost_position, &mut self.too_fast)
    }

    /// Stages 2–8 at the current (predicted) state: the neighbour list (rebuilt when a
    /// particle has moved by half the skin, or was inserted or removed), rotated
    /// corners, and every candidate's contact and force from its spring of the last
    /// step. Public for measurements and tests of the contacts of a given state; it does
    /// not advance and keeps the springs as they were.
    pub fn evaluate_contacts(&mut self) {
        self.sync_ids();
        self.place_walls(self.time());
        let moved = self.survey();
        self.evaluate_surveyed(moved);
    }

    /// `evaluate_contacts` after the survey; `moved`: its answer.
    fn evaluate_surveyed(&mut self, moved: bool) {
        if moved
            || self.force_rebuild
            || self.neighbours.stale(&self.particles)
            || self.walls_moved()
        {
            self.force_rebuild = false;
            self.walls_listed_at = self.wall_time;
            let d = &self.scene.domain;
            let domain = (d.x, d.z);
            if self.reorder {
                let reach = self.law.range_factor() * self.largest_diameter() + self.skin();
                let grid = self
                    .neighbours
                    .grid_for(domain, reach, self.particles.period_x);
                let order = cell_order(&grid, &self.particles, &self.ids);
                if order
                    .iter()
                    .enumerate()
                    .any(|(new, &old)| old as usize != new)
                {
                    self.permute(&order, false);
                    self.reorders += 1;
                }
                self.sorted.0.clone_from(&self.ids);
            }
            // Springs from a table only for a list built for the first time.
            let table = if self.neighbours.is_built() {
                SpringTable::default()
            } else {
                self.spring_table()
            };
            self.neighbours.rebuild(
                domain,
                &self.particles,
                &self.ids,
                &self.walls,
                self.law.range_factor(),
                self.largest_diameter(),
                self.skin(),
                &table,
            );
            if self.reorder {
                self.sorted.1 = self.neighbours.rebuilds;
            }
        }
        rotate_corners(&self.particles, &mut self.corners);
        if !self.use_hints {
            self.neighbours.hints.forget();
        }
        let state = StepState {
            particles: &self.particles,
            velocity: &self.velocity,
            corners: &self.corners,
            walls: &self.walls,
            wall_velocity: &self.wall_velocity,
            dt: self.scene.dt,
            pair_side: self.law.pair_table().map_or(0, |t| t.side),
            rolling: &self.rolling,
        };
        candidate_forces(
            &state,
            &self.law,
            &self.neighbours,
            &self.ids,
            self.scene.limits.max_overlap,
            self.record_contacts,
            &mut self.candidates,
        );
        self.collect_contacts();
    }

    /// The contacts, in list order (in id order: by i, then j, what find_contacts
    /// lists, once the particles are back in id order). Only when someone will look
    /// (outputs between the steps of a run need none).
    fn collect_contacts(&mut self) {
        self.pairs.clear();
        self.contacts.clear();
        if self.record_contacts {
            let listed = self.neighbours.pairs.iter().zip(&self.candidates.contacts);
            for (p, c) in listed.filter_map(|(p, c)| c.as_ref().map(|c| (p, c))) {
                self.pairs.push(*p);
                self.contacts.push(*c);
            }
        }
    }

    /// Runs `steps` steps; only the last one lists its contacts. Bitwise the same as as
    /// many `step` calls. An advance of `SORTED_ADVANCE` steps or more runs all but its
    /// last step with the particles sorted in memory by cell, sorted again at every
    /// rebuild of the neighbour list (locality: a particle's partners lie next to it in
    /// memory), and puts them back in id order for the last step (also after a
    /// divergence), so that outside `advance` index = id.
    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        let mut done = Ok(());
        let mut left = steps;
        if steps >= SORTED_ADVANCE {
            self.sort_by_cell();
            self.reorder = true;
            self.record_contacts = false;
            done = (1..steps).try_for_each(|k| self.step_with(k + 1 < steps));
            self.reorder = false;
            self.restore_id_order(done.is_err());
            left = 1;
        }
        if done.is_ok() {
            done = (0..left).try_for_each(|k| {
                self.record_contacts = k + 1 == left;
                self.step_with(k + 1 < left)
            });
        }
        self.record_contacts = true;
        done
    }

    /// The tangential springs of the last completed step as a table keyed by pair (for
    /// checkpoints and the GPU path): the contacts of that step with their springs.
    pub fn spring_table(&self) -> SpringTable {
        if !self.committed {
            return self.springs.clone();
        }
        let in_contact: Vec<bool> = self.candidates.kicks.iter().map(|k| k.contact).collect();
        self.neighbours.table(&in_contact, &self.ids)
    }

    /// One time step: insert, predict, neighbour list, contacts and forces, springs,
    /// reduce, correct, boundaries.
    pub fn step(&mut self) -> Result<(), Divergence> {
        self.step_with(false)
    }

    /// `step`; `ahead`: the caller steps again at once (inside `advance`), so that Gear
    /// may predict and survey the next step in this step's correction pass
    /// (`correct_ahead`) when no insertion is due then.
    fn step_with(&mut self, ahead: bool) -> Result<(), Divergence> {
        let dt = self.scene.dt;
        let t = self.time();
        self.sync_ids();
        let gear = self.scene.integrator == IntegratorKind::Gear5;
        // Gear evaluates the forces at the predicted state (t + dt), leapfrog at t.
        self.place_walls(if gear { t + dt } else { t });
        let moved = match self.predicted.take() {
            // The last step predicted and surveyed this one (no insertion was due).
            Some(moved) => moved,
            None => {
                self.insert_from_sources(t);
                // Gear predicts each particle in the survey's pass.
                self.survey_with(gear)
            }
        };
        self.evaluate_surveyed(moved);
        self.check_divergence()?;
        // The candidates' updated springs become the list's.
        std::mem::swap(&mut self.neighbours.history, &mut self.candidates.history);
        std::mem::swap(
            &mut self.neighbours.sub_history,
            &mut self.candidates.sub_history,
        );
        self.committed = true;
        if gear {
            // Forces were evaluated at the predicted state, i.e. at time t + dt.
            let g = self.gravity(t + dt);
            let next = (self.step + 1) as f64 * dt;
            if ahead && !self.insertion_due(next) {
                self.predicted = Some(self.correct_ahead(g));
            } else {
                // Each particle's force is summed from its candidates' kicks where it is
                // used.
                let (list, kicks) = (&self.neighbours, &self.candidates.kicks);
                gear::correct(&mut self.particles, |i| kick_sum(list, kicks, i), g, dt);
                self.remove_escaped();
            }
        } else {
            let g = self.gravity(t);
            let (list, kicks) = (&self.neighbours, &self.candidates.kicks);
            leapfrog::kick_drift(&mut self.particles, |i| kick_sum(list, kicks, i), g, dt);
            self.remove_escaped();
        }
        self.step += 1;
        Ok(())
    }
}
