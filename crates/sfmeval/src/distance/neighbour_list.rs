//! A Verlet neighbour list: the nearest points of a [`KdCloud`] around where a query point
//! was, kept so that the query, moved a little, finds its exact nearest neighbour by reading a
//! few points instead of walking the tree (molecular dynamics' neighbour lists with a skin).
//! The Tanks and Temples ICP asks each source point's nearest target point once an iteration
//! while the fit moves the points by much less than the point spacing.
//!
//! Exactness: a list made at `centre` holds every point whose squared distance to `centre` is
//! below `radius2`. A query `q` a distance `δ` from `centre` therefore sees in the list every
//! point closer to `q` than `√radius2 − δ` (the coverage, taken with a relative margin of 1e-9
//! for the rounding of the distances, which is about 1e-16). The answer read from the list is
//! the tree's ([`KdCloud::nearest_below`], bit for bit, the same slot on ties through
//! [`KdCloud::visits_before`]) whenever it lies within the coverage; otherwise the list is made
//! again at `q` (the tree's `LIST_LEN` nearest points) and, in the rare case that even those
//! cannot decide (more than `LIST_LEN` points at one distance), the tree answers.

use super::kd_cloud::{KdCloud, distance2};
use crate::geometry::Point3;

/// Points a list holds.
pub(crate) const LIST_LEN: usize = 8;

/// Relative margin on the coverage, far above the rounding of the distances.
const MARGIN: f64 = 1e-9;

/// Squared coverages below this count as none (their distances could be subnormal, where the
/// relative rounding bound does not hold).
const TINY2: f64 = 1e-280;

/// One query point's list (frame: the cloud's).
#[derive(Debug, Clone, Copy)]
pub struct NeighbourList {
    /// Where the list was made.
    centre: Point3,
    /// Every point nearer to `centre` than this (squared) is in `slots`; negative for no list.
    radius2: f64,
    /// Number of slots in use.
    len: u32,
    /// The points, as the cloud's slots.
    slots: [u32; LIST_LEN],
}

impl Default for NeighbourList {
    fn default() -> NeighbourList {
        NeighbourList::NONE
    }
}

impl NeighbourList {
    /// Whether the list holds `LIST_LEN` points.
    pub fn is_full(&self) -> bool {
        self.len as usize == LIST_LEN
    }

    /// No list yet: the first query walks the tree.
    pub const NONE: NeighbourList = NeighbourList {
        centre: [0.0; 3],
        radius2: -1.0,
        len: 0,
        slots: [0; LIST_LEN],
    };

    /// Exactly `cloud.nearest_below(q, bound)`: the nearest point strictly closer to `q` than
    /// `bound.0` (squared), with its slot, or `bound` when there is none. Reads the list when it
    /// decides the answer, else makes it again at `q` from the points closer than `reach2`
    /// (squared; at least `bound.0` serves, more keeps the list useful for longer). A list is
    /// made by a walk of the tree that starts with the radius of a full list's points around
    /// `q`: this list's old points, or `hint`'s (a list of the same cloud, e.g. the previous
    /// query's in the visiting order) when this one is not full. The points found are the same
    /// (only nodes with no nearer point are skipped); the walk opens fewer nodes.
    pub fn nearest_below(
        &mut self,
        cloud: &KdCloud,
        q: Point3,
        bound: (f64, usize),
        reach2: f64,
        hint: Option<&NeighbourList>,
    ) -> (f64, usize) {
        if !q.iter().all(|v| v.is_finite()) {
            return bound;
        }
        let mut radius2 = reach2.max(bound.0);
        if self.radius2 >= 0.0 {
            let coverage2 = self.coverage2(q);
            let listed = self.slots[..self.len as usize]
                .iter()
                .map(|&slot| (slot as usize, distance2(cloud.point(slot as usize), q)));
            if let Some(found) = read(cloud, q, bound, coverage2, listed) {
                return found;
            }
        }
        // A full list's points are LIST_LEN points within their farthest distance from `q`: the
        // new list's radius is no larger, and the walk can start there. The point's own list
        // if it is full, else a neighbouring query's.
        let full = if self.is_full() {
            Some(&self.slots)
        } else {
            hint.filter(|h| h.is_full()).map(|h| &h.slots)
        };
        if let Some(slots) = full {
            let farthest = slots
                .iter()
                .map(|&slot| distance2(cloud.point(slot as usize), q))
                .fold(0.0, f64::max);
            radius2 = radius2.min(farthest * (1.0 + 4.0 * f64::EPSILON) + f64::MIN_POSITIVE);
        }
        let mut nearest = [(0.0, 0u32); LIST_LEN];
        let (len, radius2) = cloud.nearest_k_below(q, radius2, &mut nearest);
        *self = NeighbourList {
            centre: q,
            radius2,
            len: len as u32,
            slots: nearest.map(|(_, slot)| slot),
        };
        // The distances the tree computed for `q` are the ones a read would compute.
        let listed = nearest[..len].iter().map(|&(d2, slot)| (slot as usize, d2));
        read(cloud, q, bound, radius2, listed).unwrap_or_else(|| cloud.nearest_below(q, bound))
    }

    /// The squared radius around `q` within which every point is in the list.
    fn coverage2(&self, q: Point3) -> f64 {
        if q == self.centre {
            return self.radius2;
        }
        let reach = self.radius2.sqrt() * (1.0 - MARGIN)
            - distance2(q, self.centre).sqrt() * (1.0 + MARGIN);
        let coverage2 = (reach.max(0.0) * reach.max(0.0)) * (1.0 - MARGIN);
        if coverage2 < TINY2 { 0.0 } else { coverage2 }
    }
}

/// The answer from a list of `(slot, squared distance to q)`, or `None` when points outside the
/// list could change it: the answer must be nearer than `coverage2`, or, when no listed point
/// beats `bound`, `bound.0` must not exceed it. Equal distances keep the point the tree visits
/// first.
fn read(
    cloud: &KdCloud,
    q: Point3,
    bound: (f64, usize),
    coverage2: f64,
    listed: impl Iterator<Item = (usize, f64)>,
) -> Option<(f64, usize)> {
    let mut best = bound;
    let mut found = false;
    for (slot, d2) in listed {
        if d2 < best.0 {
            best = (d2, slot);
            found = true;
        } else if found && d2 == best.0 && cloud.visits_before(&q, slot, best.1) {
            best = (d2, slot);
        }
    }
    let decided = if found {
        best.0 < coverage2
    } else {
        bound.0 <= coverage2
    };
    decided.then_some(best)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods, clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::distance::kd_cloud::NO_POINT;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    /// A seeded cloud with exact duplicates: points on a coarse lattice (a few copies of each
    /// site, many sites at the same distance from a query: ties the list decides) and a clump
    /// of more than `LIST_LEN` copies of one point (ties only the tree decides).
    fn cloud(n: usize, seed: u64) -> Vec<Point3> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut next = move || rng.random::<f64>();
        (0..n)
            .map(|i| match i % 5 {
                0 => [0.5, 0.25, 0.125],
                1 => [
                    (next() * 16.0).floor() / 16.0,
                    (next() * 16.0).floor() / 16.0,
                    0.0,
                ],
                _ => [next(), next(), next() * 0.1],
            })
            .collect()
    }

    fn brute(pts: &[Point3], q: Point3, bound: (f64, usize)) -> f64 {
        pts.iter()
            .map(|&a| distance2(a, q))
            .filter(|&d| d < bound.0)
            .fold(bound.0, f64::min)
    }

    /// Queries that drift in small and large steps, each seeded with its previous answer as
    /// ICP seeds them: the list's answer is the tree's (distance and slot) and the brute-force
    /// minimum, bit for bit.
    #[test]
    fn answers_equal_the_tree_and_brute_force_while_queries_move() {
        let pts = cloud(6000, 3);
        let tree = KdCloud::new(&pts).unwrap();
        let queries = cloud(300, 11);
        for (limit, reach2) in [(0.01, 0.02), (0.2, 0.2), (f64::INFINITY, f64::INFINITY)] {
            let mut lists = vec![NeighbourList::NONE; queries.len()];
            let mut previous = vec![NO_POINT; queries.len()];
            for step in 0..12 {
                // Mostly small moves, now and then a jump; some queries land on lattice points.
                let shift = if step % 5 == 4 {
                    0.05
                } else {
                    0.0007 * step as f64
                };
                for (i, q0) in queries.iter().enumerate() {
                    let mut q = [q0[0] + shift, q0[1] - 0.5 * shift, q0[2]];
                    if i % 7 == 0 {
                        q = [
                            (q[0] * 16.0).round() / 16.0,
                            (q[1] * 32.0).round() / 32.0,
                            0.0,
                        ];
                    }
                    let bound = match previous[i] {
                        NO_POINT => (limit, NO_POINT),
                        k => {
                            let d2 = distance2(tree.point(k), q);
                            if d2 < limit {
                                (d2, k)
                            } else {
                                (limit, NO_POINT)
                            }
                        }
                    };
                    // Every other query starts its walk from the list before it (any full
                    // list bounds the radius, near or not).
                    let hint = (i % 2 == 1).then(|| lists[i - 1]);
                    let got = lists[i].nearest_below(&tree, q, bound, reach2, hint.as_ref());
                    let want = tree.nearest_below(q, bound);
                    assert_eq!(got.0.to_bits(), want.0.to_bits(), "{q:?} {bound:?}");
                    assert_eq!(got.1, want.1, "{q:?} {bound:?}");
                    assert_eq!(got.0.to_bits(), brute(&pts, q, bound).to_bits());
                    previous[i] = got.1;
                }
            }
        }
        let mut list = NeighbourList::NONE;
        assert_eq!(
            list.nearest_below(&tree, [f64::NAN, 0.0, 0.0], (1.0, 3), 1.0, None),
            (1.0, 3)
        );
    }
}
