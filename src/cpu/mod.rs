//! The CPU path's stages of a step, in f64 on every core: the cell list (`cell_list`),
//! the neighbour lists of candidate pairs (`neighbours`), the contacts they hold
//! (`contacts`) with their tangential springs (`springs`), the polygons' corners at the
//! step's orientations (`orientation`) and the contact forces with their per-particle
//! sums (`forces`). Each stage has a WGSL twin of the same name (shaders/README.md).

pub mod cell_list;
pub mod contacts;
pub mod forces;
pub mod neighbours;
pub mod orientation;
pub mod springs;
