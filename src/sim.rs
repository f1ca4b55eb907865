//! The simulation on the CPU reference path (f64): state, and one time step that reads
//! like the algorithm. Each stage is a function with a GPU twin of the same name
//! (ARCHITECTURE.md).

use crate::cell_list::Grid;
use crate::contacts::Pair;
use crate::create::{self, source::SourceState};
use crate::forces::{
    CandidateResults, ContactForce, StepState, candidate_forces, kick_sum, overlap_ratio,
    reduce_candidate_forces,
};
use crate::geometry::WallSegment;
use crate::integrate::{gear, leapfrog};
use crate::law::ContactLaw;
use crate::neighbours::{DEFAULT_SKIN, NeighbourList, cell_order, gather, id_pair};
use crate::rng::Rng;
use crate::scene::{Creation, IntegratorKind, Scene, SceneError};
use crate::shape::{RotatedCorners, rotate_corners};
use crate::springs::SpringTable;
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

/// The shortest `Simulation::advance` that sorts the particles in memory: sorting and
/// putting back cost a few steps' time (measured: 1–3 steps at 10⁵ disks).
pub const SORTED_ADVANCE: u64 = 64;

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

#[derive(Clone)]
pub struct Simulation {
    pub scene: Scene,
    pub law: ContactLaw,
    pub walls: Vec<WallSegment>,
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
        let max_d = crate::scene::max_diameter(&scene).max(2.0 * particles.max_radius());
        let grid = Grid::new(scene.domain.x, scene.domain.z, law.range_factor() * max_d);
        Ok(Self {
            scene,
            law,
            walls,
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
                    .all(|(spec, st)| st.inserted >= create::layered::max_rows(spec))
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
        crate::parallel::for_each6_with(q, &mut self.velocity, |i, v, velocity| {
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
        let (x, z) = (d.x, d.z);
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
        crate::parallel::for_each6_with2(q, &mut self.velocity, active, |i, v, velocity, on| {
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
            if *on && outside(x, z, *q0) {
                *on = false;
                escaped.fetch_add(1, Ordering::Relaxed);
            }
            if integrated && *on {
                gear::predict_in_place([&mut *q0, &mut *q1, q2, q3, q4, q5]);
            }
            watch.survey_one(i, *q0, *q1, *on, radius[i], velocity);
        });
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
        let moved = self.survey();
        self.evaluate_surveyed(moved);
    }

    /// `evaluate_contacts` after the survey; `moved`: its answer.
    fn evaluate_surveyed(&mut self, moved: bool) {
        if moved || self.force_rebuild || self.neighbours.stale(&self.particles) {
            self.force_rebuild = false;
            let d = &self.scene.domain;
            let domain = (d.x, d.z);
            if self.reorder {
                let reach = self.law.range_factor() * self.largest_diameter() + self.skin();
                let grid = self.neighbours.grid_for(domain, reach);
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
            dt: self.scene.dt,
            pair_side: self.law.pair_table().map_or(0, |t| t.side),
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

    /// Ids for particles added since the last step (in id order: appended), so that
    /// `ids` covers every slot.
    fn sync_ids(&mut self) {
        let n = self.particles.len();
        self.ids.truncate(n);
        self.ids.extend(self.ids.len() as u32..n as u32);
    }

    /// Puts the particles, and everything kept per particle or per candidate, in a new
    /// memory order: `order[new] = old` slot. No result depends on the order.
    /// `results`: also the last evaluation's results per candidate (not needed at a
    /// rebuild, which is followed by a new evaluation).
    fn permute(&mut self, order: &[u32], results: bool) {
        let mut inverse = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            inverse[old as usize] = new as u32;
        }
        self.particles.permute(order);
        // The corners are laid out by memory slot: again at the next rotation.
        self.corners = RotatedCorners::default();
        if self.velocity.len() == order.len() {
            self.velocity = gather(&self.velocity, order);
        }
        self.ids = gather(&self.ids, order);
        let from = self.neighbours.permute(order, &inverse, &self.ids);
        let c = &mut self.candidates;
        if !results {
            c.kicks.clear();
            c.history.clear();
            c.sub_history.clear();
            c.contacts.clear();
            c.diverging = None;
        } else if c.kicks.len() == from.len() {
            c.kicks = gather(&c.kicks, &from);
            c.history = gather(&c.history, &from);
            if c.sub_history.len() == from.len() {
                c.sub_history = gather(&c.sub_history, &from);
            }
        }
        if c.contacts.len() == from.len() {
            c.contacts = gather(&c.contacts, &from);
        }
        if let Some((k, _)) = &mut c.diverging {
            *k = from.iter().position(|&f| f as usize == *k).unwrap_or(*k);
        }
        self.collect_contacts();
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

    /// Puts the particles in the cell order of the last sort, if it was made for the
    /// current neighbour list; otherwise the next step rebuilds the list (and sorts).
    fn sort_by_cell(&mut self) {
        self.sync_ids();
        let (order, list) = &self.sorted;
        if *list == self.neighbours.rebuilds && order.len() == self.ids.len() {
            // In id order the last sort's ids are the slots to take from.
            let order = order.clone();
            // The last step's results per candidate are not needed: the next step
            // replaces them before anyone reads them.
            self.permute(&order, false);
        } else {
            self.force_rebuild = true;
        }
    }

    /// Puts the particles back in id order; `results`: with the last evaluation's
    /// results per candidate (else the next evaluation must come first).
    fn restore_id_order(&mut self, results: bool) {
        if self.ids.iter().enumerate().all(|(k, &id)| id as usize == k) {
            return;
        }
        let mut order = vec![0u32; self.ids.len()];
        for (slot, &id) in self.ids.iter().enumerate() {
            order[id as usize] = slot as u32;
        }
        self.permute(&order, results);
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

    /// The initial state's contacts: overlaps deeper than `limits.initial_overlap` are
    /// bad input (issue 16: particles placed into each other diverged at step 0 as a run
    /// failure); under Gear the forces also give q2 = a dt²/2, so that the first
    /// prediction knows them. The lists built here are the ones the first step would
    /// build (same positions): no result changes.
    fn start(&mut self) -> Result<(), SceneError> {
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
    fn check_initial_overlaps(&self) -> Result<(), SceneError> {
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
                    p.j - crate::contacts::WALL_BASE
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
    fn seed_accelerations(&mut self) {
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

    /// Each copy's point sources at the current time, in scene order, copy after copy
    /// (`create::source::progress`), with whether each has stalled.
    pub fn source_progress(&self) -> Vec<(create::source::SourceProgress, bool)> {
        let (sources, layered) = creators(&self.scene);
        let n = sources.len() + layered.len();
        let (t, dt) = (self.time(), self.scene.dt);
        let mut out = Vec::new();
        for c in 0..self.scene.replicas {
            for (k, spec) in sources.iter().enumerate() {
                let state = &self.sources[c as usize * n + k];
                let p = create::source::progress(spec, state, (c, k), t, dt);
                let stalled = create::source::stalled(&p, spec, t, dt);
                out.push((p, stalled));
            }
        }
        out
    }

    /// Whether a source or layered block tries to insert at time t.
    fn insertion_due(&self, t: f64) -> bool {
        let (sources, layered) = creators(&self.scene);
        let (p, n) = (sources.len(), sources.len() + layered.len());
        (self.sources.chunks(n.max(1))).any(|copy| {
            (sources.iter().zip(copy)).any(|(s, st)| create::source::due(s, st, t))
                || (layered.iter().zip(&copy[p..])).any(|(l, st)| create::layered::due(l, st, t))
        })
    }

    /// Each copy's sources and layered blocks in scene order, copy after copy: within a
    /// copy the particles come in the order of a run of that copy alone.
    fn insert_from_sources(&mut self, t: f64) {
        let (sources, layered) = creators(&self.scene);
        let n = sources.len() + layered.len();
        let mut new = Vec::new();
        for c in 0..self.scene.replicas {
            let first = c as usize * n;
            for (k, spec) in sources.iter().enumerate() {
                let material = create::material_index(&self.scene, &spec.material);
                new.extend(create::source::emit(
                    spec,
                    &mut self.sources[first + k],
                    t,
                    material,
                    &self.particles,
                    c,
                ));
                self.push_new(&mut new, t, c);
            }
            for (m, spec) in layered.iter().enumerate() {
                let material = create::material_index(&self.scene, &spec.material);
                let k = first + sources.len() + m;
                new.extend(create::layered::emit(
                    spec,
                    &mut self.sources[k],
                    t,
                    material,
                    &self.particles,
                    c,
                ));
                self.push_new(&mut new, t, c);
            }
        }
    }

    /// Adds created particles of copy `copy`; Gear starts them with the gravitational
    /// acceleration.
    fn push_new(&mut self, new: &mut Vec<create::NewParticle>, t: f64, copy: u32) {
        for d in new.drain(..) {
            let id = create::push(&self.scene, &mut self.particles, &d) as usize;
            self.particles.copy[id] = copy;
            // Ids are never reused: the new one is the number of particles so far.
            self.ids.push(self.ids.len() as u32);
            let h = 0.5 * self.scene.dt * self.scene.dt;
            if self.scene.integrator == IntegratorKind::Gear5 {
                let g = self.gravity(t);
                self.particles.q[2][id] = [h * g[0], h * g[1], 0.0];
            }
        }
    }

    fn check_divergence(&self) -> Result<(), Divergence> {
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
                format!("wall {}", pair.j - crate::contacts::WALL_BASE)
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

    /// Boundary stage: particles whose centre left the domain are removed.
    fn remove_escaped(&mut self) {
        let d = &self.scene.domain;
        for i in 0..self.particles.len() {
            if !self.particles.active[i] {
                continue;
            }
            if outside(d.x, d.z, self.particles.q[0][i]) {
                self.particles.active[i] = false;
                self.lost += 1;
            }
        }
    }

    /// Copy `c` of a scene with `replicas` on its own, as the run of its seed alone
    /// would hold it at this step: its particles (renumbered in their order), sources,
    /// the contacts of the last evaluation among them, and the scene with the copy's
    /// seed. For its energies, snapshots and analysis; it is not stepped (its springs
    /// stay here).
    pub fn replica(&self, c: u32) -> Result<Simulation, SceneError> {
        let (particles, index) = self.particles.of_copy(c);
        let mut new_id = vec![u32::MAX; self.particles.len()];
        for (k, &i) in index.iter().enumerate() {
            new_id[i] = k as u32;
        }
        let n = source_count(&self.scene);
        let sources = self.sources[c as usize * n..(c as usize + 1) * n].to_vec();
        let mut scene = self.scene.clone();
        scene.seed = copy_seed(&self.scene, c);
        scene.replicas = 1;
        // Only leaving the domain deactivates a particle.
        let lost = particles.active.iter().filter(|a| !**a).count() as u64;
        let rng = self.rng.clone();
        let mut sim = Self::from_parts(
            scene,
            particles,
            SpringTable::default(),
            sources,
            rng,
            self.step,
            lost,
        )?;
        for (p, contact) in self.pairs.iter().zip(&self.contacts) {
            if self.particles.copy[p.i as usize] == c {
                let j = if p.is_wall() {
                    p.j
                } else {
                    new_id[p.j as usize]
                };
                sim.pairs.push(Pair {
                    i: new_id[p.i as usize],
                    j,
                });
                sim.contacts.push(*contact);
            }
        }
        Ok(sim)
    }

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

/// What the survey of the particles watches for (`Simulation::survey_with`): motion
/// beyond the skin of the neighbour list, positions that are not finite, and particles
/// moving too far in one step.
struct SurveyWatch<'a> {
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
    fn new(list: &'a NeighbourList, ids: &'a [u32], particles: &Particles, scene: &Scene) -> Self {
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
    fn survey_one(&self, i: usize, q0: Dof, q1: Dof, active: bool, r: f64, velocity: &mut Dof) {
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
    fn finish(self, lost_position: &mut Option<usize>, too_fast: &mut Option<usize>) -> bool {
        let lost = self.lost.into_inner();
        *lost_position = (lost != usize::MAX).then_some(lost);
        let fast = self.fast.into_inner();
        *too_fast = (fast != usize::MAX).then_some(fast);
        self.moved.into_inner()
    }
}

/// What the blocks created, checked before a run (issue 16): every particle inside the
/// domain (one outside would be lost at once, silently), and every point source with a
/// free spot at its outlet among the fixed particles (a source blocked by its own row
/// would pour nothing).
fn check_created(scene: &Scene, p: &Particles, starts: &[usize]) -> Result<(), SceneError> {
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

/// Whether a position lies outside the domain [x0, x1] × [z0, z1] (a NaN does not).
#[inline(always)]
fn outside(x: [f64; 2], z: [f64; 2], p: Dof) -> bool {
    p[0] < x[0] || p[0] > x[1] || p[1] < z[0] || p[1] > z[1]
}

/// The point sources and the layered blocks of a scene, each in block order.
pub fn creators(scene: &Scene) -> (Vec<crate::scene::PointSource>, Vec<crate::scene::Layered>) {
    let mut sources = Vec::new();
    let mut layered = Vec::new();
    for c in &scene.particles {
        match c {
            Creation::PointSource(s) => sources.push(s.clone()),
            Creation::Layered(l) => layered.push(l.clone()),
            _ => {}
        }
    }
    (sources, layered)
}

/// How many source states a scene has: its point sources, then its layered blocks.
/// The seed of copy `c` of a scene (`replicas`): the scene's seed plus c.
pub fn copy_seed(scene: &Scene, c: u32) -> u64 {
    scene.seed.wrapping_add(c as u64)
}

fn source_count(scene: &Scene) -> usize {
    let (s, l) = creators(scene);
    s.len() + l.len()
}
