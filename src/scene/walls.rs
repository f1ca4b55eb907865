//! The checks of walls that move (`walls[k].motion`, src/sim/walls.rs), beside the
//! scene's other checks (validate.rs).

use super::{Scene, SceneError};

/// A moving wall may not move farther in one step than a particle may
/// (`limits.max_step_displacement` of the smallest radius): beyond it grains pass
/// through the wall between two steps without meeting it.
pub(super) fn wall_speeds(scene: &Scene) -> Result<(), SceneError> {
    let bound = scene.limits.max_step_displacement;
    if bound <= 0.0 {
        return Ok(());
    }
    let smallest = (scene.particles.iter())
        .map(|c| super::sizes::size_bounds(c).0)
        .fold(f64::INFINITY, f64::min);
    for (k, w) in scene.walls.iter().enumerate() {
        let Some(m) = w.motion else {
            continue;
        };
        let step = m.top_speed() * scene.dt;
        if step > bound * 0.5 * smallest {
            return Err(SceneError::invalid(
                format!("walls[{k}].motion"),
                format!(
                    "moves the wall by up to {step:.4e} in a step of dt = {}, more than limits.max_step_displacement = {bound} of the smallest radius ({:.4e}): grains would pass through it; slow it down or reduce dt",
                    scene.dt,
                    0.5 * smallest
                ),
            ));
        }
    }
    Ok(())
}

/// A wall's `motion`: finite, and an oscillation with a positive period (a period alone
/// moves nothing).
pub(super) fn wall_motion(at: &str, m: &crate::scene::WallMotion) -> Result<(), SceneError> {
    for (key, v) in [("velocity", m.velocity), ("amplitude", m.amplitude)] {
        if !v.iter().all(|v| v.is_finite()) {
            return Err(SceneError::invalid(
                format!("{at}.{key}"),
                format!("must be finite, got {v:?}"),
            ));
        }
    }
    match m.period {
        Some(p) => {
            if !(p.is_finite() && p > 0.0) {
                return Err(SceneError::invalid(
                    format!("{at}.period"),
                    format!("must be positive, got {p}"),
                ));
            }
            if m.amplitude == [0.0; 2] {
                return Err(SceneError::invalid(
                    format!("{at}.period"),
                    "goes with a non-zero amplitude (the oscillation A sin(2π t / T))",
                ));
            }
        }
        None if m.amplitude != [0.0; 2] => {
            return Err(SceneError::invalid(
                format!("{at}.period"),
                "is required with an amplitude (the oscillation A sin(2π t / T))",
            ));
        }
        None => {}
    }
    Ok(())
}
