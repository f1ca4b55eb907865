//! Stage `rotate_corners` (twin of shaders/orientation.wgsl): every polygon's corners
//! turned to the step's orientation, once per polygon per step, for all its pairs.

use crate::shape::P2;
use crate::state::Particles;

/// Every polygon's corners turned to its current orientation, relative to its centre,
/// rebuilt each step after the orientations change (disks have none): particle i's are
/// `corners[start[i]..start[i + 1]]`, contiguous, computed once per polygon per step and
/// read by each of its pairs (issue 37 item 4).
#[derive(Clone, Debug, Default)]
pub struct RotatedCorners {
    pub start: Vec<u32>,
    pub corners: Vec<P2>,
    /// Which particle each corner belongs to and every body corner in one array: laid
    /// out again only when particles were added.
    owner: Vec<u32>,
    body: Vec<P2>,
}

impl RotatedCorners {
    pub fn of(&self, i: usize) -> &[P2] {
        &self.corners[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Polygon i's outline in a frame where its centre lies at `base`; `reach`: its
    /// circumscribed radius.
    #[inline]
    pub fn outline(&self, i: usize, base: P2, reach: f64) -> crate::overlap::Outline<'_> {
        crate::overlap::Outline {
            v: self.of(i),
            base,
            reach,
        }
    }
}

/// Stage (twin of `rotate_corners` in orientation.wgsl): every polygon's corners at its
/// current orientation, R(θ) v, on every thread.
pub fn rotate_corners(particles: &Particles, out: &mut RotatedCorners) {
    if out.start.len() != particles.len() + 1 {
        // Shapes never change; only new particles add corners.
        out.start.clear();
        out.owner.clear();
        out.body.clear();
        for (i, shape) in particles.shape.iter().enumerate() {
            out.start.push(out.body.len() as u32);
            out.body.extend_from_slice(shape);
            out.owner.extend(std::iter::repeat_n(i as u32, shape.len()));
        }
        out.start.push(out.body.len() as u32);
        out.corners.resize(out.body.len(), [0.0; 2]);
    }
    if out.body.is_empty() {
        return; // disks only
    }
    let (owner, body, q) = (&out.owner, &out.body, &particles.q[0]);
    // One pass over the corners: each polygon's (sin θ, cos θ) is taken at its first
    // corner in the thread's share and used for the rest of its corners.
    crate::base::parallel::for_each_share(&mut out.corners, |k0, share| {
        let n = share.len();
        let from = body[k0..k0 + n].iter().zip(&owner[k0..k0 + n]);
        let (mut last, mut s, mut c) = (u32::MAX, 0.0, 1.0);
        for (x, (v, &o)) in share.iter_mut().zip(from) {
            if o != last {
                (s, c) = q[o as usize][2].sin_cos();
                last = o;
            }
            *x = [c * v[0] - s * v[1], s * v[0] + c * v[1]];
        }
    });
}
