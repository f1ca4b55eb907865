//! How long a run will take (`talus check --estimate`, issue 37 item 7), timed where its
//! cost is.
//!
//! A particle-step costs what its particle's neighbourhood costs: a grain falling from
//! a point source has no neighbours, one in the grown heap has six candidates and four
//! contacts. Timing a pour from its start (what the estimate did before) measures the
//! falling grains and was 6–7× low for the 50 000-polygon heap. So a pour is timed on
//! stand-ins for its grown heap (`grown_pile`): a settled lattice pile of the source's
//! own particles (the same shape family, the mean size, the scene's law, time step and
//! gravity) at several sizes up to the final count. The rate between the sizes is
//! interpolated in log–log, and the run's expected work (`run::expected_work`: the
//! moving particles of each step, insertions at their rates) is divided by the rate at
//! its size, step range by step range. A scene without sources is timed as it stands.

use crate::base::progress::Work;
use crate::scene::{Creation, Scene, SceneError};
use crate::sim::Simulation;

/// The particle count of the largest stand-in pile (a bigger heap runs at this one's
/// rate: beyond a few 10⁴ particles the rate per particle hardly changes).
pub const LARGEST_PILE: usize = 60_000;

/// A measured rate: moving particles and particle-steps per second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rate {
    pub particles: f64,
    pub per_second: f64,
}

/// A stand-in for `scene`'s first point source grown to about `n` particles: a 30°
/// triangular pile of the source's own particles (the next n it would draw: their
/// shapes, sizes and orientations), centred under the outlet, on the scene's highest
/// wall below it (or on a fixed bottom row at the domain's floor), in a domain grown to
/// hold it, with the scene's point sources still pouring onto it: the falling stream
/// costs what it costs in the run (its fast grains rebuild the neighbour lists every few
/// steps, its impacts keep the top moving). The scene's other particles are left out.
/// The sites are 3 % closer than the particles' mean circumscribed diameter, so that
/// neighbours touch as in a heap (some corners into faces: the pile starts a little
/// compressed, `limits.initial_overlap` is lifted for it). None when the scene has no
/// point source, or pours rods (their deposits are not such piles).
pub fn grown_pile(scene: &Scene, n: usize) -> Result<Option<Simulation>, SceneError> {
    use crate::create::source::{SourceState, particle_at, upcoming};
    let Some((index, source)) = (scene.particles.iter())
        .filter_map(|c| match c {
            Creation::PointSource(s) => Some(s),
            _ => None,
        })
        .enumerate()
        .next()
    else {
        return Ok(None);
    };
    if source.rod.is_some() {
        return Ok(None);
    }
    // The particles the source would pour, n of them (its own draws, again from the
    // start when it pours fewer).
    let mut spec = source.clone();
    spec.count = n.max(1) as u32;
    let drawn = upcoming(&spec, &SourceState::new(scene.seed, index));
    let material = scene
        .materials
        .keys()
        .position(|m| *m == source.material)
        .unwrap_or(0) as u32;
    let mut particles: Vec<crate::state::NewParticle> = (drawn.iter())
        .map(|d| particle_at(source.polygon.as_ref(), d, [0.0; 2], [0.0; 2], material))
        .collect();
    let across = 2.0 * particles.iter().map(|p| p.radius).sum::<f64>() / particles.len() as f64;
    let spacing = if source.polygon.is_some() {
        0.97 * across
    } else {
        across
    };
    // Row M of a 30° pile holds L − 3M particles: about L²/6 in all.
    let l = (((6 * n.max(3)) as f64).sqrt().round() as usize).max(4);
    let half_width = 0.5 * l as f64 * spacing + 2.0 * across;
    let x0 = source.position[0];
    // On the highest wall under the pile's footprint, else the domain's floor.
    let under = |w: &crate::scene::Wall| {
        let (lo, hi) = (w.from[0].min(w.to[0]), w.from[0].max(w.to[0]));
        lo <= x0 + half_width && hi >= x0 - half_width
    };
    let base = (scene.walls.iter())
        .filter(|w| under(w))
        .map(|w| w.from[1].max(w.to[1]))
        .filter(|&z| z < source.position[1])
        .fold(f64::NEG_INFINITY, f64::max);
    // On a wall the bottom row rests on it, as a heap's does; else it is fixed.
    let on_wall = base.is_finite();
    let base = if on_wall {
        base
    } else {
        scene.domain.z[0] + across
    };
    let rise = spacing * 3f64.sqrt() / 2.0;
    let mut sites = Vec::new();
    for m in 0..l.div_ceil(3) {
        let count = l - 3 * m;
        for k in 0..count {
            let x = x0 + (k as f64 - 0.5 * (count - 1) as f64) * spacing;
            sites.push((
                [x, base + 0.5 * across + m as f64 * rise],
                m == 0 && !on_wall,
            ));
        }
    }
    let height = l.div_ceil(3) as f64 * rise + 2.0 * across;
    let mut v = serde_json::to_value(scene).expect("a scene serialises");
    let sources: Vec<serde_json::Value> = (scene.particles.iter())
        .filter(|c| matches!(c, Creation::PointSource(_)))
        .map(|c| serde_json::to_value(c).expect("a creation serialises"))
        .collect();
    v["particles"] = serde_json::Value::Array(sources);
    let d = &scene.domain;
    v["domain"]["x"] =
        serde_json::json!([d.x[0].min(x0 - half_width), d.x[1].max(x0 + half_width)]);
    v["domain"]["z"] = serde_json::json!([d.z[0].min(base - across), d.z[1].max(base + height)]);
    v["limits"]["initial_overlap"] = serde_json::json!(1.0);
    v["name"] = serde_json::json!(format!("{}-grown-{n}", scene.name));
    let stand_in = crate::scene::parse(&v.to_string(), &[])?;
    let mut sim = Simulation::new(stand_in)?;
    let kinds = particles.len();
    for (k, (at, fixed)) in sites.into_iter().enumerate() {
        let p = &mut particles[k % kinds];
        p.position = at;
        p.fixed = fixed;
        crate::create::push(&sim.scene, &mut sim.particles, p);
    }
    Ok(Some(sim))
}

/// How fast each point source of copy 0 really placed its particles in a run now at
/// `now`: placed over due by then (1 when it kept up, or had not started), in scene
/// order. A source waits while its spot at the outlet is taken (a grain dropped slowly
/// has not fallen clear of it when the next falls due), so its pace can be well below
/// its rate: the 50 000-polygon heap's outlet places about a third of its 200 a second.
pub fn source_pace(now: &Simulation) -> Vec<f64> {
    let (sources, _) = crate::sim::creators(&now.scene);
    let t = now.time();
    (sources.iter().zip(&now.sources))
        .map(|(spec, state)| {
            if t < spec.start_time + 1.0 / spec.rate || state.done(spec) {
                return 1.0;
            }
            let due = (((t - spec.start_time) * spec.rate).floor() + 1.0).min(spec.count as f64);
            (state.inserted as f64 / due).min(1.0)
        })
        .collect()
}

/// `scene` with each point source's rate times its pace (`source_pace`), in scene
/// order: what its expected work should assume.
pub fn at_pace(scene: &Scene, pace: &[f64]) -> Scene {
    let mut s = scene.clone();
    let mut k = 0;
    for c in &mut s.particles {
        if let Creation::PointSource(p) = c {
            p.rate *= pace.get(k).copied().unwrap_or(1.0);
            k += 1;
        }
    }
    s
}

/// The sizes a pour's stand-ins are timed at: a fifth, three fifths and all of the final
/// count (for `heap_50k.json` 10⁴, 3·10⁴ and 5·10⁴), each at least 200 and at most
/// [`LARGEST_PILE`]. A pour at a steady rate does a fraction x² of its work by the time it
/// holds a fraction x of its grains: the first fifth does 4 % of it, so the sizes lie
/// where the work is.
pub fn pile_sizes(final_count: f64) -> Vec<usize> {
    let top = (final_count as usize).clamp(200, LARGEST_PILE);
    let mut sizes: Vec<usize> = [top / 5, 3 * top / 5, top]
        .into_iter()
        .map(|n| n.max(200))
        .collect();
    sizes.dedup();
    sizes
}

/// The rate at `particles` from the measured ones: log–log between the two sizes about
/// it, the nearest one's beyond them.
pub fn rate_at(rates: &[Rate], particles: f64) -> f64 {
    let mut r: Vec<Rate> = rates.to_vec();
    r.sort_by(|a, b| a.particles.total_cmp(&b.particles));
    let (first, last) = (r[0], r[r.len() - 1]);
    if particles <= first.particles {
        return first.per_second;
    }
    if particles >= last.particles {
        return last.per_second;
    }
    let k = r.partition_point(|x| x.particles <= particles);
    let (a, b) = (r[k - 1], r[k]);
    let f = (particles.ln() - a.particles.ln()) / (b.particles.ln() - a.particles.ln());
    (a.per_second.ln() + f * (b.per_second.ln() - a.per_second.ln())).exp()
}

/// Seconds the run takes: each range of steps between the work's samples at the rate of
/// its size (its mean moving count, the work over the steps).
pub fn run_time(work: &Work, rates: &[Rate]) -> f64 {
    work.samples
        .windows(2)
        .map(|w| {
            let (steps, done) = ((w[1].0 - w[0].0) as f64, w[1].1 - w[0].1);
            if steps <= 0.0 || done <= 0.0 {
                return 0.0;
            }
            done / rate_at(rates, done / steps)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_between_sizes_is_log_log() {
        let r = [
            Rate {
                particles: 100.0,
                per_second: 1e6,
            },
            Rate {
                particles: 10_000.0,
                per_second: 4e6,
            },
        ];
        assert_eq!(rate_at(&r, 50.0), 1e6);
        assert_eq!(rate_at(&r, 1e5), 4e6);
        // Halfway in log N: the geometric mean of the rates.
        assert!((rate_at(&r, 1000.0) - 2e6).abs() < 1e-6);
        // A pour growing linearly from 0 to 10⁴ over 10⁴ steps, timed at both ends.
        let samples = (0..=100u64)
            .map(|k| (k * 100, 0.5 * (k * 100) as f64 * (k * 100) as f64))
            .collect();
        let t = run_time(&Work { samples }, &r);
        let slow = run_time(
            &Work {
                samples: vec![(0, 0.0), (10_000, 5e7)],
            },
            &r,
        );
        // Between the whole run at the small heap's rate and at the big one's.
        assert!(t < 5e7 / 1e6 && t > 5e7 / 4e6 && slow > 0.0, "{t}");
    }

    /// heap_50k's outlet as first written (grains dropped at 0.2 m/s, 200 a second)
    /// keeps about a third of its rate: a grain still covers its spot when the next
    /// falls due. At 2.5 m/s (the scene now) it keeps up; `at_pace` scales the rate.
    #[test]
    fn a_slow_drop_holds_its_source_back_and_the_pace_says_so() {
        let text = include_str!("../../scenes/heap_50k.json");
        let pace_at = |speed: &str| {
            let o = vec![format!("particles.0.velocity=[0.0,{speed}]")];
            let mut sim = Simulation::new(crate::scene::parse(text, &o).unwrap()).unwrap();
            // 1.2 time units: 240 grains due.
            sim.advance(60_000).unwrap();
            source_pace(&sim)[0]
        };
        let (slow, fast) = (pace_at("-0.2"), pace_at("-2.5"));
        assert!(slow < 0.6, "at 0.2 m/s the source keeps {slow} of its rate");
        assert!(
            fast > 0.97,
            "at 2.5 m/s the source keeps {fast} of its rate"
        );
        let s = crate::scene::parse(text, &[]).unwrap();
        let Creation::PointSource(p) = &at_pace(&s, &[0.25]).particles[0] else {
            panic!("heap_50k pours from a point source");
        };
        assert_eq!(p.rate, 50.0);
    }

    #[test]
    fn the_grown_pile_holds_about_the_count_of_the_source() {
        let s = crate::scene::parse(crate::scene::DEFAULT_SCENE, &[]).unwrap();
        let sim = grown_pile(&s, 1000)
            .unwrap()
            .expect("the default heap pours");
        let n = sim.particles.len();
        assert!((900..1100).contains(&n), "{n} particles");
        assert!(
            sim.particles.mobile_count() < n,
            "a fixed bottom row (no wall under it)"
        );
        assert_eq!(sim.sources.len(), 1, "the source still pours");
        assert_eq!(pile_sizes(50_000.0), vec![10_000, 30_000, 50_000]);
        assert_eq!(pile_sizes(333.0), vec![200, 333]);
    }
}
