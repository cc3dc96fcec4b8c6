//! Nearest-neighbour distances to a point cloud through kiddo's immutable k-d tree.

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::error::{Error, Result};
use crate::geometry::Point3;

/// A point cloud indexed for nearest-neighbour queries.
pub struct CloudIndex {
    tree: ImmutableKdTree<f64, 3>,
}

impl CloudIndex {
    /// Builds the k-d tree; fails on an empty cloud.
    pub fn new(points: &[Point3]) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::Empty {
                what: "point cloud".into(),
            });
        }
        let tree = ImmutableKdTree::new_from_slice(points)
            .map_err(|e| Error::Geometry(format!("cannot build the k-d tree: {e:?}")))?;
        Ok(CloudIndex { tree })
    }

    /// Distance from `p` to its nearest neighbour, and that neighbour's index.
    pub fn nearest(&self, p: Point3) -> (f64, usize) {
        let r = self
            .tree
            .query(&p)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (r.distance.sqrt(), r.item as usize)
    }

    /// Squared distance from `p` to its nearest neighbour, and that neighbour's index.
    pub fn nearest_squared(&self, p: Point3) -> (f64, usize) {
        let r = self
            .tree
            .query(&p)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (r.distance, r.item as usize)
    }

    /// Squared distance from `p` to its second-nearest point (+∞ for a one-point cloud): for a
    /// point of the cloud, the distance to its nearest other point.
    pub fn second_nearest_squared(&self, p: Point3) -> f64 {
        let two = std::num::NonZeroUsize::MIN.saturating_add(1);
        let found = self
            .tree
            .query(&p)
            .nearest_n::<SquaredEuclidean<f64>>(two)
            .execute();
        match found.as_slice() {
            [a, b] => a.distance.max(b.distance),
            _ => f64::INFINITY,
        }
    }
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;

    #[test]
    fn nearest_matches_brute_force() {
        let pts: Vec<Point3> = (0..500)
            .map(|i| {
                let f = f64::from(i);
                [
                    (f * 0.37).sin() * 3.0,
                    (f * 0.11).cos() * 2.0,
                    (f * 0.07).sin(),
                ]
            })
            .collect();
        let idx = CloudIndex::new(&pts).unwrap();
        for q in [[0.1, 0.2, 0.3], [5.0, -4.0, 1.0], [-1.0, 1.0, 0.5]] {
            let brute = pts
                .iter()
                .map(|p| {
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            assert!((idx.nearest(q).0 - brute).abs() < 1e-12);
        }
    }
}
