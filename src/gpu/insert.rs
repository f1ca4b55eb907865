//! What the host keeps of the sources: point sources insert on the device from
//! candidates drawn at the upload; layered blocks lay their rows from the host, on the
//! read-back pile, between batches.

use super::*;

/// The source bookkeeping of the host: where each source stood at upload.
pub(super) struct SourceBase {
    pub(super) spec: PointSource,
    pub(super) state: SourceState,
}

/// A layer-by-layer block: its rows are laid by the host (`place_layered_rows`), which
/// reads the pile back to find its surface; its progress is `sim.sources[index]`.
pub(super) struct LayeredBase {
    pub(super) spec: Layered,
    pub(super) material: u32,
    pub(super) index: usize,
    /// The copy of the scene it builds on (`replicas`).
    pub(super) copy: u32,
}

impl GpuSimulation {
    /// The first step from `from` on at which a layered block lays its next row (as the
    /// CPU path decides it: at the start of the first step with t ≥ its time).
    pub(super) fn next_layered_step(&self, from: u64) -> Option<u64> {
        let dt = self.sim.scene.dt;
        self.layered
            .iter()
            .filter_map(|b| {
                let k = self.sim.sources[b.index].inserted;
                if k >= crate::scene::rows::max_rows(&b.spec) {
                    return None;
                }
                let due = b.spec.start_time + k as f64 * b.spec.interval;
                let mut s = ((due / dt).floor() as u64).saturating_sub(1).max(from);
                while (s as f64) * dt < due {
                    s += 1;
                }
                Some(s)
            })
            .min()
    }

    /// Lays the rows due at this step (`create::layered::emit` on the read-back pile) and
    /// appends them to the device, in the CPU path's order.
    pub(super) fn place_layered_rows(&mut self) {
        let t = self.step as f64 * self.sim.scene.dt;
        self.download();
        let cell = self.params.cell_size;
        let unit = position::unit(cell);
        let gear = self.sim.scene.integrator == IntegratorKind::Gear5;
        let h = 0.5 * self.sim.scene.dt * self.sim.scene.dt;
        let g = self.sim.gravity(t);
        let mut live = self.live as usize;
        for b in &self.layered {
            let new = create::layered::emit(
                &b.spec,
                &mut self.sim.sources[b.index],
                t,
                b.material,
                &self.sim.particles,
                b.copy,
            );
            for np in &new {
                let mut one = Particles::default();
                create::push(&self.sim.scene, &mut one, np);
                one.copy[0] = b.copy;
                if gear {
                    one.q[2][0] = [h * g[0], h * g[1], 0.0];
                }
                let (st, mut pr) = to_device(&one, self.origin, cell);
                let first = self.corner_table.len();
                pr[0].shape[0] = first as u32;
                let block = transfer::corner_block(&one.shape[0], one.sweep[0]);
                let corners = device_corners(&block, &st, &pr_local(&pr[0]), unit);
                self.corner_table.extend_from_slice(&block);
                let q = &self.gpu.queue;
                q.write_buffer(
                    &self.buffers.state,
                    (live * size_of::<State>()) as u64,
                    bytemuck::cast_slice(&st[..]),
                );
                q.write_buffer(
                    &self.buffers.props,
                    (live * size_of::<Props>()) as u64,
                    bytemuck::cast_slice(&pr[..]),
                );
                // Ids are never reused: the new particle's is the number so far.
                q.write_buffer(
                    &self.buffers.ids,
                    (live * 4) as u64,
                    bytemuck::bytes_of(&(live as u32)),
                );
                if !corners.is_empty() {
                    q.write_buffer(
                        &self.buffers.corners,
                        (first * 16) as u64,
                        bytemuck::cast_slice(&corners),
                    );
                }
                live += 1;
            }
        }
        self.live = live as u32;
        self.gpu.queue.write_buffer(
            &self.buffers.control,
            (control::LIVE * 4) as u64,
            bytemuck::bytes_of(&self.live),
        );
        // New particles: the next step rebuilds the lists.
        let flags = self.read_control()[control::LISTS];
        self.write_lists_word(flags | control::REBUILD);
        self.synced = false;
    }
}

/// Everything the sources will still insert, drawn at the upload: the point sources'
/// candidates (from each source's own random stream, as the CPU path draws them) and
/// their rows, and room for the layered blocks' rows.
pub(super) struct Upcoming {
    pub(super) sources: Vec<SourceBase>,
    pub(super) source_rows: Vec<Source>,
    pub(super) candidates: Vec<Candidate>,
    /// Polygon corners: every particle's in id order, then every candidate's.
    pub(super) corner_table: Vec<[f64; 2]>,
    pub(super) layered: Vec<LayeredBase>,
    /// Particles and corners the layered blocks may still lay at most.
    pub(super) layered_count: u32,
    pub(super) layered_corners: usize,
}

pub(super) fn upcoming(
    sim: &Simulation,
    layered_specs: &[Layered],
    origin: [f64; 2],
    cell_size: f32,
) -> Upcoming {
    // Sources: every candidate still to come, drawn now.
    let specs: Vec<PointSource> = sim
        .scene
        .particles
        .iter()
        .filter_map(|c| match c {
            Creation::PointSource(s) => Some(s.clone()),
            _ => None,
        })
        .collect();
    let mut sources = Vec::new();
    let mut source_rows = Vec::new();
    let mut candidates = Vec::new();
    // Polygon corners: every particle's in id order, then every candidate's.
    let mut corner_table = transfer::corner_table(&sim.particles);
    let dt = sim.dt();
    // Copy after copy (`replicas`), each copy's point sources in scene order: the order
    // in which the CPU path inserts.
    let per_copy = specs.len() + layered_specs.len();
    for (s, st) in sim.sources.iter().enumerate() {
        let (copy, k) = (s / per_copy.max(1), s % per_copy.max(1));
        let Some(spec) = specs.get(k) else {
            continue;
        };
        let list = source::upcoming(spec, st);
        source_rows.push(Source {
            first: candidates.len() as u32,
            count: list.len() as u32,
            inserted: 0,
            _pad: 0,
        });
        let material = crate::create::material_index(&sim.scene, &spec.material);
        for (k, drawn) in list.into_iter().enumerate() {
            let disk = source::particle(spec, &drawn, material);
            let x = drawn.x;
            let mut one = Particles::default();
            crate::create::push(&sim.scene, &mut one, &disk);
            let (anchor, frac, rem) =
                position::split2(x - origin[0], spec.position[1] - origin[1], cell_size);
            let (radius_units, radius_rem) = position::length_units(one.radius[0], cell_size);
            let due = source::due_step(source::due_time(spec, st.inserted + k as u32), dt);
            let shape = [corner_table.len() as u32, one.shape[0].len() as u32];
            let (turn, turn_rem) = orientation::split_angle(drawn.theta);
            corner_table.extend_from_slice(&transfer::corner_block(&one.shape[0], one.sweep[0]));
            candidates.push(Candidate {
                anchor,
                frac,
                rem,
                // The drawn velocity (the source's, plus its spread).
                velocity: [
                    (disk.velocity[0] * dt) as f32,
                    (disk.velocity[1] * dt) as f32,
                ],
                radius: one.radius[0] as f32,
                mass: one.mass[0] as f32,
                inv_inertia: (1.0 / one.inertia[0]) as f32,
                due_step: due.min(u32::MAX as u64) as u32,
                flags: layout::flags(true, false, material, copy as u32),
                radius_units,
                radius_rem,
                turn,
                shape,
                turn_rem,
                _pad: 0,
            });
        }
        sources.push(SourceBase {
            spec: spec.clone(),
            state: st.clone(),
        });
    }
    // Layered rows still to come: the buffers are sized now for the most they can
    // hold (their corners go after the candidates').
    let mut layered = Vec::new();
    let mut layered_count = 0u32;
    let mut layered_corners = 0usize;
    for copy in 0..sim.scene.replicas {
        for (m, spec) in layered_specs.iter().enumerate() {
            let index = copy as usize * per_copy + specs.len() + m;
            let corners = spec.polygon.as_ref().map_or(0, |p| p.corners as usize);
            for k in sim.sources[index].inserted..crate::scene::rows::max_rows(spec) {
                let n = create::layered::row_capacity(spec, k);
                layered_count += n as u32;
                layered_corners += n * corners;
            }
            layered.push(LayeredBase {
                spec: spec.clone(),
                material: crate::create::material_index(&sim.scene, &spec.material),
                index,
                copy,
            });
        }
    }
    Upcoming {
        sources,
        source_rows,
        candidates,
        corner_table,
        layered,
        layered_count,
        layered_corners,
    }
}
