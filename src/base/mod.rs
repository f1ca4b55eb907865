//! The foundation every layer stands on, depending on nothing else in the crate: vector
//! algebra (`geometry`), the random numbers (`rng`), atomic file writes (`files`),
//! progress lines (`progress`), what a result file says about its making (`provenance`)
//! and the CPU path's threads (`team`, driven through `parallel`).

pub mod files;
pub mod geometry;
pub mod parallel;
pub mod progress;
pub mod provenance;
pub mod rng;
pub mod team;
