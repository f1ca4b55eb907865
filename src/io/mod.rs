//! The file formats of a run's results: snapshots (`snapshot`, docs/FORMATS.md) and
//! checkpoints (`checkpoint`), each written to a temporary name and renamed.

pub mod checkpoint;
pub mod snapshot;
