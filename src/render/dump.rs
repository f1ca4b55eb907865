//! A LAMMPS-style text dump of a snapshot's grains (`dump custom`'s layout), which
//! OVITO and most LAMMPS post-processing tools read: one frame, the simulation plane
//! x–z written as LAMMPS's x–y (z = 0), one line per grain. OVITO maps the columns by
//! name: `id`, `type`, `x y z`, `vx vy vz`, `radius`, `mass`, `omegaz` (angular
//! velocity), `fx fy fz` and `tqz` (the net contact force and torque), `quatw quati
//! quatj quatk` (the orientation, a rotation by θ about z); the rest are talus's
//! (`theta`, `fixed`, `contacts`, `pressure`). A run's series (`output.dump`) is one
//! file per snapshot, which OVITO loads with the wildcard `snap_*.dump`.
//!
//! Values are printed in Rust's shortest round-trip form, so the dump holds the
//! snapshot's f64 values exactly.

use super::RenderError;
use crate::analyze::Analysis;
use crate::base::files::write_atomic;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The columns of the `ITEM: ATOMS` line, in order.
pub const COLUMNS: &str = "id type x y z vx vy vz radius mass omegaz fx fy fz tqz \
                           quatw quati quatj quatk theta fixed contacts pressure";

/// A grain's `type`: 1 a disk, 2 a polygon or rod (LAMMPS numbers types from 1).
fn kind(corners: usize) -> u32 {
    if corners < 3 { 1 } else { 2 }
}

/// The dump of `a` as text.
pub fn text(a: &Analysis) -> String {
    let grains = &a.input.grains;
    let loads = super::vtk::net_loads(a);
    // The box: the grains' extent (LAMMPS's bounds of a finite, non-periodic box, `ff`).
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for g in grains {
        lo = [lo[0].min(g.left()), lo[1].min(g.bottom())];
        hi = [hi[0].max(g.right()), hi[1].max(g.top())];
    }
    if grains.is_empty() {
        (lo, hi) = ([0.0; 2], [0.0; 2]);
    }
    let mut s = String::with_capacity(160 * grains.len() + 256);
    let _ = write!(
        s,
        "ITEM: TIMESTEP\n{}\nITEM: TIME\n{}\nITEM: NUMBER OF ATOMS\n{}\n\
         ITEM: BOX BOUNDS ff ff ff\n{} {}\n{} {}\n-0.5 0.5\nITEM: ATOMS {COLUMNS}\n",
        a.input.step,
        a.input.time,
        grains.len(),
        lo[0],
        hi[0],
        lo[1],
        hi[1]
    );
    for (k, g) in grains.iter().enumerate() {
        let (force, torque) = loads[k];
        let (sin, cos) = (0.5 * g.theta).sin_cos();
        let (s1, s2, _) = a.moments[k].scaled(1.0 / g.area).principal();
        let _ = writeln!(
            s,
            "{} {} {} {} 0 {} {} 0 {} {} {} {} {} 0 {} {cos} 0 0 {sin} {} {} {} {}",
            g.id,
            kind(g.corners.len()),
            g.x,
            g.z,
            g.velocity[0],
            g.velocity[1],
            g.radius,
            g.mass,
            g.omega,
            force[0],
            force[1],
            torque,
            g.theta,
            g.fixed as u8,
            a.counts[k],
            0.5 * (s1 + s2),
        );
    }
    s
}

/// Writes `{prefix}grains.dump` into `dir`.
pub fn write_named(a: &Analysis, dir: &Path, prefix: &str) -> Result<PathBuf, RenderError> {
    let p = dir.join(format!("{prefix}grains.dump"));
    write_atomic(&p, text(a).as_bytes()).map_err(RenderError::write(&p))?;
    Ok(p)
}
