//! Fixed-point orientations and exactly rotated corners of the GPU path, host twin of
//! `shaders/orientation.wgsl` (bit for bit: the integer steps are the same).
//!
//! An orientation is `turn` units of 2π/2³² (u32, whole turns wrap) plus an f32
//! remainder in turn units; corners are whole position units, rotated with Q31 sin and
//! cos. The WGSL file says why.

use std::f64::consts::PI;

/// One turn unit in radians, 2π / 2³².
pub const TURN_UNIT: f64 = 2.0 * PI / 4_294_967_296.0;
/// 1.0 in Q31 (`Q31_ONE` in orientation.wgsl).
pub const Q31_ONE: u64 = 1 << 31;
/// round(2π · 2²⁹) (`TWO_PI_Q29` in orientation.wgsl).
pub const TWO_PI_Q29: u64 = 3_373_259_426;

/// Splits an angle (radians, any size) into whole turn units and a remainder.
pub fn split_angle(theta: f64) -> (u32, f32) {
    let units = theta / TURN_UNIT;
    let whole = units.round();
    let turn = (whole.rem_euclid(4_294_967_296.0)) as u64 as u32;
    (turn, (units - whole) as f32)
}

/// The angle in radians, in [-π, π).
pub fn join_angle(turn: u32, rem: f32) -> f64 {
    (turn as i32 as f64 + rem as f64) * TURN_UNIT
}

fn mul_q31(a: u64, b: u64) -> u64 {
    ((a * b) >> 31) & 0xFFFF_FFFF
}

/// (sin, cos) of 2π turn / 2³² in Q31, as `turn_sin_cos` in orientation.wgsl.
pub fn turn_sin_cos(turn: u32) -> [i32; 2] {
    let k = turn.wrapping_add(0x2000_0000) >> 30;
    let r = turn.wrapping_sub(k << 30) as i32;
    let y = ((r.unsigned_abs() as u64 * TWO_PI_Q29) >> 30) & 0xFFFF_FFFF;
    let z = mul_q31(y, y);
    let mut f = Q31_ONE - z / 156;
    for d in [110, 72, 42, 20, 6] {
        f = Q31_ONE - mul_q31(z / d, f);
    }
    let mut g = Q31_ONE - z / 182;
    for d in [132, 90, 56, 30, 12, 2] {
        g = Q31_ONE - mul_q31(z / d, g);
    }
    let mut sn = mul_q31(y, f).min(0x7FFF_FFFF) as i32;
    let cs = g.min(0x7FFF_FFFF) as i32;
    if r < 0 {
        sn = -sn;
    }
    match k {
        1 => [cs, -sn],
        2 => [-sn, -cs],
        3 => [-cs, sn],
        _ => [sn, cs],
    }
}

fn round_q31(v: i64) -> i32 {
    (v.wrapping_add(1 << 30) >> 31) as i32
}

/// R(θ) v for a corner in whole units, as `rotate_units` in orientation.wgsl.
pub fn rotate_units(v: [i32; 2], sc: [i32; 2]) -> [i32; 2] {
    let (s, c) = (sc[0] as i64, sc[1] as i64);
    let (x, z) = (v[0] as i64, v[1] as i64);
    [round_q31(c * x - s * z), round_q31(s * x + c * z)]
}

/// A body-frame corner (length units) in whole position units.
pub fn corner_units(v: [f64; 2], unit: f64) -> [i32; 2] {
    [(v[0] / unit).round() as i32, (v[1] / unit).round() as i32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_are_right_to_2e_9_all_round() {
        let error = |turn: u32| {
            let [s, c] = turn_sin_cos(turn);
            let (es, ec) = join_angle(turn, 0.0).sin_cos();
            let q = Q31_ONE as f64;
            (s as f64 / q - es).abs().max((c as f64 / q - ec).abs())
        };
        let mut worst: f64 = 0.0;
        let mut turn: u32 = 7;
        for _ in 0..200_000 {
            turn = turn.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            worst = worst.max(error(turn));
        }
        // Quarter-turn boundaries and their neighbours.
        for k in 0..4i64 {
            for d in [-1i64, 0, 1, 0x1FFF_FFFF] {
                worst = worst.max(error((k << 30).wrapping_add(d) as u32));
            }
        }
        assert!(worst < 2e-9, "worst error {worst:e}");
    }

    #[test]
    fn angles_split_and_join_and_wrap() {
        for &t in &[0.0, 1e-12, 1.0, -1.0, 3.0, -3.1, 7.0, -100.0, 12345.6789] {
            let (turn, rem) = split_angle(t);
            assert!(rem.abs() <= 0.5);
            let back = join_angle(turn, rem);
            let wrapped = (t + PI).rem_euclid(2.0 * PI) - PI;
            assert!(
                (back - wrapped).abs() < 1e-12 * (1.0 + t.abs()),
                "{t}: {back}"
            );
        }
    }

    #[test]
    fn rotated_corners_are_right_to_a_unit() {
        let v = [400_000_000, -123_456_789];
        for &t in &[0.0, 0.3, 1.7, -2.9, 3.1] {
            let (turn, _) = split_angle(t);
            let r = rotate_units(v, turn_sin_cos(turn));
            let th = join_angle(turn, 0.0);
            let (s, c) = th.sin_cos();
            let ex = [
                c * v[0] as f64 - s * v[1] as f64,
                s * v[0] as f64 + c * v[1] as f64,
            ];
            for k in 0..2 {
                assert!(
                    (r[k] as f64 - ex[k]).abs() < 1.5,
                    "{t}: {:?} vs {:?}",
                    r,
                    ex
                );
            }
        }
    }
}
