//! Sutherland–Hodgman clipping of a convex polygon by half-planes, corners tagged by the
//! line of their outgoing edge: what a polygon against a wall needs (`wall.rs`; the
//! twin of the wall's cut in shaders/polygon.wgsl) and polygon–disk's deep overlaps.

use super::dot;
use super::sub;
use crate::shape::{MAX_CORNERS, P2};
use std::cell::RefCell;

/// Most corners an overlap polygon can have: each clipping half-plane adds at most one.
pub const MAX_CLIP: usize = 2 * MAX_CORNERS as usize + 4;

/// Line ids of the clipping: edge m of p (corner m to m + 1) is m, edge m of q is
/// `Q_LINE + m`; then a wall's line and the lines across its two ends (as in
/// polygon.wgsl).
pub const Q_LINE: u32 = MAX_CORNERS;
pub const WALL_LINE: u32 = 2 * MAX_CORNERS;
pub const END_A_LINE: u32 = WALL_LINE + 1;
pub const END_B_LINE: u32 = WALL_LINE + 2;

/// A convex polygon being clipped, on the stack (the overlap is computed for every
/// contact every step; no allocation): its corners and, for each, the line of its
/// outgoing edge (corner k to k + 1).
#[derive(Clone, Copy, Debug)]
pub struct Clip {
    pub n: usize,
    pub v: [P2; MAX_CLIP],
    pub line: [u32; MAX_CLIP],
}

impl Default for Clip {
    fn default() -> Self {
        Self {
            n: 0,
            v: [[0.0; 2]; MAX_CLIP],
            line: [0; MAX_CLIP],
        }
    }
}

thread_local! {
    /// Scratch polygons for the clipping, one set per thread: the overlap of every
    /// contact is computed every step, and zeroing fresh 36-corner buffers each time
    /// cost as much as the clipping itself.
    static SCRATCH: RefCell<[Clip; 3]> = RefCell::new([Clip::default(); 3]);
}

/// Runs f with this thread's scratch polygons.
pub(super) fn with_scratch<R>(f: impl FnOnce(&mut [Clip; 3]) -> R) -> R {
    SCRATCH.with(|s| f(&mut s.borrow_mut()))
}

impl Clip {
    /// Becomes a polygon's outline: edge k on line `first_line + k`.
    pub(super) fn set_outline(&mut self, p: &[P2], first_line: u32) {
        self.n = 0;
        for (k, x) in p.iter().enumerate() {
            self.push(*x, first_line + k as u32);
        }
    }

    pub fn corners(&self) -> &[P2] {
        &self.v[..self.n]
    }

    /// The lines of the edges into and out of corner k.
    pub(super) fn lines_at(&self, k: usize) -> (u32, u32) {
        let before = if k == 0 { self.n - 1 } else { k - 1 };
        (self.line[before], self.line[k])
    }

    pub(super) fn push(&mut self, x: P2, line: u32) {
        self.v[self.n] = x;
        self.line[self.n] = line;
        self.n += 1;
    }
}

/// One Sutherland–Hodgman step (`clip_lines` in polygon.wgsl): the part of `src` in
/// the half-plane {x : (x − a)·m ≥ 0}, whose boundary is line `id`. Leaving the
/// half-plane the outline follows the clip line, entering it the edge it was on.
pub(super) fn clip_lines(src: &Clip, a: P2, m: P2, id: u32, dst: &mut Clip) {
    dst.n = 0;
    let n = src.n;
    if n == 0 {
        return;
    }
    let side = |x: P2| dot(sub(x, a), m);
    // Edge e runs from corner e to the next, the last back to the first (no modulo: an
    // integer division for every corner of every clip cost more than the clip). Each
    // corner's side is computed once and carried to the next edge (the kernel computes
    // it twice; the values are the same).
    let first = side(src.v[0]);
    let mut dx = first;
    for e in 0..n {
        let x = src.v[e];
        let (y, dy) = if e + 1 == n {
            (src.v[0], first)
        } else {
            (src.v[e + 1], side(src.v[e + 1]))
        };
        if dx >= 0.0 {
            dst.push(x, src.line[e]);
        }
        if (dx >= 0.0) != (dy >= 0.0) {
            let t = dx / (dx - dy);
            let at = [x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])];
            dst.push(at, if dx >= 0.0 { id } else { src.line[e] });
        }
        dx = dy;
    }
}
