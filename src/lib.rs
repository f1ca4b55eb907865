//! talus: 2D granular dynamics (DEM) of disks: a GPU path (WGSL kernels on wgpu, `gpu`)
//! and a CPU reference path in f64 that it is tested against.
//!
//! The step is a sequence of stages (see ARCHITECTURE.md): predict → cell list
//! (`cell_index`, `cell_histogram`, `prefix_sum`, `scatter`) → `find_contacts` →
//! `gather_history` → `contact_forces` → `store_history` → `reduce_forces` → correct →
//! boundaries on the GPU; the CPU path finds the same contacts among the candidates of
//! its neighbour lists (`cpu::neighbours`) and runs on every core (`base::parallel`). Scenes are
//! JSON files (`scene`), runs are driven by `run`.

// The layers, lowest first (ARCHITECTURE.md): each depends only on those above it in
// this list, except for the import cycles tests/architecture.rs still lists (issue 42).
pub mod analyze;
pub mod base;
pub mod bench;
pub mod cpu;
pub mod create;
pub mod gpu;
pub mod integrate;
pub mod io;
pub mod law;
pub mod overlap;
pub mod render;
pub mod reproduce;
pub mod run;
pub mod scene;
pub mod shape;
pub mod sim;
pub mod state;
pub mod sweep;
