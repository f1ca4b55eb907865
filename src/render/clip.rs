//! Cutting what a picture draws to its view.

/// The part of segment a–b inside the box from `lo` to `hi` (Liang–Barsky), if any.
pub(super) fn clip(
    a: [f64; 2],
    b: [f64; 2],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for axis in 0..2 {
        for (p, q) in [
            (-d[axis], a[axis] - lo[axis]),
            (d[axis], hi[axis] - a[axis]),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else if p < 0.0 {
                t0 = t0.max(q / p);
            } else {
                t1 = t1.min(q / p);
            }
        }
    }
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    (t0 <= t1).then(|| (at(t0), at(t1)))
}

#[cfg(test)]
mod tests {
    use super::clip;

    #[test]
    fn a_wall_is_cut_to_the_view() {
        let (lo, hi) = ([0.0, 0.0], [10.0, 5.0]);
        // A floor far wider than the view: its middle part.
        let (a, b) = clip([-100.0, 1.0], [100.0, 1.0], lo, hi).unwrap();
        assert!(
            (a[0] - 0.0).abs() < 1e-12 && (b[0] - 10.0).abs() < 1e-12,
            "{a:?} {b:?}"
        );
        assert_eq!((a[1], b[1]), (1.0, 1.0));
        // A side wall reaching below and above it.
        assert_eq!(
            clip([2.0, -3.0], [2.0, 30.0], lo, hi),
            Some(([2.0, 0.0], [2.0, 5.0]))
        );
        // Inside, as it is; outside, nothing.
        assert_eq!(
            clip([1.0, 1.0], [3.0, 2.0], lo, hi),
            Some(([1.0, 1.0], [3.0, 2.0]))
        );
        assert_eq!(clip([-5.0, -1.0], [20.0, -1.0], lo, hi), None);
        assert_eq!(clip([-5.0, 0.0], [0.0, 10.0], lo, hi), None);
    }
}
