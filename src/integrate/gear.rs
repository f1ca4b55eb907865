//! 5th-order Gear predictor–corrector with six values per degree of freedom (Allen &
//! Tildesley, *Computer Simulation of Liquids*, sec. 3.2 and app. E; SPEC 3).
//!
//! The state holds scaled derivatives q_k = (dt^k/k!) d^k r/dt^k, k = 0..5. `predict`
//! is a Taylor step (Pascal's triangle); forces are evaluated at the predicted positions
//! *and velocities*; `correct` adds c_k · Δ to each value, with Δ = (dt²/2) a − q2_pred.
//! Our forces depend on velocities (damping, tangential springs), so c0 = 3/20 — the
//! variant Allen & Tildesley give for velocity-dependent forces — instead of 3/16.

use crate::state::{Dof, GEAR_VALUES, Particles};

/// Corrector coefficients for second-order equations, velocity-dependent forces.
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

/// Taylor predictor for one particle: q_k += Σ_{l>k} C(l, k) q_l.
pub fn predict_one(q: &mut [Dof; GEAR_VALUES]) {
    for d in 0..3 {
        q[0][d] += q[1][d] + q[2][d] + q[3][d] + q[4][d] + q[5][d];
        q[1][d] += 2.0 * q[2][d] + 3.0 * q[3][d] + 4.0 * q[4][d] + 5.0 * q[5][d];
        q[2][d] += 3.0 * q[3][d] + 6.0 * q[4][d] + 10.0 * q[5][d];
        q[3][d] += 4.0 * q[4][d] + 10.0 * q[5][d];
        q[4][d] += 5.0 * q[5][d];
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
    crate::parallel::for_each6(q, |i, v| {
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
    crate::parallel::for_each6(q, |i, v| {
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
