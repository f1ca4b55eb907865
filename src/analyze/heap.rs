//! The heap's free surface, the angle of repose on each side (straight-line fits
//! excluding apex and toe, SPEC 5), and the pressure the base wall carries.

use super::input::{Grain, Touch};
use super::outline::Outline;

/// A point of the free surface: the highest top within a bin, and which grain it is.
#[derive(Clone, Debug)]
pub struct SurfacePoint {
    pub x: f64,
    pub z: f64,
    pub grain: usize,
    /// -1 left of the apex, +1 right, 0 the apex bin.
    pub side: i8,
    pub fitted: bool,
}

/// The free surface in bins of width `bin` across the outline.
pub fn surface(grains: &[Grain], o: &Outline, bin: f64) -> Vec<SurfacePoint> {
    let n = (o.width / bin).ceil().max(1.0) as usize;
    let mut best: Vec<Option<(f64, usize)>> = vec![None; n];
    let any_mobile = grains.iter().any(|g| !g.fixed);
    for (k, g) in grains.iter().enumerate() {
        if (any_mobile && g.fixed) || g.x < o.left || g.x > o.right {
            continue;
        }
        let b = (((g.x - o.left) / bin).floor().max(0.0) as usize).min(n - 1);
        let top = g.top();
        if best[b].is_none_or(|(z, _)| top > z) {
            best[b] = Some((top, k));
        }
    }
    let apex_bin = (((o.apex_x - o.left) / bin).floor().max(0.0) as usize).min(n - 1);
    best.iter()
        .enumerate()
        .filter_map(|(b, v)| {
            v.map(|(z, k)| SurfacePoint {
                x: o.left + (b as f64 + 0.5) * bin,
                z,
                grain: k,
                side: (b as i64 - apex_bin as i64).signum() as i8,
                fitted: false,
            })
        })
        .collect()
}

/// A straight-line fit of one free slope.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Slope {
    /// Angle of repose in degrees (positive for a slope falling away from the apex).
    pub angle_deg: f64,
    /// RMS distance of the fitted points from the line, vertical, in length units.
    pub residual: f64,
    pub points: usize,
    /// The line's ends over the points it was read from, [[x, z], [x, z]] (NaN where
    /// there is no line): what the pictures draw.
    pub line: [[f64; 2]; 2],
}

/// No line.
const NO_LINE: [[f64; 2]; 2] = [[f64::NAN; 2]; 2];

impl std::fmt::Display for Slope {
    /// The angle with its fit, or why there is none (a box deposit has no free slope
    /// between the fitted heights).
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        if self.angle_deg.is_finite() {
            let (angle, rms, n) = (self.angle_deg, self.residual, self.points);
            write!(f, "{angle:.1}° (rms {rms:.2e}, {n} points)")
        } else {
            write!(
                f,
                "none ({} surface points in the fitted band)",
                self.points
            )
        }
    }
}

/// Fits both slopes to the surface points whose height above the base lies between
/// `lo` and `hi` (fractions of the height), which leaves out the apex and the toe.
pub fn repose(surface: &mut [SurfacePoint], o: &Outline, lo: f64, hi: f64) -> (Slope, Slope) {
    let mut fit = |side: i8| {
        let mut pts = Vec::new();
        for p in surface.iter_mut() {
            let h = (p.z - o.base) / o.height;
            if p.side == side && h >= lo && h <= hi {
                p.fitted = true;
                pts.push((p.x, p.z));
            }
        }
        line_fit(&pts, side)
    };
    (fit(-1), fit(1))
}

/// The least-squares line through `pts` as the slope of a flank on `side` (-1 left of
/// the apex, +1 right): its angle falling away from the apex and its RMS residual.
fn line_fit(pts: &[(f64, f64)], side: i8) -> Slope {
    let n = pts.len();
    if n < 2 {
        return Slope {
            points: n,
            angle_deg: f64::NAN,
            residual: f64::NAN,
            line: NO_LINE,
        };
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let mz = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxz: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - mz)).sum();
    let b = sxz / sxx;
    let res = (pts
        .iter()
        .map(|p| (p.1 - mz - b * (p.0 - mx)).powi(2))
        .sum::<f64>()
        / n as f64)
        .sqrt();
    let (x0, x1) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    let at = |x: f64| [x, mz + b * (x - mx)];
    Slope {
        angle_deg: (b * -(side as f64)).atan().to_degrees(),
        residual: res,
        points: n,
        line: [at(x0), at(x1)],
    }
}

/// The angle of repose of each flank read three more ways than `repose`'s band
/// (issue 39: paper 001 reads "the angle between the inclined surface and the base" off
/// its Fig. 1, and a heap with a rounded cap and a foot running out over the base reads
/// differently by each rule). [left, right].
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Readings {
    /// A fit to the middle third of the height: the cap (top third) and the foot
    /// (bottom third) left out.
    pub middle: [Slope; 2],
    /// The line from the apex (the top of the highest grain) to the toe (the outer
    /// edge of the outline at the base): atan(height / run).
    pub apex_toe: [Slope; 2],
    /// The steepest fit over any run of consecutive surface points a third of the
    /// flank's points long (at least 4): the steepest stretch. Biased upwards by the
    /// surface's grain-scale roughness (a maximum over noisy fits).
    pub steepest: [Slope; 2],
}

impl Readings {
    /// Both flanks' mean angle of a reading, in degrees.
    pub fn mean(r: &[Slope; 2]) -> f64 {
        0.5 * (r[0].angle_deg + r[1].angle_deg)
    }
}

/// The readings of both flanks of `surface` (`Readings`).
pub fn readings(surface: &[SurfacePoint], o: &Outline) -> Readings {
    let mut r = Readings::default();
    for (k, side) in [(0, -1i8), (1, 1)] {
        // The flank from the apex outwards.
        let mut flank: Vec<(f64, f64)> = (surface.iter())
            .filter(|p| p.side == side)
            .map(|p| (p.x, p.z))
            .collect();
        flank.sort_by(|a, b| (side as f64 * a.0).total_cmp(&(side as f64 * b.0)));
        let h = |p: &(f64, f64)| (p.1 - o.base) / o.height;
        let middle: Vec<(f64, f64)> = (flank.iter())
            .filter(|p| (1.0 / 3.0..=2.0 / 3.0).contains(&h(p)))
            .copied()
            .collect();
        r.middle[k] = line_fit(&middle, side);
        let toe = if side < 0 { o.left } else { o.right };
        let run = (toe - o.apex_x).abs();
        r.apex_toe[k] = Slope {
            angle_deg: if run > 0.0 {
                (o.height / run).atan().to_degrees()
            } else {
                f64::NAN
            },
            residual: f64::NAN,
            points: 2,
            line: [[o.apex_x, o.top], [toe, o.base]],
        };
        let w = flank.len().div_ceil(3).max(4);
        r.steepest[k] = (flank.windows(w))
            .map(|pts| line_fit(pts, side))
            .filter(|s| s.angle_deg.is_finite())
            .max_by(|a, b| a.angle_deg.total_cmp(&b.angle_deg))
            .unwrap_or_else(|| line_fit(&[], side));
    }
    r
}

/// The base pressure from wall contacts: the vertical force the walls carry from grains
/// centred within each window of `width`, per unit length, at centres every `step`.
pub fn wall_pressure(
    grains: &[Grain],
    touches: &[Touch],
    o: &Outline,
    width: f64,
    step: f64,
) -> Vec<(f64, f64)> {
    let columns = (o.width / step).floor() as usize + 1;
    let walls: Vec<(f64, f64)> = touches
        .iter()
        .filter(|t| t.b.is_none())
        .map(|t| (grains[t.a].x, t.force[1]))
        .collect();
    (0..columns)
        .map(|c| {
            let x = o.left + c as f64 * step;
            let f: f64 = walls
                .iter()
                .filter(|(gx, _)| (gx - x).abs() <= 0.5 * width)
                .map(|(_, fz)| fz)
                .sum();
            (x, f / width)
        })
        .collect()
}

/// The load on one fixed base particle (paper 001 Fig. 3b: the normal force on the base).
#[derive(Clone, Debug)]
pub struct BaseForce {
    pub grain: usize,
    pub x: f64,
    /// The downward force the mobile grains press onto it.
    pub load: f64,
}

/// The loads on the fixed grains from the mobile ones, by x; empty without fixed grains
/// (a wall base is measured by [`wall_pressure`]).
pub fn base_forces(grains: &[Grain], touches: &[Touch]) -> Vec<BaseForce> {
    let mut load = vec![0.0; grains.len()];
    let mut touched = vec![false; grains.len()];
    for t in touches {
        let Some(b) = t.b else { continue };
        // The force on a is t.force, on b its opposite; the load is the force's
        // downward part on the fixed one.
        for (k, other, fz) in [(t.a, b, t.force[1]), (b, t.a, -t.force[1])] {
            if grains[k].fixed && !grains[other].fixed {
                load[k] -= fz;
                touched[k] = true;
            }
        }
    }
    let mut out: Vec<BaseForce> = (0..grains.len())
        .filter(|&k| grains[k].fixed && touched[k])
        .map(|k| BaseForce {
            grain: k,
            x: grains[k].x,
            load: load[k],
        })
        .collect();
    out.sort_by(|p, q| p.x.total_cmp(&q.x));
    out
}

/// The base loads averaged over `span` neighbouring base particles (an odd number),
/// fewer at the ends: the M profile without the particle-to-particle raggedness.
pub fn smoothed_loads(base: &[BaseForce], span: usize) -> Vec<(f64, f64)> {
    let loads: Vec<f64> = base.iter().map(|b| b.load).collect();
    (base.iter().zip(super::spread::smooth(&loads, span)))
        .map(|(b, mean)| (b.x, mean))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trapezoid heap 10 high: a flat cap 10 wide, flanks at 40° (left) and 30°
    /// (right) from the cap down to a foot 1 high that runs out 6 further. Every reading
    /// finds the flanks' angle where its rule sees only the flank, and departs from it
    /// by what its rule takes in of the cap and the foot.
    #[test]
    fn each_reading_of_the_angle_follows_its_rule() {
        let (lt, rt) = (40f64.to_radians().tan(), 30f64.to_radians().tan());
        // From the apex outwards: cap to x = ±5, flank down to z = 1, foot at z = 1.
        let (l_run, r_run) = (9.0 / lt, 9.0 / rt);
        let height = |x: f64| {
            let (t, run) = if x < 0.0 { (lt, l_run) } else { (rt, r_run) };
            let a = x.abs() - 5.0;
            if a <= 0.0 {
                10.0
            } else if a <= run {
                10.0 - t * a
            } else {
                1.0
            }
        };
        let (left, right) = (-(5.0 + l_run + 6.0), 5.0 + r_run + 6.0);
        let o = Outline {
            base: 0.0,
            top: 10.0,
            height: 10.0,
            left,
            right,
            width: right - left,
            apex_x: 0.0,
        };
        let n = (o.width / 0.25) as usize;
        let surface: Vec<SurfacePoint> = (0..n)
            .map(|k| {
                let x = left + (k as f64 + 0.5) * 0.25;
                SurfacePoint {
                    x,
                    z: height(x),
                    grain: k,
                    side: (x.signum() as i8) * (x.abs() > 0.125) as i8,
                    fitted: false,
                }
            })
            .collect();
        let r = readings(&surface, &o);
        // The middle third (heights 3.3–6.7) lies on the flanks alone.
        let a = |s: &[Slope; 2]| [s[0].angle_deg, s[1].angle_deg];
        let (middle, apex_toe, steepest) = (a(&r.middle), a(&r.apex_toe), a(&r.steepest));
        assert!((middle[0] - 40.0).abs() < 1e-9 && (middle[1] - 30.0).abs() < 1e-9);
        // Apex to toe: the cap and the foot lengthen the run.
        let want = |run: f64| (10f64 / (5.0 + run + 6.0)).atan().to_degrees();
        assert!((apex_toe[0] - want(l_run)).abs() < 1e-12);
        assert!((apex_toe[1] - want(r_run)).abs() < 1e-12);
        assert!(apex_toe[0] < 30.0 && apex_toe[1] < 25.0);
        assert_eq!(r.apex_toe[1].line, [[0.0, 10.0], [right, 0.0]]);
        // The steepest stretch is the flank itself where a third of the points fit on
        // it: the right flank is 15.6 long of 32.6 from the apex.
        assert!((steepest[1] - 30.0).abs() < 1e-9, "{steepest:?}");
        // Each fitted line lies on the flank it read: at its ends, the heap's surface.
        for s in [&r.middle[1], &r.steepest[1]] {
            for [x, z] in s.line {
                assert!((z - height(x)).abs() < 1e-9, "{:?}", s.line);
            }
        }
        // The band 15–85 % sees the flanks alone here (the foot is 10 % high); a band
        // from 5 % takes in the foot and reads low.
        let mut s = surface.clone();
        let (band_l, band_r) = repose(&mut s, &o, 0.15, 0.85);
        assert!((band_l.angle_deg - 40.0).abs() < 1e-9 && (band_r.angle_deg - 30.0).abs() < 1e-9);
        let (low_l, low_r) = repose(&mut s, &o, 0.05, 0.85);
        assert!(low_l.angle_deg < 38.0 && low_r.angle_deg < 28.0);
    }

    #[test]
    fn a_slope_prints_its_fit_or_that_there_is_none() {
        let fitted = Slope {
            angle_deg: 31.25,
            residual: 0.012,
            points: 40,
            line: NO_LINE,
        };
        assert_eq!(fitted.to_string(), "31.2° (rms 1.20e-2, 40 points)");
        let outline = Outline {
            base: 0.0,
            top: 1.0,
            height: 1.0,
            left: -1.0,
            right: 1.0,
            width: 2.0,
            apex_x: 0.0,
        };
        let (left, right) = repose(&mut [], &outline, 0.2, 0.8);
        assert_eq!(left.points, 0);
        assert_eq!(
            right.to_string(),
            "none (0 surface points in the fitted band)"
        );
    }
}
