//! Summary statistics of a list of distances: count, min, max, mean, population std, median,
//! RMS, percentiles (linear interpolation between order statistics, as numpy's default) and a
//! histogram. Sums run in input order, so results do not depend on thread count.

use serde::{Deserialize, Serialize};

use crate::parallel;

/// Percentiles reported in every statistics block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
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
/// Values below the first edge or above the last are not in any bin but counted in
/// `underflow` / `overflow`, so `counts` + both always add up to the number of values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Histogram {
    /// Bin edges, increasing.
    pub edges: Vec<f64>,
    /// Values per bin.
    pub counts: Vec<u64>,
    /// Values below the first edge.
    #[serde(default)]
    pub underflow: u64,
    /// Values above the last edge.
    #[serde(default)]
    pub overflow: u64,
}

/// How far beyond the 1st–99th percentile range (as a fraction of that range) a value may lie
/// before the histogram stops stretching to it: a few far outliers (SfM background points)
/// would otherwise squash every other value into the first bin.
pub(crate) const HISTOGRAM_TAIL: f64 = 0.5;

/// Statistics of a set of values. All zero when `count == 0`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
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

/// Linear-interpolated percentile `q` in [0, 100] of sorted values (the reference the tests
/// hold [`percentile_by`] to).
#[cfg(test)]
pub(crate) fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => 0.0,
        1 => sorted[0],
        n => {
            let pos = (q / 100.0).clamp(0.0, 1.0) * (n - 1) as f64;
            let lo = pos.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            let frac = pos - lo as f64;
            let v = sorted[lo] + (sorted[hi] - sorted[lo]) * frac;
            if v.is_finite() {
                v
            } else {
                // The difference overflowed (values near ±f64::MAX): interpolate the halves.
                2.0 * (sorted[lo] / 2.0 + (sorted[hi] / 2.0 - sorted[lo] / 2.0) * frac)
            }
        }
    }
}

impl Statistics {
    /// Computes the statistics of `values` (NaNs must not be present). The histogram has `bins`
    /// equal bins over `[min(0, min), max]` (`[min, max]` for signed values), except where the
    /// tail is long: an end farther than 0.5 × (p99 − p1) beyond p99 (or below p1)
    /// is replaced by p99 (p1), and the values beyond are counted in `overflow` (`underflow`).
    pub fn of(values: &[f64], bins: usize) -> Statistics {
        Statistics::of_owned(values.to_vec(), bins)
    }

    /// [`Statistics::of`] on values it may reorder (the sums run in the given order).
    pub(crate) fn of_owned(values: Vec<f64>, bins: usize) -> Statistics {
        Statistics::of_kept(&values, |_| true, bins)
    }

    /// [`Statistics::of`] on the values `values[i]` with `keep(i)`, in that order, without a copy
    /// of them: the sums run in input order as in [`Statistics::of`], and the order statistics
    /// are selected exactly by `select_ranks` (a few counting passes), so the results are the
    /// same bits as sorting a copy would give. The count, extremes, counting passes and
    /// histogram run on one range of the values per thread (exact, so thread-independent).
    pub(crate) fn of_kept(
        values: &[f64],
        keep: impl Fn(usize) -> bool + Sync,
        bins: usize,
    ) -> Statistics {
        let kept = || {
            values
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(*i))
                .map(|(_, &v)| v)
        };
        let parts = parallel::map_ranges(values.len(), |range| {
            let mut count = 0usize;
            let mut extremes: Option<(f64, f64)> = None;
            for i in range.filter(|&i| keep(i)) {
                let v = values[i];
                count += 1;
                extremes = Some(extremes.map_or((v, v), |(lo, hi)| widen(lo, hi, v, v)));
            }
            (count, extremes)
        });
        let n: usize = parts.iter().map(|p| p.0).sum();
        let Some((min, max)) = parts
            .iter()
            .filter_map(|p| p.1)
            .reduce(|(lo, hi), (a, b)| widen(lo, hi, a, b))
        else {
            return Statistics::default();
        };
        // Scale-safe: values whose squares (or sums) could overflow are divided by the largest
        // magnitude first and the results multiplied back; ordinary values are divided by 1
        // (bit-identical to the plain sums).
        let largest = min.abs().max(max.abs());
        let k = if largest.is_finite() && largest > 1e100 {
            largest
        } else {
            1.0
        };
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for v in kept() {
            let v = v / k;
            sum += v;
            sum_sq += v * v;
        }
        let nf = n as f64;
        let mean_k = sum / nf;
        let mut dev = 0.0f64;
        for v in kept() {
            let v = v / k;
            dev += (v - mean_k) * (v - mean_k);
        }
        let mean = mean_k * k;
        // Every rank the percentiles interpolate between, selected together.
        const QS: [f64; 5] = [1.0, 50.0, 90.0, 95.0, 99.0];
        let ranks: Vec<usize> = QS
            .iter()
            .flat_map(|&q| {
                let (lo, hi, _) = percentile_ranks(n, q);
                [lo, hi]
            })
            .collect();
        let picked = select_ranks(values, &keep, &ranks);
        let mut at = |r: usize| {
            ranks
                .iter()
                .position(|&x| x == r)
                .map_or(f64::NAN, |j| picked[j])
        };
        let [p1, p50, p90, p95, p99] = QS.map(|q| percentile_by(n, q, &mut at));
        let (lo, hi) = histogram_range(min, max, p1, p99);
        Statistics {
            count: n as u64,
            min,
            max,
            mean,
            std: (dev / nf).sqrt() * k,
            median: p50,
            rms: (sum_sq / nf).sqrt() * k,
            percentiles: Percentiles { p50, p90, p95, p99 },
            histogram: histogram_of(values, &keep, lo, hi, bins),
        }
    }
}

/// `(lo, hi)` widened to hold `a` and `b` (`a <= b`), in `total_cmp` order.
fn widen(lo: f64, hi: f64, a: f64, b: f64) -> (f64, f64) {
    (
        if a.total_cmp(&lo).is_lt() { a } else { lo },
        if b.total_cmp(&hi).is_gt() { b } else { hi },
    )
}

/// `v`'s position in the total order of `f64` as an unsigned integer (monotone).
fn order_key(v: f64) -> u64 {
    let b = v.to_bits();
    if b >> 63 == 1 { !b } else { b | 1 << 63 }
}

/// The value whose [`order_key`] is `key`.
fn from_order_key(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

/// Candidates collected and sorted at most, per rank: a bucket larger than this is split by
/// the next 16 bits of the key in one more counting pass.
const SELECT_LIMIT: u64 = 1 << 16;

/// Whether `key`'s top `fixed` bits are `prefix`'s.
fn has_prefix(key: u64, prefix: u64, fixed: u32) -> bool {
    fixed == 0 || key >> (64 - fixed) == prefix >> (64 - fixed)
}

/// A rank being narrowed: its rank among the values whose key starts with `prefix`'s top
/// `fixed` bits.
#[derive(Clone, Copy)]
struct Narrowing {
    rank: u64,
    prefix: u64,
    fixed: u32,
    /// Its position in the caller's list.
    slot: usize,
}

/// The values of ranks `ranks` (0-based, in `total_cmp` order) among the `values[i]` with
/// `keep(i)`, in the order of `ranks`. Counting passes over the keys' ([`order_key`]) top bits,
/// 16 bits a pass and one pass for all ranks, narrow each rank to one bucket; a bucket of at
/// most [`SELECT_LIMIT`] values is collected and sorted (one pass for all such buckets), a
/// bucket whose key is complete is that key's value. Exact; memory is 65 536 counters a
/// distinct bucket and thread, and the collected buckets. Each rank must be below the number of
/// kept values.
pub(crate) fn select_ranks(
    values: &[f64],
    keep: &(impl Fn(usize) -> bool + Sync),
    ranks: &[usize],
) -> Vec<f64> {
    let mut out = vec![f64::NAN; ranks.len()];
    let mut open: Vec<Narrowing> = ranks
        .iter()
        .enumerate()
        .map(|(slot, &r)| Narrowing {
            rank: r as u64,
            prefix: 0,
            fixed: 0,
            slot,
        })
        .collect();
    let mut small: Vec<Narrowing> = Vec::new();
    let group_of = |list: &[Narrowing]| {
        let mut g: Vec<(u64, u32)> = list.iter().map(|x| (x.prefix, x.fixed)).collect();
        g.sort_unstable();
        g.dedup();
        g
    };
    while !open.is_empty() {
        let groups = group_of(&open);
        let parts = parallel::map_ranges(values.len(), |range| {
            let mut counts = vec![0u64; groups.len() << 16];
            for i in range.filter(|&i| keep(i)) {
                let key = order_key(values[i]);
                for (g, &(prefix, fixed)) in groups.iter().enumerate() {
                    if has_prefix(key, prefix, fixed) {
                        counts[g << 16 | ((key >> (48 - fixed)) & 0xffff) as usize] += 1;
                    }
                }
            }
            counts
        });
        let mut counts = vec![0u64; groups.len() << 16];
        for part in &parts {
            for (c, p) in counts.iter_mut().zip(part) {
                *c += p;
            }
        }
        drop(parts);
        let mut still = Vec::new();
        for mut x in open {
            let Ok(g) = groups.binary_search(&(x.prefix, x.fixed)) else {
                continue;
            };
            let group = &counts[g << 16..(g + 1) << 16];
            let mut bucket = group.len() - 1;
            for (b, &c) in group.iter().enumerate() {
                if x.rank < c {
                    bucket = b;
                    break;
                }
                x.rank -= c;
            }
            let shift = 48 - x.fixed;
            x.prefix |= (bucket as u64) << shift;
            x.fixed += 16;
            let count = group[bucket];
            if x.fixed == 64 {
                // Every value of the bucket has this key: the rank's value, or none at all.
                out[x.slot] = if count > 0 {
                    from_order_key(x.prefix)
                } else {
                    f64::NAN
                };
            } else if count <= SELECT_LIMIT {
                small.push(x);
            } else {
                still.push(x);
            }
        }
        open = still;
    }
    if small.is_empty() {
        return out;
    }
    let groups = group_of(&small);
    let parts = parallel::map_ranges(values.len(), |range| {
        let mut found = vec![Vec::new(); groups.len()];
        for i in range.filter(|&i| keep(i)) {
            let key = order_key(values[i]);
            for (g, &(prefix, fixed)) in groups.iter().enumerate() {
                if has_prefix(key, prefix, fixed) {
                    found[g].push(values[i]);
                }
            }
        }
        found
    });
    let mut found: Vec<Vec<f64>> = vec![Vec::new(); groups.len()];
    for part in parts {
        for (f, p) in found.iter_mut().zip(part) {
            f.extend(p);
        }
    }
    for f in &mut found {
        f.sort_unstable_by(f64::total_cmp);
    }
    for x in small {
        let Ok(g) = groups.binary_search(&(x.prefix, x.fixed)) else {
            continue;
        };
        let f = &found[g];
        out[x.slot] = f
            .get(x.rank as usize)
            .or(f.last())
            .copied()
            .unwrap_or(f64::NAN);
    }
    out
}

/// The two ranks (0-based) the linear-interpolated percentile `q` in [0, 100] of `n > 0` values
/// lies between, and the fraction of the way from the first (numpy's default).
fn percentile_ranks(n: usize, q: f64) -> (usize, usize, f64) {
    let pos = (q / 100.0).clamp(0.0, 1.0) * n.saturating_sub(1) as f64;
    let lo = pos.floor() as usize;
    (lo, (lo + 1).min(n.saturating_sub(1)), pos - lo as f64)
}

/// Linear-interpolated percentile `q` in [0, 100] of `n` values, `at(r)` giving the value of
/// rank `r` (numpy's default).
fn percentile_by(n: usize, q: f64, at: &mut impl FnMut(usize) -> f64) -> f64 {
    match n {
        0 => 0.0,
        1 => at(0),
        n => {
            let (lo, hi, frac) = percentile_ranks(n, q);
            let (a, b) = (at(lo), at(hi));
            let v = a + (b - a) * frac;
            if v.is_finite() {
                v
            } else {
                // The difference overflowed (values near ±f64::MAX): interpolate the halves.
                2.0 * (a / 2.0 + (b / 2.0 - a / 2.0) * frac)
            }
        }
    }
}

/// The histogram's `[lo, hi]` (see [`Statistics::of`]): from 0 (or the minimum when negative)
/// to the maximum, each end pulled in to p1 / p99 when it lies beyond the tail allowance.
fn histogram_range(min: f64, max: f64, p1: f64, p99: f64) -> (f64, f64) {
    let lo_robust = if min >= 0.0 { 0.0 } else { p1.min(0.0) };
    let allowance = HISTOGRAM_TAIL * (p99 - lo_robust);
    // p99 == lo (mostly zeros): keep the maximum, or there would be no bin width at all
    let hi = if max > p99 + allowance && p99 > lo_robust {
        p99
    } else {
        max
    };
    let lo = if min >= 0.0 {
        0.0
    } else if min < p1 - HISTOGRAM_TAIL * (p99 - p1) {
        p1
    } else {
        min
    };
    (lo, hi)
}

/// Histogram of values into `bins` equal bins over `[lo, hi]`; values outside are counted in
/// `underflow` / `overflow`.
#[cfg(test)]
pub(crate) fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Histogram {
    histogram_of(values, &|_| true, lo, hi, bins)
}

/// Histogram of the values `values[i]` with `keep(i)` into `bins` equal bins over `[lo, hi]`;
/// values outside are counted in `underflow` / `overflow`. Counted on one range per thread.
fn histogram_of(
    values: &[f64],
    keep: &(impl Fn(usize) -> bool + Sync),
    lo: f64,
    hi: f64,
    bins: usize,
) -> Histogram {
    let bins = bins.max(1);
    let width = if hi > lo {
        let w = (hi - lo) / bins as f64;
        if w.is_finite() {
            w
        } else {
            hi / bins as f64 - lo / bins as f64
        }
    } else {
        1.0
    };
    let edges = (0..=bins)
        .map(|i| {
            if i == bins && hi > lo {
                hi
            } else {
                let e = lo + width * i as f64;
                if e.is_finite() {
                    e
                } else {
                    let f = i as f64 / bins as f64;
                    lo * (1.0 - f) + hi * f
                }
            }
        })
        .collect();
    let parts = parallel::map_ranges(values.len(), |range| {
        let mut counts = vec![0u64; bins];
        let (mut underflow, mut overflow) = (0u64, 0u64);
        for v in range.filter(|&i| keep(i)).map(|i| values[i]) {
            if v < lo {
                underflow += 1;
            } else if v > hi {
                overflow += 1;
            } else {
                let mut x = (v - lo) / width;
                if !x.is_finite() {
                    x = v / width - lo / width;
                }
                let b = (x.floor().max(0.0) as usize).min(bins - 1);
                counts[b] += 1;
            }
        }
        (counts, underflow, overflow)
    });
    let mut counts = vec![0u64; bins];
    let (mut underflow, mut overflow) = (0u64, 0u64);
    for (c, u, o) in parts {
        for (a, b) in counts.iter_mut().zip(c) {
            *a += b;
        }
        underflow += u;
        overflow += o;
    }
    Histogram {
        edges,
        counts,
        underflow,
        overflow,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_values_stay_finite() {
        // Squares of 1e200 overflow; the statistics must not.
        let v = [1e200, 3e200, -2e200, 1.5e308, -1.7e308];
        let s = Statistics::of(&v, 10);
        for x in [
            s.mean,
            s.std,
            s.rms,
            s.min,
            s.max,
            s.median,
            s.percentiles.p90,
            s.percentiles.p99,
        ] {
            assert!(x.is_finite(), "{s:?}");
        }
        assert!(s.histogram.edges.iter().all(|e| e.is_finite()));
        assert_eq!(
            s.histogram.counts.iter().sum::<u64>() + s.histogram.underflow + s.histogram.overflow,
            5
        );
        let s = Statistics::of(&[1e200, 1e200], 4);
        assert!((s.rms / 1e200 - 1.0).abs() < 1e-15 && s.std == 0.0 && s.mean == 1e200);
    }

    /// The copy-free statistics equal those of a sorted copy bit for bit: clustered values
    /// (one bucket holding more than [`SELECT_LIMIT`] values, so the selection refines), ties,
    /// negatives and signed zeros, huge values, and a filter.
    #[test]
    fn kept_statistics_equal_the_sorted_copy() {
        let n = 300_000u64;
        let mut v: Vec<f64> = (0..n)
            .map(|i| {
                let h = i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11;
                let u = h as f64 / (1u64 << 53) as f64;
                match i % 10 {
                    0 => 0.25,
                    1 => -0.0,
                    2 => 0.0,
                    3 => -u,
                    _ => 0.5 + u * 1e-9,
                }
            })
            .collect();
        v[17] = 1e300;
        v[18] = -1.5e308;
        for (keep_every, bins) in [(1u64, 50usize), (3, 7)] {
            let keep = |i: usize| i as u64 % keep_every != 1;
            let copy: Vec<f64> = (0..v.len()).filter(|&i| keep(i)).map(|i| v[i]).collect();
            let mut sorted = copy.clone();
            sorted.sort_unstable_by(f64::total_cmp);
            let ranks = [0, 1, copy.len() / 2, copy.len() - 2, copy.len() - 1];
            let got = select_ranks(&copy, &|_| true, &ranks);
            for (r, g) in ranks.into_iter().zip(got) {
                assert_eq!(g.to_bits(), sorted[r].to_bits(), "rank {r}");
            }
            let got = Statistics::of_kept(&v, keep, bins);
            assert_eq!(
                format!("{got:?}"),
                format!("{:?}", Statistics::of_owned(copy, bins))
            );
            // Order statistics and histogram as a sorted copy gives them.
            let bits = |x: f64| x.to_bits();
            assert_eq!(bits(got.min), bits(sorted[0]));
            assert_eq!(bits(got.max), bits(sorted[sorted.len() - 1]));
            for (q, g) in [
                (50.0, got.percentiles.p50),
                (90.0, got.percentiles.p90),
                (95.0, got.percentiles.p95),
                (99.0, got.percentiles.p99),
            ] {
                assert_eq!(bits(g), bits(percentile_sorted(&sorted, q)), "p{q}");
            }
            let (lo, hi) = histogram_range(
                sorted[0],
                sorted[sorted.len() - 1],
                percentile_sorted(&sorted, 1.0),
                percentile_sorted(&sorted, 99.0),
            );
            assert_eq!(got.histogram, histogram(&sorted, lo, hi, bins));
        }
    }

    /// More equal values than [`SELECT_LIMIT`] (a perfect reconstruction's zeros, a quantised
    /// cloud): the selection fixes all 64 bits of the key and reads the value from it.
    #[test]
    fn select_ranks_through_runs_of_equal_values() {
        let mut v: Vec<f64> = Vec::new();
        for i in 0..400_000u64 {
            v.push(match i % 4 {
                0 | 1 => 0.0,
                2 => 0.125,
                _ => (i as f64).sqrt() * 1e-3,
            });
        }
        v[5] = -0.0;
        let mut sorted = v.clone();
        sorted.sort_unstable_by(f64::total_cmp);
        let ranks: Vec<usize> = [
            0, 1, 2, 100_000, 199_999, 200_000, 250_000, 299_999, 399_999,
        ]
        .into_iter()
        .collect();
        let got = select_ranks(&v, &|_| true, &ranks);
        for (&r, g) in ranks.iter().zip(got) {
            assert_eq!(g.to_bits(), sorted[r].to_bits(), "rank {r}");
        }
        for x in [0.0, -0.0, 0.125, -3.5, f64::MAX, f64::MIN_POSITIVE] {
            assert_eq!(from_order_key(order_key(x)).to_bits(), f64::to_bits(x));
        }
    }

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

    /// All values equal (a perfect reconstruction's distances): the edges still increase.
    #[test]
    fn constant_values() {
        // [0, 0] has no width: unit bins from 0; [0, 2] puts 2 in the last bin (right edge)
        for (v, want) in [
            (0.0, [5, 0, 0, 0]),
            (2.0, [0, 0, 0, 5]),
            (-1.0, [5, 0, 0, 0]),
        ] {
            let s = Statistics::of(&[v; 5], 4);
            let e = &s.histogram.edges;
            assert!(e.windows(2).all(|w| w[0] < w[1]), "{e:?}");
            assert_eq!(s.histogram.counts, want, "{v}");
        }
        let mut v = vec![0.0; 200];
        v.push(3.0);
        let s = Statistics::of(&v, 4);
        assert_eq!(*s.histogram.edges.last().unwrap(), 3.0);
        assert_eq!(s.histogram.counts, vec![200, 0, 0, 1]);
    }

    /// 1000 values in [0, 1) and two far outliers: the bins span [0, p99], the outliers are
    /// counted in `overflow`; without outliers the bins reach the maximum and nothing overflows.
    #[test]
    fn long_tails_go_to_overflow_and_underflow() {
        let mut v: Vec<f64> = (0..1000).map(|i| i as f64 / 1000.0).collect();
        let s = Statistics::of(&v, 10);
        assert_eq!(*s.histogram.edges.last().unwrap(), s.max);
        assert_eq!((s.histogram.underflow, s.histogram.overflow), (0, 0));
        assert_eq!(s.histogram.counts, vec![100; 10]);
        v.extend([50.0, 80.0]);
        let s = Statistics::of(&v, 10);
        assert_eq!(*s.histogram.edges.last().unwrap(), s.percentiles.p99);
        assert_eq!(s.histogram.edges[0], 0.0);
        let beyond = v.iter().filter(|&&x| x > s.percentiles.p99).count() as u64;
        assert_eq!(s.histogram.overflow, beyond);
        assert_eq!(s.histogram.underflow, 0);
        assert_eq!(
            s.histogram.counts.iter().sum::<u64>() + beyond,
            v.len() as u64
        );
        // signed: one far value on each side
        let mut w: Vec<f64> = (0..1000).map(|i| i as f64 / 500.0 - 1.0).collect();
        w.extend([-40.0, 40.0]);
        let s = Statistics::of(&w, 8);
        let p1 = percentile_sorted(
            &{
                let mut x = w.clone();
                x.sort_by(f64::total_cmp);
                x
            },
            1.0,
        );
        assert_eq!(s.histogram.edges[0], p1);
        assert_eq!(*s.histogram.edges.last().unwrap(), s.percentiles.p99);
        let below = w.iter().filter(|&&x| x < p1).count() as u64;
        let above = w.iter().filter(|&&x| x > s.percentiles.p99).count() as u64;
        assert_eq!(
            (s.histogram.underflow, s.histogram.overflow),
            (below, above)
        );
        assert_eq!(
            s.histogram.counts.iter().sum::<u64>() + below + above,
            w.len() as u64
        );
    }
}
