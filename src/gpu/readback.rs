//! Readback of the device state into the host mirror (`download`, `device_state`),
//! and the device's contacts read back for the host's contact list.

use super::transfer::*;
use super::*;

impl GpuSimulation {
    /// Copies `count` elements of type T from a buffer (blocking).
    pub(super) fn read_buffer<T: bytemuck::Pod>(
        &self,
        buf: &wgpu::Buffer,
        first: usize,
        count: usize,
    ) -> Vec<T> {
        let size = size_of::<T>() as u64;
        let bytes = (count as u64 * size).next_multiple_of(4);
        if bytes == 0 {
            return Vec::new();
        }
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buf, first as u64 * size, &staging, 0, bytes);
        self.gpu.queue.submit([enc.finish()]);
        self.submissions.set(self.submissions.get() + 1);
        let slice = staging.slice(..);
        let mapped = self.map_flag();
        let flag = mapped.clone();
        slice.map_async(wgpu::MapMode::Read, move |r| flag.set(r));
        if let Err(e) = self.gpu.wait(None) {
            return self.failed(e, count);
        }
        if let Err(e) = mapped.outcome() {
            return self.failed(e, count);
        }
        let view = match slice.get_mapped_range() {
            Ok(view) => view,
            Err(e) => return self.failed(format!("{e}"), count),
        };
        let out = bytemuck::cast_slice::<u8, T>(&view[..count * size as usize]).to_vec();
        drop(view);
        staging.unmap();
        out
    }

    /// A readback that failed: noted (the first reason is kept), zeros in its place.
    fn failed<T: bytemuck::Pod>(&self, reason: String, count: usize) -> Vec<T> {
        self.note_failure(reason);
        vec![T::zeroed(); count]
    }

    pub(super) fn note_failure(&self, reason: String) {
        self.gpu.note_failure(reason)
    }

    /// Why the device failed, if it did (a readback, a lost device, an error it
    /// reported): from then on reads return zeros and no state read can be trusted. The
    /// run loop asks before it uses a read (issue 16 item 8: no panic on a lost device).
    pub fn failure(&self) -> Option<GpuError> {
        self.gpu.failure().map(GpuError::Readback)
    }

    /// Where a `map_async` callback leaves its outcome for the thread that polled.
    pub(super) fn map_flag(&self) -> MapFlag {
        MapFlag::default()
    }
}

/// The outcome of a `map_async`, handed from its callback to the thread that polled.
#[derive(Clone, Default)]
pub(super) struct MapFlag(std::sync::Arc<std::sync::Mutex<Option<Result<(), String>>>>);

impl MapFlag {
    pub(super) fn set(&self, r: Result<(), wgpu::BufferAsyncError>) {
        let mut o = self.0.lock().unwrap_or_else(|p| p.into_inner());
        *o = Some(r.map_err(|e| e.to_string()));
    }

    /// Ok once mapped; the reason otherwise (also when the callback has not run).
    pub(super) fn outcome(&self) -> Result<(), String> {
        let o = self.0.lock().unwrap_or_else(|p| p.into_inner());
        o.clone()
            .unwrap_or_else(|| Err("the buffer was not mapped after the wait".into()))
    }
}

impl GpuSimulation {
    pub(super) fn write_buffer<T: bytemuck::Pod>(&mut self, buf: &wgpu::Buffer, data: &[T]) {
        self.gpu
            .queue
            .write_buffer(buf, 0, bytemuck::cast_slice(data));
        self.synced = false;
    }

    /// Reads the device state into the host mirror `self.sim` (f64 particles, this step's
    /// contacts and forces, the spring table, source progress, step and losses).
    pub fn download(&mut self) -> &Simulation {
        if self.synced {
            return &self.sim;
        }
        let c = self.read_control();
        let live = c[control::LIVE] as usize;
        self.live = live as u32;
        let ds = self.device_state();
        let cell = self.params.cell_size;
        let p = from_device(&ds.states, &ds.props, self.origin, cell, &self.corner_table);
        self.sim.particles = p;
        self.sim.step = self.step;
        self.sim.place_walls(self.sim.time());
        self.sim.lost = self.lost_base + c[control::LOST] as u64;
        let mut table = SpringTable::with_capacity_for(ds.springs.len());
        for (k, e) in ds.springs.iter().enumerate() {
            let key = pair_key(Pair { i: e.i, j: e.j });
            table.insert(key, e.value as f64);
            if let Some(sub) = ds.sub.get(k).map(sub_from_device)
                && sub.count > 0
            {
                table.sub.insert(key, sub);
            }
        }
        self.sim.springs = table;
        let rows: Vec<Source> = self.read_buffer(&self.buffers.sources, 0, self.sources.len());
        // Point sources advance on the device; layered blocks (after them) on the host.
        for (k, (b, r)) in self.sources.iter().zip(&rows).enumerate() {
            self.sim.sources[k] = source::advanced(&b.spec, &b.state, r.inserted);
        }
        // This step's contacts, in the CPU's order (by i, then j, ids; walls last).
        let m = self.params.list_cap as usize;
        let ids: Vec<u32> = self.read_buffer(&self.buffers.ids, 0, live);
        let key = |j: u32| if j >= WALL_BASE { j } else { ids[j as usize] };
        let count: Vec<u32> = self.read_buffer(&self.buffers.contact_count, 0, live);
        let js: Vec<u32> = self.read_buffer(&self.buffers.contact_j, 0, live * m);
        let outs = self.read_contact_out(live * m);
        let touching: Vec<u32> = self.read_buffer(&self.buffers.touching, 0, live * m);
        let mut listed = Vec::new();
        // Every contact as the device computed it: its force, normal and contact point
        // (relative to i's centre), converted exactly from f32 (issue 19).
        let parts = &self.sim.particles;
        for s in 0..live {
            // The lists' candidates that touch: the contacts.
            for k in (0..count[s] as usize).filter(|&k| touching[s * m + k] != 0) {
                let (i, j) = (ids[s], key(js[s * m + k]));
                let o = outs[s * m + k];
                let p = parts.position(i as usize);
                let arm = [o.geo[2] as f64, o.geo[3] as f64];
                let pair = Pair { i, j };
                listed.push((
                    pair,
                    ContactForce {
                        force: [o.ft[0] as f64, o.ft[1] as f64],
                        // contact_out holds the torque on j; ContactForce the torque of F
                        // about j's centre.
                        torque: [o.ft[2] as f64, -(o.ft[3] as f64)],
                        point: [p[0] + arm[0], p[1] + arm[1]],
                        arm,
                        n: [o.geo[0] as f64, o.geo[1] as f64],
                        f_n: o.info[0] as f64,
                        f_t: o.info[1] as f64,
                        overlap: o.info[2] as f64,
                        energy: o.info[3] as f64,
                        // The rolling springs come back with the spring table.
                        rolling: 0.0,
                    },
                ));
            }
        }
        listed.sort_by_key(|(p, _)| (p.i, p.j));
        let (pairs, contacts) = listed.into_iter().unzip();
        self.sim.pairs = pairs;
        self.sim.contacts = contacts;
        self.downloaded = Some(ds);
        self.synced = true;
        &self.sim
    }

    /// The host mirror and the exact device state it was read from, for a checkpoint
    /// (reads the device back first if it has run since).
    pub fn checkpoint_state(&mut self) -> (&Simulation, Option<&DeviceState>) {
        self.download();
        (&self.sim, self.downloaded.as_ref())
    }

    /// Every particle's position (x, z) in id order: a light readback (the state alone)
    /// for observers that follow a few particles step by step.
    pub fn positions(&self) -> Vec<[f64; 2]> {
        let live = self.read_control()[control::LIVE] as usize;
        let ids: Vec<u32> = self.read_buffer(&self.buffers.ids, 0, live);
        let states: Vec<State> = by_id(&ids, self.read_buffer(&self.buffers.state, 0, live));
        let cell = self.params.cell_size;
        (states.iter())
            .map(|s| {
                [0, 1].map(|k| {
                    let f = position::Fixed {
                        anchor: s.anchor[k],
                        frac: s.frac[k],
                        rem: s.q[0][k],
                    };
                    self.origin[k] + position::join(f, cell)
                })
            })
            .collect()
    }

    /// The exact device state (for checkpoints).
    pub fn device_state(&self) -> DeviceState {
        let live = self.read_control()[control::LIVE] as usize;
        // In id order, whatever the memory order on the device.
        let ids: Vec<u32> = self.read_buffer(&self.buffers.ids, 0, live);
        let mut states: Vec<State> = by_id(&ids, self.read_buffer(&self.buffers.state, 0, live));
        // Where each particle was at the last rebuild belongs to the lists, not to the
        // state: an upload rebuilds them (and a resumed run may rebuild on other steps).
        for s in &mut states {
            s.listed_anchor = 0;
            s.listed_frac = [0; 2];
        }
        let props = by_id(&ids, self.read_buffer(&self.buffers.props, 0, live));
        let cap = self.params.table_mask as usize + 1;
        self.flush_table();
        let table: Vec<Entry> = self.read_buffer(&self.buffers.table, 0, cap);
        // Spheropolygons' sub-contact springs, disks' rolling springs: from beside each
        // entry.
        let swept = super::params_keep_sub_springs(&self.params);
        let subs: Vec<SubSprings> = if swept {
            self.read_buffer(&self.buffers.table_sub, 0, cap)
        } else {
            Vec::new()
        };
        let mut springs: Vec<(Entry, SubSprings)> = (table.into_iter().enumerate())
            .filter(|(_, e)| e.i != EMPTY)
            .map(|(k, e)| (e, subs.get(k).copied().unwrap_or_default()))
            .collect();
        springs.sort_by_key(|(e, _)| (e.i, e.j));
        let (springs, sub): (Vec<Entry>, Vec<SubSprings>) = springs.into_iter().unzip();
        DeviceState {
            states,
            props,
            springs,
            sub: if swept { sub } else { Vec::new() },
        }
    }

    /// Whether rebuilds sort the particles in memory by cell (default: yes). No result
    /// depends on it (tests compare both).
    pub fn set_reorder(&mut self, reorder: bool) {
        self.params.reorder = reorder as u32;
        let params = self.params;
        self.gpu
            .queue
            .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(&params));
    }

    /// Makes the spring table hold the springs of the current lists (those of the
    /// candidates that touched at the last step), unless it already holds the springs
    /// (nothing has run since an upload). Between steps the springs live in the lists'
    /// slots; the table is written only at a rebuild (issue 13).
    pub(super) fn flush_table(&self) {
        let flags = self.read_control()[control::LISTS];
        if flags & control::TABLE_CURRENT != 0 {
            return;
        }
        self.write_lists_word(control::FLUSH);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            self.mark_start(&mut pass);
            self.encode_kernel(&mut pass, Kernel::ClearTable);
            self.encode_kernel(&mut pass, Kernel::StoreHistory);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.write_lists_word(flags);
    }

    pub(super) fn write_lists_word(&self, flags: u32) {
        self.gpu.queue.write_buffer(
            &self.buffers.control,
            (control::LISTS * 4) as u64,
            bytemuck::bytes_of(&flags),
        );
    }

    pub fn read_contact_out(&self, count: usize) -> Vec<ContactOut> {
        let b = &self.buffers;
        let ft: Vec<[f32; 4]> = self.read_buffer(&b.contact_ft, 0, count);
        let info: Vec<[f32; 4]> = self.read_buffer(&b.contact_info, 0, count);
        let geo: Vec<[f32; 4]> = self.read_buffer(&b.contact_geo, 0, count);
        (ft.into_iter().zip(info).zip(geo))
            .map(|((ft, info), geo)| ContactOut { ft, info, geo })
            .collect()
    }
}
