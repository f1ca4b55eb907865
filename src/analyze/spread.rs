//! Spreads of one heap's profiles (issue 20 item 6): a block bootstrap along x of the
//! base particles' loads, for the base-load summary and its "M or not" verdict, and of
//! the grains in each stress window, for bands on the S profiles. It reads the
//! analysis's numbers and never changes the snapshot; a fixed seed makes the same input
//! give the same spreads.
//!
//! The base loads are resampled as a residual bootstrap: each load is the trend (a
//! straight line fitted to the loads over `TREND_SPANS` × `BASE_SPAN` neighbours) plus a
//! fluctuation, and the fluctuations, each in units of its neighbourhood's RMS, are
//! drawn in blocks. Why blocks: a force chain presses on a few neighbouring base
//! particles at once, so neighbours are not independent samples; blocks of `BASE_SPAN`
//! (the summary's own averaging) keep them together (the moving block bootstrap,
//! Künsch 1989). Why a trend: a heap's base load has a shape (small at the toes, large
//! in the middle) that every replica must keep; a line rather than a mean follows the
//! steep rise at the toes. Why in RMS units: force-chain fluctuations grow with the
//! load (paper 000 sec. 4: the forces are distributed exponentially in f/⟨f⟩), so a
//! fluctuation from under the middle is not planted at full size on a toe.

use super::input::Grain;
use super::stress::{Tensor, Window};
use crate::base::rng::Rng;

/// The seed of every bootstrap in an analysis: fixed, so an analysis is reproducible.
pub const SEED: u64 = 0x7a1e_5eed;
/// Replicas of the base-load bootstrap (its se is then known to ~2 %: 1/√(2 R)).
pub const BASE_REPLICAS: usize = 1000;
/// Replicas of each stress window (fewer: there are thousands of windows).
pub const WINDOW_REPLICAS: usize = 200;
/// The trend of the base loads is fitted over this many summary spans: wide enough
/// that it holds little of the noise, narrow enough to follow the heap's shape. What
/// of an M is narrower than it counts as fluctuation, which widens the spread (the
/// cautious side).
pub const TREND_SPANS: usize = 3;
/// |z| from which the dip (or the hump) is called significant: about 2 standard errors.
pub const Z_SIGNIFICANT: f64 = 2.0;

/// For each of `n` places, the place its replica value is taken from: the places are
/// cut into blocks of `block` (the last one shorter), each copied from a start drawn
/// uniformly among all starts of a whole block in the data (the moving block bootstrap;
/// `block` 1 is the ordinary bootstrap).
pub fn blocks(n: usize, block: usize, rng: &mut Rng) -> Vec<usize> {
    let b = block.clamp(1, n.max(1));
    let mut from = Vec::with_capacity(n);
    for j in (0..n).step_by(b) {
        let s = (rng.uniform() * (n - b + 1) as f64) as usize;
        from.extend((s..).take(b.min(n - j)));
    }
    from
}

/// Mean and sample standard deviation (n − 1); NaN deviation for fewer than two.
pub fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, if xs.len() > 1 { var.sqrt() } else { f64::NAN })
}

/// Values averaged over `span` neighbours (an odd number), fewer at the ends.
pub fn smooth(values: &[f64], span: usize) -> Vec<f64> {
    let half = span / 2;
    (0..values.len())
        .map(|k| {
            let (lo, hi) = (k.saturating_sub(half), (k + half + 1).min(values.len()));
            values[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect()
}

/// At each place, the value at that place of the least-squares line through the values
/// within `width` (an odd number) of places around it, fewer at the ends: a trend that
/// follows a straight rise to the end.
pub fn local_line(values: &[f64], width: usize) -> Vec<f64> {
    let half = width / 2;
    (0..values.len())
        .map(|k| {
            let (lo, hi) = (k.saturating_sub(half), (k + half + 1).min(values.len()));
            let n = (hi - lo) as f64;
            let u = |i: usize| i as f64 - k as f64;
            let (mu, mv) = (
                (lo..hi).map(u).sum::<f64>() / n,
                values[lo..hi].iter().sum::<f64>() / n,
            );
            let suu: f64 = (lo..hi).map(|i| (u(i) - mu).powi(2)).sum();
            let suv: f64 = (lo..hi).map(|i| (u(i) - mu) * (values[i] - mv)).sum();
            let slope = if suu > 0.0 { suv / suu } else { 0.0 };
            mv - slope * mu
        })
        .collect()
}

/// The base-load summary of loads ordered by x: averaged over `span` neighbours, the
/// value at the centre place `c` and the largest on each side, the sides starting `span`
/// places from the centre so that they share no load with the centre's average
/// (−∞ for a side with no place).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dip {
    pub centre: f64,
    pub left_max: f64,
    pub right_max: f64,
}

impl Dip {
    pub fn of(loads: &[f64], c: usize, span: usize) -> Dip {
        let s = smooth(loads, span);
        let max = |r: &[f64]| r.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Dip {
            centre: s[c],
            left_max: max(&s[..(c + 1).saturating_sub(span)]),
            right_max: max(s.get(c + span..).unwrap_or(&[])),
        }
    }

    /// D = (left_max + right_max)/2 − centre: positive for an M (paper 001 Fig. 3b),
    /// negative for a hump under the apex.
    pub fn dip(&self) -> f64 {
        0.5 * (self.left_max + self.right_max) - self.centre
    }
}

/// The bootstrap spread of the base-load summary (in the loads' units), flattened into
/// `BaseLoad` in summary.json.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DipSpread {
    pub centre_se: f64,
    pub left_max_se: f64,
    pub right_max_se: f64,
    /// D = (left_max + right_max)/2 − centre.
    pub dip: f64,
    pub dip_se: f64,
    /// The mean and standard deviation of D over replicas of the same fluctuations on
    /// the trend with its sides cut down to the centre's level (a plateau: no dip). A
    /// side maximum picks the highest of many noisy values, so noise alone gives D > 0;
    /// this is how much.
    pub dip_null: f64,
    pub dip_null_sd: f64,
    /// (dip − dip_null)/dip_null_sd: how far the dip stands above what noise makes.
    pub dip_z: f64,
    /// The fraction of the no-dip replicas with a D at least the heap's (one-sided p).
    pub dip_p: f64,
    /// `M` (z ≥ 2), `no significant dip`, or `no sides` when a side has no base
    /// particle.
    pub verdict: String,
    pub bootstrap_replicas: usize,
    /// Block length and trend width, in base particles.
    pub bootstrap_block: usize,
    pub bootstrap_trend: usize,
}

/// The residual block bootstrap (module comment) of `Dip::of(loads, c, span)`:
/// `replicas` replicas from `seed`, blocks of `span`, each drawn onto the trend and onto
/// the no-dip plateau. Also returns the standard error of the smoothed profile at each
/// place (for the band of the base-force plot).
pub fn base_dip(
    loads: &[f64],
    c: usize,
    span: usize,
    replicas: usize,
    seed: u64,
) -> (DipSpread, Vec<f64>) {
    let (block, width) = (span, TREND_SPANS * span);
    let trend = local_line(loads, width);
    let residual: Vec<f64> = loads.iter().zip(&trend).map(|(l, t)| l - t).collect();
    let rms: Vec<f64> = smooth(&residual.iter().map(|e| e * e).collect::<Vec<_>>(), width)
        .iter()
        .map(|v| v.sqrt())
        .collect();
    // The trend took part of each span's own fluctuation: for independent loads of
    // variance σ² the span averages of the residuals have variance σ² (1/span −
    // 1/width), not σ²/span (the line's value mid-window is the window's mean), so the
    // fluctuations are scaled back by √(width/(width − span)).
    let restore = (width as f64 / (width - block) as f64).sqrt();
    let unit: Vec<f64> = (residual.iter().zip(&rms))
        .map(|(e, s)| if *s > 0.0 { restore * e / s } else { 0.0 })
        .collect();
    // The null hypothesis "no M" at its least favourable: nothing beside the centre
    // stands above it, and as much as possible stands level with it (where noise lifts
    // the side maxima most); its fluctuations shrink with it where it is cut down.
    let plateau: Vec<f64> = trend.iter().map(|t| t.min(trend[c])).collect();
    let plateau_rms: Vec<f64> = (rms.iter().zip(&plateau).zip(&trend))
        .map(|((s, p), t)| if *t > 0.0 { s * p.max(0.0) / t } else { *s })
        .collect();
    let replica = |shape: &[f64], size: &[f64], from: &[usize]| -> Vec<f64> {
        (0..shape.len())
            .map(|k| shape[k] + size[k] * unit[from[k]])
            .collect()
    };
    let mut rng = Rng::new(seed);
    let n = loads.len();
    let (mut dips, mut null) = (Vec::with_capacity(replicas), Vec::with_capacity(replicas));
    let mut smoothed: Vec<Vec<f64>> = vec![Vec::with_capacity(replicas); n];
    for _ in 0..replicas {
        let from = blocks(n, block, &mut rng);
        let l = replica(&trend, &rms, &from);
        for (acc, v) in smoothed.iter_mut().zip(smooth(&l, span)) {
            acc.push(v);
        }
        dips.push(Dip::of(&l, c, span));
        null.push(Dip::of(&replica(&plateau, &plateau_rms, &from), c, span).dip());
    }
    let se = |f: fn(&Dip) -> f64| mean_sd(&dips.iter().map(f).collect::<Vec<_>>()).1;
    let dip = Dip::of(loads, c, span).dip();
    let (dip_null, dip_null_sd) = mean_sd(&null);
    let dip_z = (dip - dip_null) / dip_null_sd;
    let verdict = if !dip.is_finite() {
        "no sides"
    } else if dip_z >= Z_SIGNIFICANT {
        "M"
    } else {
        "no significant dip"
    };
    let spread = DipSpread {
        centre_se: se(|d| d.centre),
        left_max_se: se(|d| d.left_max),
        right_max_se: se(|d| d.right_max),
        dip,
        dip_se: se(Dip::dip),
        dip_null,
        dip_null_sd,
        dip_z,
        dip_p: null.iter().filter(|&&d| d >= dip).count() as f64 / replicas as f64,
        verdict: verdict.into(),
        bootstrap_replicas: replicas,
        bootstrap_block: block,
        bootstrap_trend: width,
    };
    (spread, smoothed.iter().map(|v| mean_sd(v).1).collect())
}

/// The standard error of each window's σ_xx and σ_zz (`stress::moving_averages`, same
/// rows and membership): the grains of a window, in order of x, resampled in blocks of
/// `block` (`blocks`: from anywhere in the window, the sample of its own stress),
/// `WINDOW_REPLICAS` times from `SEED`. Returns [se σ_xx, se σ_zz] per window, 0 for an empty one.
pub fn window_se(
    grains: &[Grain],
    moments: &[Tensor],
    windows: &[Window],
    base: f64,
    dz: f64,
    width: f64,
    block: usize,
) -> Vec<[f64; 2]> {
    let mut rng = Rng::new(SEED);
    // Each row's grains in order of x, as moving_averages assigns them to rows.
    let mut rows: Vec<Vec<usize>> =
        vec![Vec::new(); windows.iter().map(|w| w.row + 1).max().unwrap_or(0)];
    for (k, g) in grains.iter().enumerate() {
        let r = ((g.z - base) / dz).floor();
        if r >= 0.0 && (r as usize) < rows.len() {
            rows[r as usize].push(k);
        }
    }
    rows.iter_mut()
        .for_each(|r| r.sort_by(|&p, &q| grains[p].x.total_cmp(&grains[q].x)));
    let area = width * dz;
    windows
        .iter()
        .map(|w| {
            let members: Vec<usize> = rows.get(w.row).map_or(Vec::new(), |r| {
                r.iter()
                    .copied()
                    .filter(|&k| (grains[k].x - w.x).abs() <= 0.5 * width)
                    .collect()
            });
            let n = members.len();
            if n == 0 {
                return [0.0, 0.0];
            }
            let (mut xx, mut zz) = (Vec::new(), Vec::new());
            for _ in 0..WINDOW_REPLICAS {
                let from = blocks(n, block, &mut rng);
                xx.push(from.iter().map(|&i| moments[members[i]].xx).sum::<f64>() / area);
                zz.push(from.iter().map(|&i| moments[members[i]].zz).sum::<f64>() / area);
            }
            [mean_sd(&xx).1, mean_sd(&zz).1]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A standard normal number (Box–Muller), for the tests' synthetic noise.
    fn normal(rng: &mut Rng) -> f64 {
        let u = 1.0 - rng.uniform();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * rng.uniform()).cos()
    }

    #[test]
    fn blocks_copy_runs_of_the_data() {
        let mut rng = Rng::new(3);
        for (n, block) in [(23, 5), (4, 5), (40, 1), (1, 3)] {
            let from = blocks(n, block, &mut rng);
            assert_eq!(from.len(), n);
            for (k, &f) in from.iter().enumerate() {
                assert!(f < n, "{n} {block}: {from:?}");
                // Inside a block, consecutive places are copied from consecutive ones.
                if k % block != 0 {
                    assert_eq!(f, from[k - 1] + 1, "{from:?}");
                }
            }
        }
        // Not always the same start.
        let a = blocks(23, 5, &mut rng);
        assert!((0..20).any(|_| blocks(23, 5, &mut rng) != a));
    }

    #[test]
    fn the_bootstrap_se_of_a_mean_of_iid_normals_is_sigma_over_root_n() {
        // n = 400 samples of N(0, 3²): the se of their mean is 3/20 = 0.15. The
        // bootstrap gives it within 15 % with single values and with blocks of 5.
        let (n, sigma) = (400, 3.0);
        let mut rng = Rng::new(2024);
        let x: Vec<f64> = (0..n).map(|_| sigma * normal(&mut rng)).collect();
        for block in [1, 5] {
            let means: Vec<f64> = (0..2000)
                .map(|_| {
                    blocks(n, block, &mut rng)
                        .iter()
                        .map(|&k| x[k])
                        .sum::<f64>()
                        / n as f64
                })
                .collect();
            let se = mean_sd(&means).1;
            let want = sigma / (n as f64).sqrt();
            assert!(
                (se / want - 1.0).abs() < 0.15,
                "block {block}: se {se}, σ/√n {want}"
            );
        }
    }

    #[test]
    fn the_local_line_follows_a_straight_rise_to_the_ends() {
        // A line is its own trend, ends included (a moving mean would sag there); a
        // parabola's trend at the vertex is the window's mean.
        let line: Vec<f64> = (0..12).map(|k| 2.0 + 0.5 * k as f64).collect();
        for (a, b) in local_line(&line, 7).iter().zip(&line) {
            assert!((a - b).abs() < 1e-12, "{a} {b}");
        }
        let parabola: Vec<f64> = (0..11).map(|k| ((k as f64) - 5.0).powi(2)).collect();
        assert!((local_line(&parabola, 5)[5] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_windows_se_is_the_standard_error_of_its_sum() {
        // 400 grains in one row (z = 0.5, dz = 1) across a window 100 wide: moments
        // m_zz ~ 2 + N(0, 1) give σ_zz = Σ m/100 with se √400 · 1/100 = 0.2 (within
        // 15 %); equal moments m_xx = 3 give se 0; a window with no grain 0.
        let mut rng = Rng::new(9);
        let grains: Vec<Grain> = (0..400)
            .map(|k| Grain {
                id: k,
                x: 0.25 * k as f64,
                z: 0.5,
                theta: 0.0,
                radius: 0.1,
                mass: 1.0,
                fixed: false,
                area: 0.03,
                corners: Vec::new(),
                ..Default::default()
            })
            .collect();
        let moments: Vec<Tensor> = (0..400)
            .map(|_| Tensor {
                xx: 3.0,
                zz: 2.0 + normal(&mut rng),
                ..Default::default()
            })
            .collect();
        let window = |x: f64| Window {
            row: 0,
            z_lo: 0.0,
            z_hi: 1.0,
            x,
            particles: 0,
            sigma: Tensor::default(),
        };
        let se = window_se(
            &grains,
            &moments,
            &[window(50.0), window(500.0)],
            0.0,
            1.0,
            100.0,
            5,
        );
        assert_eq!(se[0][0], 0.0);
        assert!((se[0][1] / 0.2 - 1.0).abs() < 0.15, "{se:?}");
        assert_eq!(se[1], [0.0, 0.0]);
    }

    #[test]
    fn the_dip_takes_the_sides_beyond_the_centres_average() {
        // Eleven loads, span 3, centre 5 (average 4): the left side is places 0..=2
        // (largest 3 at place 2; places 3 and 4, averaging 6 and 5, share loads with the
        // centre's average), the right 8..=10 (largest 5 at the end, over two loads).
        let loads = [0.0, 0.0, 6.0, 3.0, 9.0, 3.0, 0.0, 0.0, 2.0, 2.0, 8.0];
        let d = Dip::of(&loads, 5, 3);
        assert_eq!((d.centre, d.left_max, d.right_max), (4.0, 3.0, 5.0));
        assert_eq!(d.dip(), 0.0);
        // No place on the left: −∞, and the dip is not a number.
        assert_eq!(Dip::of(&loads, 1, 3).left_max, f64::NEG_INFINITY);
    }

    /// 81 base loads under a heap, 10 (1 − x²) (1 + a x²) with x from −1 to 1: for a = 0
    /// a parabola (a hump), for a = 3.3 a broad M as paper 001 Fig. 3b, maxima 40 % above
    /// the centre at x = ±0.59; times 1 + `noise` N(0, 1) (force-chain noise).
    fn heap_loads(m: bool, noise: f64, seed: u64) -> Vec<f64> {
        let mut rng = Rng::new(seed);
        let a = if m { 3.3 } else { 0.0 };
        (0..81)
            .map(|k| {
                let u = ((k as f64 - 40.0) / 40.0).powi(2);
                10.0 * (1.0 - u) * (1.0 + a * u) * (1.0 + noise * normal(&mut rng))
            })
            .collect()
    }

    #[test]
    fn a_clear_m_is_called_m_and_a_plain_heap_is_not() {
        let mut m_calls = 0;
        let mut hump_calls = 0;
        for seed in 0..20 {
            let (m, _) = base_dip(&heap_loads(true, 0.15, seed), 40, 5, 400, SEED);
            assert!(m.dip > 0.0, "seed {seed}: {m:?}");
            m_calls += (m.verdict == "M") as usize;
            let (f, _) = base_dip(&heap_loads(false, 0.3, seed), 40, 5, 400, SEED);
            hump_calls += (f.verdict == "M") as usize;
            // Noise alone lifts the side maxima: the no-dip mean is positive.
            assert!(f.dip_null > 0.0, "seed {seed}: {f:?}");
        }
        assert!(m_calls >= 18, "an M called M in {m_calls} of 20 heaps");
        assert!(
            hump_calls <= 2,
            "a parabola called M in {hump_calls} of 20 heaps"
        );
    }

    #[test]
    fn a_flat_noisy_base_has_no_significant_dip_in_most_seeds() {
        // Flat mean 10, noise 3 (a third): the raw D is positive from the maxima of the
        // noise; after the bias, at most a few of 40 seeds reach z = 2.
        let mut significant = 0;
        let mut raw_positive = 0;
        for seed in 100..140 {
            let mut rng = Rng::new(seed);
            let loads: Vec<f64> = (0..81).map(|_| 10.0 + 3.0 * normal(&mut rng)).collect();
            let (s, _) = base_dip(&loads, 40, 5, 400, SEED);
            significant += (s.dip_z.abs() >= Z_SIGNIFICANT) as usize;
            raw_positive += (s.dip > 0.0) as usize;
        }
        assert!(
            significant <= 4,
            "{significant} of 40 flat bases significant"
        );
        assert!(
            raw_positive >= 30,
            "the raw dip is biased: {raw_positive} of 40 > 0"
        );
    }

    #[test]
    fn the_same_loads_give_the_same_spread_and_other_seeds_differ() {
        let loads = heap_loads(true, 0.3, 5);
        let (a, sa) = base_dip(&loads, 40, 5, 300, SEED);
        let (b, sb) = base_dip(&loads, 40, 5, 300, SEED);
        assert_eq!(format!("{a:?}{sa:?}"), format!("{b:?}{sb:?}"));
        let (c, _) = base_dip(&loads, 40, 5, 300, SEED + 1);
        assert_ne!(a.dip_se, c.dip_se);
        assert_eq!(a.dip, c.dip);
    }
}
