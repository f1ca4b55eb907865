//! Data parallelism of the CPU path (issue 13): the stages that treat each particle or
//! each candidate pair on its own run on every thread of the current rayon pool
//! (`--threads`, default all cores).
//!
//! Every item is computed by the same code from the same inputs whichever thread takes
//! it, and no stage sums across items in parallel (the force reduction sums each
//! particle's contacts on one thread, in a fixed order), so results are bitwise the same
//! for any thread count. Small stages stay on the calling thread: waking the pool costs
//! more than a thousand items.

use rayon::prelude::*;

use std::sync::atomic::{AtomicUsize, Ordering};

/// Below this many items a stage runs on the calling thread (1024 unless a test lowers
/// it to run small scenes on every thread).
static MIN_PARALLEL: AtomicUsize = AtomicUsize::new(1024);
/// Items per task: at most 512, fewer for a small stage so that every thread gets some.
fn chunk(n: usize) -> usize {
    (n / (8 * rayon::current_num_threads())).clamp(1, 512)
}

/// Sets the smallest stage that runs on every thread (tests: 1, to split small scenes).
pub fn set_min_parallel(n: usize) {
    MIN_PARALLEL.store(n, Ordering::Relaxed);
}

fn parallel(n: usize) -> bool {
    n >= MIN_PARALLEL.load(Ordering::Relaxed) && rayon::current_num_threads() > 1
}

/// f(k, &mut v[k]) for every k.
pub fn for_each<T, F>(v: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut T) + Sync + Send,
{
    if parallel(v.len()) {
        let c = chunk(v.len());
        v.par_iter_mut()
            .enumerate()
            .with_min_len(c)
            .for_each(|(k, x)| f(k, x));
    } else {
        v.iter_mut().enumerate().for_each(|(k, x)| f(k, x));
    }
}

/// f(k, &mut a[k], &mut b[k]) for every k (a and b of equal length).
pub fn for_each2<A, B, F>(a: &mut [A], b: &mut [B], f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut A, &mut B) + Sync + Send,
{
    assert_eq!(a.len(), b.len());
    if parallel(a.len()) {
        let c = chunk(a.len());
        a.par_iter_mut()
            .zip(b.par_iter_mut())
            .enumerate()
            .with_min_len(c)
            .for_each(|(k, (x, y))| f(k, x, y));
    } else {
        a.iter_mut()
            .zip(b.iter_mut())
            .enumerate()
            .for_each(|(k, (x, y))| f(k, x, y));
    }
}

/// f(k0, &mut a[k0..k0 + m], &mut b[k0..k0 + m]) for consecutive blocks of m ≤ `block`
/// items (a and b of equal length): for loops that treat a few items stage by stage.
pub fn for_each_block2<A, B, F>(a: &mut [A], b: &mut [B], block: usize, f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync + Send,
{
    assert_eq!(a.len(), b.len());
    if parallel(a.len()) {
        let c = chunk(a.len()).div_ceil(block);
        a.par_chunks_mut(block)
            .zip(b.par_chunks_mut(block))
            .enumerate()
            .with_min_len(c)
            .for_each(|(m, (x, y))| f(m * block, x, y));
    } else {
        for (m, (x, y)) in a.chunks_mut(block).zip(b.chunks_mut(block)).enumerate() {
            f(m * block, x, y);
        }
    }
}

/// f(k, [&mut v0[k], …, &mut v5[k]]) for every k: the six Gear values of a particle.
pub fn for_each6<T, F>(v: &mut [Vec<T>; 6], f: F)
where
    T: Send,
    F: Fn(usize, [&mut T; 6]) + Sync + Send,
{
    // A slice of () takes no memory.
    let mut none = vec![(); v[0].len()];
    for_each6_with(v, &mut none, |k, q, _| f(k, q));
}

/// f(k, [&mut v0[k], …, &mut v5[k]], &mut w[k]) for every k: a particle's six Gear
/// values and one more value of it.
pub fn for_each6_with<T, U, F>(v: &mut [Vec<T>; 6], w: &mut [U], f: F)
where
    T: Send,
    U: Send,
    F: Fn(usize, [&mut T; 6], &mut U) + Sync + Send,
{
    let mut none = vec![(); w.len()];
    for_each6_with2(v, w, &mut none, |k, q, y, _| f(k, q, y));
}

/// f(k, [&mut v0[k], …, &mut v5[k]], &mut w[k], &mut x[k]) for every k: a particle's six
/// Gear values and two more values of it.
pub fn for_each6_with2<T, U, V, F>(v: &mut [Vec<T>; 6], w: &mut [U], x: &mut [V], f: F)
where
    T: Send,
    U: Send,
    V: Send,
    F: Fn(usize, [&mut T; 6], &mut U, &mut V) + Sync + Send,
{
    let [a, b, c, d, e, g] = v;
    let n = a.len();
    assert_eq!(w.len(), n);
    assert_eq!(x.len(), n);
    if parallel(n) {
        a.par_iter_mut()
            .zip(b.par_iter_mut())
            .zip(c.par_iter_mut())
            .zip(d.par_iter_mut())
            .zip(e.par_iter_mut())
            .zip(g.par_iter_mut())
            .zip(w.par_iter_mut())
            .zip(x.par_iter_mut())
            .enumerate()
            .with_min_len(chunk(n))
            .for_each(|(k, (((((((q0, q1), q2), q3), q4), q5), y), z))| {
                f(k, [q0, q1, q2, q3, q4, q5], y, z)
            });
    } else {
        for (k, (((((((q0, q1), q2), q3), q4), q5), y), z)) in a
            .iter_mut()
            .zip(b.iter_mut())
            .zip(c.iter_mut())
            .zip(d.iter_mut())
            .zip(e.iter_mut())
            .zip(g.iter_mut())
            .zip(w.iter_mut())
            .zip(x.iter_mut())
            .enumerate()
        {
            f(k, [q0, q1, q2, q3, q4, q5], y, z);
        }
    }
}

/// The first k in 0..n for which f(k) holds (the same k whatever the thread count).
pub fn position_first<F>(n: usize, f: F) -> Option<usize>
where
    F: Fn(usize) -> bool + Sync + Send,
{
    if parallel(n) {
        // Each task scans its block on its own and the smallest hit wins: rayon's
        // position_first would synchronise on every item.
        let c = chunk(n);
        (0..n.div_ceil(c))
            .into_par_iter()
            .filter_map(|b| (b * c..n.min((b + 1) * c)).find(|&k| f(k)))
            .min()
    } else {
        (0..n).position(f)
    }
}

/// [f(0), …, f(n − 1)], in order.
pub fn map<T, F>(n: usize, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize) -> T + Sync + Send,
{
    if parallel(n) {
        (0..n)
            .into_par_iter()
            .with_min_len(chunk(n))
            .map(f)
            .collect()
    } else {
        (0..n).map(f).collect()
    }
}

/// Sorts v (unstable: for keys that are all different, the order is the same either way).
pub fn sort_unstable<T: Ord + Send>(v: &mut [T]) {
    if parallel(v.len()) {
        v.par_sort_unstable();
    } else {
        v.sort_unstable();
    }
}
