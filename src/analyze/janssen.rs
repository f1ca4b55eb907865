//! The trace of the mean stress against depth in a deposit, and its Janssen fit (paper
//! 004 sec. 3, Fig. 6): σ = σ_m (1 − exp(−x/h_s)), with x the depth below the top in
//! units of the deposit's width W. A deposit whose side walls carry part of its weight
//! saturates at σ_m below a depth of a few h_s.

use super::input::Grain;
use super::outline::Outline;
use super::stress::Tensor;
use serde::Serialize;

/// The fit σ = σ_m (1 − exp(−x/h_s)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Janssen {
    /// Saturation stress, in units of ρ g W.
    pub sigma_m: f64,
    /// Saturation depth, in units of W.
    pub h_s: f64,
}

/// The trace σ_xx + σ_zz of the mean stress against depth below the deposit's surface,
/// the depth in units of its width W and the stress in units of ρ g W (`density` ρ,
/// gravity `g`). W is that of the grains' true shapes (the inner width of the box they
/// fill); the surface is the mean over bins one particle length wide of the highest
/// grain top in each (a rough top's highest grain would put the surface above most of
/// the deposit). As the paper's representative volume elements of five particle lengths
/// a side (A_RVE = 5d × 5d) side by side across the width, each point is a slab five mean
/// particle lengths high (a length being twice the reach: d for a rod, the diameter for a
/// disk) spanning the deposit, its stress the Σ f ⊗ l (`moments`) of the mobile grains
/// centred in it over its area. Slabs lie in the deposit, centred every particle length
/// from the surface down (so they overlap).
pub fn stress_against_depth(
    grains: &[Grain],
    moments: &[Tensor],
    o: &Outline,
    density: f64,
    g: f64,
) -> Vec<(f64, f64)> {
    let mobile: Vec<&Grain> = grains.iter().filter(|g| !g.fixed).collect();
    let left = mobile
        .iter()
        .map(|g| g.left())
        .fold(f64::INFINITY, f64::min);
    let right = mobile
        .iter()
        .map(|g| g.right())
        .fold(f64::NEG_INFINITY, f64::max);
    let width = right - left;
    if mobile.is_empty() || width <= 0.0 || density * g <= 0.0 {
        return Vec::new();
    }
    let length = mobile.iter().map(|g| 2.0 * g.radius).sum::<f64>() / mobile.len() as f64;
    let bins = ((width / length).round() as usize).max(1);
    let mut tops = vec![f64::NEG_INFINITY; bins];
    for g in &mobile {
        let b = ((g.x - left) / width * bins as f64)
            .floor()
            .clamp(0.0, (bins - 1) as f64);
        tops[b as usize] = tops[b as usize].max(g.top());
    }
    let tops: Vec<f64> = tops.into_iter().filter(|t| t.is_finite()).collect();
    let surface = tops.iter().sum::<f64>() / tops.len() as f64;
    let height = 5.0 * length;
    let unit = density * g * width;
    let mut out = Vec::new();
    let mut centre = surface - 0.5 * height;
    // A tenth of a length of slack at the base: a deposit's top is its grains' top, below
    // a whole number of lengths by their overlaps.
    while centre - 0.5 * height >= o.base - 0.1 * length {
        let trace: f64 = (grains.iter().zip(moments))
            .filter(|(g, _)| !g.fixed && (g.z - centre).abs() <= 0.5 * height)
            .map(|(_, m)| m.xx + m.zz)
            .sum();
        out.push(((surface - centre) / width, trace / (width * height) / unit));
        centre -= length;
    }
    out
}

/// The Janssen form fitted to (x, σ): h_s from a scan of 400 log-spaced values in
/// [10⁻³, 10²], σ_m by least squares for each. None with fewer than three points, none
/// deeper than 0.5 (the pressure has not begun to saturate there: any h_s beyond the
/// depth fits), or a best h_s at either end of the scan.
pub fn fit(points: &[(f64, f64)]) -> Option<Janssen> {
    let deepest = points.iter().map(|p| p.0).fold(0.0, f64::max);
    if points.len() < 3 || deepest < 0.5 {
        return None;
    }
    let scan: Vec<f64> = (0..400)
        .map(|k| 10f64.powf(-3.0 + 5.0 * k as f64 / 399.0))
        .collect();
    let (_, sigma_m, h_s, k) = (scan.iter().enumerate())
        .map(|(k, &h)| {
            let b: Vec<f64> = points.iter().map(|(x, _)| 1.0 - (-x / h).exp()).collect();
            let bb: f64 = b.iter().map(|v| v * v).sum();
            let bp: f64 = b.iter().zip(points).map(|(v, (_, p))| v * p).sum();
            let sigma_m = bp / bb;
            let residual: f64 = (b.iter().zip(points))
                .map(|(v, (_, p))| (p - sigma_m * v).powi(2))
                .sum();
            (residual, sigma_m, h, k)
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))?;
    (k > 0 && k + 1 < scan.len()).then_some(Janssen { sigma_m, h_s })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_finds_the_saturation_depth() {
        let points: Vec<(f64, f64)> = (1..=20)
            .map(|k| {
                let x = 0.1 * k as f64;
                (x, 2.0 * (1.0 - (-x / 0.4).exp()))
            })
            .collect();
        let j = fit(&points).unwrap();
        assert!(
            (j.sigma_m - 2.0).abs() < 0.02 && (j.h_s - 0.4).abs() < 0.02,
            "{j:?}"
        );
        // Too shallow to saturate: no fit.
        assert!(fit(&points[..4]).is_none());
        // A straight line (hydrostatic, no walls carrying weight) has no saturation: its
        // best h_s lies at the end of the scan.
        let line: Vec<(f64, f64)> = (1..=20).map(|k| (0.1 * k as f64, k as f64)).collect();
        assert!(fit(&line).is_none());
    }
}
