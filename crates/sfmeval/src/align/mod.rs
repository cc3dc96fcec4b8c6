//! Alignment of a reconstruction into the ground-truth frame by a similarity (rotation,
//! translation, uniform scale), in stages that can run alone or chained:
//!
//! - [`umeyama()`]: the closed-form least-squares similarity between matched point sets;
//! - `cameras` ([`align_cameras`]): matched camera centres (and orientations when the centres
//!   are nearly collinear) inside a seeded LO-RANSAC loop;
//! - `points` ([`align_points`]): user-given point pairs;
//! - `global` ([`GlobalOptions`]): no correspondences at all — PCA / spread normalisation and a
//!   multi-start search over rotations, each start scored by a short trimmed ICP;
//! - `icp` ([`refine_icp`]): trimmed, scaled ICP against the exact ground-truth surface with a
//!   scale-collapse guard;
//! - `auto` ([`align()`]): `cameras` (or `points`, or `global`) then `icp`, with fallbacks named
//!   in the report.
//!
//! Everything is deterministic: random choices come from a seeded ChaCha8 stream and parallel
//! work goes through [`crate::parallel::map`], so results do not depend on the thread count.

mod auto;
mod fit;
mod global;
mod icp;
mod points;
mod ransac;
mod request;
mod result;
mod umeyama;

#[cfg(test)]
mod tests;

pub(crate) use auto::fell_back;
pub use auto::{AlignInput, AlignMethod, AlignOptions, align};
pub(crate) use fit::fit_verdict;
pub use global::GlobalOptions;
pub use icp::{IcpOptions, refine_icp};
pub use points::{PointPair, align_points, parse_point_pairs};
pub use ransac::{CameraPair, CamerasOptions, align_cameras};
pub use request::{AlignMode, AlignRequest};
pub use result::{AlignStage, Alignment, StageKind};
pub use umeyama::umeyama;
pub use umeyama::{PairSums, umeyama_pairs};

use nalgebra::{Matrix3, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::geometry::Point3;
use crate::note::{Code, Note};
use crate::transform::Similarity;

/// A row-major 3×3 rotation matrix.
pub(crate) type Rotation = [[f64; 3]; 3];

/// A stage's result.
pub(crate) fn make_stage(
    kind: StageKind,
    t: &Similarity,
    rmse: Option<f64>,
    inlier_ratio: Option<f64>,
    iterations: u64,
    converged: bool,
    notes: Vec<Note>,
) -> AlignStage {
    AlignStage {
        kind,
        gt_from_recon: *t,
        rmse,
        inlier_ratio,
        iterations,
        converged,
        notes,
    }
}

/// The note of a stage that ignored `count` non-finite reconstruction points.
pub(crate) fn non_finite_ignored(stage: &str, count: usize) -> Note {
    Note::new(
        Code::NonFinitePointsIgnored,
        format!(
            "{stage}: {count} reconstruction point(s) with non-finite coordinates were ignored"
        ),
    )
    .with("stage", stage)
    .with("count", count)
}

pub(crate) fn to_v(p: Point3) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

pub(crate) fn to_m(r: &Rotation) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| r[i][j])
}

pub(crate) fn from_m(m: &Matrix3<f64>) -> Rotation {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = m[(i, j)];
        }
    }
    r
}

pub(crate) fn is_finite(p: &Point3) -> bool {
    p.iter().all(|v| v.is_finite())
}

/// Angle in degrees between two rotations (the angle of `a·bᵀ`).
pub(crate) fn rotation_angle_deg(a: &Rotation, b: &Rotation) -> f64 {
    let mut tr = 0.0;
    for i in 0..3 {
        for k in 0..3 {
            tr += a[i][k] * b[i][k];
        }
    }
    libm::acos(((tr - 1.0) / 2.0).clamp(-1.0, 1.0)).to_degrees()
}

/// The proper rotation closest (Frobenius) to `m`, `None` when `m` is degenerate or not finite.
pub(crate) fn project_to_rotation(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (u * vt).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = u * d * vt;
    r.iter().all(|v| v.is_finite()).then_some(r)
}

/// Centroid and covariance (divided by n) of points; `None` for an empty set.
pub(crate) fn centroid_cov(points: &[Point3]) -> Option<(Vector3<f64>, Matrix3<f64>)> {
    if points.is_empty() {
        return None;
    }
    let n = points.len() as f64;
    let mut c = Vector3::zeros();
    for p in points {
        c += to_v(*p);
    }
    c /= n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = to_v(*p) - c;
        cov += d * d.transpose();
    }
    Some((c, cov / n))
}

/// Eigenvalues (descending) and matching eigenvectors (columns) of a symmetric 3×3.
pub(crate) fn sorted_eigen(cov: &Matrix3<f64>) -> ([f64; 3], Matrix3<f64>) {
    let e = cov.symmetric_eigen();
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| {
        e.eigenvalues[b]
            .total_cmp(&e.eigenvalues[a])
            .then(a.cmp(&b))
    });
    let vals = idx.map(|i| e.eigenvalues[i].max(0.0));
    let vecs = Matrix3::from_columns(&idx.map(|i| e.eigenvectors.column(i).into_owned()));
    (vals, vecs)
}

/// How far from collinear a point set is: √(λ₂/λ₁) of its covariance (0 = on a line or a point).
pub(crate) fn planarity_ratio(points: &[Point3]) -> f64 {
    match centroid_cov(points) {
        Some((_, cov)) => {
            let (l, _) = sorted_eigen(&cov);
            if l[0] > 0.0 {
                (l[1] / l[0]).sqrt()
            } else {
                0.0
            }
        }
        None => 0.0,
    }
}

/// A deterministic random subset (without replacement, in random order) of `0..n`, at most `m`.
pub(crate) fn subsample_indices(n: usize, m: usize, seed: u64) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..n).collect();
    if m >= n {
        return idx;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for i in 0..m {
        let j = rng.random_range(i..n);
        idx.swap(i, j);
    }
    idx.truncate(m);
    idx
}

/// The `q`-quantile (0..=1) of `values` (nearest rank on a sorted copy); 0 for an empty slice.
pub(crate) fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    let k = (((v.len() - 1) as f64) * q.clamp(0.0, 1.0)).round() as usize;
    let (_, x, _) = v.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    *x
}
