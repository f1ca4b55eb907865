//! The device's buffers (one per array of `shaders/common.wgsl`'s bindings) and their
//! bind groups: group 0 holds every per-run and per-step array, group 1 the spring
//! table, group 2 the rebuild stages' indirect dispatch arguments (`plan_rebuild` only).

use super::*;

/// Every buffer of a run, by its WGSL name.
pub(super) struct Buffers {
    pub(super) params: wgpu::Buffer,
    pub(super) state: wgpu::Buffer,
    pub(super) props: wgpu::Buffer,
    pub(super) cell_of: wgpu::Buffer,
    pub(super) cell_count: wgpu::Buffer,
    pub(super) cell_start: wgpu::Buffer,
    pub(super) scan: wgpu::Buffer,
    pub(super) sorted: wgpu::Buffer,
    pub(super) contact_j: wgpu::Buffer,
    pub(super) contact_count: wgpu::Buffer,
    pub(super) down: wgpu::Buffer,
    pub(super) down_count: wgpu::Buffer,
    pub(super) hist_in: wgpu::Buffer,
    pub(super) touching: wgpu::Buffer,
    /// Each candidate's result: what the reduction sums, and for outputs only.
    pub(super) contact_ft: wgpu::Buffer,
    pub(super) contact_info: wgpu::Buffer,
    pub(super) contact_geo: wgpu::Buffer,
    pub(super) force: wgpu::Buffer,
    pub(super) walls: wgpu::Buffer,
    pub(super) control: wgpu::Buffer,
    pub(super) sources: wgpu::Buffer,
    pub(super) candidates: wgpu::Buffer,
    pub(super) corners: wgpu::Buffer,
    /// Each memory slot's particle id, and the particles on their way to a new order.
    pub(super) ids: wgpu::Buffer,
    pub(super) state_next: wgpu::Buffer,
    pub(super) props_next: wgpu::Buffer,
    pub(super) ids_next: wgpu::Buffer,
    pub(super) table: wgpu::Buffer,
    /// The rebuild stages' indirect dispatch arguments (shaders/plan.wgsl).
    pub(super) dispatch_args: wgpu::Buffer,
    /// The candidates as one list (`PairList` in common.wgsl).
    pub(super) pairs: wgpu::Buffer,
}

/// What the buffers hold at the upload (the others start zeroed).
pub(super) struct Initial<'a> {
    pub(super) state: &'a [State],
    pub(super) props: &'a [Props],
    pub(super) walls: &'a [Wall],
    pub(super) control: &'a [u32],
    pub(super) sources: &'a [Source],
    pub(super) candidates: &'a [Candidate],
    pub(super) corners: &'a [[i32; 4]],
    pub(super) table: &'a [Entry],
}

impl Buffers {
    /// Creates every buffer for `params.n_cap` particles and `cells` cells, with the
    /// initial contents `c`.
    pub(super) fn new(dev: &wgpu::Device, params: &Params, cells: u64, c: &Initial) -> Self {
        let n = params.n_cap as u64;
        let m = MAX_CONTACTS as u64;

        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let zeroed = |label: &str, bytes: u64| {
            dev.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(MIN_BUFFER).next_multiple_of(16),
                usage: storage,
                mapped_at_creation: false,
            })
        };
        let init = |label: &str, bytes: &[u8]| {
            let mut v = bytes.to_vec();
            v.resize(v.len().max(MIN_BUFFER as usize).next_multiple_of(16), 0);
            dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &v,
                usage: storage,
            })
        };
        Buffers {
            params: dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytemuck::bytes_of(params),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            }),
            state: init("state", bytemuck::cast_slice(c.state)),
            props: init("props", bytemuck::cast_slice(c.props)),
            cell_of: zeroed("cell_of", n * 4),
            cell_count: zeroed("cell_count", cells * 4),
            cell_start: zeroed("cell_start", cells * 4),
            scan: zeroed("scan", (params.scan_offset2 as u64 + SCAN_WG as u64) * 4),
            sorted: zeroed("sorted", n * 4),
            contact_j: zeroed("contact_j", n * m * 4),
            contact_count: zeroed("contact_count", n * 4),
            down: zeroed("down", n * m * 4),
            down_count: zeroed("down_count", n * 4),
            hist_in: zeroed("hist_in", n * m * 4),
            touching: zeroed("touching", n * m * 4),
            contact_ft: zeroed("contact_ft", n * m * 16),
            contact_info: zeroed("contact_info", n * m * 16),
            contact_geo: zeroed("contact_geo", n * m * 16),
            force: zeroed("force", n * 16),
            walls: init("walls", bytemuck::cast_slice(c.walls)),
            control: init("control", bytemuck::cast_slice(c.control)),
            sources: init("sources", bytemuck::cast_slice(c.sources)),
            candidates: init("candidates", bytemuck::cast_slice(c.candidates)),
            corners: init("corners", bytemuck::cast_slice(c.corners)),
            ids: init(
                "ids",
                bytemuck::cast_slice(&(0..params.n_cap).collect::<Vec<u32>>()),
            ),
            state_next: zeroed("state_next", n * size_of::<State>() as u64),
            props_next: zeroed("props_next", n * size_of::<Props>() as u64),
            ids_next: zeroed("ids_next", n * 4),
            table: init("springs", bytemuck::cast_slice(c.table)),
            dispatch_args: dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dispatch_args"),
                contents: bytemuck::cast_slice(&dispatch_args(params)),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_SRC,
            }),
            pairs: {
                // The count, then a slot per candidate.
                zeroed("pairs", 4 + n * m * 4)
            },
        }
    }

    /// The bind groups of the talus kernels (`kernels::Pipelines`' layouts).
    pub(super) fn bind_groups(
        &self,
        dev: &wgpu::Device,
        pipelines: &Pipelines,
    ) -> [wgpu::BindGroup; 3] {
        let b = self;
        let group0_buffers = [
            &b.params,
            &b.state,
            &b.props,
            &b.cell_of,
            &b.cell_count,
            &b.cell_start,
            &b.scan,
            &b.sorted,
            &b.contact_j,
            &b.contact_count,
            &b.down,
            &b.down_count,
            &b.hist_in,
            &b.touching,
            &b.contact_ft,
            &b.force,
            &b.walls,
            &b.control,
            &b.sources,
            &b.candidates,
            &b.corners,
            &b.ids,
            &b.state_next,
            &b.props_next,
            &b.ids_next,
            &b.contact_info,
            &b.contact_geo,
            &b.pairs,
        ];
        let entries0: Vec<_> = group0_buffers
            .iter()
            .enumerate()
            .map(|(k, buf)| wgpu::BindGroupEntry {
                binding: k as u32,
                resource: buf.as_entire_binding(),
            })
            .collect();
        let group0 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("talus group 0"),
            layout: &pipelines.group0,
            entries: &entries0,
        });
        let group1 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("springs"),
            layout: &pipelines.group1,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: b.table.as_entire_binding(),
            }],
        });
        let group2 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dispatch arguments"),
            layout: &pipelines.group2,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: b.dispatch_args.as_entire_binding(),
            }],
        });
        [group0, group1, group2]
    }
}
