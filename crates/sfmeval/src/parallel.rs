//! Order-preserving parallel map: rayon with the `parallel` feature, a plain loop without it.
//! Results come back in input order, so every later reduction is independent of thread count.

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::geometry::Point3;
use crate::progress::Progress;
use crate::spatial_order::morton_keys;

/// Items per progress tick and per parallel work unit.
const CHUNK: usize = 8192;

/// Maps `f` over `items`, keeping order, reporting progress per chunk.
pub fn map<T, R, F>(items: &[T], progress: &dyn Progress, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    F: Fn(&T) -> R + Sync + Send,
{
    map_with_state(items, progress, |_: &mut (), t| f(t))
}

/// `map(item)` for each of `items` that `keep(item)` keeps, in input order (a filter that
/// tests each item on its own), in parallel where threads are available.
///
/// Two passes: the tests, as one flag an item and a count a run of 8192 items; then the
/// output at its final size (zeroed pages where `R::default()` is all zero bits, as for
/// points), each run's kept items mapped straight into their place. `map` runs once per kept
/// item, `keep` once per item. Collecting a filter through rayon's lists instead grew each
/// part by doubling and appended the parts on one thread: a crop keeping 1.5M of 2M points
/// spent longer on that than on its tests.
pub fn keep_map<T, R>(
    items: &[T],
    keep: impl Fn(&T) -> bool + Sync + Send,
    map: impl Fn(&T) -> R + Sync + Send,
) -> Vec<R>
where
    T: Sync,
    R: Send + Copy + Default,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        if items.len() <= CHUNK {
            return items.iter().filter(|t| keep(t)).map(map).collect();
        }
        let mut flags = vec![false; items.len()];
        let counts: Vec<usize> = flags
            .par_chunks_mut(CHUNK)
            .zip(items.par_chunks(CHUNK))
            .map(|(flags, items)| {
                let mut kept = 0;
                for (flag, item) in flags.iter_mut().zip(items) {
                    *flag = keep(item);
                    kept += usize::from(*flag);
                }
                kept
            })
            .collect();
        let mut out = vec![R::default(); counts.iter().sum()];
        let mut rest = out.as_mut_slice();
        let mut targets = Vec::with_capacity(counts.len());
        for &n in &counts {
            let (head, tail) = rest.split_at_mut(n);
            targets.push(head);
            rest = tail;
        }
        targets
            .into_par_iter()
            .zip(flags.par_chunks(CHUNK).zip(items.par_chunks(CHUNK)))
            .for_each(|(target, (flags, items))| {
                let kept = items.iter().zip(flags).filter(|(_, f)| **f).map(|(t, _)| t);
                for (slot, item) in target.iter_mut().zip(kept) {
                    *slot = map(item);
                }
            });
        out
    }
    #[cfg(not(feature = "parallel"))]
    items.iter().filter(|t| keep(t)).map(map).collect()
}

/// [`map`] where `f` also gets a state that starts as `S::default()` in each work unit and
/// goes from one item to the next in order, to carry a hint (e.g. the previous query's answer);
/// for results independent of the thread count they must not depend on it.
pub(crate) fn map_with_state<T, R, S, F>(items: &[T], progress: &dyn Progress, f: F) -> Vec<R>
where
    T: Sync,
    R: Send,
    S: Default,
    F: Fn(&mut S, &T) -> R + Sync + Send,
{
    let abandon = Abandon::default();
    let run = |c: &[T]| {
        abandon.run(|| {
            let mut state = S::default();
            let out: Vec<R> = c.iter().map(|t| f(&mut state, t)).collect();
            progress.advance(c.len() as u64);
            out
        })
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        // Small inputs (ICP's coarse phase) still get split over every thread.
        let chunk = (items.len() / (4 * rayon::current_num_threads())).clamp(256, CHUNK);
        let chunks: Vec<Vec<R>> = items.par_chunks(chunk).with_max_len(1).map(run).collect();
        let mut out = Vec::with_capacity(items.len());
        for c in chunks {
            out.extend(c);
        }
        out
    }
    #[cfg(not(feature = "parallel"))]
    {
        let mut out = Vec::with_capacity(items.len());
        for c in items.chunks(CHUNK) {
            out.extend(run(c));
        }
        out
    }
}

/// Maps `f` over `0..n` cut into ranges of `size` (the last one shorter), keeping order: the
/// cuts depend on `n` and `size` only, so partial sums made per range and added in order give
/// the same bits for any thread count.
pub(crate) fn map_fixed_ranges<R, F>(n: usize, size: usize, f: F) -> Vec<R>
where
    R: Send,
    F: Fn(std::ops::Range<usize>) -> R + Sync + Send,
{
    let size = size.max(1);
    let range = |j: usize| j * size..((j + 1) * size).min(n);
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n.div_ceil(size))
            .into_par_iter()
            .map(range)
            .map(f)
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n.div_ceil(size)).map(range).map(f).collect()
    }
}

/// Maps `f` over `0..n`, keeping order (no progress).
pub fn map_range<R, F>(n: usize, f: F) -> Vec<R>
where
    R: Send,
    F: Fn(usize) -> R + Sync + Send,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n).into_par_iter().with_min_len(1024).map(f).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n).map(f).collect()
    }
}

/// [`map_range`] of a function giving pairs, collected straight into two vectors.
pub(crate) fn map_range_unzip<A, B, F>(n: usize, f: F) -> (Vec<A>, Vec<B>)
where
    A: Send,
    B: Send,
    F: Fn(usize) -> (A, B) + Sync + Send,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        (0..n)
            .into_par_iter()
            .with_min_len(1024)
            .map(f)
            .unzip_into_vecs(&mut a, &mut b);
        (a, b)
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n).map(f).unzip()
    }
}

/// `f` over `0..n` cut into one contiguous range per thread (a single range without threads),
/// the results in range order: for reductions whose partial results are large (histograms,
/// counters), where a range per work unit would multiply them.
pub fn map_ranges<R, F>(n: usize, f: F) -> Vec<R>
where
    R: Send,
    F: Fn(std::ops::Range<usize>) -> R + Sync + Send,
{
    #[cfg(feature = "parallel")]
    let parts = rayon::current_num_threads().min(n.div_ceil(1 << 15)).max(1);
    #[cfg(not(feature = "parallel"))]
    let parts = 1;
    let range = |j: usize| j * n / parts..(j + 1) * n / parts;
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..parts).into_par_iter().map(|j| f(range(j))).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..parts).map(|j| f(range(j))).collect()
    }
}

/// Sets `out[k] = f(state, k)` for every `k`, in parallel chunks; each chunk's state starts as
/// `S::default()` and goes from one index to the next in order, as in
/// [`map_range_with_state`], but the results go straight into `out` (no second buffer).
pub(crate) fn fill_with_state<R, S, F>(out: &mut [R], f: F)
where
    R: Send,
    S: Default,
    F: Fn(&mut S, usize) -> R + Sync + Send,
{
    let run = |(c, chunk): (usize, &mut [R])| {
        let mut state = S::default();
        for (j, r) in chunk.iter_mut().enumerate() {
            *r = f(&mut state, c * CHUNK + j);
        }
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK).enumerate().for_each(run);
    }
    #[cfg(not(feature = "parallel"))]
    out.chunks_mut(CHUNK).enumerate().for_each(run);
}

/// `slice.sort_unstable()`, in parallel where threads are available (the same result: equal
/// elements are indistinguishable).
pub fn sort_unstable<T: Ord + Send>(slice: &mut [T]) {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        slice.par_sort_unstable();
    }
    #[cfg(not(feature = "parallel"))]
    slice.sort_unstable();
}

/// Sorts numbers ascending with NaN last (the order of JavaScript's typed-array sort), in
/// parallel where threads are available. Every NaN becomes the positive quiet NaN.
pub fn sort_floats(values: &mut [f64]) {
    for v in values.iter_mut().filter(|v| v.is_nan()) {
        *v = f64::NAN;
    }
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        values.par_sort_unstable_by(f64::total_cmp);
    }
    #[cfg(not(feature = "parallel"))]
    values.sort_unstable_by(f64::total_cmp);
}

/// Runs `a` and `b`, in parallel where threads are available.
#[cfg(feature = "parallel")]
pub fn join<RA: Send, RB: Send>(
    a: impl FnOnce() -> RA + Send,
    b: impl FnOnce() -> RB + Send,
) -> (RA, RB) {
    rayon::join(a, b)
}

/// Runs `a` and `b`, in parallel where threads are available.
#[cfg(not(feature = "parallel"))]
pub fn join<RA, RB>(a: impl FnOnce() -> RA, b: impl FnOnce() -> RB) -> (RA, RB) {
    (a(), b())
}

/// Maps `f` over `items` with each item's index and mutable access to it, keeping order (no
/// progress).
pub(crate) fn map_mut<T, R, F>(items: &mut [T], f: F) -> Vec<R>
where
    T: Send,
    R: Send,
    F: Fn(usize, &mut T) -> R + Sync + Send,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        items
            .par_iter_mut()
            .enumerate()
            .with_min_len(256)
            .map(|(k, t)| f(k, t))
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        items.iter_mut().enumerate().map(|(k, t)| f(k, t)).collect()
    }
}

/// Runs `f(state, acc, &mut item)` over every item, in fixed runs of `size` items (in
/// parallel where threads are available); each run starts from `S::default()` and `init()`,
/// goes through its items in order, and its accumulator comes back in run order. The runs do
/// not depend on the thread count, so neither does any reduction of the accumulators in order.
pub fn fold_runs_mut<T, S, A, I, F>(items: &mut [T], size: usize, init: I, f: F) -> Vec<A>
where
    T: Send,
    A: Send,
    S: Default,
    I: Fn() -> A + Sync + Send,
    F: Fn(&mut S, &mut A, &mut T) + Sync + Send,
{
    let run = |run: &mut [T]| {
        let (mut state, mut acc) = (S::default(), init());
        for t in run {
            f(&mut state, &mut acc, t);
        }
        acc
    };
    let size = size.max(1);
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        items
            .par_chunks_mut(size)
            .with_max_len(1)
            .map(run)
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    items.chunks_mut(size).map(run).collect()
}

/// Indices per work unit of [`map_range_with_state`]: closest-point queries in tree order take
/// from 1 to 50 µs, and a unit of far points at the end would keep one thread working alone.
const STATE_CHUNK: usize = 1024;

/// Maps `f` over `start..end`, keeping order, reporting progress per chunk; `f` also gets a
/// state carried from one index to the next within a chunk (each chunk starts from
/// `S::default()`), as in [`map_with_state`].
pub(crate) fn map_range_with_state<R, S, F>(
    start: usize,
    end: usize,
    progress: &dyn Progress,
    f: F,
) -> Vec<R>
where
    R: Send,
    S: Default,
    F: Fn(&mut S, usize) -> R + Sync + Send,
{
    let starts: Vec<usize> = (start..end).step_by(STATE_CHUNK).collect();
    let abandon = Abandon::default();
    let chunk = |&s: &usize| {
        abandon.run(|| {
            let e = (s + STATE_CHUNK).min(end);
            let mut state = S::default();
            let out: Vec<R> = (s..e).map(|k| f(&mut state, k)).collect();
            progress.advance((e - s) as u64);
            out
        })
    };
    #[cfg(feature = "parallel")]
    let chunks: Vec<Vec<R>> = {
        use rayon::prelude::*;
        starts.par_iter().with_max_len(1).map(chunk).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let chunks: Vec<Vec<R>> = starts.iter().map(chunk).collect();
    let mut out = Vec::with_capacity(end - start);
    for c in chunks {
        out.extend(c);
    }
    out
}

/// Lets the chunks of one map that reports progress stop early. A chunk that panics (a front
/// end's hook stopping the work, as the Python package's Ctrl-C does, or a bug) marks the map
/// abandoned, and the chunks that start after it return nothing instead of doing their work:
/// rayon runs the rest of a split before it passes a panic on (on one thread, all the rest of
/// the map), so without this a stop asked for early came near the stage's end.
#[derive(Default)]
struct Abandon(AtomicBool);

impl Abandon {
    /// `work()`, or nothing once a chunk of the map has panicked.
    fn run<R>(&self, work: impl FnOnce() -> Vec<R>) -> Vec<R> {
        if self.0.load(Ordering::Relaxed) {
            return Vec::new();
        }
        match catch_unwind(AssertUnwindSafe(work)) {
            Ok(out) => out,
            Err(payload) => {
                self.0.store(true, Ordering::Relaxed);
                resume_unwind(payload)
            }
        }
    }
}

/// Indices of `points` in Morton order (`spatial_order::morton_keys`, sorted in parallel): ties
/// by index, non-finite points last. A permutation of `0..points.len()`, the same for any
/// thread count.
pub fn morton_order(points: &[Point3]) -> Vec<u32> {
    let mut keyed = morton_keys(points);
    sort_unstable(&mut keyed);
    map_range(keyed.len(), |k| keyed[k].1)
}

/// Maps `f` over 3D points visited in Morton order (a Z-curve: neighbours in space are
/// queried one after the other, which keeps a BVH or k-d tree in cache) and returns the results
/// in input order, like [`map`]. Worth it for closest-point queries on large inputs.
pub fn map_points<R, F>(points: &[Point3], progress: &dyn Progress, f: F) -> Vec<R>
where
    R: Send + Sync + Copy,
    F: Fn(&Point3) -> R + Sync + Send,
{
    in_visiting_order(points, |visited| map(visited, progress, f))
}

/// [`map_points`] where `f` also gets a state carried from one point to the next in the
/// visiting order (each chunk of it starts from `S::default()`): neighbours in space follow
/// each other, so the previous answer is a good start.
pub fn map_points_with_state<R, S, F>(points: &[Point3], progress: &dyn Progress, f: F) -> Vec<R>
where
    R: Send + Sync + Copy,
    S: Default,
    F: Fn(&mut S, &Point3) -> R + Sync + Send,
{
    in_visiting_order(points, |visited| map_with_state(visited, progress, f))
}

/// `run`'s results over `points` taken in Morton order, returned in input order. The points
/// are gathered in visiting order first: a loop of independent loads overlaps their cache
/// misses, where each query would wait for its own.
fn in_visiting_order<R: Send + Sync + Copy>(
    points: &[Point3],
    run: impl FnOnce(&[Point3]) -> Vec<R>,
) -> Vec<R> {
    let order = morton_order(points);
    let visited_points = map_range(order.len(), |k| points[order[k] as usize]);
    let visited = run(&visited_points);
    drop(visited_points);
    by_index(&order, visited)
}

/// `visited[k]` is the result for index `order[k]`: the results by index.
fn by_index<R: Copy + Send + Sync>(order: &[u32], visited: Vec<R>) -> Vec<R> {
    let mut position = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        position[i as usize] = k as u32;
    }
    map_range(order.len(), |i| visited[position[i] as usize])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    /// Scrambled points across several chunks, with a NaN among them and repeated points.
    fn scrambled_points() -> Vec<Point3> {
        (0..3 * CHUNK as u64 + 17)
            .map(|i| {
                let h = (i % 20_000).wrapping_mul(0x9e37_79b9_7f4a_7c15);
                let f = |s: u32| ((h >> s) & 0xffff) as f64 / 65535.0;
                if i == 1234 {
                    [f64::NAN, 0.0, 0.0]
                } else {
                    [f(0), f(16), f(32)]
                }
            })
            .collect()
    }

    /// `keep_map` keeps and maps as a plain filter then map, in order, across chunks, for
    /// none, some and all kept.
    #[test]
    fn keep_map_is_filter_then_map() {
        let points = scrambled_points();
        let tests: [&(dyn Fn(&Point3) -> bool + Sync); 4] = [
            &|p| p[0] < 0.3,
            &|p| p[1] > 0.5 || p[0].is_nan(),
            &|_| false,
            &|_| true,
        ];
        let moved = |p: &Point3| [p[0] * 3.0 + 1.0, p[2], -p[1]];
        for keep in tests {
            for items in [&points[..], &points[..100]] {
                let expected: Vec<Point3> = items.iter().filter(|p| keep(p)).map(moved).collect();
                let got = keep_map(items, keep, moved);
                assert_eq!(got.len(), expected.len());
                let bits = |v: &[Point3]| -> Vec<[u64; 3]> {
                    v.iter().map(|p| p.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&got), bits(&expected));
            }
        }
    }

    /// Ascending, NaN (of either sign) last, -0 before +0, across many chunks.
    #[test]
    fn floats_sort_as_javascript_sorts_typed_arrays() {
        let mut v: Vec<f64> = (0..100_000u64)
            .map(|i| ((i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40) as f64) * 1e-3 - 100.0)
            .collect();
        v[7] = f64::NAN;
        v[70] = -f64::NAN;
        v[700] = f64::INFINITY;
        v[7000] = 0.0;
        v[7001] = -0.0;
        let mut want: Vec<f64> = v.iter().copied().filter(|x| !x.is_nan()).collect();
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        sort_floats(&mut v);
        assert_eq!(v.len(), want.len() + 2);
        assert!(
            v[want.len()..]
                .iter()
                .all(|x| x.is_nan() && x.is_sign_positive())
        );
        assert_eq!(&v[..want.len()], &want[..]);
        let zero = v.iter().position(|&x| x == 0.0).unwrap();
        assert!(v[zero].is_sign_negative() && v[zero + 1].is_sign_positive());
    }

    #[test]
    fn morton_order_is_the_sorted_keys_indices() {
        let pts = scrambled_points();
        let mut keyed = morton_keys(&pts);
        keyed.sort_by_key(|&(code, i)| (code, i));
        let want: Vec<u32> = keyed.iter().map(|&(_, i)| i).collect();
        let got = morton_order(&pts);
        assert_eq!(got, want);
        // Repeated points: the later index follows the earlier one; the NaN is last.
        let at = |i: u32| got.iter().position(|&k| k == i);
        assert!(at(20_000) > at(0));
        assert_eq!(got.last(), Some(&1234));
    }

    #[test]
    fn map_points_returns_results_in_input_order() {
        let pts = scrambled_points();
        let got = map_points(&pts, &NoProgress, |p| (p[0], p[1] + p[2]));
        let want: Vec<(f64, f64)> = pts.iter().map(|p| (p[0], p[1] + p[2])).collect();
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!(g.0.to_bits() == w.0.to_bits() && g.1 == w.1);
        }
    }

    /// A panic in one chunk reaches the caller without the rest of the map being worked
    /// through: on one thread only the first chunk runs; on two, at most one more a thread
    /// (the chunks already started). Both maps that report progress.
    #[cfg(feature = "parallel")]
    #[test]
    fn a_stop_in_one_chunk_skips_the_chunks_not_started() {
        /// A hook that stops the work at its first call (as the Python package's Ctrl-C does).
        struct StopAtFirstAdvance;

        impl Progress for StopAtFirstAdvance {
            fn start(&self, _: crate::progress::Stage, _: u64) {}
            fn advance(&self, _: u64) {
                std::panic::resume_unwind(Box::new("stop"));
            }
            fn finish(&self) {}
        }
        use std::sync::atomic::AtomicUsize;
        let items = vec![0u32; 64 * CHUNK];
        let chunks = items.len() / CHUNK;
        for threads in [1, 2] {
            let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build() else {
                panic!("a pool of {threads} threads");
            };
            let worked = AtomicUsize::new(0);
            let count = |_: &mut (), _: &u32| {
                worked.fetch_add(1, Ordering::Relaxed);
            };
            let stopped = pool.install(|| {
                catch_unwind(AssertUnwindSafe(|| {
                    map_with_state(&items, &StopAtFirstAdvance, count)
                }))
            });
            assert!(stopped.is_err());
            let per_chunk = (items.len() / (4 * threads)).clamp(256, CHUNK);
            let ran = worked.load(Ordering::Relaxed).div_ceil(per_chunk);
            assert!(
                ran <= 2 * threads,
                "{threads} threads: {ran} of {chunks} chunks ran"
            );

            let worked = AtomicUsize::new(0);
            let count = |_: &mut (), _: usize| {
                worked.fetch_add(1, Ordering::Relaxed);
            };
            let stopped = pool.install(|| {
                catch_unwind(AssertUnwindSafe(|| {
                    map_range_with_state(0, 64 * STATE_CHUNK, &StopAtFirstAdvance, count)
                }))
            });
            assert!(stopped.is_err());
            let ran = worked.load(Ordering::Relaxed).div_ceil(STATE_CHUNK);
            assert!(
                ran <= 2 * threads,
                "{threads} threads: {ran} of 64 ranges ran"
            );
        }
    }
}
