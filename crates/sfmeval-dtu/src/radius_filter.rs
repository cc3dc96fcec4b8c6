//! The port's down-sampling, a greedy radius filter: visiting the points in order, a point is
//! kept when no point kept before it lies within the radius (`d² ≤ r²`, scikit-learn's radius
//! test). Each point's fate depends on the points kept before it, so the decisions are made one
//! after the other; but which points lie within the radius of which does not depend on them.
//! So the points are grouped by cells of twice the radius (sorted by cell, then by index), and,
//! cell by cell in parallel and in cache order, each point's *earlier* neighbours are listed;
//! the sequential pass then only reads, for each point in order, whether one of its earlier
//! neighbours was kept (a bit each). The same points are kept as by testing each point against
//! the kept points of its cells in visiting order.

use sfmeval::geometry::Point3;
use sfmeval::parallel;
use sfmeval::progress::NoProgress;

/// Bits of a cell coordinate in a key; coordinates wrap modulo 2²¹ (far cells can share a key:
/// they only add candidates, each tested by its distance).
const KEY_BITS: u32 = 21;
const KEY_MASK: u64 = (1 << KEY_BITS) - 1;
/// Added to a coordinate before it is wrapped, so that keys sort as their cells do for
/// coordinates within ±2²⁰ cells (the wrap classes, and so the cells grouped, are the same).
const KEY_OFFSET: i64 = 1 << (KEY_BITS - 1);

/// A cell's key: each coordinate (offset, wrapped to 21 bits), `z` highest.
fn cell_key(c: [i64; 3]) -> u64 {
    let w = |v: i64| (v.wrapping_add(KEY_OFFSET) as u64) & KEY_MASK;
    w(c[0]) | (w(c[1]) << KEY_BITS) | (w(c[2]) << (2 * KEY_BITS))
}

/// Points of the runs handed to one parallel task, about.
const TASK_POINTS: usize = 16_384;

/// The port's down-sampling of `points` in their order at `radius`; returns the mask of kept
/// points (see the module docs).
pub fn radius_filter(points: &[Point3], radius: f64) -> Vec<bool> {
    filter_in_tasks(points, radius, TASK_POINTS)
}

/// [`radius_filter`] with the earlier neighbours listed in parallel tasks of about
/// `task_points` points.
fn filter_in_tasks(points: &[Point3], radius: f64, task_points: usize) -> Vec<bool> {
    let n = points.len();
    let r2 = radius * radius;
    let cell = 2.0 * radius;
    let coord = |v: f64| (v / cell).floor() as i64;
    let cell_of = |p: Point3| [coord(p[0]), coord(p[1]), coord(p[2])];

    // Every point by its cell's key, then by index: each cell's points are one run.
    let mut by_cell: Vec<(u64, u32)> =
        parallel::map_range(n, |i| (cell_key(cell_of(points[i])), i as u32));
    parallel::sort_unstable(&mut by_cell);
    let mut run_keys: Vec<u64> = Vec::new();
    let mut run_starts: Vec<usize> = Vec::new();
    for (k, &(key, _)) in by_cell.iter().enumerate() {
        if run_keys.last() != Some(&key) {
            run_keys.push(key);
            run_starts.push(k);
        }
    }
    run_starts.push(n);
    let order: Vec<u32> = by_cell.iter().map(|&(_, i)| i).collect();
    drop(by_cell);
    // the points in run order, so that a run's scan reads consecutive memory
    let in_runs: Vec<Point3> = parallel::map(&order, &NoProgress, |&i| points[i as usize]);

    // Tasks: consecutive runs of about TASK_POINTS points.
    let mut tasks: Vec<std::ops::Range<usize>> = Vec::new();
    let mut first = 0;
    for r in 0..run_keys.len() {
        if run_starts[r + 1] - run_starts[first] >= task_points {
            tasks.push(first..r + 1);
            first = r + 1;
        }
    }
    if first < run_keys.len() {
        tasks.push(first..run_keys.len());
    }

    // For each task, the records of its points in run order (see `Records`).
    let lists: Vec<Records> = parallel::map(&tasks, &NoProgress, |runs| {
        let mut out = Records::default();
        let mut finder = RunFinder::new(&run_keys);
        for r in runs.clone() {
            let own = cell_of(in_runs[run_starts[r]]);
            // the runs of the 27 cells around this one, by offset
            let mut around = [None; 27];
            for (q, slot) in around.iter_mut().enumerate() {
                let d = [
                    (q % 3) as i64 - 1,
                    ((q / 3) % 3) as i64 - 1,
                    (q / 9) as i64 - 1,
                ];
                let c = [0, 1, 2].map(|a| own[a].wrapping_add(d[a]));
                *slot = finder.find(q, cell_key(c));
            }
            let span = run_starts[r]..run_starts[r + 1];
            for (&i, &p) in order[span.clone()].iter().zip(&in_runs[span]) {
                let flat = &mut out.flat;
                let at = flat.len();
                out.starts.push((i, at));
                flat.extend([r as u32, 0]);
                // the candidate cells as the original test reads them: those the box p ± r
                // touches, at most three a side
                let lo = [0, 1, 2].map(|a| coord(p[a] - radius));
                let hi = [0, 1, 2].map(|a| coord(p[a] + radius));
                let mut candidates = [0u32; 27];
                let mut n_candidates = 0;
                let mut count = 0u32;
                let mut overflow = false;
                for x in lo[0]..=hi[0].min(lo[0].saturating_add(2)) {
                    for y in lo[1]..=hi[1].min(lo[1].saturating_add(2)) {
                        for z in lo[2]..=hi[2].min(lo[2].saturating_add(2)) {
                            let d = [
                                x.wrapping_sub(own[0]),
                                y.wrapping_sub(own[1]),
                                z.wrapping_sub(own[2]),
                            ];
                            let run = if d.iter().all(|v| (-1..=1).contains(v)) {
                                around[((d[2] + 1) * 9 + (d[1] + 1) * 3 + (d[0] + 1)) as usize]
                            } else {
                                // only where rounding or huge values move the box
                                run_keys.binary_search(&cell_key([x, y, z])).ok()
                            };
                            let Some(run) = run else { continue };
                            candidates[n_candidates] = run as u32;
                            n_candidates += 1;
                            if overflow {
                                continue;
                            }
                            let span = run_starts[run]..run_starts[run + 1];
                            for (&j, &q) in order[span.clone()].iter().zip(&in_runs[span]) {
                                if j >= i {
                                    break; // a run's points are in index order
                                }
                                if sfmeval::distance::distance2(p, q) <= r2 {
                                    if count == MAX_LISTED {
                                        overflow = true;
                                        break;
                                    }
                                    flat.push(j);
                                    count += 1;
                                }
                            }
                        }
                    }
                }
                if overflow {
                    flat.truncate(at + 2);
                    flat[at + 1] = OVERFLOW | n_candidates as u32;
                    flat.extend_from_slice(&candidates[..n_candidates]);
                } else {
                    flat[at + 1] = count;
                }
            }
        }
        out
    });
    drop(order);
    drop(in_runs);

    // Where each point's record lies in the lists laid end to end.
    let mut record = vec![0usize; n];
    let mut base = 0usize;
    for l in &lists {
        for &(i, at) in &l.starts {
            record[i as usize] = base + at;
        }
        base += l.flat.len();
    }
    let mut flat: Vec<u32> = Vec::with_capacity(base);
    for l in lists {
        flat.extend_from_slice(&l.flat);
    }

    // The decisions in visiting order; each cell's kept points are listed too (`head` of its
    // run, then `next`) for the points with too many earlier neighbours to list.
    let mut kept_bits = vec![0u64; n.div_ceil(64)];
    let mut head = vec![u32::MAX; run_keys.len()];
    let mut next = vec![u32::MAX; n];
    for i in 0..n {
        let at = record[i];
        let own = flat[at] as usize;
        let h = flat[at + 1];
        let near = if h & OVERFLOW == 0 {
            flat[at + 2..at + 2 + h as usize]
                .iter()
                .any(|&j| kept_bits[j as usize / 64] >> (j % 64) & 1 == 1)
        } else {
            let p = points[i];
            flat[at + 2..at + 2 + (h & !OVERFLOW) as usize]
                .iter()
                .any(|&run| {
                    let mut k = head[run as usize];
                    while k != u32::MAX {
                        if sfmeval::distance::distance2(p, points[k as usize]) <= r2 {
                            return true;
                        }
                        k = next[k as usize];
                    }
                    false
                })
        };
        if !near {
            kept_bits[i / 64] |= 1 << (i % 64);
            next[i] = head[own];
            head[own] = i as u32;
        }
    }
    (0..n)
        .map(|i| kept_bits[i / 64] >> (i % 64) & 1 == 1)
        .collect()
}

/// The most earlier neighbours listed for a point: one with more is decided by its cells' kept
/// points instead (a dense cluster would make the lists quadratic).
const MAX_LISTED: u32 = 15;
/// Marks a record that lists candidate cells instead of neighbours.
const OVERFLOW: u32 = 1 << 31;

/// One task's records, each `[own run, header, ...]`: a header below [`OVERFLOW`] counts the
/// earlier neighbours listed after it; `OVERFLOW | n` says `n` candidate runs follow.
#[derive(Default)]
struct Records {
    /// The records laid end to end.
    flat: Vec<u32>,
    /// Each point (by index) and where its record starts in `flat`.
    starts: Vec<(u32, usize)>,
}

/// Finds runs by key for cells visited in increasing key order, one cursor per neighbour
/// offset, each moving forward (a binary search when it would go back).
struct RunFinder<'a> {
    keys: &'a [u64],
    cursors: [usize; 27],
}

impl<'a> RunFinder<'a> {
    fn new(keys: &'a [u64]) -> Self {
        Self {
            keys,
            cursors: [0; 27],
        }
    }

    /// The run of `key`, if any, with cursor `q`.
    fn find(&mut self, q: usize, key: u64) -> Option<usize> {
        let keys = self.keys;
        let c = &mut self.cursors[q];
        if *c > 0 && keys[*c - 1] >= key {
            *c = keys.partition_point(|&k| k < key);
        } else {
            // gallop forward, then search the last step
            let mut step = 1;
            while *c + step <= keys.len() && keys[*c + step - 1] < key {
                step *= 2;
            }
            let end = (*c + step).min(keys.len());
            *c += keys[*c..end].partition_point(|&k| k < key);
        }
        (keys.get(*c) == Some(&key)).then_some(*c)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// Brute force: kept iff no earlier kept point within `r` (`d² ≤ r²`; a NaN distance is
    /// not within).
    fn brute(pts: &[Point3], r: f64) -> Vec<bool> {
        let mut kept = vec![false; pts.len()];
        for i in 0..pts.len() {
            kept[i] = (0..i)
                .all(|j| !kept[j] || !(sfmeval::distance::distance2(pts[i], pts[j]) <= r * r));
        }
        kept
    }

    #[test]
    fn radius_filter_is_the_greedy_rule() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut pts: Vec<Point3> = (0..3000)
            .map(|_| {
                [
                    rng.random_range(-2.0..2.0),
                    rng.random_range(-2.0..2.0),
                    rng.random_range(-0.5..0.5),
                ]
            })
            .collect();
        // Copies 2²¹ cells away share cell keys with the originals: only more candidates.
        let far: Vec<Point3> = pts[..500]
            .iter()
            .map(|p| {
                [
                    p[0] + 0.4 * f64::from(1u32 << 21),
                    p[1],
                    p[2] - 0.4 * f64::from(1u32 << 21),
                ]
            })
            .collect();
        pts.extend(far);
        let kept = radius_filter(&pts, 0.2);
        assert_eq!(kept, brute(&pts, 0.2));
        assert!(kept.iter().filter(|&&k| k).count() > 100);
    }

    #[test]
    fn dense_clusters_across_many_tasks_and_odd_values() {
        // Clusters denser than the radius (many earlier neighbours), over more points than a
        // task takes, in an order that is not spatial; then points on cell borders, repeated
        // points, a NaN and infinities (never near anything, so kept).
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut pts: Vec<Point3> = (0..12_000)
            .map(|k| {
                let c = f64::from(k % 97);
                [
                    c * 0.37 + rng.random_range(0.0..0.3),
                    (c * 1.3).sin() + rng.random_range(0.0..0.3),
                    rng.random_range(-0.1..0.1),
                ]
            })
            .collect();
        for k in 0..50 {
            let v = f64::from(k) * 0.1; // exactly on cell borders of width 0.1
            pts.push([v, -v, 0.05]);
            pts.push([v, -v, 0.05]);
        }
        // a cluster far denser than the radius, and duplicates: more earlier neighbours
        // than are listed
        for k in 0..2000 {
            let t = f64::from(k) * 1e-5;
            pts.push([3.0 + t, 0.5 - t, 0.0]);
            pts.push([3.0, 0.5, 0.0]);
        }
        pts.push([f64::NAN, 0.0, 0.0]);
        pts.push([f64::INFINITY, 0.0, 0.0]);
        pts.push([f64::INFINITY, 0.0, 0.0]);
        pts.push([0.0, f64::NEG_INFINITY, 1e300]);
        let want = brute(&pts, 0.05);
        for task_points in [1, 700, TASK_POINTS] {
            assert_eq!(
                filter_in_tasks(&pts, 0.05, task_points),
                want,
                "{task_points}"
            );
        }
        let kept = radius_filter(&pts, 0.05);
        let n = kept.len();
        assert!(kept[n - 4] && kept[n - 3] && kept[n - 2] && kept[n - 1]);
        assert!(kept.iter().filter(|&&k| !k).count() > 3_000);
    }

    #[test]
    fn empty_and_single() {
        assert!(radius_filter(&[], 0.2).is_empty());
        assert_eq!(radius_filter(&[[1.0, 2.0, 3.0]], 0.2), [true]);
    }
}
