//! Precision, recall, F-score and the cumulative distance curves exactly as the toolbox's
//! `get_f1_score_histo2` computes them (with NumPy): P and R are the shares of distances strictly
//! below τ; the curves are `cumsum(histogram(d, bins)) / len(d)` with
//! `bins = numpy.arange(0, τ·stretch, τ/100)`, the last bin closed on the right.

use std::fmt::Write as _;

use serde::Serialize;

/// P, R, F and the two cumulative curves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scores {
    /// Share of reconstruction points within τ of the ground truth.
    pub precision: f64,
    /// Share of ground-truth points within τ of the reconstruction.
    pub recall: f64,
    /// Harmonic mean of the two (0 when both are 0).
    pub f_score: f64,
    /// The bin edges (`numpy.arange(0, τ·stretch, τ/100)`).
    pub edges: Vec<f64>,
    /// Cumulative share of reconstruction points per bin (the toolbox's `cum_source`).
    pub precision_curve: Vec<f64>,
    /// Cumulative share of ground-truth points per bin (`cum_target`).
    pub recall_curve: Vec<f64>,
}

/// `numpy.arange(0, stop, step)` for doubles: `ceil(stop / step)` values `i · step`.
pub fn arange(stop: f64, step: f64) -> Vec<f64> {
    let len = libm::ceil(stop / step);
    if !(len.is_finite() && len > 0.0) {
        return Vec::new();
    }
    (0..len as usize).map(|i| i as f64 * step).collect()
}

/// The cumulative histogram of `sorted` (ascending): entry `k` is the share of the distances
/// below `edges[k + 1]` (at most it for the last one), as
/// `cumsum(numpy.histogram(d, edges)[0]) / len(d)`.
pub fn cumulative(sorted: &[f64], edges: &[f64]) -> Vec<f64> {
    if edges.len() < 2 || sorted.is_empty() {
        return Vec::new();
    }
    let n = sorted.len() as f64;
    let first = sorted.partition_point(|d| *d < edges[0]);
    let last = edges.len() - 1;
    edges[1..]
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let below = if k + 1 == last {
                sorted.partition_point(|d| d <= e)
            } else {
                sorted.partition_point(|d| d < e)
            };
            (below - first) as f64 / n
        })
        .collect()
}

/// Scores at `tau` with the toolbox's plot stretch (5): distances of the reconstruction to the
/// ground truth (`precision_distances`) and back (`recall_distances`), each sorted ascending.
/// Empty inputs give zeros and one-entry curves, as the toolbox returns.
pub fn scores(
    precision_distances: &[f64],
    recall_distances: &[f64],
    tau: f64,
    stretch: f64,
) -> Scores {
    if precision_distances.is_empty() || recall_distances.is_empty() {
        return Scores {
            precision: 0.0,
            recall: 0.0,
            f_score: 0.0,
            edges: vec![0.0],
            precision_curve: vec![0.0],
            recall_curve: vec![0.0],
        };
    }
    let share = |d: &[f64]| d.partition_point(|d| *d < tau) as f64 / d.len() as f64;
    let precision = share(precision_distances);
    let recall = share(recall_distances);
    let f_score = if precision + recall > 0.0 {
        2.0 * recall * precision / (recall + precision)
    } else {
        0.0
    };
    let edges = arange(tau * stretch, tau / 100.0);
    Scores {
        precision,
        recall,
        f_score,
        precision_curve: cumulative(precision_distances, &edges),
        recall_curve: cumulative(recall_distances, &edges),
        edges,
    }
}

/// One number as C's `%.18e` (NumPy's `savetxt` default): 18 decimals, a signed exponent of at
/// least two digits.
pub fn format_e18(v: f64) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            "nan".into()
        } else if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    let s = format!("{v:.18e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
    let (sign, digits) = match exponent.strip_prefix('-') {
        Some(d) => ('-', d),
        None => ('+', exponent),
    };
    format!("{mantissa}e{sign}{digits:0>2}")
}

/// Values one per line in `%.18e`, as `numpy.savetxt(path, values)` writes a 1-D array.
pub fn savetxt(values: &[f64]) -> String {
    let mut s = String::with_capacity(values.len() * 26);
    for v in values {
        let _ = writeln!(s, "{}", format_e18(*v));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numpy_semantics() {
        // numpy.arange(0, 0.015, 0.00003) has 500 values (ceil of 499.99999999999994).
        assert_eq!(arange(0.003 * 5.0, 0.003 / 100.0).len(), 500);
        assert_eq!(arange(1.0, 0.25), vec![0.0, 0.25, 0.5, 0.75]);
        let edges = [0.0, 1.0, 2.0, 3.0];
        let d = [0.0, 0.5, 1.0, 2.5, 3.0, 3.5];
        // histogram: [0,1): 2, [1,2): 1, [2,3]: 2 (3.0 included, 3.5 not); cumsum / 6.
        assert_eq!(
            cumulative(&d, &edges),
            vec![2.0 / 6.0, 3.0 / 6.0, 5.0 / 6.0]
        );
        let s = scores(&[0.1, 0.2, 0.5], &[0.1, 0.6], 0.3, 5.0);
        assert_eq!((s.precision, s.recall), (2.0 / 3.0, 0.5));
        assert!((s.f_score - 2.0 * (2.0 / 3.0) * 0.5 / (2.0 / 3.0 + 0.5)).abs() < 1e-15);
        assert_eq!(s.edges.len(), s.precision_curve.len() + 1);
        assert_eq!(scores(&[], &[0.1], 0.3, 5.0).f_score, 0.0);
    }

    #[test]
    fn savetxt_format() {
        assert_eq!(format_e18(0.5), "5.000000000000000000e-01");
        assert_eq!(format_e18(0.0), "0.000000000000000000e+00");
        assert_eq!(format_e18(5.0), "5.000000000000000000e+00");
        assert_eq!(format_e18(1e-100), "1.000000000000000020e-100");
        assert_eq!(format_e18(-2.5e12), "-2.500000000000000000e+12");
        assert_eq!(
            savetxt(&[1.0, 0.25]),
            "1.000000000000000000e+00\n2.500000000000000000e-01\n"
        );
    }
}
