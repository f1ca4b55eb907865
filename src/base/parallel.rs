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

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Below this many items a stage runs on the calling thread (1024 unless a test lowers
/// it to run small scenes on every thread).
static MIN_PARALLEL: AtomicUsize = AtomicUsize::new(1024);

/// Sets the smallest stage that runs on every thread (tests: 1, to split small scenes).
pub fn set_min_parallel(n: usize) {
    MIN_PARALLEL.store(n, Ordering::Relaxed);
}

/// The number of threads a stage of n items runs on (1: the calling thread alone).
fn threads_for(n: usize) -> usize {
    let t = rayon::current_num_threads();
    if n >= MIN_PARALLEL.load(Ordering::Relaxed) && t > 1 {
        t.min(n)
    } else {
        1
    }
}

/// Where the shares of n items split for `parts` threads: thread t takes
/// bounds[t]..bounds[t + 1], contiguous and of equal size to within one `align`, so that
/// a thread treats the same particles (and their pairs) in every stage.
fn bounds(n: usize, parts: usize, align: usize) -> Vec<usize> {
    let blocks = n.div_ceil(align);
    (0..=parts)
        .map(|t| (blocks * t / parts * align).min(n))
        .collect()
}

/// v cut at `bounds`, one share per thread (each behind a lock that only its thread takes).
fn shares<'a, T>(mut v: &'a mut [T], bounds: &[usize]) -> Vec<Mutex<&'a mut [T]>> {
    let mut out = Vec::with_capacity(bounds.len() - 1);
    for w in bounds.windows(2) {
        let (share, rest) = std::mem::take(&mut v).split_at_mut(w[1] - w[0]);
        out.push(Mutex::new(share));
        v = rest;
    }
    out
}

/// Share t of `shares` (taken by thread t only).
fn take<'b, 'a, T>(
    shares: &'b [Mutex<&'a mut [T]>],
    t: usize,
) -> std::sync::MutexGuard<'b, &'a mut [T]> {
    shares[t].lock().unwrap_or_else(|e| e.into_inner())
}

/// f(k, &mut v[k]) for every k.
pub fn for_each<T, F>(v: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut T) + Sync + Send,
{
    let parts = threads_for(v.len());
    let b = bounds(v.len(), parts, 1);
    let s = shares(v, &b);
    crate::base::team::run(parts, &|t| {
        for (m, x) in take(&s, t).iter_mut().enumerate() {
            f(b[t] + m, x);
        }
    });
}

/// f(k0, share) for each thread's contiguous share v[k0..k0 + share.len()] (all of v on
/// one thread for a small stage): for loops that walk their items with iterators, with
/// no call and no bounds check per item.
pub fn for_each_share<T, F>(v: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut [T]) + Sync + Send,
{
    let parts = threads_for(v.len());
    let b = bounds(v.len(), parts, 1);
    let s = shares(v, &b);
    crate::base::team::run(parts, &|t| f(b[t], &mut take(&s, t)));
}

/// f(k, &mut a[k], &mut b[k]) for every k (a and b of equal length).
pub fn for_each2<A, B, F>(a: &mut [A], b: &mut [B], f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut A, &mut B) + Sync + Send,
{
    for_each_block2(a, b, 1, |k, x, y| f(k, &mut x[0], &mut y[0]));
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
    let parts = threads_for(a.len());
    // Candidates differ in cost (a touching polygon pair is clipped, a distant one is
    // not), so each thread's share is cut into pieces: a thread takes its own in order,
    // then helps with what is left of the others'. Who computes a piece changes no
    // result.
    let pieces = if parts > 1 { PIECES } else { 1 };
    let bd = bounds(a.len(), parts * pieces, block);
    let (sa, sb) = (shares(a, &bd), shares(b, &bd));
    let next: Vec<AtomicUsize> = (0..parts).map(|t| AtomicUsize::new(t * pieces)).collect();
    crate::base::team::run(parts, &|t| {
        for owner in (0..parts).map(|o| (t + o) % parts) {
            loop {
                let k = next[owner].fetch_add(1, Ordering::Relaxed);
                if k >= (owner + 1) * pieces {
                    break;
                }
                let (mut x, mut y) = (take(&sa, k), take(&sb, k));
                for (m, (x, y)) in x.chunks_mut(block).zip(y.chunks_mut(block)).enumerate() {
                    f(bd[k] + m * block, x, y);
                }
            }
        }
    });
}

/// Pieces per thread of a stage over candidates (`for_each_block2`).
const PIECES: usize = 8;

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
    let n = v[0].len();
    assert!(v.iter().all(|q| q.len() == n));
    assert_eq!(w.len(), n);
    assert_eq!(x.len(), n);
    let parts = threads_for(n);
    let b = bounds(n, parts, 1);
    let q = v.each_mut().map(|q| shares(q, &b));
    let (sw, sx) = (shares(w, &b), shares(x, &b));
    crate::base::team::run(parts, &|t| {
        let mut g = [0, 1, 2, 3, 4, 5].map(|d| take(&q[d], t));
        let (mut w, mut x) = (take(&sw, t), take(&sx, t));
        let [a, b1, c, d, e, h] = &mut g;
        let rows = (a.iter_mut())
            .zip(b1.iter_mut())
            .zip(c.iter_mut())
            .zip(d.iter_mut())
            .zip(e.iter_mut())
            .zip(h.iter_mut())
            .zip(w.iter_mut())
            .zip(x.iter_mut());
        for (m, (((((((q0, q1), q2), q3), q4), q5), y), z)) in rows.enumerate() {
            f(b[t] + m, [q0, q1, q2, q3, q4, q5], y, z);
        }
    });
}

/// The first k in 0..n for which f(k) holds (the same k whatever the thread count).
pub fn position_first<F>(n: usize, f: F) -> Option<usize>
where
    F: Fn(usize) -> bool + Sync + Send,
{
    let parts = threads_for(n);
    let b = bounds(n, parts, 1);
    let hits: Vec<Mutex<Option<usize>>> = (0..parts).map(|_| Mutex::new(None)).collect();
    crate::base::team::run(parts, &|t| {
        *take_slot(&hits, t) = (b[t]..b[t + 1]).find(|&k| f(k));
    });
    hits.into_iter()
        .find_map(|h| h.into_inner().unwrap_or_else(|e| e.into_inner()))
}

/// [f(0), …, f(n − 1)], in order.
pub fn map<T, F>(n: usize, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize) -> T + Sync + Send,
{
    let parts = threads_for(n);
    if parts == 1 {
        return (0..n).map(f).collect();
    }
    let b = bounds(n, parts, 1);
    let out: Vec<Mutex<Vec<T>>> = (0..parts).map(|_| Mutex::new(Vec::new())).collect();
    crate::base::team::run(parts, &|t| {
        *take_slot(&out, t) = (b[t]..b[t + 1]).map(&f).collect();
    });
    let mut all = Vec::with_capacity(n);
    for o in out {
        all.append(&mut o.into_inner().unwrap_or_else(|e| e.into_inner()));
    }
    all
}

fn take_slot<T>(slots: &[Mutex<T>], t: usize) -> std::sync::MutexGuard<'_, T> {
    slots[t].lock().unwrap_or_else(|e| e.into_inner())
}

/// Sorts v (unstable: for keys that are all different, the order is the same either way).
pub fn sort_unstable<T: Ord + Send>(v: &mut [T]) {
    if threads_for(v.len()) > 1 {
        v.par_sort_unstable();
    } else {
        v.sort_unstable();
    }
}
