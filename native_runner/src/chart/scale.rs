//! Axis scales of the charts: round tick values and their labels.

/// Heckbert's "nice number" ≥ (or ≈ when `round`) x: 1, 2, 5 × 10ⁿ.
fn nice_num(x: f64, round: bool) -> f64 {
    let e = x.log10().floor();
    let p = 10f64.powf(e);
    let f = x / p;
    let nf = if round {
        if f < 1.5 {
            1.0
        } else if f < 3.0 {
            2.0
        } else if f < 7.0 {
            5.0
        } else {
            10.0
        }
    } else if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    nf * p
}

/// About `target` evenly spaced round ticks covering `[lo, hi]` (the first ≤ lo, the last ≥
/// hi). Non-finite bounds give `[0, 1]`; an empty range is widened by 10 % (or ±1 around 0).
pub fn nice_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let (mut lo, mut hi) = if lo.is_finite() && hi.is_finite() {
        (lo.min(hi), lo.max(hi))
    } else {
        (0.0, 1.0)
    };
    if hi - lo <= f64::EPSILON * lo.abs().max(hi.abs()) {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        lo -= pad;
        hi += pad;
    }
    let target = target.max(2);
    let step = nice_num(nice_num(hi - lo, false) / (target - 1) as f64, true);
    let first = (lo / step).floor();
    let last = (hi / step).ceil();
    let n = (last - first).round() as i64;
    (0..=n)
        .map(|k| {
            let v = (first + k as f64) * step;
            // snap to the step's decimals so labels and tests see 0.3, not 0.30000000000000004
            let digits = (-step.log10().floor()).max(0.0) as i32 + 1;
            let s = 10f64.powi(digits);
            (v * s).round() / s
        })
        .collect()
}

/// Decade ticks 10ⁿ covering `[lo, hi]` (both > 0).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let a = lo.log10().floor() as i32;
    let b = hi.log10().ceil().max(a as f64 + 1.0) as i32;
    (a..=b).map(|e| 10f64.powi(e)).collect()
}

/// A tick label: plain decimals for ordinary magnitudes, scientific otherwise.
pub fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{v:.0e}");
        return s;
    }
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// The y scale of the finite values: `(ticks, log)`. Linear from 0 when every value is ≥ 0;
/// logarithmic when all are > 0 and span more than three decades (one broken run would
/// otherwise flatten every other line).
pub fn y_scale(values: &[f64]) -> (Vec<f64>, bool) {
    let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (nice_ticks(0.0, 1.0, 5), false);
    }
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo > 0.0 && hi / lo > 1000.0 {
        return (log_ticks(lo, hi), true);
    }
    let lo = if lo >= 0.0 { 0.0 } else { lo };
    (nice_ticks(lo, hi, 5), false)
}

/// The smallest of 1, 2, 2.5, 5, 10 × 10ⁿ that is ≥ `v`: the top of a bar or cumulative
/// chart's axis (1 when `v` is not > 0).
pub fn nice_max(v: f64) -> f64 {
    if !(v > 0.0) {
        return 1.0;
    }
    let e = 10f64.powf(v.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if v <= m * e {
            return m * e;
        }
    }
    10.0 * e
}

/// A short tick label of a bar or cumulative chart: `0`, whole numbers from 100, one decimal
/// from 1, scientific with two decimals below (`2.50e-3`).
pub fn short_tick_label(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(nice_ticks(0.0, 1.0, 5), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(nice_ticks(0.0, 0.87, 5), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(nice_ticks(0.0, 37.0, 5), vec![0.0, 10.0, 20.0, 30.0, 40.0]);
        assert_eq!(
            nice_ticks(0.0012, 0.0047, 5),
            vec![0.001, 0.002, 0.003, 0.004, 0.005]
        );
        let t = nice_ticks(-3.2, 7.9, 5);
        assert!(t[0] <= -3.2 && *t.last().unwrap() >= 7.9);
        assert_eq!(t, vec![-5.0, 0.0, 5.0, 10.0]);
        // reversed bounds, an empty range, non-finite bounds
        assert_eq!(nice_ticks(1.0, 0.0, 5), nice_ticks(0.0, 1.0, 5));
        let t = nice_ticks(5.0, 5.0, 5);
        assert!(t[0] < 5.0 && *t.last().unwrap() > 5.0, "{t:?}");
        assert_eq!(nice_ticks(0.0, 0.0, 5), vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        assert_eq!(nice_ticks(f64::NAN, 3.0, 5), nice_ticks(0.0, 1.0, 5));
        assert_eq!(nice_ticks(0.0, f64::INFINITY, 5), nice_ticks(0.0, 1.0, 5));
    }

    #[test]
    fn y_scale_ignores_nan_starts_at_zero_and_goes_log_over_decades() {
        let (t, log) = y_scale(&[0.5, f64::NAN, 0.9, f64::INFINITY]);
        assert!(!log);
        assert_eq!(t, vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        let (t, log) = y_scale(&[f64::NAN]);
        assert!(!log && t[0] == 0.0 && *t.last().unwrap() == 1.0);
        let (t, log) = y_scale(&[0.002, 0.004, 4.3]);
        assert!(log);
        assert_eq!(t, vec![0.001, 0.01, 0.1, 1.0, 10.0]);
        let (t, log) = y_scale(&[-2.0, 3.0]);
        assert!(!log && t[0] <= -2.0 && *t.last().unwrap() >= 3.0);
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(1e-5), "1e-5");
        assert_eq!(tick_label(20.0), "20");
    }

    #[test]
    fn bar_axis_tops_and_labels() {
        assert_eq!(nice_max(0.0), 1.0);
        assert_eq!(nice_max(f64::NAN), 1.0);
        assert_eq!(nice_max(0.0043), 0.005);
        assert_eq!(nice_max(2.2), 2.5);
        assert_eq!(nice_max(100.0), 100.0);
        assert_eq!(short_tick_label(0.0), "0");
        assert_eq!(short_tick_label(250.0), "250");
        assert_eq!(short_tick_label(2.5), "2.5");
        assert_eq!(short_tick_label(0.0025), "2.50e-3");
    }
}
