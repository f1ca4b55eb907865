//! The engine a run drives: the CPU reference path or the GPU path, behind one face.

use crate::gpu::{DeviceState, GpuError, GpuSimulation};
use crate::sim::{Divergence, Simulation};

/// The path that advances the state: the CPU reference path or the GPU path. Outputs
/// always read the host `Simulation` (for the GPU, a mirror refreshed by `download`).
pub enum Engine {
    Cpu(Box<Simulation>),
    Gpu(Box<GpuSimulation>),
}

impl Engine {
    pub fn cpu(sim: Simulation) -> Self {
        Self::Cpu(Box::new(sim))
    }

    /// The host state and, on the GPU path, the exact device state: what a checkpoint
    /// holds (reads the device back on the GPU path; an error when it could not).
    pub fn checkpoint_state(&mut self) -> Result<(&Simulation, Option<&DeviceState>), GpuError> {
        match self {
            Self::Cpu(s) => Ok((s, None)),
            Self::Gpu(g) => {
                g.download();
                match g.failure() {
                    Some(e) => Err(e),
                    None => Ok(g.checkpoint_state()),
                }
            }
        }
    }

    pub fn name(&self) -> String {
        match self {
            Self::Cpu(_) => "cpu".into(),
            Self::Gpu(g) => format!("gpu ({})", g.adapter_name()),
        }
    }

    pub fn step(&self) -> u64 {
        match self {
            Self::Cpu(s) => s.step,
            Self::Gpu(g) => g.step(),
        }
    }

    /// Active particles now (no readback on the GPU).
    pub fn active_count(&self) -> u64 {
        match self {
            Self::Cpu(s) => s.particles.active_count() as u64,
            Self::Gpu(g) => g.active_count(),
        }
    }

    /// Active particles that move (not fixed), no readback on the GPU: what throughput
    /// counts.
    pub fn mobile_count(&self) -> u64 {
        match self {
            Self::Cpu(s) => s.particles.mobile_count() as u64,
            Self::Gpu(g) => g.mobile_count(),
        }
    }

    pub fn advance(&mut self, steps: u64) -> Result<(), Divergence> {
        match self {
            Self::Cpu(s) => s.advance(steps),
            Self::Gpu(g) => g.advance(steps),
        }
    }

    /// The host state, current (reads the device back on the GPU path): an error when
    /// the device could not be read, so that nothing is written from a failed readback.
    pub fn sim(&mut self) -> Result<&Simulation, GpuError> {
        match self {
            Self::Cpu(s) => Ok(s),
            Self::Gpu(g) => {
                g.download();
                match g.failure() {
                    Some(e) => Err(e),
                    None => Ok(&g.sim),
                }
            }
        }
    }

    /// Every particle's position in id order (on the GPU path the state alone is read
    /// back: observers that follow particles step by step).
    pub fn positions(&mut self) -> Vec<[f64; 2]> {
        match self {
            Self::Cpu(s) => (0..s.particles.len())
                .map(|i| s.particles.position(i))
                .collect(),
            Self::Gpu(g) => g.positions(),
        }
    }

    /// The host copy without a readback: scene, law and grid are always current.
    pub fn host(&self) -> &Simulation {
        match self {
            Self::Cpu(s) => s,
            Self::Gpu(g) => &g.sim,
        }
    }
}
