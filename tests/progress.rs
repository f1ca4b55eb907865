//! The progress's ETA follows the expected work (particle-steps of the moving particles)
//! rather than the steps, since a pour's steps get dearer as its heap grows (issue 20: an
//! ETA 9× too early). Checked without timing: the expected work against the particle-
//! steps a pour really takes, and the ETA it gives at 10 % of the run against the one
//! the real work would give.

use talus::run::{expected_work, total_steps};
use talus::scene;
use talus::sim::Simulation;

#[test]
fn the_expected_work_of_a_pour_is_its_real_work() {
    for extra in [&["replicas=1"][..], &["replicas=2"][..]] {
        let mut o: Vec<String> = [
            "stop.time=40",
            "particles[1].count=200",
            "particles[1].rate=10",
            "stop.kinetic_fraction=null",
        ]
        .map(String::from)
        .to_vec();
        o.extend(extra.iter().map(|s| s.to_string()));
        let mut sim = Simulation::new(scene::parse(scene::DEFAULT_SCENE, &o).unwrap()).unwrap();
        let total = total_steps(&sim);
        let work = expected_work(&sim, total);
        // The real work, step by step: the moving particles of every step.
        let mut real = vec![0.0];
        for _ in 0..total {
            let moving = sim.particles.mobile_count() as f64;
            sim.advance(1).unwrap();
            real.push(real.last().unwrap() + moving);
        }
        for tenth in 1..=10 {
            let step = total * tenth / 10;
            let (expected, got) = (work.at(step), real[step as usize]);
            assert!(
                (expected - got).abs() <= 0.05 * got,
                "{extra:?}: at {tenth}0 % expected {expected:.4e} particle-steps, took {got:.4e}"
            );
        }
        // At 10 % of the run, the ETA if each particle-step costs the same: the model's
        // against the real work's, within a factor 1.5 (the steps alone are off by 3×).
        let step = total / 10;
        let at = |w: f64, total_w: f64| (total_w - w) / w;
        let model = at(work.at(step), work.total());
        let truth = at(real[step as usize], *real.last().unwrap());
        let by_steps = (total - step) as f64 / step as f64;
        assert!(
            (model / truth - 1.0).abs() < 0.5,
            "{extra:?}: remaining/done {model:.2} by the model, {truth:.2} really"
        );
        assert!(
            by_steps / truth < 0.5,
            "the steps alone would have been fine: {by_steps} vs {truth}"
        );
    }
}

#[test]
fn eta_is_the_remaining_work_at_the_rate_so_far() {
    let w = talus::base::progress::Work {
        samples: vec![(0, 0.0), (100, 100.0), (200, 400.0)],
    };
    assert_eq!(w.at(50), 50.0);
    assert_eq!(w.at(150), 250.0);
    assert_eq!(w.at(300), 400.0);
    // 100 of 400 done in 10 s: 300 more at 10 per second.
    assert!((w.eta(100, 10.0) - 30.0).abs() < 1e-12);
}
