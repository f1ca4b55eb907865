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
    /// Spheropolygons' sub-contact springs: per candidate slot, and beside the table.
    pub(super) sub_hist: wgpu::Buffer,
    pub(super) table_sub: wgpu::Buffer,
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
    pub(super) table_sub: &'a [SubSprings],
}

impl Buffers {
    /// Creates every buffer for `params.n_cap` particles and `cells` cells, with the
    /// initial contents `c`.
    pub(super) fn new(dev: &wgpu::Device, params: &Params, cells: u64, c: &Initial) -> Self {
        let n = params.n_cap as u64;
        let m = params.list_cap as u64;

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
            // Only spheropolygon scenes and rolling springs use them (32 bytes a slot).
            sub_hist: {
                let slots = if super::params_keep_sub_springs(params) {
                    n * m
                } else {
                    1
                };
                let empty = vec![SubSprings::default(); slots as usize];
                init("sub_hist", bytemuck::cast_slice(&empty))
            },
            table_sub: init("table_sub", bytemuck::cast_slice(c.table_sub)),
            dispatch_args: dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dispatch_args"),
                contents: bytemuck::cast_slice(&dispatch_args(params)),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_SRC,
            }),
            pairs: {
                // The count, then a slot per candidate: only the overlap-area law and
                // spheropolygons take a thread per pair (64 bytes a particle the disk
                // laws do not need).
                let slots = if per_pair(params) { n * m } else { 0 };
                zeroed("pairs", 4 + slots * 4)
            },
        }
    }

    /// The buffer bound to a WGSL variable.
    pub(super) fn named(&self, name: &str) -> Option<&wgpu::Buffer> {
        let b = self;
        Some(match name {
            "params" => &b.params,
            "state" => &b.state,
            "props" => &b.props,
            "cell_of" => &b.cell_of,
            "cell_count" => &b.cell_count,
            "cell_start" => &b.cell_start,
            "scan" => &b.scan,
            "sorted" => &b.sorted,
            "contact_j" => &b.contact_j,
            "contact_count" => &b.contact_count,
            "down" => &b.down,
            "down_count" => &b.down_count,
            "hist_in" => &b.hist_in,
            "touching" => &b.touching,
            "contact_ft" => &b.contact_ft,
            "force" => &b.force,
            "walls" => &b.walls,
            "control" => &b.control,
            "sources" => &b.sources,
            "candidates" => &b.candidates,
            "corners" => &b.corners,
            "ids" => &b.ids,
            "state_next" => &b.state_next,
            "props_next" => &b.props_next,
            "ids_next" => &b.ids_next,
            "contact_info" => &b.contact_info,
            "contact_geo" => &b.contact_geo,
            "pairs" => &b.pairs,
            "table" => &b.table,
            "sub_hist" => &b.sub_hist,
            "table_sub" => &b.table_sub,
            "dispatch_args" => &b.dispatch_args,
            _ => return None,
        })
    }

    /// The bind groups of the talus kernels, one per shape in `Pipelines::groups`.
    pub(super) fn bind_groups(
        &self,
        dev: &wgpu::Device,
        pipelines: &Pipelines,
    ) -> Vec<wgpu::BindGroup> {
        (pipelines.groups.iter())
            .map(|((g, shape), layout)| {
                let entries: Vec<_> = (shape.iter())
                    .map(|&(binding, _)| {
                        let b = (BINDINGS.iter())
                            .find(|b| b.group == *g && b.binding == binding)
                            .expect("a layout's bindings are in BINDINGS");
                        wgpu::BindGroupEntry {
                            binding,
                            resource: self
                                .named(b.name)
                                .unwrap_or_else(|| panic!("no buffer for binding {}", b.name))
                                .as_entire_binding(),
                        }
                    })
                    .collect();
                dev.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("talus"),
                    layout,
                    entries: &entries,
                })
            })
            .collect()
    }
}
