//! A k-d tree that is the point storage itself: the caller reorders its points into the tree's
//! order once ([`kd_order`]), and the tree keeps only one box a node ([`SlotTree`]), no copy of
//! the points. Leaves are ranges of storage slots; the points are read through a closure, so
//! they can stay in the file's `f32` and be mapped into another frame on the fly.
//!
//! Why not kiddo's k-d tree (used before for the reconstruction): it copies every point into
//! its leaves (24 bytes a point in `f64` plus an index), the second copy of a dense cloud that
//! the evaluation cannot afford at 10–100M points. The visiting order of the tree also serves
//! as the cache-friendly order of the accuracy queries (it replaces a Morton sort).
//!
//! Exactness: the nearest squared distance is the minimum of `(a₀−q₀)² + (a₁−q₁)² + (a₂−q₂)²`
//! in `f64` over the live points, the sum kiddo computes. The node boxes are rounded outwards to
//! `f32`, so a box contains its points and its distance never exceeds theirs (rounding is
//! monotone); pruning a node whose box distance is not below the best never drops a strictly
//! nearer point.

use super::split_key::{Keyed, key_bounds, longest_axis, select_at};
use super::{down, up};
use crate::geometry::Point3;

/// Most points in a leaf.
pub(crate) const LEAF_SIZE: usize = 32;

/// Levels below the root where the points are split in halves: the smallest `d` with
/// `⌈n / 2^d⌉ ≤ LEAF_SIZE`.
fn depth_for(n: usize) -> u32 {
    let mut d = 0;
    while n.div_ceil(1 << d) > LEAF_SIZE {
        d += 1;
    }
    d
}

/// The storage order of a k-d tree over `n` points, `point(i)` giving point `i`: slot `k` of the
/// reordered storage holds point `order[k]`. Each node's range is split at its middle along the
/// longest axis of its points (median by that coordinate, ties by index), `depth_for(n)` times;
/// deterministic and independent of the thread count. Non-finite points sort last on their axis.
/// Holds 16 bytes a point while it runs.
pub(crate) fn kd_order(n: usize, point: impl Fn(usize) -> Point3 + Sync) -> Vec<u32> {
    // The keys only choose the splits (boxes are computed from the exact points afterwards),
    // so `f32` keys are enough.
    let mut keys: Vec<Keyed> =
        crate::parallel::map_range(n, |i| (point(i).map(|v| v as f32), i as u32));
    split(&mut keys, depth_for(n));
    // Not `into_iter().collect()`: collecting in place would keep the keys' allocation,
    // four times the size of the order.
    crate::parallel::map_range(keys.len(), |j| keys[j].1)
}

fn split(keys: &mut [Keyed], levels: u32) {
    if levels == 0 || keys.len() < 2 {
        return;
    }
    let (lo, hi) = key_bounds(keys);
    let mid = keys.len() / 2;
    // By coordinate (`total_cmp`'s order), ties by index: the same order as comparing the
    // pairs, so the same arrangement.
    select_at(keys, mid, longest_axis(lo, hi));
    let (left, right) = keys.split_at_mut(mid);
    crate::parallel::join(|| split(left, levels - 1), || split(right, levels - 1));
}

/// An axis-aligned box in `f32`, rounded outwards; empty (`min > max`) when no live point.
#[derive(Debug, Clone, Copy)]
struct NodeBox {
    min: [f32; 3],
    max: [f32; 3],
}

impl NodeBox {
    const EMPTY: NodeBox = NodeBox {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };

    fn union(a: NodeBox, b: NodeBox) -> NodeBox {
        NodeBox {
            min: [0, 1, 2].map(|k| a.min[k].min(b.min[k])),
            max: [0, 1, 2].map(|k| a.max[k].max(b.max[k])),
        }
    }

    /// Squared distance from `q` to the box (0 inside; +∞ for an empty box, whose corners are
    /// +∞ and −∞). `q` must be finite. Plain comparisons rather than `f64::max`, whose NaN
    /// rule costs instructions in the hottest test of the searches (the same values: no NaN
    /// arises here).
    #[inline]
    fn distance2(&self, q: &Point3) -> f64 {
        let mut d2 = 0.0;
        for ((&min, &max), &qk) in self.min.iter().zip(&self.max).zip(q) {
            let below = f64::from(min) - qk;
            let above = qk - f64::from(max);
            let d = if below > above { below } else { above };
            let d = if d > 0.0 { d } else { 0.0 };
            d2 += d * d;
        }
        d2
    }
}

/// The boxes of a k-d tree over storage in [`kd_order`]: node `i` (heap layout, children
/// `2i + 1` and `2i + 2`) covers a range of slots that halves at every level; the leaves are
/// the nodes of the last level. Only live points (a predicate on the slot) count. Slots are
/// `u32`, as [`kd_order`]'s.
pub(crate) struct SlotTree {
    boxes: Vec<NodeBox>,
    depth: u32,
    n: usize,
}

impl SlotTree {
    /// The boxes of the tree over `n` slots, `point(k)` giving the point in slot `k` and
    /// `live(k)` whether it counts (non-finite points never do).
    pub(crate) fn new(
        n: usize,
        point: impl Fn(usize) -> Point3 + Sync,
        live: impl Fn(usize) -> bool + Sync,
    ) -> SlotTree {
        debug_assert!(u32::try_from(n).is_ok());
        let depth = depth_for(n);
        let leaves = 1usize << depth;
        let first_leaf = leaves - 1;
        let mut boxes = vec![NodeBox::EMPTY; 2 * leaves - 1];
        let leaf_boxes = crate::parallel::map_range(leaves, |j| {
            let (s, e) = leaf_range(n, depth, j);
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for k in s..e {
                let p = point(k);
                if live(k) && p.iter().all(|v| v.is_finite()) {
                    for a in 0..3 {
                        lo[a] = lo[a].min(p[a]);
                        hi[a] = hi[a].max(p[a]);
                    }
                }
            }
            if lo[0] > hi[0] {
                NodeBox::EMPTY
            } else {
                NodeBox {
                    min: lo.map(down),
                    max: hi.map(up),
                }
            }
        });
        boxes[first_leaf..].copy_from_slice(&leaf_boxes);
        for i in (0..first_leaf).rev() {
            boxes[i] = NodeBox::union(boxes[2 * i + 1], boxes[2 * i + 2]);
        }
        SlotTree { boxes, depth, n }
    }

    /// The smallest squared distance from `q` to a live point, and its slot; `None` when no
    /// point is live or `q` is not finite.
    pub(crate) fn nearest(
        &self,
        q: Point3,
        point: impl Fn(usize) -> Point3,
        live: impl Fn(usize) -> bool,
    ) -> Option<(f64, usize)> {
        if !q.iter().all(|v| v.is_finite()) {
            return None;
        }
        let best = self.nearest_below(q, (f64::INFINITY, usize::MAX), point, live);
        (best.1 != usize::MAX).then_some(best)
    }

    /// The nearest live point strictly closer to `q` than `bound.0` (squared), with its slot;
    /// `bound` itself when there is none. `bound` is a known candidate (its squared distance
    /// and slot, e.g. the previous answer of a query that moved a little) or a search radius
    /// (`usize::MAX` as the slot): only nodes nearer than the bound are opened, so a tight bound
    /// visits a leaf or two and a radius skips the empty space. The minimum found is the one
    /// [`SlotTree::nearest`] finds whenever it is below the bound. `q` must be finite.
    pub(crate) fn nearest_below(
        &self,
        q: Point3,
        bound: (f64, usize),
        point: impl Fn(usize) -> Point3,
        live: impl Fn(usize) -> bool,
    ) -> (f64, usize) {
        let mut best = bound;
        self.walk(q, bound.0, |s, e| {
            for k in s..e {
                if !live(k) {
                    continue;
                }
                let a = point(k);
                let d2 = (a[0] - q[0]) * (a[0] - q[0])
                    + (a[1] - q[1]) * (a[1] - q[1])
                    + (a[2] - q[2]) * (a[2] - q[2]);
                // A select, not a branch: a leaf's new best is rare and unpredictable.
                let better = d2 < best.0;
                best.0 = if better { d2 } else { best.0 };
                best.1 = if better { k } else { best.1 };
            }
            best.0
        });
        best
    }

    /// The depth-first walk both bounded searches share: leaves whose box is nearer to `q` than
    /// the bound, the child whose box is nearer first (the left one on a tie); `leaf(s, e)`
    /// scans slots `s..e` and returns the new bound (never larger).
    #[inline]
    fn walk(&self, q: Point3, bound: f64, mut leaf: impl FnMut(usize, usize) -> f64) {
        let mut bound = bound;
        // Each level pushes two entries and pops one, so the stack never holds more than
        // `depth + 2` entries (`depth` ≤ 27: slots are `u32`, leaves hold up to 32). An entry
        // is (node, first slot, end slot, box distance): 24 bytes, so the stack zeroed at
        // every query is small.
        let first_leaf = (1usize << self.depth) - 1;
        let mut stack = [(0u32, 0u32, 0u32, 0f64); 30];
        let mut top = 1;
        stack[0] = (0, 0, self.n as u32, self.boxes[0].distance2(&q));
        while top > 0 {
            top -= 1;
            let (node, s, e, d) = stack[top];
            if d >= bound {
                continue;
            }
            let (node, s, e) = (node as usize, s as usize, e as usize);
            if node >= first_leaf {
                bound = leaf(s, e);
                continue;
            }
            let m = s + (e - s) / 2;
            let (l, r) = (2 * node + 1, 2 * node + 2);
            let (dl, dr) = (self.boxes[l].distance2(&q), self.boxes[r].distance2(&q));
            // Nearer child popped first; a child no nearer than the bound is not pushed.
            let (near, far) = if dl <= dr {
                ((l, s, m, dl), (r, m, e, dr))
            } else {
                ((r, m, e, dr), (l, s, m, dl))
            };
            if far.3 < bound {
                stack[top] = (far.0 as u32, far.1 as u32, far.2 as u32, far.3);
                top += 1;
            }
            if near.3 < bound {
                stack[top] = (near.0 as u32, near.1 as u32, near.2 as u32, near.3);
                top += 1;
            }
        }
    }
}

impl SlotTree {
    /// The `K` nearest live points strictly closer to `q` than `radius2` (squared), nearest
    /// first, into `out`; returns how many were found and the squared radius below which every
    /// live point is among them: `radius2` when fewer than `K` were found, else the `K`-th
    /// squared distance (a point at exactly that distance may be left out). Visits the nodes in
    /// [`SlotTree::nearest_below`]'s order, pruning by that radius as it shrinks. `q` must be
    /// finite.
    pub(crate) fn nearest_k_below<const K: usize>(
        &self,
        q: Point3,
        radius2: f64,
        out: &mut [(f64, u32); K],
        point: impl Fn(usize) -> Point3,
        live: impl Fn(usize) -> bool,
    ) -> (usize, f64) {
        const { assert!(K > 0) };
        let mut count = 0;
        let mut bound = radius2;
        // A leaf's points nearer than the bound, gathered without a branch a point (the test
        // would mispredict often: a few points of a leaf pass it), then inserted in slot order,
        // each against the bound as it stands then: the same list as inserting while scanning.
        let mut below = [(0.0f64, 0u32); LEAF_SIZE];
        self.walk(q, radius2, |s, e| {
            let mut found = 0;
            // (a leaf holds at most LEAF_SIZE slots)
            for k in s..e {
                let a = point(k);
                let d2 = (a[0] - q[0]) * (a[0] - q[0])
                    + (a[1] - q[1]) * (a[1] - q[1])
                    + (a[2] - q[2]) * (a[2] - q[2]);
                below[found] = (d2, k as u32);
                found += usize::from(d2 < bound && live(k));
            }
            for &(d2, k) in &below[..found] {
                if d2 < bound {
                    // Insert in distance order (after equal distances), dropping the
                    // farthest when full.
                    let mut j = count.min(K - 1);
                    while j > 0 && out[j - 1].0 > d2 {
                        out[j] = out[j - 1];
                        j -= 1;
                    }
                    out[j] = (d2, k);
                    if count < K {
                        count += 1;
                    }
                    if count == K {
                        bound = out[K - 1].0;
                    }
                }
            }
            bound
        });
        (count, bound)
    }

    /// Whether [`SlotTree::nearest_below`] for `q` reaches slot `a` before slot `b` (`a != b`):
    /// its depth-first walk takes the child whose box is nearer to `q` first (the left one on a
    /// tie) and a leaf's slots in order. Among points at the same distance the walk keeps the
    /// first, so this is its tie rule, for other searches to keep.
    pub(crate) fn visits_before(&self, q: &Point3, a: usize, b: usize) -> bool {
        let (mut node, mut s, mut e) = (0usize, 0usize, self.n);
        for _ in 0..self.depth {
            let m = s + (e - s) / 2;
            let (a_right, b_right) = (a >= m, b >= m);
            if a_right != b_right {
                let (l, r) = (2 * node + 1, 2 * node + 2);
                let left_first = self.boxes[l].distance2(q) <= self.boxes[r].distance2(q);
                return a_right != left_first;
            }
            if a_right {
                (node, s) = (2 * node + 2, m);
            } else {
                (node, e) = (2 * node + 1, m);
            }
        }
        a < b
    }
}

/// Slot range of leaf `j` of a tree of `depth` levels over `n` slots.
fn leaf_range(n: usize, depth: u32, j: usize) -> (usize, usize) {
    let (mut s, mut e) = (0, n);
    for level in (0..depth).rev() {
        let m = s + (e - s) / 2;
        if (j >> level) & 1 == 0 {
            e = m;
        } else {
            s = m;
        }
    }
    (s, e)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods, clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::distance::CloudIndex;

    fn cloud(n: usize, seed: u64) -> Vec<Point3> {
        (0..n as u64)
            .map(|i| {
                let h = (i ^ seed).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5bd1_e995;
                let h2 = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
                let f = |x: u64, s: u32| ((x >> s) & 0xffff) as f64 / 65535.0 * 2.0 - 1.0;
                // clumps: many duplicates in one corner
                if i % 7 == 0 {
                    [0.25, 0.25, f(h, 0).round()]
                } else {
                    [f(h, 0), f(h, 16) * 0.3, f(h2, 32) * 3.0]
                }
            })
            .collect()
    }

    #[test]
    fn order_is_a_permutation_and_leaves_cover_the_slots() {
        for n in [0usize, 1, 2, 31, 32, 33, 64, 65, 1000, 4097] {
            let pts = cloud(n, 1);
            let order = kd_order(n, |i| pts[i]);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..n as u32).collect::<Vec<_>>());
            let d = depth_for(n);
            let mut next = 0;
            for j in 0..1usize << d {
                let (s, e) = leaf_range(n, d, j);
                assert_eq!(s, next);
                assert!(e - s <= LEAF_SIZE);
                next = e;
            }
            assert_eq!(next, n);
        }
    }

    /// The split of the pairs by `total_cmp` and index, with the bounds of the finite
    /// coordinates, as written before the integer keys and the vectorised bounds.
    fn reference_split(keys: &mut [([f32; 3], u32)], levels: u32) {
        if levels == 0 || keys.len() < 2 {
            return;
        }
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for (p, _) in keys.iter() {
            for k in 0..3 {
                if p[k].is_finite() {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let mid = keys.len() / 2;
        keys.select_nth_unstable_by(mid, |a, b| {
            a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
        });
        let (left, right) = keys.split_at_mut(mid);
        reference_split(left, levels - 1);
        reference_split(right, levels - 1);
    }

    /// The order is the reference split's slot for slot, also with negative values, signed
    /// zeros, NaN and infinities among the coordinates.
    #[test]
    fn order_equals_the_pairwise_split() {
        for (n, odd) in [
            (33usize, 0usize),
            (1000, 0),
            (4097, 0),
            (4097, 5),
            (20_000, 3),
        ] {
            let mut pts = cloud(n, 7);
            if odd > 0 {
                let specials = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0];
                for (i, p) in pts.iter_mut().enumerate().filter(|(i, _)| i % 97 == 0) {
                    p[i % 3] = specials[(i / 97) % odd];
                }
            }
            let got = kd_order(n, |i| pts[i]);
            let mut keys: Vec<([f32; 3], u32)> = (0..n)
                .map(|i| (pts[i].map(|v| v as f32), i as u32))
                .collect();
            reference_split(&mut keys, depth_for(n));
            let want: Vec<u32> = keys.iter().map(|&(_, i)| i).collect();
            assert_eq!(got, want, "{n} points, {odd} kinds of special values");
        }
    }

    /// Bit for bit the squared distance kiddo's tree finds (the index it replaces), with and
    /// without dead points, for points stored in `f32` and mapped by a similarity on the fly.
    #[test]
    fn nearest_equals_kiddo_and_brute_force_bitwise() {
        let n = 5000;
        let raw: Vec<[f32; 3]> = cloud(n, 2).iter().map(|p| p.map(|v| v as f32)).collect();
        let t = crate::transform::Similarity::from_matrix([
            [0.0, -1.7, 0.0, 0.3],
            [1.7, 0.0, 0.0, -2.0],
            [0.0, 0.0, 1.7, 1.1],
            [0.0, 0.0, 0.0, 1.0],
        ])
        .unwrap();
        let in_gt = |p: [f32; 3]| t.apply(p.map(f64::from));
        let order = kd_order(n, |i| in_gt(raw[i]));
        let stored: Vec<[f32; 3]> = order.iter().map(|&i| raw[i as usize]).collect();
        let point = |k: usize| in_gt(stored[k]);
        let queries = cloud(700, 3);
        for dead_every in [0usize, 3] {
            let live =
                |k: usize| dead_every == 0 || !(order[k] as usize).is_multiple_of(dead_every);
            let tree = SlotTree::new(n, point, live);
            let kept: Vec<Point3> = (0..n).filter(|&k| live(k)).map(point).collect();
            let kiddo = CloudIndex::new(&kept).unwrap();
            for q in queries.iter().map(|q| t.apply(*q)) {
                let (d2, k) = tree.nearest(q, point, live).unwrap();
                assert!(live(k));
                let want = kiddo.nearest(q).0;
                assert_eq!(d2.sqrt().to_bits(), want.to_bits(), "{q:?}");
                let brute = kept
                    .iter()
                    .map(|a| {
                        (a[0] - q[0]) * (a[0] - q[0])
                            + (a[1] - q[1]) * (a[1] - q[1])
                            + (a[2] - q[2]) * (a[2] - q[2])
                    })
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(d2.to_bits(), brute.to_bits());
            }
        }
        let none = SlotTree::new(n, point, |_| false);
        assert!(none.nearest([0.0; 3], point, |_| false).is_none());
        let tree = SlotTree::new(n, point, |_| true);
        assert!(
            tree.nearest([f64::NAN, 0.0, 0.0], point, |_| true)
                .is_none()
        );
    }

    /// The slots in the order `nearest_below` visits them for `q` when nothing is pruned.
    fn visiting_order(tree: &SlotTree, q: &Point3) -> Vec<usize> {
        fn walk(
            t: &SlotTree,
            q: &Point3,
            node: usize,
            s: usize,
            e: usize,
            l: u32,
            out: &mut Vec<usize>,
        ) {
            if l == t.depth {
                out.extend(s..e);
                return;
            }
            let m = s + (e - s) / 2;
            let (a, b) = (2 * node + 1, 2 * node + 2);
            if t.boxes[a].distance2(q) <= t.boxes[b].distance2(q) {
                walk(t, q, a, s, m, l + 1, out);
                walk(t, q, b, m, e, l + 1, out);
            } else {
                walk(t, q, b, m, e, l + 1, out);
                walk(t, q, a, s, m, l + 1, out);
            }
        }
        let mut out = Vec::new();
        walk(tree, q, 0, 0, tree.n, 0, &mut out);
        out
    }

    /// The k nearest below a radius against brute force (distances bit for bit, every point
    /// below the returned radius listed), and the visiting order against a plain walk; the
    /// cloud has exact duplicates.
    #[test]
    fn k_nearest_and_visiting_order_equal_brute_force() {
        let n = 3000;
        let pts = cloud(n, 4);
        let order = kd_order(n, |i| pts[i]);
        let stored: Vec<Point3> = order.iter().map(|&i| pts[i as usize]).collect();
        let point = |k: usize| stored[k];
        let tree = SlotTree::new(n, point, |_| true);
        let d2 = |a: Point3, q: Point3| {
            (a[0] - q[0]) * (a[0] - q[0])
                + (a[1] - q[1]) * (a[1] - q[1])
                + (a[2] - q[2]) * (a[2] - q[2])
        };
        for (j, q) in cloud(200, 8).into_iter().enumerate() {
            let q = if j % 4 == 0 {
                [0.25, 0.25, q[2].round()]
            } else {
                q
            };
            let mut all: Vec<f64> = (0..n).map(|k| d2(stored[k], q)).collect();
            let by_slot = all.clone();
            all.sort_by(f64::total_cmp);
            for radius2 in [1e-4, 0.01, 0.5, f64::INFINITY] {
                let mut out = [(0.0, 0u32); 8];
                let (count, r2) = tree.nearest_k_below(q, radius2, &mut out, point, |_| true);
                let below: Vec<f64> = all.iter().copied().filter(|&d| d < radius2).collect();
                assert_eq!(count, below.len().min(8));
                for (got, want) in out[..count].iter().zip(&below) {
                    assert_eq!(got.0.to_bits(), want.to_bits());
                    assert_eq!(by_slot[got.1 as usize].to_bits(), got.0.to_bits());
                }
                assert_eq!(
                    r2.to_bits(),
                    if count == 8 { below[7] } else { radius2 }.to_bits()
                );
                for (k, &d) in by_slot.iter().enumerate() {
                    if d < r2 {
                        assert!(out[..count].iter().any(|o| o.1 as usize == k));
                    }
                }
            }
            let walk = visiting_order(&tree, &q);
            let mut rank = vec![0; n];
            for (r, &k) in walk.iter().enumerate() {
                rank[k] = r;
            }
            for t in 0..400 {
                let (a, b) = ((t * 7919 + j) % n, (t * 104_729 + 3 * j) % n);
                if a != b {
                    assert_eq!(tree.visits_before(&q, a, b), rank[a] < rank[b]);
                }
            }
            // Of exact duplicates the nearest query keeps the first visited.
            let (best, k) = tree.nearest(q, point, |_| true).unwrap();
            let first = walk.iter().copied().find(|&s| by_slot[s] == best).unwrap();
            assert_eq!(k, first);
        }
    }
}
