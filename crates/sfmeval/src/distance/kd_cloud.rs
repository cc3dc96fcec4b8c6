//! A cloud copied into k-d tree order with its [`SlotTree`]: exact nearest neighbours, and the
//! nearest below a bound (a search radius, or the previous answer of a query that moved a
//! little), which the Tanks and Temples ICP asks 10–20M times a run.
//!
//! Why not kiddo's tree ([`super::CloudIndex`]): kiddo 6.3 has no bounded `nearest_one`, and a
//! query must descend from the root with an infinite radius. With the bound, an ICP query whose
//! match moved by less than the point spacing opens a leaf or two, and a point farther than the
//! correspondence distance from everything stops at the first boxes.

use super::slot_tree::{SlotTree, kd_order};
use crate::error::{Error, Result};
use crate::geometry::Point3;

/// A slot that names no point: the bound given to [`KdCloud::nearest_below`] was a radius.
pub const NO_POINT: usize = usize::MAX;

/// The cloud in tree order and its boxes; answers name points by their slot in that order.
pub struct KdCloud {
    points: Vec<Point3>,
    tree: SlotTree,
}

impl KdCloud {
    /// Copies `points` into tree order and builds the boxes; fails on an empty cloud.
    pub fn new(points: &[Point3]) -> Result<KdCloud> {
        if points.is_empty() {
            return Err(Error::Empty {
                what: "point cloud".into(),
            });
        }
        let order = kd_order(points.len(), |i| points[i]);
        // Gathered in parallel: the reads land all over the input.
        let points: Vec<Point3> =
            crate::parallel::map_range(order.len(), |j| points[order[j] as usize]);
        let tree = SlotTree::new(points.len(), |k| points[k], |_| true);
        Ok(KdCloud { points, tree })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The point in slot `k`.
    pub fn point(&self, k: usize) -> Point3 {
        self.points[k]
    }

    /// Distance from `p` to its nearest point (kiddo's squared sum, bit for bit, then the
    /// square root), and that point's slot; `(+∞, NO_POINT)` for a non-finite `p`.
    pub fn nearest(&self, p: Point3) -> (f64, usize) {
        match self.tree.nearest(p, |k| self.points[k], |_| true) {
            Some((d2, k)) => (d2.sqrt(), k),
            None => (f64::INFINITY, NO_POINT),
        }
    }

    /// [`KdCloud::nearest`]'s distance (bit for bit), the search bounded from the start by the
    /// point in slot `start` (a neighbouring query's answer; [`NO_POINT`] for none). The slot
    /// returned is a nearest point's, not necessarily the one `nearest` names among equally
    /// near points.
    pub fn nearest_from(&self, p: Point3, start: usize) -> (f64, usize) {
        if start >= self.points.len() || !p.iter().all(|v| v.is_finite()) {
            return self.nearest(p);
        }
        let bound = (distance2(self.points[start], p), start);
        let (d2, k) = self
            .tree
            .nearest_below(p, bound, |k| self.points[k], |_| true);
        (d2.sqrt(), k)
    }

    /// The nearest point strictly closer to `p` than `bound.0` (squared distance), with its
    /// slot; `bound` when there is none. `bound` is `(d², slot)` of a known point or
    /// `(r², NO_POINT)` for a radius `r`.
    pub fn nearest_below(&self, p: Point3, bound: (f64, usize)) -> (f64, usize) {
        if !p.iter().all(|v| v.is_finite()) {
            return bound;
        }
        self.tree
            .nearest_below(p, bound, |k| self.points[k], |_| true)
    }

    /// The `K` nearest points strictly closer to `p` than `radius2` (squared), nearest first,
    /// as `(d², slot)` into `out`; returns how many, and the squared radius below which every
    /// point is among them (`radius2`, or the `K`-th distance when `K` were found). `p` must be
    /// finite.
    pub fn nearest_k_below<const K: usize>(
        &self,
        p: Point3,
        radius2: f64,
        out: &mut [(f64, u32); K],
    ) -> (usize, f64) {
        self.tree
            .nearest_k_below(p, radius2, out, |k| self.points[k], |_| true)
    }

    /// Whether [`KdCloud::nearest_below`] for `p` reaches slot `a` before slot `b`: of two
    /// points at the same distance it answers the first.
    pub(crate) fn visits_before(&self, p: &Point3, a: usize, b: usize) -> bool {
        self.tree.visits_before(p, a, b)
    }
}

/// `(a₀−b₀)² + (a₁−b₁)² + (a₂−b₂)²` summed in that order, the squared distance every tree here
/// computes.
pub fn distance2(a: Point3, b: Point3) -> f64 {
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods, clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::distance::CloudIndex;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    /// A seeded scatter with clumps of exact duplicates.
    fn cloud(n: usize, seed: u64) -> Vec<Point3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut next = move || rng.random::<f64>();
        (0..n)
            .map(|i| {
                if i % 11 == 0 {
                    [0.5, 0.5, (i % 3) as f64 * 0.01]
                } else {
                    [next() * 2.0, next(), next() * 0.5]
                }
            })
            .collect()
    }

    fn brute(pts: &[Point3], q: Point3) -> f64 {
        pts.iter()
            .map(|&a| distance2(a, q))
            .fold(f64::INFINITY, f64::min)
    }

    /// The exact minimum (brute force, bitwise) and kiddo's distance, for plain queries,
    /// radius-bounded ones and ones seeded with a nearby point.
    #[test]
    fn nearest_and_bounded_nearest_equal_brute_force() {
        let pts = cloud(20_000, 5);
        let cloud_index = CloudIndex::new(&pts).unwrap();
        let tree = KdCloud::new(&pts).unwrap();
        assert_eq!(tree.len(), pts.len());
        let queries = cloud(2_000, 9);
        for (n, &q) in queries.iter().enumerate() {
            let q = [q[0] * 1.2 - 0.1, q[1] * 1.2 - 0.1, q[2] * 3.0 - 0.5];
            let want = brute(&pts, q);
            let (d, k) = tree.nearest(q);
            assert_eq!(d.to_bits(), want.sqrt().to_bits());
            assert_eq!(d.to_bits(), cloud_index.nearest(q).0.to_bits());
            assert_eq!(distance2(tree.point(k), q).to_bits(), want.to_bits());
            assert!(pts.contains(&tree.point(k)));
            // A radius: the minimum when it is below, else the bound itself.
            for r2 in [1e-6, 1e-4, 1e-3, 1e-2, f64::INFINITY] {
                let got = tree.nearest_below(q, (r2, NO_POINT));
                if want < r2 {
                    assert_eq!(got.0.to_bits(), want.to_bits());
                    assert_eq!(distance2(tree.point(got.1), q).to_bits(), want.to_bits());
                } else {
                    assert_eq!(got, (r2, NO_POINT));
                }
            }
            // A seed: some point, its distance the bound.
            let slot = (n * 7919) % tree.len();
            let bound = (distance2(tree.point(slot), q), slot);
            let got = tree.nearest_below(q, bound);
            assert_eq!(got.0.to_bits(), want.to_bits());
            assert_eq!(distance2(tree.point(got.1), q).to_bits(), want.to_bits());
            // Started from that point (or from none): `nearest`'s distance.
            for start in [slot, NO_POINT, tree.len()] {
                let (d, k) = tree.nearest_from(q, start);
                assert_eq!(d.to_bits(), want.sqrt().to_bits());
                assert_eq!(distance2(tree.point(k), q).to_bits(), want.to_bits());
            }
        }
        assert_eq!(tree.nearest([f64::NAN, 0.0, 0.0]).1, NO_POINT);
        assert_eq!(tree.nearest_from([f64::NAN, 0.0, 0.0], 3).1, NO_POINT);
        assert_eq!(tree.nearest_below([f64::NAN, 0.0, 0.0], (1.0, 3)), (1.0, 3));
        assert!(KdCloud::new(&[]).is_err());
    }
}
