//! Contact stress, paper 000 eq. 8–9: σ_αβ = (1/V) Σ_c f_α^c l_β^c over the contacts of
//! the particles in V, with f the force on the particle and l the branch vector from its
//! centre to the contact point. talus reports compression as positive (the sign of the
//! paper's figures), i.e. σ = −(1/V) Σ f ⊗ l. In 2D, V is an area and σ a force per
//! length; the dimensionless S = 2σ/(ρ g h) then needs ρ as mass per area, which cancels
//! the thickness.

use super::input::{Grain, Touch};
use super::outline::Outline;

/// A 2×2 tensor [[xx, xz], [zx, zz]].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tensor {
    pub xx: f64,
    pub xz: f64,
    pub zx: f64,
    pub zz: f64,
}

impl Tensor {
    pub fn scaled(self, s: f64) -> Tensor {
        Tensor {
            xx: self.xx * s,
            xz: self.xz * s,
            zx: self.zx * s,
            zz: self.zz * s,
        }
    }

    pub fn plus(self, o: Tensor) -> Tensor {
        let mut t = self;
        t.add(o);
        t
    }

    fn add(&mut self, o: Tensor) {
        self.xx += o.xx;
        self.xz += o.xz;
        self.zx += o.zx;
        self.zz += o.zz;
    }

    /// Principal values (σ_max, σ_min) of the symmetric part, and the angle φ of the
    /// major axis from the horizontal, counter-clockwise, in [0, π) (paper 000 eq. 9).
    pub fn principal(&self) -> (f64, f64, f64) {
        let plus = 0.5 * (self.xx + self.zz);
        let minus = 0.5 * (self.xx - self.zz);
        let star = 0.5 * (self.xz + self.zx);
        let r = minus.hypot(star);
        let phi = (0.5 * (2.0 * star).atan2(self.xx - self.zz)).rem_euclid(std::f64::consts::PI);
        (plus + r, plus - r, phi)
    }
}

/// Σ_c f ⊗ l of each grain (not divided by any volume), compression positive.
/// `period_x`: the domain's period in x (0: none), across which a contact point lies
/// by one grain and its image by the other.
pub fn moments(grains: &[Grain], touches: &[Touch], period_x: f64) -> Vec<Tensor> {
    let mut m = vec![Tensor::default(); grains.len()];
    let mut add = |k: usize, f: [f64; 2], sign: f64, p: [f64; 2]| {
        let g = &grains[k];
        let l = [
            crate::state::nearest_image(p[0] - g.x, period_x),
            p[1] - g.z,
        ];
        m[k].add(Tensor {
            xx: -sign * f[0] * l[0],
            xz: -sign * f[0] * l[1],
            zx: -sign * f[1] * l[0],
            zz: -sign * f[1] * l[1],
        });
    };
    for t in touches {
        add(t.a, t.force, 1.0, t.point);
        if let Some(b) = t.b {
            add(b, t.force, -1.0, t.point);
        }
    }
    m
}

/// The coarse-grained stress of one window: the particles whose centres lie in it.
#[derive(Clone, Debug)]
pub struct Window {
    pub row: usize,
    pub z_lo: f64,
    pub z_hi: f64,
    pub x: f64,
    pub particles: usize,
    pub sigma: Tensor,
}

/// Horizontal moving averages (paper 000 sec. 3): rows of height `dz` from the base up,
/// in each a window of width `width` centred every `step` from the left end to the
/// right; σ = Σ moments / (width · dz).
pub fn moving_averages(
    grains: &[Grain],
    moments: &[Tensor],
    o: &Outline,
    dz: f64,
    width: f64,
    step: f64,
) -> Vec<Window> {
    let (base, top, left, right) = (o.base, o.top, o.left, o.right);
    let rows = ((top - base) / dz).ceil().max(1.0) as usize;
    let mut by_row: Vec<Vec<usize>> = vec![Vec::new(); rows];
    for (k, g) in grains.iter().enumerate() {
        let r = ((g.z - base) / dz).floor();
        if r >= 0.0 && (r as usize) < rows {
            by_row[r as usize].push(k);
        }
    }
    let columns = ((right - left) / step).floor() as usize + 1;
    let mut out = Vec::new();
    for (row, members) in by_row.iter().enumerate() {
        for c in 0..columns {
            let x = left + c as f64 * step;
            let mut sigma = Tensor::default();
            let mut n = 0;
            for &k in members {
                if (grains[k].x - x).abs() <= 0.5 * width {
                    sigma.add(moments[k]);
                    n += 1;
                }
            }
            out.push(Window {
                row,
                z_lo: base + row as f64 * dz,
                z_hi: base + (row + 1) as f64 * dz,
                x,
                particles: n,
                sigma: sigma.scaled(1.0 / (width * dz)),
            });
        }
    }
    out
}

/// The polar distribution P(φ) of the particles' principal directions (paper 004 sec. 3,
/// Fig. 5): the angle φ ∈ [0, π) of the larger eigenvalue of each loaded particle's own
/// stress (`moments`; grains with no contact left out), in `bins` bins, normalised so
/// that ∫ P dφ = 1 (binned as f(θ) is). Returns the bins and the number of particles
/// counted.
pub fn principal_directions(moments: &[Tensor], bins: usize) -> (Vec<(f64, f64)>, usize) {
    let angles: Vec<Option<f64>> = moments
        .iter()
        .map(|m| (*m != Tensor::default()).then(|| m.principal().2))
        .collect();
    super::structure::orientation(&angles, bins)
}
