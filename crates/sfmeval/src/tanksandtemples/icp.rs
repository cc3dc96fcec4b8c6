//! Open3D's `registration_icp` with `TransformationEstimationPointToPoint(with_scaling=True)`,
//! the registration the toolbox refines its alignment with: each source point's nearest target
//! point closer than the correspondence distance (strictly) is its match; a scaled Umeyama fit
//! on the matches moves the source (the moved points are kept and moved again); iteration stops
//! after `max_iterations` updates or when both the fitness and the inlier RMSE changed by less
//! than their relative criteria.
//!
//! The toolbox passes `ICPConvergenceCriteria(1e-6, 20)`, which Open3D reads positionally as
//! `relative_fitness = 1e-6`, `relative_rmse = 20` with the default `max_iteration = 30`: a stage
//! stops as soon as the number of matches stops changing. [`IcpCriteria::TOOLBOX`] is that.
//!
//! Speed: each source point keeps a neighbour list ([`NeighbourList`]) between iterations, so
//! that once the moves shrink below the point spacing a match is read from 8 points instead of
//! a walk down the target's tree; the answers are the tree's, so the matches, the fits and the
//! iteration counts are those of a plain nearest-neighbour query.

use super::matrix::{self, IDENTITY, Matrix4};
use crate::align::umeyama_pairs;
use crate::distance::kd_cloud::{KdCloud, NO_POINT, distance2};
use crate::distance::neighbour_list::NeighbourList;
use crate::geometry::Point3;
use crate::parallel::{self, morton_order};

/// When ICP stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpCriteria {
    /// Stop when the fitness changed by less than this (and the RMSE by less than its own).
    pub relative_fitness: f64,
    /// Stop when the inlier RMSE changed by less than this (and the fitness by less than its own).
    pub relative_rmse: f64,
    /// At most this many updates.
    pub max_iterations: u32,
}

impl IcpCriteria {
    /// What the toolbox's `ICPConvergenceCriteria(1e-6, 20)` means to Open3D.
    pub const TOOLBOX: IcpCriteria = IcpCriteria {
        relative_fitness: 1e-6,
        relative_rmse: 20.0,
        max_iterations: 30,
    };
}

/// The outcome of one ICP run.
#[derive(Debug, Clone, PartialEq)]
pub struct IcpResult {
    /// `target_from_source` found (to compose with the source's initial transform).
    pub transformation: Matrix4,
    /// Matched share of the source points at the end.
    pub fitness: f64,
    /// RMSE of the matches at the end.
    pub inlier_rmse: f64,
    /// Updates made.
    pub iterations: u32,
}

/// Matches and their score for the source as it stands.
struct Matches {
    /// (source index, target slot) in source order.
    pairs: Vec<(u32, u32)>,
    fitness: f64,
    inlier_rmse: f64,
}

/// No match (in `Query::slot`).
const UNMATCHED: u32 = u32::MAX;

/// What a source point's query keeps between iterations: its match and its neighbour list.
#[derive(Clone, Copy)]
struct Query {
    slot: u32,
    list: NeighbourList,
}

/// The lists are made from the target points within this many correspondence distances, so
/// that a point with no match keeps an empty list while it moves by less than half of one.
const LIST_REACH: f64 = 1.5;

/// Each moved point's nearest target point strictly closer than the correspondence distance
/// (`limit` = its square). `moved` and `queries` are in the visiting order (Morton). A point
/// matched before starts from its previous match (it moved a little: the nearest now is at most
/// that far), the others from the radius; the nearest found is the exact one either way
/// (through the point's neighbour list, which answers as the tree does), so the matches are
/// those of an unbounded nearest-neighbour query filtered by the distance. Pairs and the error
/// sum come in the visiting order, so that the fit then reads the moved points in memory order.
fn matches(moved: &[Point3], target: &KdCloud, limit: f64, queries: &mut [Query]) -> Matches {
    let reach2 = limit * LIST_REACH * LIST_REACH;
    // The state: the last full list made or read in this work unit, a neighbour's in the
    // visiting order.
    let found = parallel::map_mut_with_state(queries, |hint: &mut NeighbourList, k, query| {
        let q = moved[k];
        let bound = match query.slot {
            UNMATCHED => (limit, NO_POINT),
            slot => {
                let d2 = distance2(target.point(slot as usize), q);
                if d2 < limit {
                    (d2, slot as usize)
                } else {
                    (limit, NO_POINT)
                }
            }
        };
        let (d2, slot) = query
            .list
            .nearest_below(target, q, bound, reach2, Some(hint));
        if query.list.is_full() {
            *hint = query.list;
        }
        query.slot = if slot == NO_POINT {
            UNMATCHED
        } else {
            slot as u32
        };
        (d2, query.slot)
    });
    let mut pairs = Vec::new();
    let mut error2 = 0.0;
    for (k, &(d2, slot)) in found.iter().enumerate() {
        if slot != UNMATCHED {
            error2 += d2;
            pairs.push((k as u32, slot));
        }
    }
    let (fitness, inlier_rmse) = if pairs.is_empty() {
        (0.0, 0.0)
    } else {
        (
            pairs.len() as f64 / moved.len() as f64,
            (error2 / pairs.len() as f64).sqrt(),
        )
    };
    Matches {
        pairs,
        fitness,
        inlier_rmse,
    }
}

/// Runs ICP of `source` (already in its initial pose) against `target`.
pub fn registration_icp(
    source: &[Point3],
    target: &KdCloud,
    max_distance: f64,
    criteria: IcpCriteria,
) -> IcpResult {
    let limit = max_distance * max_distance;
    // The moves are small: one spatial visiting order serves every iteration, and the moved
    // points and their queries are kept in it (neighbours in space, neighbours in memory).
    let mut moved: Vec<Point3> = morton_order(source)
        .iter()
        .map(|&i| source[i as usize])
        .collect();
    let mut queries = vec![
        Query {
            slot: UNMATCHED,
            list: NeighbourList::NONE,
        };
        source.len()
    ];
    let mut transformation = IDENTITY;
    let mut current = matches(&moved, target, limit, &mut queries);
    let mut iterations = 0;
    while iterations < criteria.max_iterations {
        let update = fit_pairs(&moved, target, &current.pairs);
        transformation = matrix::mul(&update, &transformation);
        parallel::map_mut(&mut moved, |_, p| *p = matrix::apply(&update, *p));
        iterations += 1;
        let previous =
            std::mem::replace(&mut current, matches(&moved, target, limit, &mut queries));
        if (previous.fitness - current.fitness).abs() < criteria.relative_fitness
            && (previous.inlier_rmse - current.inlier_rmse).abs() < criteria.relative_rmse
        {
            break;
        }
    }
    IcpResult {
        transformation,
        fitness: current.fitness,
        inlier_rmse: current.inlier_rmse,
        iterations,
    }
}

/// The scaled Umeyama fit of ICP's matches `(moved point, target slot)`, summed in parallel;
/// the identity without matches or when they are degenerate (Open3D returns the identity for
/// no matches).
fn fit_pairs(moved: &[Point3], target: &KdCloud, pairs: &[(u32, u32)]) -> Matrix4 {
    umeyama_pairs(
        pairs.len(),
        |k| moved[pairs[k].0 as usize],
        |k| target.point(pairs[k].1 as usize),
    )
    .map_or(IDENTITY, |s| s.matrix)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Vec<Point3> {
        let mut pts = Vec::new();
        for i in 0..12 {
            for j in 0..12 {
                let (x, y) = (f64::from(i) * 0.1, f64::from(j) * 0.1);
                pts.push([x, y, 0.3 * libm::sin(x * 3.0) * libm::cos(y * 2.0)]);
            }
        }
        pts
    }

    #[test]
    fn recovers_a_small_similarity_exactly() {
        let target = grid();
        // source = target moved by a small similarity; ICP must undo it.
        let c = libm::cos(0.02);
        let s = libm::sin(0.02);
        let t: Matrix4 = [
            [1.01 * c, -1.01 * s, 0.0, 0.01],
            [1.01 * s, 1.01 * c, 0.0, -0.005],
            [0.0, 0.0, 1.01, 0.002],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let source: Vec<Point3> = target.iter().map(|p| matrix::apply(&t, *p)).collect();
        let index = KdCloud::new(&target).unwrap();
        let strict = IcpCriteria {
            relative_fitness: 1e-12,
            relative_rmse: 1e-12,
            max_iterations: 50,
        };
        let r = registration_icp(&source, &index, 0.2, strict);
        assert_eq!(r.fitness, 1.0);
        assert!(r.inlier_rmse < 1e-9, "{}", r.inlier_rmse);
        for p in &target {
            let back = matrix::apply(&r.transformation, matrix::apply(&t, *p));
            assert!((0..3).all(|k| (back[k] - p[k]).abs() < 1e-9));
        }
        // The toolbox's criteria stop once the match count settles: here after 1 update.
        let r = registration_icp(&source, &index, 0.2, IcpCriteria::TOOLBOX);
        assert_eq!(r.iterations, 1);
        // No match within the distance: nothing moves.
        let far: Vec<Point3> = target.iter().map(|p| [p[0] + 10.0, p[1], p[2]]).collect();
        let r = registration_icp(&far, &index, 0.2, IcpCriteria::TOOLBOX);
        assert_eq!((r.fitness, r.transformation), (0.0, IDENTITY));
    }
}
