//! The toolbox's first step, `trajectory_alignment`: a RANSAC similarity between the camera
//! centres of the reconstruction's trajectory and the reference trajectory taken into the
//! ground-truth frame, frame `i` matching frame `i` (Open3D's
//! `registration_ransac_based_on_correspondence`, 6 pairs a sample, scaled point-to-point,
//! correspondence distance 0.2).
//!
//! Each sample draws 6 frames with replacement, fits a scaled Umeyama, and scores it like
//! Open3D: the fitness is the share of moved centres whose nearest reference centre lies
//! closer than the correspondence distance, ties broken by the lower inlier RMSE. Sampling is
//! sequential from a seeded ChaCha8 stream, so the result is reproducible; it stops early as
//! Open3D 0.20 does, once `log(1 − confidence) / log(1 − wⁿ)` samples have been drawn for the best
//! sample's pair-inlier ratio `w` (Open3D 0.9, which the toolbox pinned, drew every sample).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::icp::fit;
use super::matrix::{self, Matrix4};
use crate::distance::CloudIndex;
use crate::error::{Error, Result};
use crate::geometry::Point3;

/// Parameters of the trajectory alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryAlignmentOptions {
    /// Correspondence distance in ground-truth units (the toolbox's 0.2).
    pub max_correspondence_distance: f64,
    /// Pairs per sample (6).
    pub ransac_n: usize,
    /// Most samples (100000).
    pub max_iterations: u32,
    /// Confidence of the early stop (Open3D's default 0.999).
    pub confidence: f64,
    /// Seed of the sample stream.
    pub seed: u64,
}

impl Default for TrajectoryAlignmentOptions {
    fn default() -> Self {
        TrajectoryAlignmentOptions {
            max_correspondence_distance: 0.2,
            ransac_n: 6,
            max_iterations: 100_000,
            confidence: 0.999,
            seed: 0,
        }
    }
}

/// The best sample's similarity and score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryAlignment {
    /// `gt_from_recon` of the best sample.
    pub gt_from_recon: Matrix4,
    /// Share of reconstruction centres with a reference centre within the distance.
    pub fitness: f64,
    /// RMSE of those matches.
    pub inlier_rmse: f64,
    /// Samples drawn.
    pub iterations: u32,
}

/// Aligns `recon_centers` to `reference_in_gt` (same length, frame `i` ↔ frame `i`).
pub fn align_trajectories(
    recon_centers: &[Point3],
    reference_in_gt: &[Point3],
    options: &TrajectoryAlignmentOptions,
) -> Result<TrajectoryAlignment> {
    let n = reference_in_gt.len();
    if recon_centers.len() != n {
        return Err(Error::InvalidOption(format!(
            "the trajectory has {} frames and the reference trajectory {n}: the .log needs one frame per reference image, in the reference's order",
            recon_centers.len()
        )));
    }
    if n < options.ransac_n || options.ransac_n < 3 {
        return Err(Error::InvalidOption(format!(
            "trajectory alignment needs at least {} frames, the reference has {n}",
            options.ransac_n.max(3)
        )));
    }
    let index = CloudIndex::new(reference_in_gt)?;
    let limit2 = options.max_correspondence_distance * options.max_correspondence_distance;
    let log_confidence = libm::log(1.0 - options.confidence);
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut best: Option<TrajectoryAlignment> = None;
    let mut sample: Vec<(u32, u32)> = vec![(0, 0); options.ransac_n];
    let mut stop_after = options.max_iterations;
    let mut moved = vec![[0.0; 3]; n];
    let mut drawn = 0;
    while drawn < stop_after {
        drawn += 1;
        for s in sample.iter_mut() {
            let i = rng.random_range(0..n) as u32;
            *s = (i, i);
        }
        let t = fit(recon_centers, reference_in_gt, &sample);
        let (mut matched, mut error2) = (0usize, 0.0);
        for (m, p) in moved.iter_mut().zip(recon_centers) {
            *m = matrix::apply(&t, *p);
            let (d2, _) = index.nearest_squared(*m);
            if d2 < limit2 {
                matched += 1;
                error2 += d2;
            }
        }
        let fitness = matched as f64 / n as f64;
        let inlier_rmse = if matched == 0 {
            0.0
        } else {
            (error2 / matched as f64).sqrt()
        };
        let better = best.as_ref().is_none_or(|b| {
            fitness > b.fitness || (fitness == b.fitness && inlier_rmse < b.inlier_rmse)
        });
        if !better {
            continue;
        }
        best = Some(TrajectoryAlignment {
            gt_from_recon: t,
            fitness,
            inlier_rmse,
            iterations: 0,
        });
        let pair_inliers = moved
            .iter()
            .zip(reference_in_gt)
            .filter(|(a, b)| {
                let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
                d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < limit2
            })
            .count();
        let w = pair_inliers as f64 / n as f64;
        let k = log_confidence / libm::log(1.0 - libm::pow(w, options.ransac_n as f64));
        if k >= 0.0 && k < f64::from(stop_after) {
            stop_after = libm::ceil(k) as u32;
        }
    }
    let mut best =
        best.ok_or_else(|| Error::Geometry("trajectory alignment drew no sample".into()))?;
    best.iterations = drawn;
    if best.fitness == 0.0 {
        return Err(Error::Geometry(format!(
            "trajectory alignment: no sample brought any camera within {} of the reference (is the trajectory in the reference's frame order?)",
            options.max_correspondence_distance
        )));
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_similarity_despite_outliers_and_is_reproducible() {
        // 40 centres on a helix; the reconstruction is the reference under a similarity, with
        // 8 frames missing (identity pose: centre at the origin) and 4 wrong.
        let reference: Vec<Point3> = (0..40)
            .map(|i| {
                let a = f64::from(i) * 0.3;
                [2.0 * libm::cos(a), 2.0 * libm::sin(a), 0.05 * f64::from(i)]
            })
            .collect();
        // recon = (reference - t) / s rotated about z by 90°: gt_from_recon = s·Rz(-90°)… built
        // directly as the inverse map on the points.
        let s = 3.0;
        let mut recon: Vec<Point3> = reference
            .iter()
            .map(|p| [p[1] / s + 1.0, -p[0] / s - 2.0, p[2] / s + 0.5])
            .collect();
        for c in recon.iter_mut().take(8) {
            *c = [0.0; 3];
        }
        for (k, c) in recon.iter_mut().skip(8).take(4).enumerate() {
            c[0] += 1.0 + k as f64;
        }
        let o = TrajectoryAlignmentOptions::default();
        let a = align_trajectories(&recon, &reference, &o).unwrap();
        assert!((a.fitness - 28.0 / 40.0).abs() < 1e-12, "{}", a.fitness);
        for (p, r) in recon.iter().zip(&reference).skip(12) {
            let q = matrix::apply(&a.gt_from_recon, *p);
            assert!((0..3).all(|k| (q[k] - r[k]).abs() < 1e-9));
        }
        assert!(a.iterations < o.max_iterations);
        assert_eq!(align_trajectories(&recon, &reference, &o).unwrap(), a);
        let e = align_trajectories(&recon[1..], &reference, &o)
            .unwrap_err()
            .to_string();
        assert!(e.contains("39 frames"), "{e}");
    }
}
