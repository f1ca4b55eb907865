//! talus: 2D granular dynamics (DEM) of disks, convex polygons and rods: a GPU path
//! (WGSL kernels on wgpu, `gpu`) and a CPU reference path in f64 (`cpu`, `sim`) that it
//! is tested against.
//!
//! The modules are layers, lowest first (ARCHITECTURE.md, "Modules"; held by
//! tests/architecture.rs `LAYERS`, each naming only those before it): `base` (vectors,
//! rng, files, threads) → `shape` → `law` → `overlap` (contact geometry) → `state` (the
//! particles) → `integrate` → `scene` → `cpu` (the CPU path's stages) → `create` → `sim`
//! (one step, in stage order) → `gpu` → `io` (snapshot and checkpoint formats) →
//! `analyze` → `render` → `reproduce` → `run` (the run loop) → `sweep` → `bench`.
//!
//! The step is a sequence of stages: predict → cell list → neighbour list → contact
//! forces → reduce → correct → boundaries, each a function on the CPU path with a WGSL
//! kernel of the same name on the GPU path. Scenes are JSON files (`scene`), runs are
//! driven by `run`; the command line (clap) lives in the binary (`src/cli/`).

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
