//! The BVH's median splits of the triangle order: the longest axis of a range's centroids, the
//! split of a range at its median along it, and all of the build's splits done ahead, in
//! parallel over disjoint ranges.
//!
//! The build ([`super::bvh`]) splits a range near its median (after half its full leaves), then each half again, two levels
//! of splits a node. Every split reads and permutes only its own range of the order, so the
//! halves of a split can be split on different threads and the order comes out the same, bit
//! for bit, as one thread's (`select_nth_unstable_by` is deterministic for the same slice).
//! The build then reads the finished order and only places the nodes. One case is left to the
//! build's own serial path: a range of more than a leaf whose centroids all coincide (stacked
//! copies of a triangle, which the build drops).

use crate::parallel;

/// A triangle's centroid in `f32`, relative to the mesh's centre: it only chooses the splits
/// (the answer of a search does not depend on the tree's shape), at 12 bytes a triangle.
pub(crate) type Centroid = [f32; 3];

/// Ranges at least this long split their halves on two threads.
const PARALLEL_MIN: usize = 16_384;

/// The longest axis of the centroids of `order` (the axis to split along; the last of equally
/// long ones), and whether they all coincide.
pub(crate) fn centroid_axis(order: &[u32], centroids: &[Centroid]) -> (usize, bool) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for &i in order {
        let c = centroids[i as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    (axis, (0..3).all(|k| hi[k] == lo[k]))
}

/// Where a range of `n` triangles (more than a leaf) splits: after half its leaves, rounded
/// up, all full, so that every leaf but the range's last holds `leaf_size` triangles (halving
/// the count instead left 10M triangles in 4.2M leaves of 2.4 on average, not 2.5M).
pub(crate) fn split_len(n: usize, leaf_size: usize) -> usize {
    n.div_ceil(leaf_size).div_ceil(2) * leaf_size
}

/// Splits `order` along `axis` after its first [`split_len`] triangles in centroid order (ties
/// by triangle index); returns that length.
pub(crate) fn median_split(
    order: &mut [u32],
    centroids: &[Centroid],
    axis: usize,
    leaf_size: usize,
) -> usize {
    let mid = split_len(order.len(), leaf_size);
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis]
            .total_cmp(&centroids[b as usize][axis])
            .then(a.cmp(&b))
    });
    mid
}

/// Every split the build of a tree over `order` makes, with leaves of `leaf_size` triangles:
/// the build groups two levels of splits into a node, but each range of more than a leaf is
/// split once, at its median along its own longest axis, whatever the grouping. Returns `false`
/// (the order then partly split) when a range of more than a leaf has coinciding centroids: the
/// build must then start over from its own order on its serial path.
pub(crate) fn split_all(order: &mut [u32], centroids: &[Centroid], leaf_size: usize) -> bool {
    if order.len() <= leaf_size {
        return true;
    }
    let (axis, same) = centroid_axis(order, centroids);
    if same {
        return false;
    }
    let mid = median_split(order, centroids, axis, leaf_size);
    let (left, right) = order.split_at_mut(mid);
    let (a, b) = if left.len() + right.len() >= PARALLEL_MIN {
        parallel::join(
            || split_all(left, centroids, leaf_size),
            || split_all(right, centroids, leaf_size),
        )
    } else {
        (
            split_all(left, centroids, leaf_size),
            split_all(right, centroids, leaf_size),
        )
    };
    a && b
}
