//! The compute pipelines of the WGSL modules (`modules.rs`). Each kernel has its own
//! pipeline layout: the bindings its entry point touches, read-only where its module
//! never writes them (`bindings.rs`).

use super::bindings::GroupShape;
use super::modules::Kernel;

/// Storage bindings of group 0 (binding 0 is the uniform Params), of group 1 (the spring
/// table) and of group 2 (the indirect dispatch arguments, bound only to
/// `plan_rebuild`: a buffer cannot be an indirect argument and writable storage in one
/// dispatch).
pub const GROUP0_STORAGE: u32 = super::bindings::storage_bindings(0);
pub const GROUP1_STORAGE: u32 = super::bindings::storage_bindings(1);
pub const GROUP2_STORAGE: u32 = super::bindings::storage_bindings(2);

/// A layout entry: the uniform `params` (group 0, binding 0) or a storage buffer.
fn layout_entry(group: u32, binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    let ty = if group == 0 && binding == 0 {
        wgpu::BufferBindingType::Uniform
    } else {
        wgpu::BufferBindingType::Storage { read_only }
    };
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// What the contact kernels are built for: the overlap-area law (`POLYGONS` in
/// polygon.wgsl), the shapes the scene has now or will have from its sources and
/// layers, and whether it has walls. The branches of the others compile away: a GPU
/// thread that skips a branch waits for its neighbours that take it, and a software
/// adapter runs every branch of every thread (on lavapipe a polygon pile's contacts
/// took 83 ms a step with the disk and wall branches in, 55 ms without them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Build {
    pub area_law: bool,
    pub polygons: bool,
    pub disks: bool,
    pub walls: bool,
    /// Spheropolygons (law hertz_cohesive): `SPHEROPOLYGONS` in polygon.wgsl.
    pub swept: bool,
    /// A software adapter (lavapipe): `contact_forces` takes four pairs to a thread
    /// under the overlap-area law instead of one (`PAIRS_PER_THREAD`, plan.wgsl).
    pub software: bool,
    /// The contact law (`LAW` in laws.wgsl: `contact_forces` keeps only its code).
    pub law: u32,
}

impl Build {
    pub fn of(sim: &crate::sim::Simulation, adapter: &wgpu::AdapterInfo) -> Self {
        use crate::scene::Creation;
        let (mut polygons, mut disks) = (false, false);
        for c in &sim.scene.particles {
            let polygon = match c {
                Creation::LatticePile(p) => p.polygon.is_some(),
                Creation::Row(r) => r.polygon.is_some(),
                Creation::PointSource(s) => s.polygon.is_some(),
                Creation::Layered(l) => l.polygon.is_some(),
                Creation::List(l) => l.polygon.is_some(),
            };
            polygons |= polygon;
            disks |= !polygon;
        }
        // Particles as they are (a checkpoint's, or set by a test).
        for s in &sim.particles.shape {
            polygons |= !s.is_empty();
            disks |= s.is_empty();
        }
        Self {
            area_law: matches!(sim.law, crate::law::ContactLaw::OverlapArea(_)),
            polygons,
            disks,
            walls: !sim.walls.is_empty(),
            swept: matches!(sim.law, crate::law::ContactLaw::HertzCohesive(_)),
            software: adapter.device_type == wgpu::DeviceType::Cpu,
            law: super::params::law_id(&sim.law),
        }
    }
}

pub struct Pipelines {
    /// Every distinct bind group shape of the kernels, with its layout.
    pub groups: Vec<(GroupShape, wgpu::BindGroupLayout)>,
    /// Per kernel, the bind groups it sets (indices into `groups`), by group.
    pub kernel_groups: std::collections::HashMap<Kernel, [Option<usize>; 3]>,
    pub pipelines: std::collections::HashMap<Kernel, wgpu::ComputePipeline>,
}

impl Pipelines {
    /// The pipelines of every kernel, the contact kernels built for `build`.
    pub fn new(device: &wgpu::Device, build: Build) -> Self {
        let mut groups: Vec<(GroupShape, wgpu::BindGroupLayout)> = Vec::new();
        let mut kernel_groups = std::collections::HashMap::new();
        let mut layouts = std::collections::HashMap::new();
        for k in Kernel::ALL {
            let (_, entry) = k.entry();
            let sets = super::bindings::kernel_groups(k).map(|shape| {
                let shape = shape?;
                Some(match groups.iter().position(|(s, _)| *s == shape) {
                    Some(i) => i,
                    None => {
                        let entries: Vec<_> = (shape.1.iter())
                            .map(|&(b, read_only)| layout_entry(shape.0, b, read_only))
                            .collect();
                        let layout =
                            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                                label: Some(entry),
                                entries: &entries,
                            });
                        groups.push((shape, layout));
                        groups.len() - 1
                    }
                })
            });
            let used = sets.iter().rposition(Option::is_some).map_or(0, |g| g + 1);
            let bind_group_layouts: Vec<Option<&wgpu::BindGroupLayout>> = sets[..used]
                .iter()
                .map(|s| s.map(|i| &groups[i].1))
                .collect();
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &bind_group_layouts,
                immediate_size: 0,
            });
            kernel_groups.insert(k, sets);
            layouts.insert(k, layout);
        }
        let modules = super::bindings::kernel_modules();
        let pipelines = Kernel::ALL
            .iter()
            .map(|&k| {
                let (module, entry) = k.entry();
                let flag = |on: bool| if on { 1.0 } else { 0.0 };
                let polygons = ("POLYGONS", flag(build.area_law));
                let swept = ("SPHEROPOLYGONS", flag(build.swept));
                let shapes = [
                    polygons,
                    ("POLYGON_SHAPES", flag(build.polygons)),
                    ("DISK_SHAPES", flag(build.disks)),
                    ("WALLS", flag(build.walls)),
                ];
                let record = (
                    "RECORD",
                    if k == Kernel::ContactForcesOnly {
                        0.0
                    } else {
                        1.0
                    },
                );
                let ahead = ("AHEAD", if k == Kernel::CorrectAhead { 1.0 } else { 0.0 });
                let per_thread = [("PAIRS_PER_THREAD", if build.software { 4.0 } else { 1.0 })];
                let law = ("LAW", build.law as f64);
                let with_record = [
                    shapes[0], shapes[1], shapes[2], shapes[3], swept, record, law,
                ];
                let constants: &[(&str, f64)] = match module {
                    "find_contacts" => &[polygons, swept],
                    "contact_forces" => &with_record,
                    "correct" => &[ahead],
                    "plan" if k == Kernel::PlanPairs => &per_thread,
                    _ => &[],
                };
                let p = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&layouts[&k]),
                    module: &device.create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(entry),
                        source: wgpu::ShaderSource::Naga(std::borrow::Cow::Borrowed(
                            &modules[&k].module,
                        )),
                    }),
                    entry_point: Some(entry),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants,
                        ..Default::default()
                    },
                    cache: None,
                });
                (k, p)
            })
            .collect();
        Self {
            groups,
            kernel_groups,
            pipelines,
        }
    }
}
