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
use sfmeval::align::{PairSums, umeyama_pairs};
use sfmeval::distance::NeighbourList;
use sfmeval::distance::{KdCloud, NO_POINT, distance2};
use sfmeval::geometry::Point3;
use sfmeval::parallel::{self, morton_order};

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

/// What a pass over the source found: the fit's sums over the matches and their score.
struct Matches {
    sums: PairSums,
    fitness: f64,
    inlier_rmse: f64,
}

/// No match (in `Query::slot`).
const UNMATCHED: u32 = u32::MAX;

/// A source point as it stands and what its query keeps between iterations: its match and its
/// neighbour list.
#[derive(Clone, Copy)]
struct Query {
    point: Point3,
    slot: u32,
    list: NeighbourList,
}

/// The lists are made from the target points within this many correspondence distances, so
/// that a point with no match keeps an empty list while it moves by less than half of one.
const LIST_REACH: f64 = 1.5;

/// Source points per run of a pass: each run sums its matches on its own and the runs' sums
/// are added in order, so the fits do not depend on the thread count.
const RUN: usize = 1024;

/// One pass over the source: each point moved by `update` (none for the first pass), then its
/// nearest target point strictly closer than the correspondence distance (`limit` = its square)
/// found and added to the fit's sums (relative to `shift`, the moved cloud's centroid). The
/// queries are in the visiting order (Morton). A point matched before starts from its previous
/// match (it moved a little: the nearest now is at most that far), the others from the radius;
/// the nearest found is the exact one either way (through the point's neighbour list, which
/// answers as the tree does), so the matches are those of an unbounded nearest-neighbour query
/// filtered by the distance. Moving, matching and summing in one pass reads each point once an
/// iteration: the passes are bound by memory more than by arithmetic.
fn matches(
    queries: &mut [Query],
    update: Option<&Matrix4>,
    shift: Point3,
    target: &KdCloud,
    limit: f64,
) -> Matches {
    let reach2 = limit * LIST_REACH * LIST_REACH;
    // The state: the last full list made or read in this run, a neighbour's in the visiting
    // order.
    let runs = parallel::fold_runs_mut(
        queries,
        RUN,
        || (PairSums::new(shift, shift), 0.0),
        |hint: &mut NeighbourList, (sums, error2): &mut (PairSums, f64), query| {
            if let Some(update) = update {
                query.point = matrix::apply(update, query.point);
            }
            let q = query.point;
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
            if slot == NO_POINT {
                query.slot = UNMATCHED;
            } else {
                query.slot = slot as u32;
                sums.add(q, target.point(slot));
                *error2 += d2;
            }
        },
    );
    let mut sums = PairSums::new(shift, shift);
    let mut error2 = 0.0;
    for (run, run_error2) in &runs {
        sums.merge(run);
        error2 += run_error2;
    }
    let matched = sums.len();
    let (fitness, inlier_rmse) = if matched == 0 {
        (0.0, 0.0)
    } else {
        (
            matched as f64 / queries.len() as f64,
            (error2 / matched as f64).sqrt(),
        )
    };
    Matches {
        sums,
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
    let mut queries: Vec<Query> = morton_order(source)
        .iter()
        .map(|&i| Query {
            point: source[i as usize],
            slot: UNMATCHED,
            list: NeighbourList::NONE,
        })
        .collect();
    // The fits' shift: the source's centroid, moved with the points.
    let mut shift = centroid(source);
    let mut transformation = IDENTITY;
    let mut current = matches(&mut queries, None, shift, target, limit);
    let mut iterations = 0;
    while iterations < criteria.max_iterations {
        let update = fit(&queries, target, &current.sums);
        transformation = matrix::mul(&update, &transformation);
        shift = matrix::apply(&update, shift);
        iterations += 1;
        let previous = std::mem::replace(
            &mut current,
            matches(&mut queries, Some(&update), shift, target, limit),
        );
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

/// The mean of `points` (the origin for none).
fn centroid(points: &[Point3]) -> Point3 {
    let mut sum = [0.0; 3];
    for p in points {
        for k in 0..3 {
            sum[k] += p[k];
        }
    }
    let n = points.len().max(1) as f64;
    sum.map(|v| v / n)
}

/// The scaled Umeyama fit of ICP's matches from the pass's sums, or, in the rare case they
/// cannot be trusted (extreme spreads), from the matches read again through the queries; the
/// identity without matches or when they are degenerate (Open3D returns the identity for no
/// matches).
fn fit(queries: &[Query], target: &KdCloud, sums: &PairSums) -> Matrix4 {
    let fitted = sums.similarity().unwrap_or_else(|| {
        let matched: Vec<&Query> = queries.iter().filter(|q| q.slot != UNMATCHED).collect();
        umeyama_pairs(
            matched.len(),
            |k| matched[k].point,
            |k| target.point(matched[k].slot as usize),
        )
    });
    fitted.map_or(IDENTITY, |s| s.matrix)
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
        // At unit size the fits come from the passes' one-pass sums; at 1e-100 those decline
        // (squares out of range) and the two-pass fit over the queries' matches answers.
        for size in [1.0, 1e-100] {
            let target: Vec<Point3> = grid().iter().map(|p| p.map(|v| v * size)).collect();
            // source = target moved by a small similarity; ICP must undo it.
            let c = libm::cos(0.02);
            let s = libm::sin(0.02);
            let t: Matrix4 = [
                [1.01 * c, -1.01 * s, 0.0, 0.01 * size],
                [1.01 * s, 1.01 * c, 0.0, -0.005 * size],
                [0.0, 0.0, 1.01, 0.002 * size],
                [0.0, 0.0, 0.0, 1.0],
            ];
            let source: Vec<Point3> = target.iter().map(|p| matrix::apply(&t, *p)).collect();
            let index = KdCloud::new(&target).unwrap();
            let strict = IcpCriteria {
                relative_fitness: 1e-12,
                relative_rmse: 1e-12,
                max_iterations: 50,
            };
            let r = registration_icp(&source, &index, 0.2 * size, strict);
            assert_eq!(r.fitness, 1.0, "{size}");
            assert!(r.inlier_rmse < 1e-9 * size, "{size}: {}", r.inlier_rmse);
            for p in &target {
                let back = matrix::apply(&r.transformation, matrix::apply(&t, *p));
                assert!(
                    (0..3).all(|k| (back[k] - p[k]).abs() < 1e-9 * size),
                    "{size}"
                );
            }
            // The toolbox's criteria stop once the match count settles: here after 1 update.
            let r = registration_icp(&source, &index, 0.2 * size, IcpCriteria::TOOLBOX);
            assert_eq!(r.iterations, 1);
            // No match within the distance: nothing moves.
            let far: Vec<Point3> = target
                .iter()
                .map(|p| [p[0] + 10.0 * size, p[1], p[2]])
                .collect();
            let r = registration_icp(&far, &index, 0.2 * size, IcpCriteria::TOOLBOX);
            assert_eq!((r.fitness, r.transformation), (0.0, IDENTITY));
        }
    }
}
