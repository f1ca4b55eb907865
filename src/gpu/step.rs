//! Steps on the device: the kernels of a step (`encode_step`), the rebuild stages
//! dispatched indirectly, batches of steps submitted with their control words read back
//! while the next batch runs (`advance`), and what a halt reports.

use super::*;

/// Steps encoded into one submission at most. Between submissions the host reads the
/// control words (divergence check, progress).
pub const STEPS_PER_SUBMIT: u64 = 64;

/// Batches of steps in flight at most (`GpuSimulation::advance`): the host encodes and
/// submits one while the device runs the other.
pub const BATCHES_IN_FLIGHT: usize = 2;

/// The first step of every batch and every `STAGE_EVERY`-th after it are recorded with
/// the rebuild stages (issue 38); the steps between are lean: `contact_forces`, the
/// integrator (Gear's correction with the next prediction) and `advance_clock`, 3 to 5
/// commands. A lean step whose survey asks for a rebuild pauses the device
/// (`HALT_PAUSED`, shaders/contact_forces.wgsl) until the next step with the stages,
/// which rebuilds from the paused state and goes on: the same steps to the bit as if
/// every step carried the stages, with at most `STAGE_EVERY − 1` recorded steps run as
/// no-ops per rebuild (the host submits as many more). Every 16th: 15 empty dispatches
/// spread over 16 steps, about one command per step. Where the lists are rebuilt more
/// often, the stages come more often (`stage_interval`).
pub const STAGE_EVERY: u64 = 16;

/// How often the next batch records the rebuild stages, from the last batch read back:
/// `steps` run and `rebuilds` among them. Half the steps between rebuilds, so that a
/// pause loses about a quarter of them: lean steps cost ~5 commands where a staged one
/// costs ~20, so they pay down to rebuilds every ~4 steps, where this gives 1 (every
/// step staged, nothing lost).
pub(super) fn stage_interval(steps: u64, rebuilds: u64) -> u64 {
    if rebuilds == 0 {
        return STAGE_EVERY;
    }
    (steps / (2 * rebuilds)).clamp(1, STAGE_EVERY)
}

/// A submitted batch of steps: its submission and the staging buffer its control words
/// are copied to.
pub(super) struct Batch {
    pub(super) staging: wgpu::Buffer,
    pub(super) index: wgpu::SubmissionIndex,
    /// The step the device reaches at its end if no lean step pauses.
    pub(super) end: u64,
    /// Its readback's mapping outcome.
    pub(super) mapped: super::readback::MapFlag,
}

/// The stages of a rebuild of the neighbour lists, in order: the old lists' springs into
/// the table, the cell list, the new memory order, the new lists and their springs. A
/// step dispatches them indirectly (`plan_rebuild`, shaders/plan.wgsl).
pub const REBUILD_STAGES: [Kernel; 14] = {
    let c = GpuSimulation::CELL_LIST;
    [
        Kernel::ClearTable,
        Kernel::StoreHistory,
        c[0],
        c[1],
        c[2],
        c[3],
        c[4],
        c[5],
        c[6],
        c[7],
        Kernel::PermuteGather,
        Kernel::PermuteStore,
        Kernel::FindContacts,
        Kernel::GatherHistory,
    ]
};

/// What a step encodes besides its fixed stages.
#[derive(Clone, Copy, Debug)]
pub(super) struct StepKind {
    /// Sources still have candidates: the insertion kernels run first.
    pub(super) sources_left: bool,
    /// Store the contacts' outputs (the last step of an `advance`, which `download`
    /// reads).
    pub(super) record: bool,
    /// Gear: the step before predicted this one already (`Kernel::CorrectAhead`).
    pub(super) predicted: bool,
    /// Gear: predict the next step at the end of this one.
    pub(super) ahead: bool,
    /// Recorded with the rebuild stages (`STAGE_EVERY`); a lean step without them.
    pub(super) staged: bool,
}

/// One indirect dispatch's arguments in `dispatch_args`: x, y, z and a word of padding.
pub(super) const DISPATCH_ARGS_BYTES: usize = 16;

/// The workgroups of one dispatch of kernel k.
pub fn workgroups(p: &Params, k: Kernel) -> u64 {
    match k {
        Kernel::InsertPlace
        | Kernel::ScanLevel2
        | Kernel::AdvanceClock
        | Kernel::PlanRebuild
        | Kernel::PlanPairs => 1,
        // Grid-stride loops: as many workgroups as one dispatch takes.
        Kernel::ClearCells => ceil_div(p.cells.max(p.n_cap) as u64, WG as u64).min(MAX_WORKGROUPS),
        Kernel::ScanLevel0 | Kernel::ScanAdd0 => p.scan_blocks1 as u64,
        Kernel::ScanLevel1 | Kernel::ScanAdd1 => p.scan_blocks2 as u64,
        Kernel::ClearTable => ceil_div(p.table_mask as u64 + 1, WG as u64).min(MAX_WORKGROUPS),
        _ => ceil_div(p.n_cap as u64, WG as u64),
    }
    .max(1)
}

/// The contents of `dispatch_args` at the upload: each rebuild stage's workgroups, then
/// room for a step's arguments, then `contact_forces`' under the overlap-area law (none
/// until the first rebuild lists the pairs; shaders/plan.wgsl).
pub(super) fn dispatch_args(p: &Params) -> Vec<u32> {
    let mut args: Vec<u32> = REBUILD_STAGES
        .iter()
        .flat_map(|&k| [workgroups(p, k) as u32, 1, 1, 0])
        .collect();
    args.resize(2 * args.len(), 0);
    args.extend([0, 1, 1, 0]);
    args
}

/// Where `contact_forces`' arguments under the overlap-area law lie in `dispatch_args`.
pub(super) const PAIR_ARGS_OFFSET: usize = 2 * REBUILD_STAGES.len() * DISPATCH_ARGS_BYTES;

/// What the GPU path has encoded and submitted since the upload (`talus bench`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counters {
    /// Dispatches that run workgroups every step: those with a count fixed when
    /// encoded, and `contact_forces` under the overlap-area law (indirect, with the
    /// workgroups of the pairs listed at the last rebuild).
    pub direct: u64,
    /// The rebuild stages' indirect dispatches, which run workgroups only at a rebuild.
    pub indirect: u64,
    /// Submissions: batches of steps and readbacks.
    pub submissions: u64,
    /// Rebuilds of the neighbour lists (each runs the `REBUILD_STAGES.len()` indirect
    /// dispatches of its step).
    pub rebuilds: u64,
    /// Batches in which a lean step paused for a rebuild (`STAGE_EVERY`): their steps
    /// after the pause ran as no-ops and were submitted again.
    pub pauses: u64,
}

impl GpuSimulation {
    /// What has been encoded and submitted since the upload (reads the rebuild count
    /// back).
    pub fn counters(&self) -> Counters {
        Counters {
            direct: self.dispatches.get(),
            indirect: self.indirect.get(),
            submissions: self.submissions.get(),
            rebuilds: self.rebuilds(),
            pauses: self.pauses,
        }
    }

    /// The particles the device holds: those there are and every one still to come
    /// (what `footprint` counts before the upload).
    pub fn capacity(&self) -> u64 {
        self.n_cap as u64
    }

    /// Records the rebuild stages in every `k`-th step of a batch, whatever the rebuilds
    /// (`STAGE_EVERY`; 1: in every step, as before issue 38). Tests compare the two.
    pub fn set_stage_every(&mut self, k: u64) {
        self.forced_stage_every = Some(k.max(1));
    }

    pub(super) fn dispatch(&self, pass: &mut wgpu::ComputePass, k: Kernel, groups: u64) {
        self.dispatches.set(self.dispatches.get() + 1);
        self.set_kernel(pass, k);
        pass.dispatch_workgroups(groups.max(1) as u32, 1, 1);
        self.mark_kernel(pass, k);
    }

    /// Sets a kernel's pipeline and its bind groups (`bindings.rs`: only the buffers it
    /// touches, read-only where its module never writes them).
    fn set_kernel(&self, pass: &mut wgpu::ComputePass, k: Kernel) {
        pass.set_pipeline(&self.pipelines.pipelines[&k]);
        for (g, set) in self.pipelines.kernel_groups[&k].iter().enumerate() {
            if let Some(i) = set {
                pass.set_bind_group(g as u32, &self.bind_groups[*i], &[]);
            }
        }
    }

    /// Records the dispatches of one kernel (for tests of single stages). Under the
    /// overlap-area law and for spheropolygons `contact_forces` takes a thread per pair: `plan_pairs` writes
    /// its workgroups from the pairs the last rebuild listed, and it is dispatched with
    /// them (issue 14 item 5).
    pub fn encode_kernel(&self, pass: &mut wgpu::ComputePass, k: Kernel) {
        let per_pair = matches!(k, Kernel::ContactForces | Kernel::ContactForcesOnly)
            && per_pair(&self.params);
        if per_pair {
            self.dispatch(pass, Kernel::PlanPairs, 1);
            self.dispatches.set(self.dispatches.get() + 1);
            self.set_kernel(pass, k);
            pass.dispatch_workgroups_indirect(&self.buffers.dispatch_args, PAIR_ARGS_OFFSET as u64);
            self.mark_kernel(pass, k);
        } else {
            self.dispatch(pass, k, workgroups(&self.params, k));
        }
    }

    /// Records a rebuild stage (the `REBUILD_STAGES[stage]`), dispatched with the
    /// workgroups `plan_rebuild` wrote for this step: none between rebuilds.
    pub(super) fn dispatch_rebuild_stage(&self, pass: &mut wgpu::ComputePass, stage: usize) {
        self.indirect.set(self.indirect.get() + 1);
        let k = REBUILD_STAGES[stage];
        self.set_kernel(pass, k);
        let offset = (REBUILD_STAGES.len() + stage) * DISPATCH_ARGS_BYTES;
        pass.dispatch_workgroups_indirect(&self.buffers.dispatch_args, offset as u64);
        self.mark_kernel(pass, k);
    }

    /// The kernels of the cell list, in order.
    pub const CELL_LIST: [Kernel; 8] = [
        Kernel::ClearCells,
        Kernel::CellIndex,
        Kernel::ScanLevel0,
        Kernel::ScanLevel1,
        Kernel::ScanLevel2,
        Kernel::ScanAdd1,
        Kernel::ScanAdd0,
        Kernel::Scatter,
    ];

    /// One time step, stage by stage as in `Simulation::step`.
    pub(super) fn encode_step(&self, pass: &mut wgpu::ComputePass, how: StepKind) {
        if how.sources_left {
            self.encode_kernel(pass, Kernel::InsertCheck);
            self.encode_kernel(pass, Kernel::InsertPlace);
        }
        let gear = self.params.integrator == 0;
        // The neighbour lists (issue 13): the survey decides whether this step rebuilds
        // them (the stages of a rebuild: the old lists' springs into the table, the cell
        // list, the memory order, the new lists, their springs from the table). Gear's
        // prediction surveys each particle it predicts; the step before may have run it
        // ahead.
        if !gear {
            self.encode_kernel(pass, Kernel::Survey);
        } else if !how.predicted {
            self.encode_kernel(pass, Kernel::Predict);
        }
        // In a staged step the rebuild stages are dispatched with no workgroups between
        // rebuilds (issue 14 item 2): `plan_rebuild` writes their arguments once the
        // survey has decided. A lean step records none (`STAGE_EVERY`).
        if how.staged {
            self.encode_kernel(pass, Kernel::PlanRebuild);
            for stage in 0..REBUILD_STAGES.len() {
                self.dispatch_rebuild_stage(pass, stage);
            }
        }
        self.encode_kernel(
            pass,
            if how.record {
                Kernel::ContactForces
            } else {
                Kernel::ContactForcesOnly
            },
        );
        self.encode_kernel(
            pass,
            match (gear, how.ahead) {
                (true, false) => Kernel::Correct,
                (true, true) => Kernel::CorrectAhead,
                (false, _) => Kernel::KickDrift,
            },
        );
        // (The integrators' kernels sum each particle's forces first and end with the
        // boundaries.)
        self.encode_kernel(pass, Kernel::AdvanceClock);
    }

    /// Whether candidates are still waiting: every particle created on the device comes
    /// from a source, and the buffers were sized for all of them.
    pub(super) fn sources_left(&self) -> bool {
        self.live < self.n_cap && !self.sources.is_empty()
    }

    /// Advances `steps` steps, `STEPS_PER_SUBMIT` per submission. Submissions are
    /// pipelined (issue 14 item 3): each batch copies the control words into its own
    /// staging buffer, and the host reads them only once the next batch is submitted, so
    /// the device always has work queued and the host never waits on an idle device. A
    /// halt stops every later kernel on the device at once (each returns when `halted`),
    /// so a batch submitted after the halting one changes nothing, and the halt still
    /// names its step. A pause (`STAGE_EVERY`) is not a halt: the device went fewer
    /// steps than were recorded, read from its step counter, and the host submits the
    /// rest.
    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        let sources_left = self.sources_left();
        // Gear's prediction runs ahead at the end of the step before (`CorrectAhead`, as
        // the CPU path's `correct_ahead`) when the device goes on at once: not across an
        // insertion (new particles are predicted in their step), nor into a stop (the end
        // of the advance, a layered row: the host reads a corrected state). A paused
        // state is predicted and surveyed; the step that lifts the pause predicts nothing
        // more (its `predict` returns while paused).
        let can_run_ahead = self.params.integrator == 0 && !sources_left;
        let target = self.step + steps;
        let mut predicted = false;
        let mut in_flight: std::collections::VecDeque<Batch> = Default::default();
        // The step the device reaches once the batches in flight are done, if none
        // pauses.
        let mut planned = self.step;
        loop {
            if planned < target && in_flight.len() < BATCHES_IN_FLIGHT {
                let mut k = (target - planned).min(STEPS_PER_SUBMIT);
                // Submissions stop where a layered row is due; the host lays it once the
                // device has caught up.
                match self.next_layered_step(planned) {
                    Some(due) if due == planned && in_flight.is_empty() => {
                        self.place_layered_rows();
                        // The next row may be due within this batch.
                        continue;
                    }
                    Some(due) if due == planned => k = 0,
                    Some(due) => k = k.min(due - planned),
                    None => {}
                }
                if k > 0 {
                    let last = planned + k == target;
                    let stops = last || self.next_layered_step(planned + k) == Some(planned + k);
                    let how = StepKind {
                        sources_left,
                        record: false,
                        predicted,
                        ahead: can_run_ahead,
                        staged: true,
                    };
                    in_flight.push_back(self.submit_batch(k, planned + k, how, last, stops));
                    predicted = can_run_ahead && !stops;
                    planned += k;
                    continue;
                }
            }
            let Some(batch) = in_flight.pop_front() else {
                break;
            };
            let end = batch.end;
            let c = self.wait_for(batch);
            if let Some(e) = self.failure() {
                in_flight.clear();
                return Err(Divergence::Device(e.to_string()));
            }
            self.live = c[control::LIVE];
            self.lost_now = c[control::LOST] as u64;
            if c[control::HALT] & !control::HALT_PAUSED != 0 {
                // The later batches ran as no-ops; let them finish first.
                for b in in_flight.drain(..) {
                    self.wait_for(b);
                }
                return Err(self.halt_cause(&c));
            }
            // The device's step counter (32 bits) against the batch's planned end: the
            // steps it did not run (a pause and the no-ops after it) are submitted again.
            let behind = (end as u32).wrapping_sub(c[control::STEP]) as u64;
            if behind > 0 {
                self.pauses += 1;
                planned -= behind;
                for b in &mut in_flight {
                    b.end -= behind;
                }
            }
            let rebuilds = c[control::REBUILDS];
            if let Some(before) = self.rebuilds_read {
                let ran = end - behind - self.step;
                self.stage_every = stage_interval(ran, rebuilds.wrapping_sub(before) as u64);
            }
            self.rebuilds_read = Some(rebuilds);
            self.step = end - behind;
        }
        Ok(())
    }

    /// Encodes and submits `k` steps, with a copy of the control words at their end;
    /// `end`: the step the device reaches if none pauses. `how`: its first step (and
    /// whether steps may predict ahead); `last`: the batch ends the `advance`, its last
    /// step records the contacts; `stops`: the device stops after it (the end, a layered
    /// row), its last step does not predict ahead.
    pub(super) fn submit_batch(
        &mut self,
        k: u64,
        end: u64,
        first: StepKind,
        last: bool,
        stops: bool,
    ) -> Batch {
        let words = control::BLOCKED;
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("control readback"),
            size: (words * 4) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.mark_start(&mut pass);
            let mut how = first;
            // Profiled steps carry the stages (their timestamps must fit one query set).
            let profiling = self.recorder.borrow().is_some();
            let every = self.forced_stage_every.unwrap_or(self.stage_every);
            for step in 1..=k {
                let end = step == k;
                let ahead = first.ahead && !(end && stops);
                how.record = last && end;
                how.ahead = ahead;
                how.staged = profiling || (step - 1) % every == 0;
                self.encode_step(&mut pass, how);
                how.predicted = ahead;
            }
        }
        enc.copy_buffer_to_buffer(&self.buffers.control, 0, &staging, 0, (words * 4) as u64);
        let index = self.gpu.queue.submit([enc.finish()]);
        let mapped = self.map_flag();
        let flag = mapped.clone();
        staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| flag.set(r));
        self.submissions.set(self.submissions.get() + 1);
        self.synced = false;
        Batch {
            staging,
            index,
            end,
            mapped,
        }
    }

    /// Waits until a batch is done and returns the control words it left (zeros, and
    /// the failure noted, when the device cannot be read: `failure`).
    pub(super) fn wait_for(&self, batch: Batch) -> Vec<u32> {
        let words = control::BLOCKED;
        if let Err(e) = self.gpu.wait(Some(batch.index)) {
            self.note_failure(e);
            return vec![0; words];
        }
        if let Err(e) = batch.mapped.outcome() {
            self.note_failure(e);
            return vec![0; words];
        }
        match batch.staging.slice(..).get_mapped_range() {
            Ok(view) => bytemuck::cast_slice::<u8, u32>(&view[..]).to_vec(),
            Err(e) => {
                self.note_failure(e.to_string());
                vec![0; words]
            }
        }
    }

    pub(super) fn halt_cause(&mut self, c: &[u32]) -> Divergence {
        // The device stopped inside the last submission, at the start of step
        // `halt_step`; the steps before it completed.
        let halt_step = c[control::HALT_STEP] as u64;
        self.step = halt_step;
        let id = c[control::HALT_ID];
        let flags = c[control::HALT];
        self.download();
        self.sim.step = halt_step;
        if flags & control::HALT_OVERLAP != 0 {
            let limit = self.sim.scene.limits.max_overlap;
            // The halting step recorded the diverging contacts (contact_forces.wgsl); the
            // others' records are older and within the limit.
            let mut worst: Option<(u32, f64)> = None;
            for (p, cf) in self.sim.pairs.iter().zip(&self.sim.contacts) {
                if p.i != id {
                    continue;
                }
                let ri = self.sim.particles.radius[p.i as usize];
                let rmin = if p.is_wall() {
                    ri
                } else {
                    ri.min(self.sim.particles.radius[p.j as usize])
                };
                let ratio = cf.overlap / rmin;
                if worst.is_none_or(|(_, r)| ratio > r) {
                    worst = Some((p.j, ratio));
                }
            }
            let (j, ratio) = worst.unwrap_or((u32::MAX, f64::NAN));
            let j = if j >= WALL_BASE && j != u32::MAX {
                format!("wall {}", j - WALL_BASE)
            } else {
                j.to_string()
            };
            return Divergence::Overlap {
                i: id,
                j,
                ratio,
                limit,
            };
        }
        if flags & control::HALT_NOT_FINITE != 0 {
            return Divergence::NotFinite {
                id,
                what: "force or position",
            };
        }
        if flags & control::HALT_TOO_FAST != 0 {
            return self.sim.too_fast_report(id);
        }
        if flags & control::HALT_CONTACTS_FULL != 0 {
            return Divergence::TooManyContacts {
                id,
                max: self.params.list_cap,
            };
        }
        Divergence::SpringTableFull { id }
    }

    pub(super) fn read_control(&self) -> Vec<u32> {
        let words = control::BLOCKED;
        self.read_buffer::<u32>(&self.buffers.control, 0, words)
    }
}

/// The control words at the upload: the step, the particles, no halt, and the first
/// step builds the lists with the springs of the table uploaded with them.
pub(super) fn initial_control(step: u64, live: u32, sources: usize) -> Vec<u32> {
    let mut control = vec![0u32; control::BLOCKED + (sources * INSERT_WINDOW as usize).max(1)];
    control[control::STEP] = step as u32;
    control[control::LIVE] = live;
    control[control::HALT_STEP] = u32::MAX;
    control[control::HALT_ID] = u32::MAX;
    control[control::LISTS] = control::REBUILD | control::TABLE_CURRENT;
    control
}
