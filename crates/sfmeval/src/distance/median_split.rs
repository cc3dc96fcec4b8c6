//! The BVH's median splits of the triangle order: the longest axis of a range's centroids, the
//! split of a range at its median along it, and all of the build's splits done ahead, in
//! parallel over disjoint ranges.
//!
//! The build ([`super::bvh`]) splits a range near its median (after half its full leaves), then each half again, two levels
//! of splits a node. Every split reads and permutes only its own range of the order, so the
//! halves of a split can be split on different threads and the order comes out the same, bit
//! for bit, as one thread's (`select_nth_unstable` is deterministic for the same slice). The
//! order carries each triangle's centroid ([`Keyed`]: `f32`, relative to the mesh's centre; it
//! only chooses the splits, as the answer of a search does not depend on the tree's shape), so
//! a split reads one contiguous slice (looking each centroid up by index, the splits of a
//! 10M-triangle mesh took 1.2 s instead of 0.7 s on two threads).
//! The build then reads the finished order and only places the nodes. One case is left to the
//! build's own serial path: a range of more than a leaf whose centroids all coincide (stacked
//! copies of a triangle, which the build drops).

use super::split_key::{Keyed, key_bounds, longest_axis, select_at};
use crate::parallel;

/// Ranges at least this long split their halves on two threads.
const PARALLEL_MIN: usize = 16_384;

/// The longest axis of the centroids of `order` (the axis to split along; the last of equally
/// long ones), and whether they all coincide.
pub(crate) fn centroid_axis(order: &[Keyed]) -> (usize, bool) {
    let (lo, hi) = key_bounds(order);
    (longest_axis(lo, hi), (0..3).all(|k| hi[k] == lo[k]))
}

/// Where a range of `n` triangles (more than a leaf) splits: after half its leaves, rounded
/// up, all full, so that every leaf but the range's last holds `leaf_size` triangles (halving
/// the count instead left 10M triangles in 4.2M leaves of 2.4 on average, not 2.5M).
pub(crate) fn split_len(n: usize, leaf_size: usize) -> usize {
    n.div_ceil(leaf_size).div_ceil(2) * leaf_size
}

/// Splits `order` along `axis` after its first [`split_len`] triangles in centroid order (ties
/// by triangle index); returns that length.
pub(crate) fn median_split(order: &mut [Keyed], axis: usize, leaf_size: usize) -> usize {
    let mid = split_len(order.len(), leaf_size);
    select_at(order, mid, axis);
    mid
}

/// Every split the build of a tree over `order` makes, with leaves of `leaf_size` triangles:
/// the build groups two levels of splits into a node, but each range of more than a leaf is
/// split once, at its median along its own longest axis, whatever the grouping. Returns `false`
/// (the order then partly split) when a range of more than a leaf has coinciding centroids: the
/// build must then start over from its own order on its serial path.
pub(crate) fn split_all(order: &mut [Keyed], leaf_size: usize) -> bool {
    if order.len() <= leaf_size {
        return true;
    }
    let (axis, same) = centroid_axis(order);
    if same {
        return false;
    }
    let mid = median_split(order, axis, leaf_size);
    let (left, right) = order.split_at_mut(mid);
    let (a, b) = if left.len() + right.len() >= PARALLEL_MIN {
        parallel::join(
            || split_all(left, leaf_size),
            || split_all(right, leaf_size),
        )
    } else {
        (split_all(left, leaf_size), split_all(right, leaf_size))
    };
    a && b
}
