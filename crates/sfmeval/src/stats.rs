//! Summary statistics of a list of distances: count, min, max, mean, population std, median,
//! RMS, percentiles (linear interpolation between order statistics, as numpy's default) and a
//! histogram. Sums run in input order, so results do not depend on thread count.

use serde::{Deserialize, Serialize};

/// Percentiles reported in every statistics block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Percentiles {
    /// 50th percentile (the median).
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 95th percentile.
    pub p95: f64,
    /// 99th percentile.
    pub p99: f64,
}

/// A histogram with `edges.len() == counts.len() + 1`; the last bin includes its right edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Histogram {
    /// Bin edges, increasing.
    pub edges: Vec<f64>,
    /// Values per bin.
    pub counts: Vec<u64>,
}

/// Statistics of a set of values. All zero when `count == 0`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Statistics {
    /// Number of values.
    pub count: u64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Arithmetic mean.
    pub mean: f64,
    /// Population standard deviation (divides by n).
    pub std: f64,
    /// Median (= p50).
    pub median: f64,
    /// Root mean square.
    pub rms: f64,
    /// Percentiles.
    pub percentiles: Percentiles,
    /// Histogram.
    pub histogram: Histogram,
}

/// Default number of histogram bins.
pub const DEFAULT_BINS: usize = 50;

/// Linear-interpolated percentile `q` in [0, 100] of sorted values.
pub fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => 0.0,
        1 => sorted[0],
        n => {
            let pos = (q / 100.0).clamp(0.0, 1.0) * (n - 1) as f64;
            let lo = pos.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            let frac = pos - lo as f64;
            sorted[lo] + (sorted[hi] - sorted[lo]) * frac
        }
    }
}

impl Statistics {
    /// Computes the statistics of `values` (NaNs must not be present). The histogram spans
    /// `[min(0, min), max]` in `bins` equal bins (`[min, max]` for signed values).
    pub fn of(values: &[f64], bins: usize) -> Statistics {
        let n = values.len();
        if n == 0 {
            return Statistics::default();
        }
        let mut sorted = values.to_vec();
        sorted.sort_unstable_by(f64::total_cmp);
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for &v in values {
            sum += v;
            sum_sq += v * v;
        }
        let nf = n as f64;
        let mean = sum / nf;
        let mut dev = 0.0f64;
        for &v in values {
            dev += (v - mean) * (v - mean);
        }
        let min = sorted[0];
        let max = sorted[n - 1];
        let lo = if min >= 0.0 { 0.0 } else { min };
        let p50 = percentile_sorted(&sorted, 50.0);
        Statistics {
            count: n as u64,
            min,
            max,
            mean,
            std: (dev / nf).sqrt(),
            median: p50,
            rms: (sum_sq / nf).sqrt(),
            percentiles: Percentiles {
                p50,
                p90: percentile_sorted(&sorted, 90.0),
                p95: percentile_sorted(&sorted, 95.0),
                p99: percentile_sorted(&sorted, 99.0),
            },
            histogram: histogram(&sorted, lo, max, bins),
        }
    }
}

/// Histogram of values into `bins` equal bins over `[lo, hi]`; values outside are clamped into
/// the first/last bin.
pub fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Histogram {
    let bins = bins.max(1);
    let width = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        1.0
    };
    let edges = (0..=bins)
        .map(|i| {
            if i == bins {
                hi.max(lo)
            } else {
                lo + width * i as f64
            }
        })
        .collect();
    let mut counts = vec![0u64; bins];
    for &v in values {
        let b = (((v - lo) / width).floor().max(0.0) as usize).min(bins - 1);
        counts[b] += 1;
    }
    Histogram { edges, counts }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed() {
        let s = Statistics::of(&[1.0, 2.0, 3.0, 4.0], 4);
        assert_eq!(s.count, 4);
        assert_eq!(s.mean, 2.5);
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-15);
        assert_eq!(s.median, 2.5);
        assert!((s.rms - 7.5f64.sqrt()).abs() < 1e-15);
        // numpy.percentile([1,2,3,4], 90) = 3.7
        assert!((s.percentiles.p90 - 3.7).abs() < 1e-12);
        assert_eq!(s.histogram.edges, vec![0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.histogram.counts, vec![0, 1, 1, 2]);
    }

    #[test]
    fn empty_and_single() {
        assert_eq!(Statistics::of(&[], 10).count, 0);
        let s = Statistics::of(&[0.5], 10);
        assert_eq!((s.min, s.max, s.median, s.std), (0.5, 0.5, 0.5, 0.0));
        assert_eq!(s.histogram.counts.iter().sum::<u64>(), 1);
    }
}
