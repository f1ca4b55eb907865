//! Particles added and removed during a run: the point sources' insertions, escaped
//! particles, and the replicas of a scene (`copies`).

use super::Simulation;
use super::start::outside;
use crate::cpu::contacts::Pair;
use crate::cpu::springs::SpringTable;
use crate::create;
use crate::scene::{Creation, IntegratorKind, Scene, SceneError};

impl Simulation {
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
    pub(super) fn insertion_due(&self, t: f64) -> bool {
        let (sources, layered) = creators(&self.scene);
        let (p, n) = (sources.len(), sources.len() + layered.len());
        (self.sources.chunks(n.max(1))).any(|copy| {
            (sources.iter().zip(copy)).any(|(s, st)| create::source::due(s, st, t))
                || (layered.iter().zip(&copy[p..])).any(|(l, st)| create::layered::due(l, st, t))
        })
    }

    /// Each copy's sources and layered blocks in scene order, copy after copy: within a
    /// copy the particles come in the order of a run of that copy alone.
    pub(super) fn insert_from_sources(&mut self, t: f64) {
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
    pub(super) fn push_new(&mut self, new: &mut Vec<create::NewParticle>, t: f64, copy: u32) {
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

    /// Boundary stage: particles whose centre left the domain are removed (across a
    /// periodic x, brought back through the other side).
    pub(super) fn remove_escaped(&mut self) {
        let d = &self.scene.domain;
        let period = d.period_x();
        for i in 0..self.particles.len() {
            if !self.particles.active[i] {
                continue;
            }
            super::start::wrap(d.x, period, &mut self.particles.q[0][i]);
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

pub(super) fn source_count(scene: &Scene) -> usize {
    let (s, l) = creators(scene);
    s.len() + l.len()
}
