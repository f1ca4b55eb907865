//! The WGSL sources: each stage file in `shaders/` is compiled after `common.wgsl`,
//! `position.wgsl`, `orientation.wgsl` and the helper files it uses, followed by the
//! binding declarations generated for the module (`bindings.rs`, where
//! `ModuleSource::source` assembles it); and every entry point, in the order of a step
//! (`Kernel`).

/// A shader module: the stage file and the helper files it needs.
pub struct ModuleSource {
    pub name: &'static str,
    pub parts: &'static [&'static str],
}

const COMMON: &str = include_str!("../../shaders/common.wgsl");
const POSITION: &str = include_str!("../../shaders/position.wgsl");
const ORIENTATION: &str = include_str!("../../shaders/orientation.wgsl");
const GEOMETRY: &str = include_str!("../../shaders/geometry.wgsl");
/// The overlap-area law's geometry, one query a file, in this order (polygon_outline.wgsl
/// holds what they share; area_contact.wgsl picks a pair's query).
const POLYGON: [&str; 6] = [
    include_str!("../../shaders/polygon_outline.wgsl"),
    include_str!("../../shaders/polygon.wgsl"),
    include_str!("../../shaders/polygon_wall.wgsl"),
    include_str!("../../shaders/disk_area.wgsl"),
    include_str!("../../shaders/polygon_disk.wgsl"),
    include_str!("../../shaders/area_contact.wgsl"),
];
const LAWS: &str = include_str!("../../shaders/laws.wgsl");
const SPHEROPOLYGON: &str = include_str!("../../shaders/spheropolygon.wgsl");

pub const MODULES: &[ModuleSource] = &[
    ModuleSource {
        name: "insert",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/insert.wgsl"),
        ],
    },
    ModuleSource {
        name: "predict",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/predict.wgsl"),
            include_str!("../../shaders/survey.wgsl"),
        ],
    },
    ModuleSource {
        name: "survey",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/survey.wgsl"),
        ],
    },
    ModuleSource {
        name: "plan",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/plan.wgsl"),
        ],
    },
    ModuleSource {
        name: "cell_index",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/cell_index.wgsl"),
        ],
    },
    ModuleSource {
        name: "prefix_sum",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/prefix_sum.wgsl"),
        ],
    },
    ModuleSource {
        name: "scatter",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/scatter.wgsl"),
        ],
    },
    ModuleSource {
        name: "permute",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/permute.wgsl"),
        ],
    },
    ModuleSource {
        name: "find_contacts",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            GEOMETRY,
            POLYGON[0],
            POLYGON[1],
            POLYGON[2],
            POLYGON[3],
            POLYGON[4],
            POLYGON[5],
            include_str!("../../shaders/find_contacts.wgsl"),
        ],
    },
    ModuleSource {
        name: "gather_history",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/gather_history.wgsl"),
        ],
    },
    ModuleSource {
        name: "contact_forces",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            GEOMETRY,
            POLYGON[0],
            POLYGON[1],
            POLYGON[2],
            POLYGON[3],
            POLYGON[4],
            POLYGON[5],
            LAWS,
            SPHEROPOLYGON,
            include_str!("../../shaders/contact_forces.wgsl"),
        ],
    },
    ModuleSource {
        name: "store_history",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/store_history.wgsl"),
        ],
    },
    ModuleSource {
        name: "reduce_forces",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/reduce_forces.wgsl"),
        ],
    },
    ModuleSource {
        name: "correct",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/reduce_forces.wgsl"),
            include_str!("../../shaders/survey.wgsl"),
            include_str!("../../shaders/predict.wgsl"),
            include_str!("../../shaders/correct.wgsl"),
            include_str!("../../shaders/boundaries.wgsl"),
        ],
    },
    ModuleSource {
        name: "kick_drift",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/reduce_forces.wgsl"),
            include_str!("../../shaders/kick_drift.wgsl"),
            include_str!("../../shaders/boundaries.wgsl"),
        ],
    },
    ModuleSource {
        name: "boundaries",
        parts: &[
            COMMON,
            POSITION,
            ORIENTATION,
            include_str!("../../shaders/boundaries.wgsl"),
        ],
    },
];

/// Every entry point: (module, entry point). The order is the order of a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    InsertCheck,
    InsertPlace,
    Predict,
    Survey,
    PlanRebuild,
    /// The workgroups of `contact_forces` under the overlap-area law (a thread per pair).
    PlanPairs,
    ClearCells,
    CellIndex,
    ScanLevel0,
    ScanLevel1,
    ScanLevel2,
    ScanAdd1,
    ScanAdd0,
    Scatter,
    PermuteGather,
    PermuteStore,
    FindContacts,
    GatherHistory,
    ContactForces,
    /// `contact_forces` without what only outputs read (`RECORD` off): every step but
    /// the last of an `advance`.
    ContactForcesOnly,
    ClearTable,
    StoreHistory,
    ReduceForces,
    Correct,
    /// `correct` followed by the next step's prediction and survey (`AHEAD` on).
    CorrectAhead,
    KickDrift,
    AdvanceClock,
}

impl Kernel {
    pub const ALL: [Kernel; 27] = [
        Kernel::InsertCheck,
        Kernel::InsertPlace,
        Kernel::Predict,
        Kernel::Survey,
        Kernel::PlanRebuild,
        Kernel::PlanPairs,
        Kernel::ClearCells,
        Kernel::CellIndex,
        Kernel::ScanLevel0,
        Kernel::ScanLevel1,
        Kernel::ScanLevel2,
        Kernel::ScanAdd1,
        Kernel::ScanAdd0,
        Kernel::Scatter,
        Kernel::PermuteGather,
        Kernel::PermuteStore,
        Kernel::FindContacts,
        Kernel::GatherHistory,
        Kernel::ContactForces,
        Kernel::ContactForcesOnly,
        Kernel::ClearTable,
        Kernel::StoreHistory,
        Kernel::ReduceForces,
        Kernel::Correct,
        Kernel::CorrectAhead,
        Kernel::KickDrift,
        Kernel::AdvanceClock,
    ];

    /// (module name, entry point name).
    pub fn entry(self) -> (&'static str, &'static str) {
        match self {
            Kernel::InsertCheck => ("insert", "insert_check"),
            Kernel::InsertPlace => ("insert", "insert_place"),
            Kernel::Predict => ("predict", "predict"),
            Kernel::Survey => ("survey", "survey"),
            Kernel::PlanRebuild => ("plan", "plan_rebuild"),
            Kernel::PlanPairs => ("plan", "plan_pairs"),
            Kernel::ClearCells => ("cell_index", "clear_cells"),
            Kernel::CellIndex => ("cell_index", "cell_index"),
            Kernel::ScanLevel0 => ("prefix_sum", "scan_level0"),
            Kernel::ScanLevel1 => ("prefix_sum", "scan_level1"),
            Kernel::ScanLevel2 => ("prefix_sum", "scan_level2"),
            Kernel::ScanAdd1 => ("prefix_sum", "scan_add1"),
            Kernel::ScanAdd0 => ("prefix_sum", "scan_add0"),
            Kernel::Scatter => ("scatter", "scatter"),
            Kernel::PermuteGather => ("permute", "permute_gather"),
            Kernel::PermuteStore => ("permute", "permute_store"),
            Kernel::FindContacts => ("find_contacts", "find_contacts"),
            Kernel::GatherHistory => ("gather_history", "gather_history"),
            Kernel::ContactForces | Kernel::ContactForcesOnly => {
                ("contact_forces", "contact_forces")
            }
            Kernel::ClearTable => ("store_history", "clear_table"),
            Kernel::StoreHistory => ("store_history", "store_history"),
            Kernel::ReduceForces => ("reduce_forces", "reduce_forces"),
            Kernel::Correct | Kernel::CorrectAhead => ("correct", "correct"),
            Kernel::KickDrift => ("kick_drift", "kick_drift"),
            Kernel::AdvanceClock => ("boundaries", "advance_clock"),
        }
    }
}
