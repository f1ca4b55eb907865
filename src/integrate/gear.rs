//! 5th-order Gear predictor–corrector with six values per degree of freedom (Allen &
//! Tildesley, *Computer Simulation of Liquids*, sec. 3.2 and app. E; SPEC 3).
//!
//! The state holds scaled derivatives q_k = (dt^k/k!) d^k r/dt^k, k = 0..5. `predict`
//! is a Taylor step (Pascal's triangle); forces are evaluated at the predicted positions
//! *and velocities*; `correct` adds c_k · Δ to each value, with Δ = (dt²/2) a − q2_pred.
//! Our forces depend on velocities (damping, tangential springs), so c0 = 3/20 — the
//! variant Allen & Tildesley give for velocity-dependent forces — instead of 3/16.

use crate::state::{Dof, GEAR_VALUES, Particles};

/// Corrector coefficients for second-order equations, velocity-dependent forces
/// (`GEAR_C<k>` in correct.wgsl, which adds Δ to q2 without a product: c2 = 1;
/// tests/gpu_constants.rs).
pub const CORRECTOR: [f64; GEAR_VALUES] = [
    3.0 / 20.0,
    251.0 / 360.0,
    1.0,
    11.0 / 18.0,
    1.0 / 6.0,
    1.0 / 60.0,
];

/// Corrector coefficients for forces that depend on positions only (c0 = 3/16).
pub const CORRECTOR_POSITION_ONLY: [f64; GEAR_VALUES] = [
    3.0 / 16.0,
    251.0 / 360.0,
    1.0,
    11.0 / 18.0,
    1.0 / 6.0,
    1.0 / 60.0,
];

/// Predictor coefficients: `PREDICTOR[k][l]` = C(l, k), the binomial, for l > k (0
/// elsewhere), Pascal's triangle. Row 0 is all ones, which `predict_one` (and
/// predict.wgsl) add without a product; the other rows are `GEAR_P<k><l>` in
/// predict.wgsl (tests/gpu_constants.rs).
pub const PREDICTOR: [[f64; GEAR_VALUES]; GEAR_VALUES] = pascal();

const fn pascal() -> [[f64; GEAR_VALUES]; GEAR_VALUES] {
    // c[l][k] = C(l, k), row by row.
    let mut c = [[0u32; GEAR_VALUES]; GEAR_VALUES];
    let mut p = [[0.0; GEAR_VALUES]; GEAR_VALUES];
    let mut l = 0;
    while l < GEAR_VALUES {
        c[l][0] = 1;
        let mut k = 1;
        while k <= l {
            c[l][k] = c[l - 1][k - 1] + if k < l { c[l - 1][k] } else { 0 };
            k += 1;
        }
        let mut k = 0;
        while k < l {
            p[k][l] = c[l][k] as f64;
            k += 1;
        }
        l += 1;
    }
    p
}

/// Taylor predictor for one particle: q_k += Σ_{l>k} C(l, k) q_l (`PREDICTOR`).
// `d` runs over the components of all six values, as in `correct_one`.
#[allow(clippy::needless_range_loop)]
pub fn predict_one(q: &mut [Dof; GEAR_VALUES]) {
    const P: [[f64; GEAR_VALUES]; GEAR_VALUES] = PREDICTOR;
    for d in 0..3 {
        q[0][d] += q[1][d] + q[2][d] + q[3][d] + q[4][d] + q[5][d];
        q[1][d] += P[1][2] * q[2][d] + P[1][3] * q[3][d] + P[1][4] * q[4][d] + P[1][5] * q[5][d];
        q[2][d] += P[2][3] * q[3][d] + P[2][4] * q[4][d] + P[2][5] * q[5][d];
        q[3][d] += P[3][4] * q[4][d] + P[3][5] * q[5][d];
        q[4][d] += P[4][5] * q[5][d];
    }
}

/// Corrector for one particle given its acceleration at the predicted state.
pub fn correct_one(q: &mut [Dof; GEAR_VALUES], accel: Dof, dt: f64, c: &[f64; GEAR_VALUES]) {
    let half_dt2 = 0.5 * dt * dt;
    for d in 0..3 {
        let delta = half_dt2 * accel[d] - q[2][d];
        for k in 0..GEAR_VALUES {
            q[k][d] += c[k] * delta;
        }
    }
}

/// Stage: predict every integrated particle (each on its own, on every thread).
pub fn predict(p: &mut Particles) {
    let (q, active, fixed) = (&mut p.q, &p.active, &p.fixed);
    crate::base::parallel::for_each6(q, |i, v| {
        if active[i] && !fixed[i] {
            predict_in_place(v);
        }
    });
}

/// `predict_one` on the six values of a particle where they are stored.
#[inline(always)]
pub fn predict_in_place(v: [&mut Dof; GEAR_VALUES]) {
    let mut q = [*v[0], *v[1], *v[2], *v[3], *v[4], *v[5]];
    predict_one(&mut q);
    for (dst, src) in v.into_iter().zip(q) {
        *dst = src;
    }
}

/// Stage: correct every integrated particle with its force at the predicted state,
/// `force(i)` (fx, fz, τ).
pub fn correct<F>(p: &mut Particles, force: F, gravity: [f64; 2], dt: f64)
where
    F: Fn(usize) -> Dof + Sync + Send,
{
    let (q, active, fixed, mass, inertia) = (&mut p.q, &p.active, &p.fixed, &p.mass, &p.inertia);
    crate::base::parallel::for_each6(q, |i, v| {
        if active[i] && !fixed[i] {
            let a = super::acceleration(force(i), mass[i], inertia[i], gravity);
            correct_in_place(v, a, dt);
        }
    });
}

/// `correct_one` (velocity-dependent forces) on the six values of a particle where they
/// are stored.
#[inline(always)]
pub fn correct_in_place(v: [&mut Dof; GEAR_VALUES], accel: Dof, dt: f64) {
    let mut q = [*v[0], *v[1], *v[2], *v[3], *v[4], *v[5]];
    correct_one(&mut q, accel, dt, &CORRECTOR);
    for (dst, src) in v.into_iter().zip(q) {
        *dst = src;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_predictor_is_pascals_triangle() {
        let expected = [
            [0.0, 1.0, 1.0, 1.0, 1.0, 1.0],
            [0.0, 0.0, 2.0, 3.0, 4.0, 5.0],
            [0.0, 0.0, 0.0, 3.0, 6.0, 10.0],
            [0.0, 0.0, 0.0, 0.0, 4.0, 10.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 5.0],
            [0.0; GEAR_VALUES],
        ];
        assert_eq!(PREDICTOR, expected);
    }
}
