//! talus: 2D granular dynamics (DEM) of disks: a GPU path (WGSL kernels on wgpu, `gpu`)
//! and a CPU reference path in f64 that it is tested against.
//!
//! The step is a sequence of stages (see ARCHITECTURE.md): predict → cell list
//! (`cell_index`, `cell_histogram`, `prefix_sum`, `scatter`) → `find_contacts` →
//! `gather_history` → `contact_forces` → `store_history` → `reduce_forces` → correct →
//! boundaries on the GPU; the CPU path finds the same contacts among the candidates of
//! its neighbour lists (`neighbours`) and runs on every core (`parallel`). Scenes are
//! JSON files (`scene`), runs are driven by `run`.

pub mod analyze;
pub mod bench;
pub mod cell_list;
pub mod checkpoint;
pub mod contacts;
pub mod create;
pub mod files;
pub mod forces;
pub mod geometry;
pub mod gpu;
pub mod integrate;
pub mod law;
pub mod neighbours;
pub mod overlap;
pub mod parallel;
pub mod progress;
pub mod provenance;
pub mod render;
pub mod reproduce;
pub mod rng;
pub mod run;
pub mod scene;
pub mod shape;
pub mod sim;
pub mod snapshot;
pub mod spheropolygon;
pub mod springs;
pub mod state;
pub mod sweep;
pub mod team;
