//! `Params`, the uniform every kernel reads: the run's sizes, step, gravity, domain and
//! the contact law's parameters.

use super::*;

/// Law coefficients into Params (also for the tests that run laws.wgsl on its own).
pub fn law_params(law: &ContactLaw, p: &mut Params) {
    match law {
        ContactLaw::SpringDashpot(l) => {
            p.law = LAW_SPRING_DASHPOT;
            p.k_n = l.k_n as f32;
            p.nu = l.nu as f32;
            p.psi = l.psi as f32;
            p.delta0 = l.delta0 as f32;
            p.gamma_n = l.gamma_n as f32;
            p.k_t = l.k_t as f32;
            p.gamma_t = l.gamma_t as f32;
            p.mu = l.mu as f32;
            p.clamp = l.clamp as u32;
        }
        ContactLaw::OverlapArea(l) => {
            // η^n and η^t travel in gamma_n and gamma_t (common.wgsl).
            p.law = LAW_AREA;
            p.k_n = l.k_n as f32;
            p.k_t = l.k_t as f32;
            p.mu = l.mu as f32;
            p.gamma_n = l.eta_n as f32;
            p.gamma_t = l.eta_t as f32;
            p.clamp = 1;
        }
        ContactLaw::HertzCohesive(l) => {
            // γ^N, γ^T are rates: the kernels multiply them by the reduced mass.
            p.law = LAW_HERTZ;
            p.k_n = l.k_n as f32;
            p.k_t = l.k_t as f32;
            p.gamma_n = l.gamma_n as f32;
            p.gamma_t = l.gamma_t as f32;
            p.mu = l.mu as f32;
            p.bond_g = l.bond_g as f32;
            p.d_c = l.d_c as f32;
        }
        ContactLaw::Continuous(c) => {
            p.law = LAW_CONTINUOUS;
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
        }
    }
}

/// The parameters of a run on the device: the grid, the sizes of the buffers and of the
/// prefix sum's levels, the step, gravity, the domain, the fixed-point unit, the skin
/// and the contact law.
pub(super) fn step_params(
    sim: &Simulation,
    grid: &crate::cell_list::Grid,
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
        table_mask: (table_capacity(n_cap as u64) - 1) as u32,
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
        ..Default::default()
    };
    law_params(law, &mut params);
    params
}
