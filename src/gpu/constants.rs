//! Every module-scope `const` of the WGSL that mirrors a Rust value, with the value the
//! WGSL must hold (issue 42 item 3).
//!
//! The WGSL keeps its own declarations, where the code that uses them reads them (and
//! tests/common/wgsl.rs runs shader files as they are); `tests/gpu_constants.rs` parses
//! every assembled module with naga, evaluates each module-scope `const`, and checks it
//! against `shared()` by name: the same WGSL type and the same bits (a float: the f32
//! rounding of the f64 Rust value). A WGSL `const` missing from this table fails the test
//! unless the test lists it as WGSL-only with its reason, and so does an entry here that
//! no shader declares. The bindings are generated from Rust instead (`bindings.rs`), and
//! the structs are checked field by field (`layout.rs`, tests/gpu_layout.rs).

use std::fmt::Debug;

use super::layout::{self, control as c};
use super::{orientation, position};
use crate::integrate::gear::{CORRECTOR, PREDICTOR};

/// A WGSL constant's value, in its WGSL type.
#[derive(Clone, Copy, Debug)]
pub enum Value {
    U32(u32),
    I32(i32),
    F32(f32),
}

impl PartialEq for Value {
    /// Bit for bit (an f32 by its bits).
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Value::U32(a), Value::U32(b)) => a == b,
            (Value::I32(a), Value::I32(b)) => a == b,
            (Value::F32(a), Value::F32(b)) => a.to_bits() == b.to_bits(),
            _ => false,
        }
    }
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::U32(v) => write!(f, "{v}u ({v:#x})"),
            Value::I32(v) => write!(f, "{v}i"),
            Value::F32(v) => write!(f, "{v:e}f ({:#010x})", v.to_bits()),
        }
    }
}

fn u<T: TryInto<u32> + Copy + Debug>(name: &'static str, v: T) -> (&'static str, Value) {
    let w = v
        .try_into()
        .unwrap_or_else(|_| panic!("{name}: {v:?} is not a u32"));
    (name, Value::U32(w))
}

fn i<T: TryInto<i32> + Copy + Debug>(name: &'static str, v: T) -> (&'static str, Value) {
    let w = v
        .try_into()
        .unwrap_or_else(|_| panic!("{name}: {v:?} is not an i32"));
    (name, Value::I32(w))
}

/// An f32 constant: the f32 rounding of the f64 value.
fn f(name: &'static str, v: f64) -> (&'static str, Value) {
    (name, Value::F32(v as f32))
}

/// Every shared WGSL constant by name, with its Rust source. (A function rather than a
/// `const`: the entries are checked conversions.)
pub fn shared() -> Vec<(&'static str, Value)> {
    use crate::cpu::springs::MAX_SUB;
    use crate::overlap::spheropolygon as sp;
    vec![
        // common.wgsl
        u("WG", layout::WG),
        u("MAX_WORKGROUPS", super::MAX_WORKGROUPS),
        u("WALL_BASE", crate::cpu::contacts::WALL_BASE),
        u("EMPTY", layout::EMPTY),
        u("ROLLING_KEY", crate::cpu::springs::ROLLING_KEY),
        u("LAW_SPRING_DASHPOT", layout::LAW_SPRING_DASHPOT),
        u("LAW_CONTINUOUS", layout::LAW_CONTINUOUS),
        u("LAW_AREA", layout::LAW_AREA),
        u("LAW_HERTZ", layout::LAW_HERTZ),
        u("ACTIVE", layout::ACTIVE),
        u("FIXED", layout::FIXED),
        u("MATERIAL_SHIFT", layout::MATERIAL_SHIFT),
        u("COPY_SHIFT", layout::COPY_SHIFT),
        u("C_STEP", c::STEP),
        u("C_LIVE", c::LIVE),
        u("C_LOST", c::LOST),
        u("C_HALT", c::HALT),
        u("C_HALT_STEP", c::HALT_STEP),
        u("C_HALT_ID", c::HALT_ID),
        u("C_LISTS", c::LISTS),
        u("C_REBUILDS", c::REBUILDS),
        u("C_STAGED", c::STAGED),
        u("C_INACTIVE", c::INACTIVE),
        u("C_WALLS_LISTED", c::WALLS_LISTED),
        u("C_BLOCKED", c::BLOCKED),
        u("REBUILD", c::REBUILD),
        u("TABLE_CURRENT", c::TABLE_CURRENT),
        u("FLUSH", c::FLUSH),
        u("REMOVED", c::REMOVED),
        u("AHEAD_REBUILD", c::AHEAD_REBUILD),
        u("HALT_OVERLAP", c::HALT_OVERLAP),
        u("HALT_NOT_FINITE", c::HALT_NOT_FINITE),
        u("HALT_CONTACTS_FULL", c::HALT_CONTACTS_FULL),
        u("HALT_TABLE_FULL", c::HALT_TABLE_FULL),
        u("HALT_TOO_FAST", c::HALT_TOO_FAST),
        u("HALT_PAUSED", c::HALT_PAUSED),
        u("READING_SLIP_DAMPING", layout::READING_SLIP_DAMPING),
        u("READING_CONTACT_ARM", layout::READING_CONTACT_ARM),
        u("READING_ACCUMULATE", layout::READING_ACCUMULATE),
        u("READING_SLIDE", layout::READING_SLIDE),
        u("INSERT_WINDOW", layout::INSERT_WINDOW),
        u("GEAR_VALUES", crate::state::GEAR_VALUES),
        u("MAX_PAIR_SLOTS", layout::MAX_PAIR_SLOTS),
        u("HASH_X", super::HASH_X),
        u("HASH_Z", super::HASH_Z),
        u("HASH_MIX_1", super::HASH_MIX_1),
        u("HASH_MIX_2", super::HASH_MIX_2),
        u("PAIR_HASH_I", layout::PAIR_HASH_I),
        u("PAIR_HASH_J_ADD", layout::PAIR_HASH_J_ADD),
        u("PAIR_HASH_J", layout::PAIR_HASH_J),
        // position.wgsl (src/gpu/position.rs)
        i("FRAC_ONE", position::FRAC_ONE),
        i("FRAC_MASK", position::FRAC_ONE - 1),
        // orientation.wgsl (src/gpu/orientation.rs): one turn unit 2π/2³² rad, and its
        // inverse as f32 (the host divides by TURN_UNIT in f64).
        f("TURN_UNIT", orientation::TURN_UNIT),
        f("INV_TURN_UNIT", 1.0 / orientation::TURN_UNIT),
        u("Q31_ONE", orientation::Q31_ONE),
        u("TWO_PI_Q29", orientation::TWO_PI_Q29),
        // geometry.wgsl
        f("Q30", layout::Q30),
        // polygon_outline.wgsl
        u("MAX_CORNERS", crate::shape::MAX_CORNERS),
        // spheropolygon.wgsl
        u("VERTEX_I", sp::VERTEX_I),
        u("VERTEX_J", sp::VERTEX_J),
        u("VERTICES", sp::VERTICES),
        u("MAX_SUB", MAX_SUB),
        // laws.wgsl
        u("LAW_ANY", layout::LAW_ANY),
        // contact_forces.wgsl
        f("ROLLING_AT_REST", crate::law::rolling::AT_REST),
        // prefix_sum.wgsl
        u("SCAN_WG", layout::SCAN_WG),
        // predict.wgsl: the predictor's binomials C(l, k) as GEAR_P<k><l> (src/integrate/
        // gear.rs PREDICTOR; row 0, all ones, is added without products).
        f("GEAR_P12", PREDICTOR[1][2]),
        f("GEAR_P13", PREDICTOR[1][3]),
        f("GEAR_P14", PREDICTOR[1][4]),
        f("GEAR_P15", PREDICTOR[1][5]),
        f("GEAR_P23", PREDICTOR[2][3]),
        f("GEAR_P24", PREDICTOR[2][4]),
        f("GEAR_P25", PREDICTOR[2][5]),
        f("GEAR_P34", PREDICTOR[3][4]),
        f("GEAR_P35", PREDICTOR[3][5]),
        f("GEAR_P45", PREDICTOR[4][5]),
        // correct.wgsl: the corrector's c_k (src/integrate/gear.rs CORRECTOR; c2 = 1 is
        // added without a product).
        f("GEAR_C0", CORRECTOR[0]),
        f("GEAR_C1", CORRECTOR[1]),
        f("GEAR_C3", CORRECTOR[3]),
        f("GEAR_C4", CORRECTOR[4]),
        f("GEAR_C5", CORRECTOR[5]),
    ]
}
