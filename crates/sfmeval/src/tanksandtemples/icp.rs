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

use super::matrix::{self, IDENTITY, Matrix4};
use crate::align::umeyama;
use crate::distance::CloudIndex;
use crate::geometry::Point3;
use crate::parallel;
use crate::progress::NoProgress;

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
    pairs: Vec<(u32, u32)>,
    fitness: f64,
    inlier_rmse: f64,
}

fn matches(source: &[Point3], target: &CloudIndex, max_distance: f64) -> Matches {
    let limit = max_distance * max_distance;
    let nearest = parallel::map_points(source, &NoProgress, |p| target.nearest_squared(*p));
    let mut pairs = Vec::new();
    let mut error2 = 0.0;
    for (i, (d2, j)) in nearest.into_iter().enumerate() {
        if d2 < limit {
            error2 += d2;
            pairs.push((i as u32, j as u32));
        }
    }
    let (fitness, inlier_rmse) = if pairs.is_empty() {
        (0.0, 0.0)
    } else {
        (
            pairs.len() as f64 / source.len() as f64,
            (error2 / pairs.len() as f64).sqrt(),
        )
    };
    Matches {
        pairs,
        fitness,
        inlier_rmse,
    }
}

/// Runs ICP of `source` (already in its initial pose) against `target` (indexed by
/// `target_index`).
pub fn registration_icp(
    source: &[Point3],
    target: &[Point3],
    target_index: &CloudIndex,
    max_distance: f64,
    criteria: IcpCriteria,
) -> IcpResult {
    let mut moved = source.to_vec();
    let mut transformation = IDENTITY;
    let mut current = matches(&moved, target_index, max_distance);
    let mut iterations = 0;
    while iterations < criteria.max_iterations {
        let update = fit(&moved, target, &current.pairs);
        transformation = matrix::mul(&update, &transformation);
        for p in moved.iter_mut() {
            *p = matrix::apply(&update, *p);
        }
        iterations += 1;
        let previous = std::mem::replace(&mut current, matches(&moved, target_index, max_distance));
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

/// The scaled Umeyama fit of the matches; the identity without matches or when they are
/// degenerate (Open3D returns the identity for no matches).
pub(crate) fn fit(source: &[Point3], target: &[Point3], pairs: &[(u32, u32)]) -> Matrix4 {
    if pairs.is_empty() {
        return IDENTITY;
    }
    let src: Vec<Point3> = pairs.iter().map(|&(i, _)| source[i as usize]).collect();
    let dst: Vec<Point3> = pairs.iter().map(|&(_, j)| target[j as usize]).collect();
    umeyama(&src, &dst, true).map_or(IDENTITY, |s| s.matrix)
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
        let index = CloudIndex::new(&target).unwrap();
        let strict = IcpCriteria {
            relative_fitness: 1e-12,
            relative_rmse: 1e-12,
            max_iterations: 50,
        };
        let r = registration_icp(&source, &target, &index, 0.2, strict);
        assert_eq!(r.fitness, 1.0);
        assert!(r.inlier_rmse < 1e-9, "{}", r.inlier_rmse);
        for p in &target {
            let back = matrix::apply(&r.transformation, matrix::apply(&t, *p));
            assert!((0..3).all(|k| (back[k] - p[k]).abs() < 1e-9));
        }
        // The toolbox's criteria stop once the match count settles: here after 1 update.
        let r = registration_icp(&source, &target, &index, 0.2, IcpCriteria::TOOLBOX);
        assert_eq!(r.iterations, 1);
        // No match within the distance: nothing moves.
        let far: Vec<Point3> = target.iter().map(|p| [p[0] + 10.0, p[1], p[2]]).collect();
        let r = registration_icp(&far, &target, &index, 0.2, IcpCriteria::TOOLBOX);
        assert_eq!((r.fitness, r.transformation), (0.0, IDENTITY));
    }
}
