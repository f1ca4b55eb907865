//! `Params`, the uniform every kernel reads: the run's sizes, step, gravity, domain and
//! the contact law's parameters.

use super::*;

/// The law's id (`Params::law`, and `LAW` of the contact kernels' pipelines).
pub fn law_id(law: &ContactLaw) -> u32 {
    match law {
        ContactLaw::SpringDashpot(_) => LAW_SPRING_DASHPOT,
        ContactLaw::OverlapArea(_) => LAW_AREA,
        ContactLaw::HertzCohesive(_) => LAW_HERTZ,
        ContactLaw::Continuous(_) => LAW_CONTINUOUS,
    }
}

/// Law coefficients into Params (also for the tests that run laws.wgsl on its own).
pub fn law_params(law: &ContactLaw, p: &mut Params) {
    p.law = law_id(law);
    match law {
        ContactLaw::SpringDashpot(l) => {
            p.k_n = l.k_n as f32;
            p.nu = l.nu as f32;
            p.psi = l.psi as f32;
            p.delta0 = l.delta0 as f32;
            p.gamma_n = l.gamma_n as f32;
            p.k_t = l.k_t as f32;
            p.gamma_t = l.gamma_t as f32;
            p.mu = l.mu as f32;
            p.clamp = l.clamp as u32;
            pair_law(l, p);
        }
        ContactLaw::OverlapArea(l) => {
            // η^n and η^t travel in gamma_n and gamma_t (common.wgsl).
            p.k_n = l.k_n as f32;
            p.k_t = l.k_t as f32;
            p.mu = l.mu as f32;
            p.gamma_n = l.eta_n as f32;
            p.gamma_t = l.eta_t as f32;
            p.clamp = 1;
            fill_pairs(
                &ContactLaw::OverlapArea(l.clone()),
                l.pairs.as_ref(),
                p,
                || crate::law::restitution::PerMass {
                    k_n: l.k_n,
                    gamma_n: l.eta_n,
                    k_t: l.k_t,
                    gamma_t: l.eta_t,
                    mu: l.mu,
                },
            );
        }
        ContactLaw::HertzCohesive(l) => {
            // γ^N, γ^T are rates: the kernels multiply them by the reduced mass.
            p.k_n = l.k_n as f32;
            p.k_t = l.k_t as f32;
            p.gamma_n = l.gamma_n as f32;
            p.gamma_t = l.gamma_t as f32;
            p.mu = l.mu as f32;
            p.bond_g = l.bond_g as f32;
            p.d_c = l.d_c as f32;
        }
        ContactLaw::Continuous(c) => {
            match c.elastic {
                crate::law::continuous::Elastic::Power { n } => {
                    p.elastic = 0;
                    p.n_exp = n as f32;
                }
                crate::law::continuous::Elastic::Hooke { k } => {
                    p.elastic = 1;
                    p.hooke_k = k as f32;
                }
            }
            p.r0 = c.r0 as f32;
            p.mu = c.mu as f32;
            p.alpha = c.alpha as f32;
            p.damping_fraction = c.damping_fraction as f32;
            p.g_scale = c.g as f32;
            use crate::scene::{RollingArm, TangentialDamping, TangentialLimit};
            p.clamp = c.reading.clamp as u32;
            p.reading = match c.reading.damping {
                TangentialDamping::Centres => 0,
                TangentialDamping::Slip => layout::READING_SLIP_DAMPING,
            } | match c.reading.arm {
                RollingArm::CentreDistance => 0,
                RollingArm::ContactPoint => layout::READING_CONTACT_ARM,
            } | match c.reading.limit {
                TangentialLimit::Hold => 0,
                TangentialLimit::Slide => layout::READING_SLIDE,
                TangentialLimit::Accumulate => layout::READING_ACCUMULATE,
            };
        }
    }
}

/// The side of the pair table the GPU holds for a law: 1 when every pair has the same
/// coefficients (the stiffness form, or the material form without `pairs`), else the
/// materials and the walls; None when it is larger than the GPU's table. The rolling
/// resistance's table (`rolling_params`) may widen it to the same side.
pub fn gpu_pair_side(law: &ContactLaw) -> Option<usize> {
    let side = match law.pair_table() {
        Some(t) if t.coeffs.iter().any(|c| *c != t.coeffs[0]) => t.side,
        _ => 1,
    };
    (side * side <= MAX_PAIR_SLOTS).then_some(side)
}

/// The spring-dashpot law's coefficients into `Params.pair_law`.
fn pair_law(l: &crate::law::spring_dashpot::SpringDashpot, p: &mut Params) {
    fill_pairs(
        &ContactLaw::SpringDashpot(l.clone()),
        l.pairs.as_ref(),
        p,
        || crate::law::restitution::PerMass {
            k_n: l.k_n,
            gamma_n: l.gamma_n,
            k_t: l.k_t,
            gamma_t: l.gamma_t,
            mu: l.mu,
        },
    );
}

/// A law's pair table into `Params.pair_law` (`absolute`: its one entry in the stiffness
/// form).
fn fill_pairs(
    law: &ContactLaw,
    table: Option<&crate::law::restitution::PairTable>,
    p: &mut Params,
    absolute: impl Fn() -> crate::law::restitution::PerMass,
) {
    let side = gpu_pair_side(law).expect("checked when the run was set up (GpuSimulation)");
    p.pair_side = side as u32;
    let entry = |c: &crate::law::restitution::PerMass| {
        [
            [
                c.k_n as f32,
                c.gamma_n as f32,
                c.k_t as f32,
                c.gamma_t as f32,
            ],
            [c.mu as f32, 0.0, 0.0, 0.0],
        ]
    };
    match table {
        None => {
            p.per_mass = 0;
            let [a, b] = entry(&absolute());
            (p.pair_law[0], p.pair_law[1]) = (a, b);
        }
        Some(t) => {
            p.per_mass = 1;
            for a in 0..side {
                for b in 0..side {
                    // With one slot (side 1) every pair has the first pair's values.
                    let [x, y] = entry(&t.coeffs[a * t.side + b]);
                    let s = a * side + b;
                    (p.pair_law[2 * s], p.pair_law[2 * s + 1]) = (x, y);
                }
            }
        }
    }
}

/// The parameters of a run on the device: the grid, the sizes of the buffers and of the
/// prefix sum's levels, the step, gravity, the domain, the fixed-point unit, the skin
/// and the contact law.
pub(super) fn step_params(
    sim: &Simulation,
    grid: &crate::cpu::cell_list::Grid,
    n_cap: u32,
    cells: u64,
    n_sources: usize,
    cell_size: f32,
    skin: f64,
) -> Params {
    let law = &sim.law;
    let g = sim.scene.gravity.g;
    let ramp = sim.scene.gravity.ramp_time;
    let d = &sim.scene.domain;
    let blocks1 = ceil_div(cells, SCAN_WG as u64) as u32;
    let blocks2 = ceil_div(blocks1 as u64, SCAN_WG as u64) as u32;
    let dt = sim.dt();
    let origin = grid.origin;
    let mut params = Params {
        n_cap,
        nx: grid.nx,
        nz: grid.nz,
        cells: cells as u32,
        n_walls: sim.walls.len() as u32,
        n_sources: n_sources as u32,
        table_mask: (super::footprint::table_capacity(n_cap as u64) - 1) as u32,
        integrator: match sim.scene.integrator {
            IntegratorKind::Gear5 => 0,
            IntegratorKind::Leapfrog => 1,
        },
        cell_size,
        dt: dt as f32,
        max_overlap: sim.scene.limits.max_overlap as f32,
        range_factor: law.range_factor() as f32,
        gx: g[0] as f32,
        gz: g[1] as f32,
        ramp_steps: if ramp > 0.0 { (ramp / dt) as f32 } else { 0.0 },
        law: 0,
        dom_lo_x: (d.x[0] - origin[0]) as f32,
        dom_lo_z: (d.z[0] - origin[1]) as f32,
        dom_hi_x: (d.x[1] - origin[0]) as f32,
        dom_hi_z: (d.z[1] - origin[1]) as f32,
        scan_blocks1: blocks1,
        scan_blocks2: blocks2,
        scan_offset2: blocks1.next_multiple_of(SCAN_WG),
        unit: position::unit(cell_size) as f32,
        inv_unit: (1.0 / position::unit(cell_size)) as f32,
        skin: skin as f32,
        reorder: 1,
        list_cap: super::list_capacity(sim),
        max_step2: sim.scene.limits.max_step_displacement.powi(2) as f32,
        period_cells: if sim.scene.domain.periodic_x {
            grid.nx
        } else {
            0
        },
        ..Default::default()
    };
    law_params(law, &mut params);
    rolling_params(&sim.rolling, &mut params);
    params
}

/// The rolling resistance's table into `Params.pair_law[2s + 1].yzw`, on the slots of the
/// law's table: where the law has one entry and the rolling resistance a table, the
/// law's entry is copied into every slot first. `rolling_mu` and `rolling_k` get the
/// largest μ_r and spring k_roll, which choose the kernels' branches.
pub fn rolling_params(rolling: &crate::law::rolling::RollingTable, p: &mut Params) {
    let side = p.pair_side.max(1) as usize;
    let side = if rolling.side > side {
        let (a, b) = (p.pair_law[0], p.pair_law[1]);
        for s in 0..rolling.side * rolling.side {
            (p.pair_law[2 * s], p.pair_law[2 * s + 1]) = (a, b);
        }
        p.pair_side = rolling.side as u32;
        rolling.side
    } else {
        side
    };
    for a in 0..side as u32 {
        for b in 0..side as u32 {
            let r = rolling.get(a, b);
            let s = (a as usize) * side + b as usize;
            let k_roll = if r.has_spring() { r.k_roll } else { 0.0 };
            p.pair_law[2 * s + 1][1] = r.mu_r as f32;
            p.pair_law[2 * s + 1][2] = k_roll as f32;
            p.pair_law[2 * s + 1][3] = r.eta_r as f32;
            p.rolling_mu = p.rolling_mu.max(r.mu_r as f32);
            p.rolling_k = p.rolling_k.max(k_roll as f32);
        }
    }
}
