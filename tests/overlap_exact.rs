//! The polygon–polygon overlap (issue 37: `overlap::polygon_polygon_of`, the facing
//! edges cut by each other's half-planes) against the shoelace area of an exact clip in
//! rational arithmetic, on random pairs and on the configurations that break clipping
//! codes: parallel edges, shared corners, one polygon inside the other, spikes. And the
//! per-candidate hint (`overlap::Hint`): it never changes a result, to the bit, whether
//! it is last step's, a stale one, a random one or none.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive, Zero};
use talus::base::rng::Rng;
use talus::overlap::{AreaContact, Hint, Outline, Seen, THICKNESS_FLOOR, polygon_polygon_hinted};
use talus::shape::{P2, ellipse_polygon, rotate};

type Q = BigRational;

fn exact(x: f64) -> Q {
    Q::from_float(x).expect("a finite coordinate")
}

/// Sutherland–Hodgman in rationals: the part of `p` inside every half-plane of the
/// counter-clockwise convex `q` (left of each edge), exactly.
fn clip_exact(p: &[(Q, Q)], q: &[(Q, Q)]) -> Vec<(Q, Q)> {
    let mut out: Vec<(Q, Q)> = p.to_vec();
    for k in 0..q.len() {
        let (a, b) = (&q[k], &q[(k + 1) % q.len()]);
        let side = |x: &(Q, Q)| (&b.0 - &a.0) * (&x.1 - &a.1) - (&b.1 - &a.1) * (&x.0 - &a.0);
        let src = std::mem::take(&mut out);
        for m in 0..src.len() {
            let (x, y) = (&src[m], &src[(m + 1) % src.len()]);
            let (sx, sy) = (side(x), side(y));
            if !sx.is_negative() {
                out.push(x.clone());
            }
            if sx.is_negative() != sy.is_negative() && !(sx.is_zero() || sy.is_zero()) {
                let t = &sx / (&sx - &sy);
                out.push((&x.0 + &t * (&y.0 - &x.0), &x.1 + &t * (&y.1 - &x.1)));
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

fn shoelace(v: &[(Q, Q)]) -> Q {
    let mut s = Q::zero();
    for k in 0..v.len() {
        let (a, b) = (&v[k], &v[(k + 1) % v.len()]);
        s += &a.0 * &b.1 - &a.1 * &b.0;
    }
    s / Q::from_integer(BigInt::from(2))
}

/// A pair as the step sees it: p's corners about its centre, q's about its own, d =
/// r_i − r_j; the outlines in i's frame.
struct Pair {
    p: Vec<P2>,
    q: Vec<P2>,
    d: P2,
}

fn reach(v: &[P2]) -> f64 {
    v.iter().map(|x| x[0].hypot(x[1])).fold(0.0, f64::max)
}

impl Pair {
    fn contact(&self, hint: Hint) -> (Option<AreaContact>, Hint) {
        let p = Outline {
            v: &self.p,
            base: [0.0; 2],
            reach: reach(&self.p),
        };
        let q = Outline {
            v: &self.q,
            base: [-self.d[0], -self.d[1]],
            reach: reach(&self.q),
        };
        polygon_polygon_hinted(&p, &q, self.d, hint)
    }

    /// The exact overlap area of the outlines the code works on (q's corners moved to
    /// i's frame in f64, as `Outline::at` does: the reference is exact for the same
    /// numbers).
    fn exact_area(&self) -> f64 {
        let p: Vec<(Q, Q)> = self.p.iter().map(|v| (exact(v[0]), exact(v[1]))).collect();
        let q: Vec<(Q, Q)> = (self.q.iter())
            .map(|v| (exact(v[0] + -self.d[0]), exact(v[1] + -self.d[1])))
            .collect();
        let o = clip_exact(&p, &q);
        if o.len() < 3 {
            return 0.0;
        }
        shoelace(&o).abs().to_f64().unwrap()
    }
}

/// A polygon of 3–16 corners on an ellipse (semi-axes 0.35–0.6), turned by θ.
fn polygon(rng: &mut Rng, theta: f64) -> Vec<P2> {
    let n = 3 + (rng.next_u64() % 14) as u32;
    let a = rng.range(0.7, 1.2);
    let body = ellipse_polygon(n, a, a * rng.range(0.4, 1.0), rng.range(0.0, 1.0));
    let mut out = Vec::new();
    rotate(&body, theta, &mut out);
    out
}

/// The kinds of configuration, each built to hit one hard case.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// Centres at a random offset, random shapes and turns.
    Random,
    /// Two regular polygons turned to face each other, edge on edge, pressed or apart by
    /// a gap log-uniform in 1e-9 … 1e-2.
    Parallel,
    /// A corner of q placed on a corner of p (to rounding), then nudged by ~1e-12.
    SharedCorner,
    /// q small, inside p or nearly.
    Inside,
    /// Thin spikes: triangles of aspect ~20, tip into face or tip on tip.
    Spike,
}

fn config(rng: &mut Rng, kind: Kind) -> Pair {
    use std::f64::consts::{PI, TAU};
    let theta = rng.range(0.0, TAU);
    match kind {
        Kind::Random => {
            let turn = rng.range(0.0, TAU);
            let (p, q) = (polygon(rng, theta), polygon(rng, turn));
            let r = rng.range(0.3, 1.1);
            let a = rng.range(0.0, TAU);
            Pair {
                p,
                q,
                d: [r * a.cos(), r * a.sin()],
            }
        }
        Kind::Parallel => {
            // A regular n-gon of inradius 0.5 whose edge 0 faces +x, p turned by θ and q
            // by θ + π: their edges 0 face each other, parallel, along u.
            let n = 3 + (rng.next_u64() % 14) as u32;
            let r = 0.5 / (PI / n as f64).cos();
            let body = ellipse_polygon(n, 2.0 * r, 2.0 * r, -PI / n as f64);
            let (mut p, mut q) = (Vec::new(), Vec::new());
            rotate(&body, theta, &mut p);
            rotate(&body, theta + PI, &mut q);
            // The faces meet at a distance of 1; pressed or apart by the gap, slid along.
            let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            let along = 1.0 + sign * 10f64.powf(rng.range(-9.0, -2.0));
            let slide = rng.range(-0.1, 0.1);
            let (c, s) = (theta.cos(), theta.sin());
            Pair {
                p,
                q,
                d: [-(along * c - slide * s), -(along * s + slide * c)],
            }
        }
        Kind::SharedCorner => {
            let turn = rng.range(0.0, TAU);
            let (p, q) = (polygon(rng, theta), polygon(rng, turn));
            let (a, b) = (
                rng.next_u64() as usize % p.len(),
                rng.next_u64() as usize % q.len(),
            );
            // q's corner b at p's corner a: r_j + q_b = r_i + p_a, d = q_b − p_a.
            let nudge = [rng.range(-1e-12, 1e-12), rng.range(-1e-12, 1e-12)];
            Pair {
                d: [q[b][0] - p[a][0] + nudge[0], q[b][1] - p[a][1] + nudge[1]],
                p,
                q,
            }
        }
        Kind::Inside => {
            let p = polygon(rng, theta);
            let turn = rng.range(0.0, TAU);
            let small: Vec<P2> = (polygon(rng, turn).iter())
                .map(|v| [0.2 * v[0], 0.2 * v[1]])
                .collect();
            let r = rng.range(0.0, 0.45);
            let a = rng.range(0.0, TAU);
            Pair {
                p,
                q: small,
                d: [r * a.cos(), r * a.sin()],
            }
        }
        Kind::Spike => {
            // A triangle 1 long and 0.075 thick, tip into a face or onto another tip.
            let spike = |t: f64| {
                let body = [[0.0, 0.05], [-0.5, -0.025], [0.5, -0.025]];
                let (c, s) = (t.cos(), t.sin());
                (body.iter())
                    .map(|v| [c * v[0] - s * v[1], s * v[0] + c * v[1]])
                    .collect::<Vec<P2>>()
            };
            let p = spike(theta);
            let q = if rng.uniform() < 0.5 {
                let turn = rng.range(0.0, TAU);
                spike(turn)
            } else {
                polygon(rng, 0.0)
            };
            let r = rng.range(0.4, 0.9);
            let a = rng.range(0.0, TAU);
            Pair {
                p,
                q,
                d: [r * a.cos(), r * a.sin()],
            }
        }
    }
}

/// Every kind of configuration the tests draw.
const KINDS: [Kind; 5] = [
    Kind::Random,
    Kind::Parallel,
    Kind::SharedCorner,
    Kind::Inside,
    Kind::Spike,
];

/// Every kind, many times: the area agrees with the exact clip's to 1e-9 relative or
/// 64 ε of the polygons' size squared (the corners' own rounding), and an overlap the
/// code does not report is below its floor (`THICKNESS_FLOOR` of the radii times the
/// overlap's span, at most the smaller polygon's diameter √2; with the same room). Each kind must produce overlaps and non-overlaps, so no kind is
/// vacuous.
#[test]
fn the_overlap_area_is_the_exact_clips() {
    let mut rng = Rng::new(37);
    for kind in KINDS {
        let (mut overlapping, mut apart) = (0, 0);
        for _ in 0..300 {
            let c = config(&mut rng, kind);
            let want = c.exact_area();
            let scale = (reach(&c.p) + reach(&c.q)).powi(2);
            let room = 1e-9 * want + 64.0 * f64::EPSILON * scale;
            let (rp, rq) = (reach(&c.p), reach(&c.q));
            let floor = THICKNESS_FLOOR * (rp + rq) * 2.0 * rp.min(rq) * 1.5;
            match c.contact(Hint::NONE).0 {
                Some(g) => {
                    overlapping += 1;
                    assert!(
                        (g.area - want).abs() <= room,
                        "{kind:?}: area {} against the exact {want} (p {:?}, q {:?}, d {:?})",
                        g.area,
                        c.p,
                        c.q,
                        c.d
                    );
                    assert!(g.n[0].is_finite() && g.n[1].is_finite() && g.l > 0.0);
                    assert!((g.n[0].hypot(g.n[1]) - 1.0).abs() < 1e-12);
                }
                None => {
                    apart += 1;
                    assert!(
                        want <= floor + room,
                        "{kind:?}: missed an overlap of {want} (p {:?}, q {:?}, d {:?})",
                        c.p,
                        c.q,
                        c.d
                    );
                }
            }
        }
        eprintln!("{kind:?}: {overlapping} overlapping, {apart} apart");
        assert!(
            overlapping > 30 && (apart > 10 || matches!(kind, Kind::Inside)),
            "{kind:?}: {overlapping} overlapping, {apart} apart"
        );
    }
}

/// Both bitwise the same (areas, normals, points: every bit of the contact).
fn same(a: &(Option<AreaContact>, Hint), b: &(Option<AreaContact>, Hint)) -> bool {
    let bits = |c: &Option<AreaContact>| {
        c.map(|c| [c.area, c.n[0], c.n[1], c.arm[0], c.arm[1], c.chord, c.l].map(f64::to_bits))
    };
    bits(&a.0) == bits(&b.0)
}

/// A hint never changes the result: a pair evaluated from no hint, from its own hint,
/// from the hint of the same pair a step earlier (moved and turned a little, as in a
/// run), and from random words, gives the same contact to the bit. The hints must also
/// be used (most pairs get one: the test would pass vacuously if none did).
#[test]
fn a_hint_never_changes_a_contact() {
    let mut rng = Rng::new(38);
    let (mut resting, mut apart, mut total) = (0, 0, 0);
    for kind in KINDS {
        for _ in 0..400 {
            let c = config(&mut rng, kind);
            let cold = c.contact(Hint::NONE);
            total += 1;
            match cold.1.seen() {
                Seen::Resting(_) => resting += 1,
                Seen::Apart { .. } => apart += 1,
                Seen::Nothing => {}
            }
            assert!(same(&c.contact(cold.1), &cold), "{kind:?}: own hint");
            // The next step: moved by up to 1e-4 and turned by up to 1e-4.
            let turn = rng.range(-1e-4, 1e-4);
            let mut q = Vec::new();
            rotate(&c.q, turn, &mut q);
            let next = Pair {
                p: c.p.clone(),
                q,
                d: [
                    c.d[0] + rng.range(-1e-4, 1e-4),
                    c.d[1] + rng.range(-1e-4, 1e-4),
                ],
            };
            assert!(
                same(&next.contact(cold.1), &next.contact(Hint::NONE)),
                "{kind:?}: last step's hint"
            );
            for _ in 0..4 {
                let random = Hint(rng.next_u64() as u32);
                assert!(same(&c.contact(random), &cold), "{kind:?}: hint {random:?}");
            }
        }
    }
    eprintln!("{resting} resting, {apart} apart of {total}");
    assert!(
        resting > total / 5 && apart > total / 10,
        "{resting} resting, {apart} apart of {total}"
    );
}
