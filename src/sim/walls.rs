//! Walls that move (scene `walls[k].motion`, issue 43 item 3): each segment is placed
//! at the time its contacts are evaluated, and the neighbour list is rebuilt once a
//! wall has moved by half the skin since it was built, as it is for a particle (a
//! particle and a wall then close in by at most the skin between two rebuilds).

use super::Simulation;
use crate::base::geometry::WallSegment;

impl Simulation {
    /// Whether some wall moves.
    pub fn walls_move(&self) -> bool {
        self.scene.walls.iter().any(|w| w.motion.is_some())
    }

    /// Places every moving wall at time t (its segment and the velocity its contacts
    /// see: the surface's along it plus the segment's own); the GPU path's mirror places
    /// them at the state's time when it is read back.
    pub fn place_walls(&mut self, t: f64) {
        if !self.walls_move() {
            return;
        }
        self.wall_time = t;
        for (k, w) in self.scene.walls.iter().enumerate() {
            let Some(m) = w.motion else {
                continue;
            };
            let d = m.displacement(t);
            let v = m.velocity_at(t);
            self.walls[k] = WallSegment {
                a: [w.from[0] + d[0], w.from[1] + d[1]],
                b: [w.to[0] + d[0], w.to[1] + d[1]],
            };
            self.wall_velocity[k] = [w.velocity[0] + v[0], w.velocity[1] + v[1]];
        }
    }

    /// Whether a wall has moved by more than half the skin since the neighbour list was
    /// built (at `walls_listed_at`); the GPU twin is `walls_moved` in survey.wgsl.
    pub(super) fn walls_moved(&self) -> bool {
        if !self.walls_move() {
            return false;
        }
        let half = 0.5 * self.skin();
        self.scene.walls.iter().filter_map(|w| w.motion).any(|m| {
            let (now, then) = (
                m.displacement(self.wall_time),
                m.displacement(self.walls_listed_at),
            );
            (now[0] - then[0]).hypot(now[1] - then[1]) > half
        })
    }
}
