//! The packing's structure: packing fraction against depth, the orientation
//! distribution f(θ) and the orientation correlation Q(r) = ⟨cos 2(θ_i − θ_j)⟩ at
//! distance r (SPEC 5, paper 004 sec. 3).

use super::input::Grain;
use super::outline::Outline;

/// One horizontal layer: its middle height, depth below the top, the width it spans
/// (inside a margin from the outermost grains) and the packing fraction there.
#[derive(Clone, Debug)]
pub struct Layer {
    pub z: f64,
    pub depth: f64,
    pub width: f64,
    pub grains: usize,
    pub fraction: f64,
}

/// Packing fraction in layers of height `dz`: the area of the grains centred in a
/// layer over the layer's area, between the outermost centres in it shrunk by `margin`
/// on each side (so that the ragged outline does not count as empty space). A grain's
/// area counts in the layer of its centre, so layers should hold many grains (or, on a
/// lattice, whole rows).
pub fn packing(grains: &[Grain], o: &Outline, dz: f64, margin: f64) -> Vec<Layer> {
    let rows = (o.height / dz).ceil().max(1.0) as usize;
    let mut out = Vec::new();
    for r in 0..rows {
        let (lo, hi) = (o.base + r as f64 * dz, o.base + (r + 1) as f64 * dz);
        let members: Vec<&Grain> = grains.iter().filter(|g| g.z >= lo && g.z < hi).collect();
        if members.is_empty() {
            continue;
        }
        let left = members.iter().map(|g| g.x).fold(f64::INFINITY, f64::min) + margin;
        let right = members
            .iter()
            .map(|g| g.x)
            .fold(f64::NEG_INFINITY, f64::max)
            - margin;
        if right <= left {
            continue;
        }
        // Half-open, so that a row of grains d apart counts one grain per d.
        let inner: Vec<&&Grain> = members
            .iter()
            .filter(|g| g.x >= left && g.x < right)
            .collect();
        let area: f64 = inner.iter().map(|g| g.area).sum();
        out.push(Layer {
            z: 0.5 * (lo + hi),
            depth: o.top - 0.5 * (lo + hi),
            width: right - left,
            grains: inner.len(),
            fraction: area / ((right - left) * dz),
        });
    }
    out
}

/// The direction of a polygon's long axis in [0, π), from the second moment of its
/// corners about its centre; None for a disk or a shape without a long axis (a regular
/// polygon, anisotropy below 1e-3).
pub fn long_axis(g: &Grain) -> Option<f64> {
    if g.corners.len() < 3 {
        return None;
    }
    let (mut sxx, mut sxz, mut szz) = (0.0, 0.0, 0.0);
    for c in &g.corners {
        let (dx, dz) = (c[0] - g.x, c[1] - g.z);
        sxx += dx * dx;
        sxz += dx * dz;
        szz += dz * dz;
    }
    let trace = sxx + szz;
    let spread = (0.5 * (sxx - szz)).hypot(sxz);
    if trace <= 0.0 || 2.0 * spread / trace < 1e-3 {
        return None;
    }
    Some((0.5 * (2.0 * sxz).atan2(sxx - szz)).rem_euclid(std::f64::consts::PI))
}

/// f(θ) over `bins` bins of [0, π), normalised so that its integral is 1, and the
/// number of grains that have a long axis.
pub fn orientation(axes: &[Option<f64>], bins: usize) -> (Vec<(f64, f64)>, usize) {
    let pi = std::f64::consts::PI;
    let width = pi / bins as f64;
    let mut h = vec![0usize; bins];
    let mut n = 0;
    for a in axes.iter().flatten() {
        h[((a / width) as usize).min(bins - 1)] += 1;
        n += 1;
    }
    let f = h
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            (
                (k as f64 + 0.5) * width,
                if n > 0 {
                    c as f64 / (n as f64 * width)
                } else {
                    0.0
                },
            )
        })
        .collect();
    (f, n)
}

/// Q(r) in bins of `bin` up to `r_max`: (r, Q, pairs); pairs found through a grid of
/// cells of size r_max.
pub fn orientation_correlation(
    grains: &[Grain],
    axes: &[Option<f64>],
    bin: f64,
    r_max: f64,
) -> Vec<(f64, f64, usize)> {
    let bins = (r_max / bin).ceil() as usize;
    let mut sum = vec![0.0; bins];
    let mut count = vec![0usize; bins];
    let with: Vec<(usize, f64)> = axes
        .iter()
        .enumerate()
        .filter_map(|(k, a)| a.map(|a| (k, a)))
        .collect();
    let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (m, &(k, _)) in with.iter().enumerate() {
        let key = (
            (grains[k].x / r_max).floor() as i64,
            (grains[k].z / r_max).floor() as i64,
        );
        cells.entry(key).or_default().push(m);
    }
    for (m, &(k, a)) in with.iter().enumerate() {
        let (cx, cz) = (
            (grains[k].x / r_max).floor() as i64,
            (grains[k].z / r_max).floor() as i64,
        );
        for dx in -1..=1 {
            for dz in -1..=1 {
                let Some(list) = cells.get(&(cx + dx, cz + dz)) else {
                    continue;
                };
                for &n in list {
                    if n <= m {
                        continue;
                    }
                    let (l, b) = with[n];
                    let r = (grains[k].x - grains[l].x).hypot(grains[k].z - grains[l].z);
                    if r < r_max {
                        let i = (r / bin) as usize;
                        sum[i] += (2.0 * (a - b)).cos();
                        count[i] += 1;
                    }
                }
            }
        }
    }
    (0..bins)
        .filter(|&i| count[i] > 0)
        .map(|i| ((i as f64 + 0.5) * bin, sum[i] / count[i] as f64, count[i]))
        .collect()
}
