//! The toolbox's first step, `trajectory_alignment`: a RANSAC similarity between the camera
//! centres of the reconstruction's trajectory and the reference trajectory taken into the
//! ground-truth frame, frame `i` matching frame `i` (Open3D's
//! `registration_ransac_based_on_correspondence`, 6 pairs a sample, scaled point-to-point,
//! correspondence distance 0.2).
//!
//! Each sample draws 6 frames with replacement, fits a scaled Umeyama, and is scored like
//! Open3D scores it: the fitness is the share of moved centres whose nearest reference centre lies
//! closer than the correspondence distance, ties broken by the lower inlier RMSE. Every one of the
//! toolbox's 100000 samples is scored and the best kept, as in Open3D 0.9, which the toolbox
//! pinned and the leaderboard's numbers come from (Open3D 0.20 stops at the first sample whose
//! pairs are all inliers, so its result varies from run to run). The samples come from one seeded
//! ChaCha8 stream and are scored in parallel, the best chosen in sample order: the result does
//! not depend on the thread count.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::matrix::{self, IDENTITY, Matrix4};
use sfmeval::align::umeyama;
use sfmeval::distance::CloudIndex;
use sfmeval::geometry::Point3;
use sfmeval::parallel;
use sfmeval::progress::NoProgress;
use sfmeval::{Error, Result};

/// Parameters of the trajectory alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryAlignmentOptions {
    /// Correspondence distance in ground-truth units (the toolbox's 0.2).
    pub max_correspondence_distance: f64,
    /// Pairs per sample (6).
    pub ransac_n: usize,
    /// Samples drawn and scored (100000).
    pub max_iterations: u32,
    /// Seed of the sample stream.
    pub seed: u64,
}

impl Default for TrajectoryAlignmentOptions {
    fn default() -> Self {
        TrajectoryAlignmentOptions {
            max_correspondence_distance: 0.2,
            ransac_n: 6,
            max_iterations: 100_000,
            seed: 0,
        }
    }
}

/// The best sample's similarity and score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
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

/// Aligns `recon_centers` to `reference_in_gt`, frame `i` ↔ frame `i`, as the toolbox's
/// correspondence RANSAC does: samples pair the first `reference_in_gt.len()` frames with the
/// reference's, and every reconstruction centre counts in the fitness (matched centres over all
/// of them), so a trajectory with frames beyond the reference's is scored with its extra
/// frames, as the toolbox scores it. Fewer frames than the reference is an error.
pub fn align_trajectories(
    recon_centers: &[Point3],
    reference_in_gt: &[Point3],
    options: &TrajectoryAlignmentOptions,
) -> Result<TrajectoryAlignment> {
    let n = reference_in_gt.len();
    let m = recon_centers.len();
    if m < n {
        return Err(Error::InvalidContent(format!(
            "the trajectory has {m} frames and the reference trajectory {n}: the .log needs one frame per reference image, in the reference's order"
        )));
    }
    if n < options.ransac_n || options.ransac_n < 3 || options.max_iterations == 0 {
        return Err(Error::InvalidContent(format!(
            "trajectory alignment needs at least {} frames, the reference has {n}",
            options.ransac_n.max(3)
        )));
    }
    let reference = Reference::new(reference_in_gt)?;
    let limit2 = options.max_correspondence_distance * options.max_correspondence_distance;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    // The samples' frames, `ransac_n` a sample, in one buffer (frame i pairs with frame i).
    let frames: Vec<u32> = (0..options.max_iterations as usize * options.ransac_n)
        .map(|_| rng.random_range(0..n) as u32)
        .collect();
    let samples: Vec<&[u32]> = frames.chunks(options.ransac_n).collect();
    // A sample's score: (matched, sum of squared distances), or None once it provably cannot beat
    // `bound` (the best of the chunks before): too few centres left to reach its match count, or
    // its match count reached at most and its squared error already larger. Pruning never
    // drops a sample that would have won, so the winner is the exhaustive search's.
    let score = |sample: &&[u32], bound: Option<(usize, f64)>| -> Option<(usize, f64)> {
        let t = fit(recon_centers, reference_in_gt, sample);
        let (mut matched, mut error2) = (0usize, 0.0);
        for (k, p) in recon_centers.iter().enumerate() {
            let d2 = reference.nearest2(k, matrix::apply(&t, *p));
            if d2 < limit2 {
                matched += 1;
                error2 += d2;
            }
            if let Some((best_matched, best_error2)) = bound {
                let reachable = matched + (m - k - 1);
                if reachable < best_matched || (reachable == best_matched && error2 > best_error2) {
                    return None;
                }
            }
        }
        Some((matched, error2))
    };
    let rmse = |(matched, error2): (usize, f64)| {
        if matched == 0 {
            0.0
        } else {
            (error2 / matched as f64).sqrt()
        }
    };
    // Chunks in sample order: each chunk is scored in parallel against the best before it.
    let mut best: Option<(usize, (usize, f64))> = None;
    for (c, chunk) in samples.chunks(4096).enumerate() {
        let bound = best.map(|(_, s)| s);
        let scores = parallel::map(chunk, &NoProgress, |s| score(s, bound));
        for (k, s) in scores.into_iter().enumerate() {
            let Some(s) = s else { continue };
            let better = best.is_none_or(|(_, b)| s.0 > b.0 || (s.0 == b.0 && rmse(s) < rmse(b)));
            if better {
                best = Some((c * 4096 + k, s));
            }
        }
    }
    let (best, scores) = best.map_or((0, (0, 0.0)), |b| b);
    let (fitness, inlier_rmse) = (scores.0 as f64 / m as f64, rmse(scores));
    if fitness == 0.0 {
        return Err(Error::Geometry(format!(
            "trajectory alignment: no sample brought any camera within {} of the reference (is the trajectory in the reference's frame order?)",
            options.max_correspondence_distance
        )));
    }
    Ok(TrajectoryAlignment {
        gt_from_recon: fit(recon_centers, reference_in_gt, samples[best]),
        fitness,
        inlier_rmse,
        iterations: options.max_iterations,
    })
}

/// The reference centres indexed for the scores' nearest-centre searches.
struct Reference<'a> {
    centres: &'a [Point3],
    index: CloudIndex,
    /// Per centre, a quarter of the squared distance to its nearest other centre (less a
    /// margin): a point that close to centre `k` has `k` as its nearest centre.
    own_reach2: Vec<f64>,
}

impl<'a> Reference<'a> {
    fn new(centres: &'a [Point3]) -> Result<Reference<'a>> {
        let index = CloudIndex::new(centres)?;
        let own_reach2 = centres
            .iter()
            .map(|&c| index.second_nearest_squared(c) * 0.25 * (1.0 - 1e-9))
            .collect();
        Ok(Reference {
            centres,
            index,
            own_reach2,
        })
    }

    /// The squared distance from `q` (the moved centre of frame `k`) to its nearest reference
    /// centre, the search's to the bit. A centre within half the distance from its own
    /// reference centre to the next one has its own as the nearest (any other is farther by the
    /// triangle inequality, by a relative 1e-9 with the margin, far above the rounding): the
    /// distance is then computed as the search computes it, without a search. Most frames of a
    /// good sample are such.
    fn nearest2(&self, k: usize, q: Point3) -> f64 {
        let Some(&own) = self.centres.get(k) else {
            // A frame beyond the reference's has no own centre.
            return self.index.nearest_squared(q).0;
        };
        let d2 = (own[0] - q[0]) * (own[0] - q[0])
            + (own[1] - q[1]) * (own[1] - q[1])
            + (own[2] - q[2]) * (own[2] - q[2]);
        if d2 <= self.own_reach2[k] {
            d2
        } else {
            self.index.nearest_squared(q).0
        }
    }
}

/// The scaled Umeyama fit of a sample's frames (`source[i]` to `target[i]`); the identity when
/// they are degenerate (fewer than 3, collinear, ...).
fn fit(source: &[Point3], target: &[Point3], frames: &[u32]) -> Matrix4 {
    // The pairs of a sample of the usual size on the stack: the RANSAC fits 100,000 of them.
    const ON_STACK: usize = 8;
    if frames.len() <= ON_STACK {
        let (mut src, mut dst) = ([[0.0; 3]; ON_STACK], [[0.0; 3]; ON_STACK]);
        for (k, &i) in frames.iter().enumerate() {
            (src[k], dst[k]) = (source[i as usize], target[i as usize]);
        }
        let n = frames.len();
        return umeyama(&src[..n], &dst[..n], true).map_or(IDENTITY, |s| s.matrix);
    }
    let src: Vec<Point3> = frames.iter().map(|&i| source[i as usize]).collect();
    let dst: Vec<Point3> = frames.iter().map(|&i| target[i as usize]).collect();
    umeyama(&src, &dst, true).map_or(IDENTITY, |s| s.matrix)
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
        assert_eq!(a.iterations, o.max_iterations);
        assert_eq!(align_trajectories(&recon, &reference, &o).unwrap(), a);
        let e = align_trajectories(&recon[1..], &reference, &o)
            .unwrap_err()
            .to_string();
        assert!(e.contains("39 frames"), "{e}");
        // Frames beyond the reference's (as the toolbox takes them): samples pair the first 40,
        // all 45 count in the fitness; three extras lie on reference centres, two far away.
        let mut longer = recon.clone();
        longer.extend(
            reference[20..23]
                .iter()
                .map(|p| [p[1] / s + 1.0, -p[0] / s - 2.0, p[2] / s + 0.5]),
        );
        longer.extend([[50.0, 0.0, 0.0], [0.0, -70.0, 3.0]]);
        let b = align_trajectories(&longer, &reference, &o).unwrap();
        assert!((b.fitness - 31.0 / 45.0).abs() < 1e-12, "{}", b.fitness);
        for (p, r) in recon.iter().zip(&reference).skip(12) {
            let q = matrix::apply(&b.gt_from_recon, *p);
            assert!((0..3).all(|k| (q[k] - r[k]).abs() < 1e-9));
        }
    }

    /// The shortcut through a frame's own reference centre gives the search's distance to the
    /// bit, for points near their own centre, between centres, near duplicated centres and far
    /// away.
    #[test]
    fn nearest_reference_distance_equals_the_search() {
        let mut centres: Vec<Point3> = (0..30)
            .map(|i| {
                let a = f64::from(i) * 0.4;
                [libm::cos(a), libm::sin(a), 0.1 * f64::from(i)]
            })
            .collect();
        centres[7] = centres[3];
        centres[8] = [centres[9][0] + 1e-12, centres[9][1], centres[9][2]];
        let reference = Reference::new(&centres).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(0x2545_f491_4f6c_dd1du64);
        let mut next = move || rng.random::<f64>() - 0.5;
        let mut shortcuts = 0;
        for reach in [1e-6, 0.01, 0.1, 0.3, 1.0, 10.0] {
            for (k, c) in centres.iter().enumerate() {
                let q = [0, 1, 2].map(|a| c[a] + reach * next());
                let want = reference.index.nearest_squared(q).0;
                assert_eq!(
                    reference.nearest2(k, q).to_bits(),
                    want.to_bits(),
                    "{k} {q:?}"
                );
                shortcuts += usize::from(want <= reference.own_reach2[k]);
            }
        }
        assert!(shortcuts > 60, "{shortcuts}");
    }
}
