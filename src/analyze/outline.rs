//! The heap's outline: base, top, apex and width, with and without the grains that
//! rolled away from it (the frame every other measure of a heap is taken in).

use super::input::Grain;

#[derive(Clone, Debug, serde::Serialize)]
pub struct Outline {
    pub base: f64,
    pub top: f64,
    pub height: f64,
    pub left: f64,
    pub right: f64,
    pub width: f64,
    pub apex_x: f64,
}

/// The outline of the heap: base the lowest bottom of any grain (a fixed base row
/// included), top, apex, left and right from the mobile grains (a fixed base row wider
/// than the heap does not widen it); all grains when every grain is fixed.
pub fn outline(grains: &[Grain]) -> Outline {
    let any_mobile = grains.iter().any(|g| !g.fixed);
    let mut o = Outline {
        base: f64::INFINITY,
        top: f64::NEG_INFINITY,
        height: 0.0,
        left: f64::INFINITY,
        right: f64::NEG_INFINITY,
        width: 0.0,
        apex_x: 0.0,
    };
    for g in grains {
        o.base = o.base.min(g.bottom());
        if any_mobile && g.fixed {
            continue;
        }
        if g.top() > o.top {
            o.top = g.top();
            o.apex_x = g.x;
        }
        o.left = o.left.min(g.x - g.radius);
        o.right = o.right.max(g.x + g.radius);
    }
    o.height = o.top - o.base;
    o.width = o.right - o.left;
    o
}

/// The outline without the grains that rolled away: from the apex outwards the heap
/// ends where, over `d`-wide bins, the material is less than `1.5 d` high for more than
/// two bins in a row. Grains lying singly on the floor beyond the toe (one diameter
/// high) are then outside the outline, and no longer stretch X = x/l.
pub fn trimmed(grains: &[Grain], d: f64) -> Outline {
    let mut o = outline(grains);
    let any_mobile = grains.iter().any(|g| !g.fixed);
    let n = (o.width / d).ceil().max(1.0) as usize;
    let mut top = vec![f64::NEG_INFINITY; n];
    for g in grains.iter().filter(|g| !(any_mobile && g.fixed)) {
        let b = (((g.x - o.left) / d).floor().max(0.0) as usize).min(n - 1);
        top[b] = top[b].max(g.top());
    }
    let tall = |b: usize| top[b] - o.base >= 1.5 * d;
    let apex = (((o.apex_x - o.left) / d).floor().max(0.0) as usize).min(n - 1);
    let walk = |step: i64| {
        let (mut edge, mut gap, mut b) = (apex as i64, 0, apex as i64);
        while b >= 0 && (b as usize) < n && gap <= 2 {
            if tall(b as usize) {
                edge = b;
                gap = 0;
            } else {
                gap += 1;
            }
            b += step;
        }
        edge as usize
    };
    let (lo, hi) = (walk(-1), walk(1));
    let (left, right) = (o.left + lo as f64 * d, o.left + (hi + 1) as f64 * d);
    // The exact extents of the grains inside those bins.
    let (mut l, mut r) = (f64::INFINITY, f64::NEG_INFINITY);
    for g in grains.iter().filter(|g| !(any_mobile && g.fixed)) {
        if g.x >= left && g.x < right {
            l = l.min(g.x - g.radius);
            r = r.max(g.x + g.radius);
        }
    }
    if r > l {
        o.left = l;
        o.right = r;
        o.width = r - l;
    }
    o
}
