//! Fixed-point positions of the GPU path, host twin of `shaders/position.wgsl`.
//!
//! A coordinate measured from the grid origin is `anchor · cell + (frac + rem) · unit`
//! with `unit = cell / 2^30`: a whole cell, a whole number of units below one cell and
//! an f32 remainder in [-0.5, 0.5] units. That keeps about 1e-9 of a cell exactly and
//! the remainder another 24 bits, so neighbour offsets and overlaps are exact to far
//! below SPEC 3's 1e-3 of a 1e-5 d overlap anywhere in the domain. The WGSL file says
//! why it is built from integers rather than double-single floats.

/// Units per cell (`FRAC_ONE` in position.wgsl).
pub const FRAC_ONE: i64 = 1 << 30;

/// One coordinate in fixed point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fixed {
    pub anchor: i32,
    pub frac: u32,
    pub rem: f32,
}

/// The fixed-point unit of a cell size, exact in f64.
pub fn unit(cell: f32) -> f64 {
    cell as f64 / FRAC_ONE as f64
}

/// Splits a coordinate measured from the grid origin.
pub fn split(v: f64, cell: f32) -> Fixed {
    let l = cell as f64;
    let mut anchor = (v / l).floor() as i64;
    let units = (v - anchor as f64 * l) / unit(cell);
    let whole = units.round();
    let rem = (units - whole) as f32;
    let mut frac = whole as i64;
    // Rounding at the top or bottom of the cell moves to the neighbouring cell.
    if frac >= FRAC_ONE {
        frac -= FRAC_ONE;
        anchor += 1;
    }
    if frac < 0 {
        frac += FRAC_ONE;
        anchor -= 1;
    }
    Fixed {
        anchor: anchor as i32,
        frac: frac as u32,
        rem,
    }
}

/// The coordinate from the grid origin, in f64.
pub fn join(f: Fixed, cell: f32) -> f64 {
    f.anchor as f64 * cell as f64 + (f.frac as f64 + f.rem as f64) * unit(cell)
}

/// A length below one cell (a radius) as whole units and an f32 remainder.
pub fn length_units(len: f64, cell: f32) -> (u32, f32) {
    let units = len / unit(cell);
    let whole = units.round();
    (whole as u32, (units - whole) as f32)
}

/// Splits a point measured from the grid origin.
pub fn split2(x: f64, z: f64, cell: f32) -> ([i32; 2], [u32; 2], [f32; 2]) {
    let (a, b) = (split(x, cell), split(z, cell));
    ([a.anchor, b.anchor], [a.frac, b.frac], [a.rem, b.rem])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_and_join_round_trip_to_far_below_a_unit() {
        let cell = 1.1f32;
        let u = unit(cell);
        for &v in &[
            0.0,
            1e-12,
            0.55,
            1.1,
            1.1 - 1e-13,
            -0.3,
            12345.678901234,
            1.1e4 + 1e-9,
        ] {
            let f = split(v, cell);
            assert!(f.frac < FRAC_ONE as u32, "{v}: frac {}", f.frac);
            assert!(f.rem.abs() <= 0.5, "{v}: rem {}", f.rem);
            // The remainder keeps 24 bits of a unit: 1e-7 u ≈ 1e-16 cell.
            let back = join(f, cell);
            assert!(
                (back - v).abs() <= 1e-7 * u + 1e-15 * v.abs(),
                "{v} -> {back}"
            );
        }
    }

    #[test]
    fn length_units_round_trip() {
        let cell = 2.3f32;
        let (w, r) = length_units(0.5000000123, cell);
        let back = (w as f64 + r as f64) * unit(cell);
        assert!((back - 0.5000000123).abs() < 1e-16);
    }
}
