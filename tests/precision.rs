//! The same contact anywhere in the domain (issue 18, SPEC 3): the CPU path's contact
//! geometry is computed in a frame local to the pair, so a configuration translated far
//! from the origin gives the same contacts and forces; and a corner 1e-6 d deep gives
//! the area of its exact triangle. The GPU's side of this is in tests/gpu_precision.rs.

mod common;

use common::pairs::{Config, GAPS, Kind, PairSet, pair_set};
use serde_json::json;
use std::collections::BTreeMap;
use talus::base::geometry::WallSegment;
use talus::base::rng::Rng;
use talus::cpu::contacts::Pair;
use talus::cpu::forces::{ContactForce, area_contact};
use talus::overlap::{polygon_polygon, polygon_wall};
use talus::shape::{P2, ellipse_polygon, rotate};
use talus::sim::Simulation;
use talus::state::offset;

const K_N: f64 = 1e7;

fn area_law() -> serde_json::Value {
    json!({ "law": "overlap_area", "k_n": K_N, "eta_n": 0.5, "mu": 0.5 })
}

fn spring_dashpot() -> serde_json::Value {
    json!({ "law": "spring_dashpot", "k_n": K_N, "gamma_n": 10.0, "k_t": 2e6, "gamma_t": 1.0, "mu": 0.5 })
}

/// Translations x = z = T, in d.
const OFFSETS: [f64; 3] = [1e2, 1e3, 1e4];

/// The two sets every test here uses: every shape pair under the overlap-area law, and
/// disks under the spring-dashpot law.
fn sets() -> [(&'static str, PairSet); 2] {
    [
        ("area law", pair_set(area_law(), &Kind::AREA_LAW, 1800, 18)),
        (
            "spring-dashpot",
            pair_set(spring_dashpot(), &Kind::DISK_LAWS, 600, 19),
        ),
    ]
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

fn diff(a: [f64; 2], b: [f64; 2]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1]])
}

/// Every configuration has exactly its own contact: (config, contact) in contact order.
fn contacts_of<'a>(set: &'a PairSet, sim: &'a Simulation) -> Vec<(&'a Config, Pair, ContactForce)> {
    let rows: Vec<_> = sim
        .pairs
        .iter()
        .zip(&sim.contacts)
        .map(|(p, c)| (set.config_of(p.i), *p, *c))
        .collect();
    for (c, p, _) in &rows {
        let partner = matches!(c.kind, Kind::PolygonWall | Kind::DiskWall) == p.is_wall();
        assert!(
            p.i as usize == c.i && partner && (p.is_wall() || p.j == p.i + 1),
            "{p:?} is not the contact of its configuration {c:?}"
        );
    }
    rows
}

#[test]
fn contacts_are_the_same_after_translations_that_are_exact() {
    // The sets lie on a 2⁻³⁶ grid: x + T is exact, so the translated configuration is the
    // same numbers and the demanded agreement has no absolute floor. Only a computation
    // from absolute coordinates could tell the places apart (the plain shoelace formula
    // at 1e4 d was off by up to 49× for A ~ 1e-12 D², issue 18).
    for (name, set) in sets() {
        let origin = set.at([0.0, 0.0]);
        let base = contacts_of(&set, &origin);
        assert_eq!(
            base.len(),
            set.configs.len(),
            "{name}: every configuration touches at the origin"
        );
        let mut seen = BTreeMap::new();
        for (c, _, _) in &base {
            *seen.entry(c.kind.name()).or_insert(0) += 1;
        }
        eprintln!("{name}: {} configurations {seen:?}", base.len());
        for t in OFFSETS {
            let moved = set.at([t, t]);
            assert_eq!(
                moved.pairs, origin.pairs,
                "{name} at {t}: the same contacts"
            );
            let mut worst = 0.0f64;
            for ((c, p, a), b) in base.iter().zip(&moved.contacts) {
                let f = norm(a.force);
                let e = diff(a.force, b.force).max(diff(a.arm, b.arm) * f / norm(a.arm));
                worst = worst.max(e / f);
                assert!(
                    e <= 1e-9 * f,
                    "{name} at {t}: {} (gap {:.1e}, {p:?}) force {:?} vs {:?}",
                    c.kind.name(),
                    c.gap,
                    a.force,
                    b.force
                );
                assert_eq!(a.n, b.n, "{name} at {t}: normal of {p:?}");
            }
            eprintln!("{name} at x = z = {t:e}: largest relative difference {worst:.1e}");
        }
    }
}

/// The largest change of the pair's relative geometry when translated by t, from the
/// rounding of the translated positions (exact: differences of nearby f64 are exact).
fn offset_change(origin: &Simulation, moved: &Simulation, p: Pair) -> f64 {
    let i = p.i as usize;
    if p.is_wall() {
        let w = (p.j - talus::cpu::contacts::WALL_BASE) as usize;
        let rel = |s: &Simulation| {
            let (c, wall): ([f64; 2], &WallSegment) = (s.particles.position(i), &s.walls[w]);
            [
                [wall.a[0] - c[0], wall.a[1] - c[1]],
                [wall.b[0] - c[0], wall.b[1] - c[1]],
            ]
        };
        let (a, b) = (rel(origin), rel(moved));
        diff(a[0], b[0]).max(diff(a[1], b[1]))
    } else {
        let j = p.j as usize;
        diff(
            offset(&origin.particles, i, j),
            offset(&moved.particles, i, j),
        )
    }
}

#[test]
fn translations_that_round_stay_within_the_rounding_of_the_positions() {
    // A translation by T that is not a whole number rounds each coordinate by up to
    // ε|T|/2, so the pair itself moves relative to itself by Δd (measured per pair). The
    // force may change by what that moves: k^n (L/l) Δd for an area contact (the area
    // changes by L Δd; the normal turns by ~Δd/L, which moves k^n (A/l) along it by
    // k^n (A/L)/l Δd, less as A/L < L), k^n Δd for the linear law. The demanded bound is
    // 1e-9 |f| + 4 k_eff |Δd| with k_eff = k^n L/l or k^n.
    // The sets jittered off their grid by up to 1e-9 d (well below their smallest gap),
    // at the origin and at 10⁴/3 and 1000π d.
    let t = [1e4 / 3.0, 1e3 * std::f64::consts::PI];
    for (name, set) in sets() {
        let set = set.jittered(1e-9, 5);
        let origin = set.at([0.0, 0.0]);
        let moved = set.at(t);
        assert_eq!(moved.pairs, origin.pairs, "{name}: the same contacts");
        let area = name == "area law";
        let (mut changed, mut worst_floor, mut worst) = (0, 0.0f64, 0.0f64);
        for ((p, a), b) in origin
            .pairs
            .iter()
            .zip(&origin.contacts)
            .zip(&moved.contacts)
        {
            let shift = offset_change(&origin, &moved, *p);
            let stiffness = if area {
                let g = area_contact(&origin.particles, &origin.corners, &origin.walls, *p)
                    .expect("in contact");
                assert!(
                    g.chord > 0.0,
                    "{p:?}: no overlap this shallow is degenerate"
                );
                K_N * g.chord / g.l
            } else {
                K_N
            };
            let floor = 4.0 * stiffness * shift;
            let f = norm(a.force);
            let e = diff(a.force, b.force);
            if e > 0.0 {
                changed += 1;
            }
            worst_floor = worst_floor.max(floor / f);
            worst = worst.max(e / (1e-9 * f + floor));
            assert!(
                e <= 1e-9 * f + floor,
                "{name}: {p:?} force {:?} vs {:?} (shift {shift:.1e})",
                a.force,
                b.force
            );
        }
        eprintln!(
            "{name}: {changed} of {} forces changed by rounding, at most {worst:.2} of the bound; the floor reaches {worst_floor:.1e} |f|",
            origin.pairs.len()
        );
        // The translation did move the pairs: the comparison is not vacuous.
        assert!(changed > 0, "{name}: rounding changed no force");
    }
}

/// Corners of a square of side 2 about the origin, face up.
const SQUARE: [P2; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

#[test]
fn a_corner_a_millionth_deep_has_the_area_of_its_exact_triangle() {
    // Issue 18: corner-first contacts 1–2e-6 d deep were off by up to 5.9e-6 relative at
    // the origin and far more away from it. A polygon's lowest corner v pushed h into a
    // face z = const cuts off the triangle of its two edges: A = h²/2 |u1x/u1z − u2x/u2z|
    // for the edge directions u from v. Against a square's top face (polygon–polygon)
    // and against a wall (polygon–wall), at the origin and at 10⁴ d, to 1e-9 relative
    // for h = 2⁻²⁰ ≈ 9.5e-7 d (the case), and likewise from 2⁻⁷ to 2⁻²⁴ ≈ 6e-8 d.
    let mut rng = Rng::new(3);
    let mut worst = std::collections::BTreeMap::new();
    for depth in [7, 14, 20, 24] {
        let h = (-(depth as f64)).exp2();
        let mut checked = 0;
        while checked < 400 {
            let body = ellipse_polygon(
                3 + (rng.next_u64() % 14) as u32,
                rng.range(0.8, 1.2),
                rng.range(0.5, 1.2),
                rng.range(0.0, 6.3),
            );
            let mut p = Vec::new();
            rotate(&body, rng.range(-3.2, 3.2), &mut p);
            // Corners on a 2⁻³⁰ grid: then the face's height v_z + h, and everything the
            // test places at 10⁴ d, is exact, and the reference triangle is the true one.
            let g = 30f64.exp2();
            for c in &mut p {
                *c = [(c[0] * g).round() / g, (c[1] * g).round() / g];
            }
            let n = p.len();
            let k = (0..n).min_by(|&a, &b| p[a][1].total_cmp(&p[b][1])).unwrap();
            let v = p[k];
            let (a, b) = (p[(k + n - 1) % n], p[(k + 1) % n]);
            let (u1, u2) = ([a[0] - v[0], a[1] - v[1]], [b[0] - v[0], b[1] - v[1]]);
            // Edges within 5° of the face give triangles too long for the test's purpose.
            if u1[1] < 0.09 * norm(u1) || u2[1] < 0.09 * norm(u2) {
                continue;
            }
            checked += 1;
            let expect = 0.5 * h * h * (u1[0] / u1[1] - u2[0] / u2[1]).abs();
            for t in [0.0, 1e4] {
                // Particle i at (t, t); the face at z = t + v_z + h. The square's centre lies
                // 1 below it, under the corner; the wall runs 2 to either side.
                let ci = [t, t];
                let face = ci[1] + v[1] + h;
                let cj = [ci[0] + v[0], face - 1.0];
                let g = polygon_polygon(&p, &SQUARE, [ci[0] - cj[0], ci[1] - cj[1]])
                    .expect("the corner overlaps the square");
                let e: &mut f64 = worst.entry(depth).or_default();
                *e = e.max((g.area / expect - 1.0).abs());
                assert!(
                    (g.area / expect - 1.0).abs() < 1e-9,
                    "polygon-polygon at {t}: {} vs {expect} ({:.1e})",
                    g.area,
                    g.area / expect - 1.0
                );
                let x = ci[0] + v[0];
                let wall = WallSegment {
                    a: [x - 2.0 - ci[0], face - ci[1]],
                    b: [x + 2.0 - ci[0], face - ci[1]],
                };
                let g = polygon_wall(&p, &wall).expect("the corner crosses the wall");
                let e: &mut f64 = worst.entry(depth).or_default();
                *e = e.max((g.area / expect - 1.0).abs());
                assert!(
                    (g.area / expect - 1.0).abs() < 1e-9,
                    "polygon-wall at {t}: {} vs {expect}",
                    g.area
                );
            }
        }
    }
    for (depth, e) in &worst {
        eprintln!("a corner 2^-{depth} deep: area to {e:.1e} relative");
    }
    assert!(
        GAPS[0] <= (-20f64).exp2(),
        "the property tests reach below this depth"
    );
}
