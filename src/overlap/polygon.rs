//! The overlap of two convex polygons (SPEC 2.3, paper 000 sec. 2.2): each one's edges
//! facing the other cut to the part inside it (`edges_inside`), the twin of
//! `polygon_polygon` in shaders/polygon.wgsl, step for step and name for name (issue 37
//! item 1).
//!
//! The overlap of two convex polygons is bounded by the parts of p's edges inside q and
//! the parts of q's edges inside p. Each edge is cut to the interval of it inside the
//! half-planes of the other polygon (Cyrus–Beck); an interval's ends are a corner or a
//! crossing of the outlines, known by the two edges that cross. Only the few edges that
//! face each other are cut (`facing_edges`): along the line of centres u (from i to j),
//! q lies beyond its nearest point, u·x ≥ l_q, and p short of its farthest, u·x ≤ h_p.
//! p's edges that reach beyond l_q form a chain whose ends cross that line, and inside
//! that slab p is the intersection of the chain's half-planes alone (a convex outline
//! crosses a line at most twice): so p's facing edges cut by q's facing half-planes
//! give every piece of p's outline inside q, and the other way round. h_p < l_q proves
//! the pair apart at once. A resting pair of 12-gons cuts three edges by three
//! half-planes, where Sutherland–Hodgman clipped all of p by half of q's edges, every
//! candidate, every step. Bit masks say which edges have a part inside, which parts
//! start or end at a crossing (and with which edge of the other, in nibbles), which
//! corners lie inside.
//!
//! Two crossings, p entering q at one and leaving it at the other (polygons resting on
//! each other), close the outline with the chain of q's corners between them, so q is
//! not cut in turn; nor is it when p lies inside q, or when none of p's outline lies in
//! q and q's first corner lies outside p (then they are apart: q inside p would put
//! every point of q there).
//!
//! The area is the sum of the pieces' triangles about the first piece's start, a point
//! of the overlap's outline, so no triangle is larger than the overlap is long times
//! deep: a sliver 1e-6 d deep keeps ~1e-10 of relative precision (issue 18). (The
//! kernel works in f32 and takes the area from exact integer distances from the contact
//! line instead; the f64 path needs no such care.)

use super::hint::{
    Chain, Hint, NO_BOX, Seen, below_floor, hold, rest, separated_by, separating_edge,
};
use super::outline::{Outline, along, bits, chord_frame};
use super::{AreaContact, dot, norm, pair_scale, reduced_arm, sub, unit_or_up};
use crate::base::geometry::cross;
use crate::shape::{MAX_CORNERS, P2};

const MAX: usize = MAX_CORNERS as usize;
use smallvec::SmallVec;

/// The part [t0, t1] of an edge x–y inside some half-planes (Cyrus–Beck): the lines it
/// enters and leaves by (their number + 1; 0: it starts at x, ends at y), whether x is
/// inside them all, and whether the edge lies wholly outside one.
#[derive(Clone, Copy, Debug)]
struct Cut {
    t0: f64,
    t1: f64,
    fin: u32,
    fout: u32,
    x_in: bool,
    empty: bool,
}

impl Cut {
    fn uncut() -> Self {
        Self {
            t0: 0.0,
            t1: 1.0,
            fin: 0,
            fout: 0,
            x_in: true,
            empty: false,
        }
    }

    /// Cuts by the half-plane (z − a)·m ≥ 0, line number `line`, where x and y lie at dx
    /// and dy (counter-clockwise outlines: inside is to the left of each edge).
    #[inline(always)]
    fn cut_by(&mut self, dx: f64, dy: f64, line: u32) {
        self.x_in &= dx >= 0.0;
        match (dx >= 0.0, dy >= 0.0) {
            (false, false) => self.empty = true,
            (false, true) => {
                let s = dx / (dx - dy);
                if s > self.t0 {
                    self.t0 = s;
                    self.fin = line + 1;
                }
            }
            (true, false) => {
                let s = dx / (dx - dy);
                if s < self.t1 {
                    self.t1 = s;
                    self.fout = line + 1;
                }
            }
            (true, true) => {}
        }
    }
}

/// Polygon a's edges inside polygon b. Bit e of `pieces`: part of edge e (corner e to the
/// next) lies in b; of `cross`, bit 2e: that part starts at a crossing with b's edge
/// nibble e of `entry` (else at corner e), bit 2e + 1: it ends at a crossing with b's
/// edge nibble e of `exit` (else at corner e + 1). Bit e of `corners`: corner e lies in
/// b; `sum` adds those corners up, `cross_sum` the crossings; `area2` is the pieces'
/// share of twice the area, about `o`; `span` the box of the pieces' ends.
#[derive(Clone, Copy, Debug)]
struct Inside {
    pieces: u32,
    cross: u32,
    entry: u64,
    exit: u64,
    corners: u32,
    sum: P2,
    cross_sum: P2,
    area2: f64,
    span: (P2, P2),
}

impl Default for Inside {
    fn default() -> Self {
        Self {
            pieces: 0,
            cross: 0,
            entry: 0,
            exit: 0,
            corners: 0,
            sum: [0.0; 2],
            cross_sum: [0.0; 2],
            area2: 0.0,
            span: NO_BOX,
        }
    }
}

fn nibble(v: u64, e: usize) -> usize {
    ((v >> (4 * e)) & 15) as usize
}

/// The pieces' triangles about o, the first piece's start (a point of the overlap's
/// outline), which `edges_inside` sets when it finds that piece.
#[inline(always)]
fn triangle2(o: &mut Option<P2>, s: P2, e: P2) -> f64 {
    let o = *o.get_or_insert(s);
    cross(sub(s, o), sub(e, o))
}

/// Each corner's reach along u, u·x, into `proj`; returns the largest (how far a
/// reaches along u).
#[inline(always)]
fn reaches(a: &Outline, u: P2, proj: &mut [f64; MAX]) -> f64 {
    // u·(v + base) = u·v + u·base: the base once.
    let shift = dot(a.base, u);
    let mut most = f64::NEG_INFINITY;
    for (x, v) in proj.iter_mut().zip(a.v) {
        *x = dot(*v, u) + shift;
        most = most.max(*x);
    }
    most
}

/// The edges of a that reach to the far side of the line u·x = t, {x : u·x ≥ t}, from
/// its corners' reaches along u: those with a corner there (every point of an edge
/// beyond it puts one of its ends there).
#[inline(always)]
fn facing_edges(n: usize, proj: &[f64; MAX], t: f64) -> u32 {
    let mut beyond = 0u32;
    for (k, x) in proj[..n].iter().enumerate() {
        beyond |= ((*x >= t) as u32) << k;
    }
    // Edge k runs from corner k to k + 1: it faces if either end is beyond.
    beyond | (beyond >> 1) | ((beyond & 1) << (n - 1))
}

/// Where edge e of a (x to y) crosses the line of b's edge f: its parameter from x, as
/// `edges_inside` cuts it (the same arithmetic, so the same point to the bit).
#[inline(always)]
pub(super) fn edge_cut(x: P2, y: P2, b: &Outline, f: usize) -> f64 {
    let (ba, m) = (b.at(f), b.normal(f));
    let (dx, dy) = (dot(sub(x, ba), m), dot(sub(y, ba), m));
    dx / (dx - dy)
}

/// `edges_inside` in polygon.wgsl: the parts of a's edges `a_edges` inside b, whose
/// half-planes `b_edges` are the only ones that can cut them.
fn edges_inside(
    a: &Outline,
    a_edges: u32,
    b: &Outline,
    b_edges: u32,
    o: &mut Option<P2>,
) -> Inside {
    let mut r = Inside::default();
    for e in bits(a_edges) {
        let x = a.at(e);
        let y = a.at(a.next_corner(e));
        // The part of x–y inside the half-planes (z − b_f)·m_f ≥ 0 of b.
        let mut cut = Cut::uncut();
        for f in bits(b_edges) {
            let (ba, m) = (b.at(f), b.normal(f));
            cut.cut_by(dot(sub(x, ba), m), dot(sub(y, ba), m), f as u32);
        }
        if cut.x_in {
            r.corners |= 1 << e;
            r.sum = [r.sum[0] + x[0], r.sum[1] + x[1]];
        }
        if !cut.empty && cut.t0 < cut.t1 {
            r.pieces |= 1 << e;
            let s = if cut.fin > 0 { along(x, y, cut.t0) } else { x };
            let t = if cut.fout > 0 { along(x, y, cut.t1) } else { y };
            r.area2 += triangle2(o, s, t);
            hold(&mut r.span, s);
            hold(&mut r.span, t);
            if cut.fin > 0 {
                r.cross |= 1 << (2 * e);
                r.entry |= ((cut.fin - 1) as u64) << (4 * e);
                r.cross_sum = [r.cross_sum[0] + s[0], r.cross_sum[1] + s[1]];
            }
            if cut.fout > 0 {
                r.cross |= 2 << (2 * e);
                r.exit |= ((cut.fout - 1) as u64) << (4 * e);
                r.cross_sum = [r.cross_sum[0] + t[0], r.cross_sum[1] + t[1]];
            }
        }
    }
    r
}

/// Crossing k of `in_p` (bit k of `cross`): p's edge and q's edge that cross there.
fn crossing_edges(in_p: &Inside, k: usize) -> (usize, usize) {
    let e = k >> 1;
    (
        e,
        nibble(if k & 1 == 1 { in_p.exit } else { in_p.entry }, e),
    )
}

/// Crossing k of `in_p`, the same point to the bit as `edges_inside` found it.
fn crossing_at(p: &Outline, q: &Outline, in_p: &Inside, k: usize) -> P2 {
    let (e, f) = crossing_edges(in_p, k);
    let (x, y) = (p.at(e), p.at(p.next_corner(e)));
    along(x, y, edge_cut(x, y, q, f))
}

/// Area contact of polygon p (particle i) with polygon q (particle j), each given by its
/// outline in a frame at i's centre (q's `base` = −d, d = r_i − r_j). None when the
/// outlines do not overlap.
pub fn polygon_polygon_of(p: &Outline, q: &Outline, d: P2) -> Option<AreaContact> {
    polygon_polygon_hinted(p, q, d, Hint::NONE).0
}

/// [`polygon_polygon_of`] starting from what the pair's last evaluation found (`hint`,
/// src/overlap/hint.rs): the same result to the bit, whatever the hint, and the hint for
/// the next step.
pub fn polygon_polygon_hinted(
    p: &Outline,
    q: &Outline,
    d: P2,
    hint: Hint,
) -> (Option<AreaContact>, Hint) {
    match hint.seen() {
        Seen::Apart { of_q, edge, corner } => {
            let (a, b) = if of_q { (q, p) } else { (p, q) };
            let mut corner = corner;
            if edge < a.v.len() && separated_by(a, edge, b, &mut corner) {
                return (None, Hint::apart(of_q, edge, corner));
            }
        }
        Seen::Resting(c) => {
            if let Some(contact) = rest(p, q, d, c) {
                return (contact, hint);
            }
        }
        Seen::Nothing => {}
    }
    cut_out(p, q, d)
}

/// The overlap from no hint: the facing edges cut by each other's half-planes.
#[inline(never)]
fn cut_out(p: &Outline, q: &Outline, d: P2) -> (Option<AreaContact>, Hint) {
    // The slab between them along the line of centres (any direction would do; this
    // one makes it narrow): q lies beyond l_q, p short of h_p.
    let u = unit_or_up([-d[0], -d[1]]);
    let (mut reach_p, mut reach_q) = ([0.0; MAX], [0.0; MAX]);
    let h_p = reaches(p, u, &mut reach_p);
    let l_q = -reaches(q, [-u[0], -u[1]], &mut reach_q);
    // Room for the projections' rounding: an edge kept needlessly is cut to nothing.
    let room = 1e-9 * (h_p.abs() + l_q.abs());
    let p_edges = facing_edges(p.v.len(), &reach_p, l_q - room);
    let q_edges = facing_edges(q.v.len(), &reach_q, -(h_p + room));
    // What proves them apart next time: an edge at the corner of either that reaches
    // farthest towards the other, if its line separates them.
    let apart = || {
        let at_most = |reach: &[f64; MAX], n: usize, most: f64| {
            let k = reach[..n].iter().position(|&x| x == most).unwrap_or(0);
            1u32 << k | 1u32 << (if k == 0 { n - 1 } else { k - 1 })
        };
        let (np, nq) = (p.v.len(), q.v.len());
        separating_edge(p, at_most(&reach_p, np, h_p), q)
            .map(|(k, c)| Hint::apart(false, k, c))
            .or_else(|| {
                separating_edge(q, at_most(&reach_q, nq, -l_q), p)
                    .map(|(k, c)| Hint::apart(true, k, c))
            })
            .unwrap_or(Hint::NONE)
    };
    if h_p < l_q - room {
        return (None, apart());
    }
    let mut o = None;
    let in_p = edges_inside(p, p_edges, q, q_edges, &mut o);
    let n_x = in_p.cross.count_ones();
    // Two crossings, p entering q at one and leaving it at the other: q's part of the
    // overlap's outline is the chain of q's edges from where p leaves q to where it
    // enters it again, and q's own cut is not needed. Nor is it when p lies inside q (no
    // crossing, p's edges inside), nor when none of p's outline lies in q and q's first
    // corner is outside p. Otherwise it is: more crossings, or q inside p.
    let entries = in_p.cross & 0x5555_5555;
    let exits = in_p.cross & 0xAAAA_AAAA;
    // Resting on each other: an entry and an exit that make the overlap's whole outline
    // (hint.rs `certify`; at most one pair can). Its contact comes from the chain alone,
    // as from a hint.
    for k_in in bits(entries) {
        for k_out in bits(exits) {
            let c = Chain {
                e_in: k_in >> 1,
                f_in: crossing_edges(&in_p, k_in).1,
                e_out: k_out >> 1,
                f_out: crossing_edges(&in_p, k_out).1,
            };
            if let Some(contact) = rest(p, q, d, c) {
                return (contact, Hint::resting(c));
            }
        }
    }
    let chained = entries.count_ones() == 1 && exits.count_ones() == 1;
    let p_inside = n_x == 0 && in_p.pieces != 0;
    let run_q = !chained && !p_inside && (in_p.pieces != 0 || p.contains(q.at(0)));
    let in_q = if run_q {
        edges_inside(q, q_edges, p, p_edges, &mut o)
    } else {
        Inside::default()
    };
    if in_p.pieces == 0 && in_q.pieces == 0 {
        return (None, apart());
    }
    // The crossings (two, resting on each other; more only for nearly parallel edges or
    // a deep overlap).
    let xs: SmallVec<[(usize, P2); 4]> = bits(in_p.cross)
        .map(|k| (k, crossing_at(p, q, &in_p, k)))
        .collect();
    let x_of = |k: usize| xs.iter().find(|x| x.0 == k).map_or([0.0; 2], |x| x.1);
    // The chain: q's corners g_out + 1 … g_in, from the crossing out of q (on q's edge
    // g_out) to the one into it (on q's edge g_in); on one edge, none, or all of q's if
    // the crossings follow each other the other way round it.
    let nq = q.v.len();
    let (k_in, k_out) = (
        entries.trailing_zeros() as usize,
        exits.trailing_zeros() as usize,
    );
    let (mut links, mut g_out) = (0, 0);
    if chained {
        let g_in = crossing_edges(&in_p, k_in).1;
        g_out = crossing_edges(&in_p, k_out).1;
        links = if g_in >= g_out {
            g_in - g_out
        } else {
            g_in + nq - g_out
        };
        if g_in == g_out {
            let along_q = sub(q.at(q.next_corner(g_in)), q.at(g_in));
            if dot(sub(x_of(k_in), x_of(k_out)), along_q) < 0.0 {
                links = nq;
            }
        }
    }
    // The chain's corners, their sum and their pieces' triangles, from the crossing out
    // of q to the one into it.
    let (mut chain_sum, mut chain2) = ([0.0; 2], 0.0);
    let mut span = NO_BOX;
    for b in [in_p.span, in_q.span] {
        span = (
            [span.0[0].min(b.0[0]), span.0[1].min(b.0[1])],
            [span.1[0].max(b.1[0]), span.1[1].max(b.1[1])],
        );
    }
    if chained {
        let mut prev = x_of(k_out);
        let mut k = q.next_corner(g_out);
        for _ in 0..links {
            let x = q.at(k);
            hold(&mut span, x);
            chain_sum = [chain_sum[0] + x[0], chain_sum[1] + x[1]];
            chain2 += triangle2(&mut o, prev, x);
            prev = x;
            k = q.next_corner(k);
        }
        chain2 += triangle2(&mut o, prev, x_of(k_in));
    }
    let n_p = in_p.corners.count_ones();
    let (n_q, q_sum) = if chained {
        (links as u32, chain_sum)
    } else {
        (in_q.corners.count_ones(), in_q.sum)
    };
    if n_p + n_q + n_x < 3 {
        return (None, apart());
    }
    let scale = pair_scale(p, q, d);
    // The two crossings farthest apart (more than two: nearly parallel edges; they span
    // the thin overlap along its length).
    let (mut best, mut xa, mut xb) = (-1.0, [0.0; 2], [0.0; 2]);
    for (a, &(_, pa)) in xs.iter().enumerate() {
        for &(_, pb) in &xs[a + 1..] {
            let e = sub(pb, pa);
            if dot(e, e) > best {
                (best, xa, xb) = (dot(e, e), pa, pb);
            }
        }
    }
    let (np, nq) = (n_p as f64, n_q as f64);
    let (n, point, chord) = match chord_frame(xa, xb, (in_p.sum, np), (q_sum, nq), d, scale) {
        Some(frame) if best >= 0.0 => frame,
        _ => {
            // Fewer than two crossings or a vanishing chord: n along the centres, S at
            // the mean of the overlap's corners.
            let k = (n_p + n_q + n_x) as f64;
            let s = [
                (in_p.sum[0] + q_sum[0] + in_p.cross_sum[0]) / k,
                (in_p.sum[1] + q_sum[1] + in_p.cross_sum[1]) / k,
            ];
            (unit_or_up(d), s, 0.0)
        }
    };
    let area2 = in_p.area2 + in_q.area2 + chain2;
    let area = 0.5 * area2;
    if below_floor(p, q, area, span) {
        return (None, apart());
    }
    // S − r_j = S + d.
    let l = reduced_arm(norm(point), norm([point[0] + d[0], point[1] + d[1]]), scale);
    let contact = AreaContact {
        area,
        n,
        arm: point,
        chord,
        l,
    };
    (Some(contact), Hint::NONE)
}

/// [`polygon_polygon_of`] for polygons given by their corners relative to their own
/// centres, d = r_i − r_j.
pub fn polygon_polygon(p: &[P2], q: &[P2], d: P2) -> Option<AreaContact> {
    let reach = |v: &[P2]| v.iter().map(|x| dot(*x, *x)).fold(0.0, f64::max).sqrt();
    let op = Outline {
        v: p,
        base: [0.0; 2],
        reach: reach(p),
    };
    let oq = Outline {
        v: q,
        base: [-d[0], -d[1]],
        reach: reach(q),
    };
    polygon_polygon_of(&op, &oq, d)
}
