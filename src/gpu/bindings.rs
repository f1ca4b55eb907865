//! Every binding of the talus kernels, and how each kernel uses it (issue 14 items 2
//! and 7).
//!
//! `BINDINGS` is the one list: the WGSL declarations of every module are generated from
//! it (`declarations`), and the bind group layouts and bind groups are built from it
//! (`kernels::Pipelines`, `buffers::Buffers::bind_groups`). Each kernel is compiled from
//! its module reduced to its entry point, with a storage buffer declared `read` unless
//! the entry point writes it (naga's analysis, `kernel_modules`), and binds only the
//! buffers it touches. wgpu then
//! knows which dispatches only read a buffer, and orders with a barrier only the
//! dispatches where one writes what another reads or writes (with every binding
//! `read_write`, as before, every buffer was ordered at every dispatch).

use std::collections::HashMap;
use std::sync::OnceLock;

use super::modules::{Kernel, MODULES, ModuleSource};

/// A WGSL variable's binding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Binding {
    pub name: &'static str,
    pub group: u32,
    pub binding: u32,
    /// Its WGSL type (a `uniform` for `params`, storage otherwise).
    pub ty: &'static str,
}

const fn bind(name: &'static str, group: u32, binding: u32, ty: &'static str) -> Binding {
    Binding {
        name,
        group,
        binding,
        ty,
    }
}

/// Every binding, by WGSL name. Group 0: the uniform `params`, then every per-run and
/// per-step array; group 1: the spring table; group 2: the indirect dispatch arguments
/// (`plan_rebuild`, `plan_pairs` only: a buffer cannot be an indirect argument and
/// writable storage in one dispatch).
pub const BINDINGS: [Binding; 32] = [
    bind("params", 0, 0, "Params"),
    bind("state", 0, 1, "array<State>"),
    bind("props", 0, 2, "array<Props>"),
    bind("cell_of", 0, 3, "array<u32>"),
    bind("cell_count", 0, 4, "array<atomic<u32>>"),
    bind("cell_start", 0, 5, "array<u32>"),
    bind("scan", 0, 6, "array<u32>"),
    bind("sorted", 0, 7, "array<u32>"),
    bind("contact_j", 0, 8, "array<u32>"),
    bind("contact_count", 0, 9, "array<u32>"),
    bind("down", 0, 10, "array<u32>"),
    bind("down_count", 0, 11, "array<atomic<u32>>"),
    bind("hist_in", 0, 12, "array<f32>"),
    // Whether each candidate of the lists touched at the last evaluation (1) or not (0).
    bind("touching", 0, 13, "array<u32>"),
    // Each candidate's result, one array per use so that each takes 16 bytes per slot
    // (256 per particle: 5.2e5 particles in lavapipe's 128 MiB binding) and the
    // reduction reads only what it sums: (f_x, f_z) on i, torque on i, torque on j.
    bind("contact_ft", 0, 14, "array<vec4<f32>>"),
    bind("force", 0, 15, "array<vec4<f32>>"),
    bind("walls", 0, 16, "array<Wall>"),
    bind("control", 0, 17, "array<atomic<u32>>"),
    bind("sources", 0, 18, "array<Source>"),
    bind("candidates", 0, 19, "array<Candidate>"),
    // Polygon corners in whole position units (counter-clockwise, centroid at the
    // origin): xy in the body frame, zw rotated to the particle's orientation
    // (orientation.wgsl).
    bind("corners", 0, 20, "array<vec4<i32>>"),
    // Each memory slot's particle id (issue 13 item 4): the particles are sorted in
    // memory by cell at every rebuild; ids never change, and every choice of order (a
    // pair's lower id, the order of sums, the spring table's keys, the reported
    // particle) goes by id, so no result depends on where a particle lies in memory.
    bind("ids", 0, 21, "array<u32>"),
    // The particles in their new order, on the way (permute.wgsl).
    bind("state_next", 0, 22, "array<State>"),
    bind("props_next", 0, 23, "array<Props>"),
    bind("ids_next", 0, 24, "array<u32>"),
    // For outputs only (written for the candidates that touch, never read by the
    // kernels): (f_n, f_t, overlap, elastic energy) and the geometry the force was
    // computed with, the normal (n_x, n_z) from j to i and the contact point relative to
    // i's centre (issue 19).
    bind("contact_info", 0, 25, "array<vec4<f32>>"),
    bind("contact_geo", 0, 26, "array<vec4<f32>>"),
    // Every candidate of the lists as one compact list (`PairList`, common.wgsl).
    bind("pairs", 0, 27, "PairList"),
    // A spheropolygon pair's sub-contact springs per candidate slot (`SubSprings`,
    // common.wgsl; one element unless the law is hertz_cohesive).
    bind("sub_hist", 0, 28, "array<SubSprings>"),
    // The spring table keyed by pair: touched only at a rebuild of the lists, which
    // stores the old lists' springs into it and gathers the new lists' from it (issue 13).
    bind("table", 1, 0, "array<Entry>"),
    // Beside each entry of the table, its pair's sub-contact springs (spheropolygons).
    bind("table_sub", 1, 1, "array<SubSprings>"),
    // Per rebuild stage, its workgroups (plan.wgsl).
    bind("dispatch_args", 2, 0, "array<u32>"),
];

/// Storage bindings of a group (group 0's binding 0 is the uniform `params`).
pub const fn storage_bindings(group: u32) -> u32 {
    let mut n = 0;
    let mut k = 0;
    while k < BINDINGS.len() {
        if BINDINGS[k].group == group && !is_uniform(&BINDINGS[k]) {
            n += 1;
        }
        k += 1;
    }
    n
}

const fn is_uniform(b: &Binding) -> bool {
    b.group == 0 && b.binding == 0
}

/// Whether a module declares bindings of a group: group 2 only in `plan`.
pub fn declares(module: &str, group: u32) -> bool {
    group < 2 || module == "plan"
}

/// The declarations of a module's bindings in WGSL, `writable(b)` saying which storage
/// buffers are `read_write` (the others are `read`; a type with atomics is always
/// `read_write`, as WGSL requires).
pub fn declarations(module: &str, writable: impl Fn(&Binding) -> bool) -> String {
    let mut out = String::from("\n// Generated from src/gpu/bindings.rs BINDINGS.\n");
    for b in BINDINGS.iter().filter(|b| declares(module, b.group)) {
        let space = if is_uniform(b) {
            "uniform".to_string()
        } else if writable(b) || has_atomics(b) {
            "storage, read_write".to_string()
        } else {
            "storage, read".to_string()
        };
        out += &format!(
            "@group({}) @binding({}) var<{space}> {}: {};\n",
            b.group, b.binding, b.name, b.ty
        );
    }
    out
}

fn has_atomics(b: &Binding) -> bool {
    b.ty.contains("atomic") || b.ty == "PairList"
}

/// One kernel as compiled: its module reduced to its entry point and what that entry
/// point calls, with each storage binding it does not write declared `read`, and which
/// bindings it touches (indices into BINDINGS).
pub struct KernelModule {
    pub module: naga::Module,
    /// Whether the entry point touches the binding at all (reads, writes, or asks its
    /// length).
    pub touched: Vec<bool>,
    /// Whether it is declared `read_write`: the entry point writes it or uses its
    /// atomics.
    pub writable: Vec<bool>,
}

/// Every kernel's module, built once per process: the module's WGSL (`source`, every
/// binding `read_write`), parsed by naga, reduced to the kernel's entry point and its
/// calls, and the bindings it never writes switched to `read`. Per entry point rather
/// than per module: a helper that writes a buffer (rotate_corners writes `corners`)
/// would otherwise make it writable for every kernel whose file includes the helper.
pub fn kernel_modules() -> &'static HashMap<Kernel, KernelModule> {
    static MODULES_BY_KERNEL: OnceLock<HashMap<Kernel, KernelModule>> = OnceLock::new();
    MODULES_BY_KERNEL.get_or_init(|| {
        let parsed: HashMap<&str, naga::Module> = (MODULES.iter())
            .map(|m| (m.name, parse(m.name, &m.source())))
            .collect();
        (Kernel::ALL.iter())
            .map(|&k| {
                let (module, entry) = k.entry();
                (k, kernel_module(&parsed[module], module, entry))
            })
            .collect()
    })
}

fn parse(name: &str, src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(src)))
}

fn validate(name: &str, module: &naga::Module) -> naga::valid::ModuleInfo {
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(module)
    .unwrap_or_else(|e| panic!("{name} does not validate: {e:?}"))
}

fn kernel_module(parsed: &naga::Module, module: &str, entry: &str) -> KernelModule {
    use naga::valid::GlobalUse;
    let name = format!("{module}.wgsl `{entry}`");
    let mut m = parsed.clone();
    m.entry_points.retain(|e| e.name == entry);
    assert_eq!(m.entry_points.len(), 1, "{name}: no such entry point");
    naga::compact::compact(&mut m, naga::compact::KeepUnused::No);
    let info = validate(&name, &m);
    let uses = info.get_entry_point(0);
    let mut touched = vec![false; BINDINGS.len()];
    let mut writable = vec![false; BINDINGS.len()];
    for (handle, var) in m.global_variables.iter_mut() {
        let Some(k) = (var.name.as_deref()).and_then(|n| BINDINGS.iter().position(|b| b.name == n))
        else {
            continue;
        };
        let u = uses[handle];
        touched[k] = !u.is_empty();
        writable[k] =
            u.intersects(GlobalUse::WRITE | GlobalUse::ATOMIC) || has_atomics(&BINDINGS[k]);
        if let naga::AddressSpace::Storage { access } = &mut var.space
            && !writable[k]
        {
            *access = naga::StorageAccess::LOAD;
        }
    }
    validate(&name, &m);
    KernelModule {
        module: m,
        touched,
        writable,
    }
}

/// A bind group's shape: its group and its (binding, read-only) entries. Kernels whose
/// shapes are equal share one layout and one bind group.
pub type GroupShape = (u32, Vec<(u32, bool)>);

/// The bind groups a kernel needs, by group (None: it touches nothing of that group).
pub fn kernel_groups(k: Kernel) -> [Option<GroupShape>; 3] {
    let km = &kernel_modules()[&k];
    [0, 1, 2].map(|g| {
        let entries: Vec<(u32, bool)> = (BINDINGS.iter().enumerate())
            .filter(|(i, b)| b.group == g && km.touched[*i])
            .map(|(i, b)| (b.binding, !km.writable[i]))
            .collect();
        (!entries.is_empty()).then_some((g, entries))
    })
}

impl ModuleSource {
    /// The module's WGSL: its files and its bindings, every storage buffer
    /// `read_write` (each kernel is compiled from it reduced to its entry point, with
    /// what that does not write made `read`: `bindings::kernel_modules`).
    pub fn source(&self) -> String {
        self.source_with(|_| true)
    }

    /// The module with the bindings `writable` says declared `read_write`.
    pub fn source_with(&self, writable: impl Fn(&Binding) -> bool) -> String {
        self.parts.join("\n") + &declarations(self.name, writable)
    }
}
