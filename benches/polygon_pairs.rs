//! Nanoseconds per candidate pair of the polygon–polygon contact geometry alone
//! (`overlap::polygon_polygon_hinted`: from no hint, the facing edges' cut, and from the
//! hint a cold evaluation leaves, as the step does between rebuilds), on the candidate
//! pairs of real piles as the step sees them (the rotated corners laid out
//! contiguously, pairs in the list's order): the settled lattice pile of 12-gons of
//! `talus bench` (`polygon-pile-N`) and a heap of irregular heptagons poured from a
//! point source (R6's grains). `cargo bench --bench polygon_pairs` prints one JSON line
//! per set, with how many pairs the hints found apart and resting and whether any hinted
//! contact differed from the cold one in any bit (it must not); with CI=true the sets
//! are small (a smoke run, not a measurement). ROUNDS=N sets the passes timed;
//! PILE_ONLY=1 skips the heap.

use std::time::Instant;
use talus::cpu::orientation::RotatedCorners;
use talus::overlap::{AreaContact, Hint, Seen, polygon_polygon_hinted};
use talus::scene;
use talus::shape::P2;
use talus::sim::Simulation;

/// The polygon–polygon candidates of a state: (i, j, d = r_i − r_j).
fn candidates(sim: &mut Simulation) -> Vec<(usize, usize, P2)> {
    sim.evaluate_contacts();
    let p = &sim.particles;
    (sim.neighbours.pairs.iter())
        .filter(|pair| {
            !pair.is_wall() && p.is_polygon(pair.i as usize) && p.is_polygon(pair.j as usize)
        })
        .map(|pair| {
            let (i, j) = (pair.i as usize, pair.j as usize);
            (i, j, talus::state::offset(p, i, j))
        })
        .collect()
}

fn contact(c: &RotatedCorners, (i, j, d): (usize, usize, P2)) -> Option<AreaContact> {
    hinted(c, (i, j, d), Hint::NONE).0
}

fn hinted(
    c: &RotatedCorners,
    (i, j, d): (usize, usize, P2),
    hint: Hint,
) -> (Option<AreaContact>, Hint) {
    let (p, q) = (
        c.outline(i, [0.0; 2], 1.0),
        c.outline(j, [-d[0], -d[1]], 1.0),
    );
    polygon_polygon_hinted(&p, &q, d, hint)
}

fn measure(name: &str, sim: &mut Simulation, rounds: usize) {
    let set = candidates(sim);
    let corners = &sim.corners;
    let touching = set
        .iter()
        .filter(|&&c| contact(corners, c).is_some())
        .count();
    let time = |f: &dyn Fn((usize, usize, P2)) -> Option<AreaContact>| {
        let mut sum = 0.0;
        let t = Instant::now();
        for _ in 0..rounds {
            for &c in &set {
                if let Some(a) = f(c) {
                    sum += a.area;
                }
            }
        }
        (
            t.elapsed().as_secs_f64() * 1e9 / (rounds * set.len()) as f64,
            sum,
        )
    };
    // The hints a cold evaluation leaves, and whether the hinted one is the same to
    // the bit.
    let hints: Vec<Hint> = set
        .iter()
        .map(|&c| hinted(corners, c, Hint::NONE).1)
        .collect();
    let (mut apart, mut resting, mut unequal) = (0, 0, 0);
    for (&c, &h) in set.iter().zip(&hints) {
        match h.seen() {
            Seen::Apart { .. } => apart += 1,
            Seen::Resting(_) => resting += 1,
            Seen::Nothing => {}
        }
        let (a, b) = (hinted(corners, c, h), hinted(corners, c, Hint::NONE));
        if format!("{a:?}") != format!("{b:?}") {
            unequal += 1;
        }
    }
    let with_hints: Vec<_> = set.iter().copied().zip(hints.iter().copied()).collect();
    let time_hinted = || {
        let t = Instant::now();
        let mut sum = 0.0;
        for _ in 0..rounds {
            for &(c, h) in &with_hints {
                if let Some(a) = hinted(corners, c, h).0 {
                    sum += a.area;
                }
            }
        }
        (
            t.elapsed().as_secs_f64() * 1e9 / (rounds * set.len()) as f64,
            sum,
        )
    };
    // Interleaved, the least of five of each (this machine swings by tens of percent).
    let (mut t_cut, mut t_hint) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        t_cut = t_cut.min(time(&|c| contact(corners, c)).0);
        t_hint = t_hint.min(time_hinted().0);
    }
    println!(
        "{{\"set\": \"{name}\", \"pairs\": {}, \"touching\": {touching}, \"hints_apart\": {apart}, \"hints_resting\": {resting}, \"ns_per_pair_hinted\": {t_hint:.1}, \"ns_per_pair_cold\": {t_cut:.1}, \"hinted_unequal\": {unequal}}}",
        set.len()
    );
}

fn main() {
    // One thread: the timed loops are serial, and a team of threads between stages
    // would spin beside them.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    pool.install(run);
}

fn run() {
    let small = std::env::var("CI").is_ok_and(|v| v == "true");
    let (n, settle, mut rounds) = if small {
        (500, 20, 2)
    } else {
        (10_000, 200, 20)
    };
    if let Some(r) = std::env::var("ROUNDS").ok().and_then(|r| r.parse().ok()) {
        rounds = r;
    }
    let pile = scene::parse(&talus::bench::polygon_pile_scene(n), &[]).expect("pile");
    let mut sim = Simulation::new(pile).expect("pile");
    sim.advance(settle).expect("pile settles");
    measure(&format!("polygon-pile-{n}"), &mut sim, rounds);

    if std::env::var("PILE_ONLY").is_ok() {
        return;
    }
    // R6's heptagons, poured fast (a grain every 10 ms) so that a heap forms in seconds.
    let (grains, time) = if small { ("60", "0.8") } else { ("600", "7") };
    let heap = scene::parse(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/r6_heap_reduced.json"
        ))
        .expect("scene"),
        &[
            format!("particles[0].count={grains}"),
            "particles[0].rate=100".into(),
            format!("stop.time={time}"),
        ],
    )
    .expect("heap");
    let steps = (time.parse::<f64>().unwrap() / heap.dt) as u64;
    let mut sim = Simulation::new(heap).expect("heap");
    sim.advance(steps).expect("heap pours");
    measure(&format!("heptagon-heap-{grains}"), &mut sim, rounds * 20);
}
