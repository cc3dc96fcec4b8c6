//! Camera-pose metrics: an estimated [`Reconstruction`] against ground-truth cameras (from
//! `cameras.json`) after a similarity `gt_from_recon`, for the report's `cameras` section.
//!
//! - Absolute: per matched image, the rotation error (angle of `R_gt · R_estᵀ`, with `R_est`
//!   the estimated rotation expressed in the ground-truth frame, `cam_from_gt = cam_from_recon ∘
//!   recon_from_gt`) and the camera-centre error (GT units and % of the scene radius = mean
//!   distance of the GT centres from their centroid); their statistics; ATE RMSE (RMS of the
//!   centre errors).
//! - Relative, over **all** ground-truth image pairs: the angle of the relative-rotation error and
//!   the angle between the relative translation directions (`cam_j_from_cam_i`; no sign folding),
//!   a pair with an unregistered image counting as 180° for both; RRA / RTA (share of pairs under
//!   each threshold, default 5/10/15°) and the AUC of `max(rotation, translation)` error up to
//!   30° (the 1°-step cumulative-histogram mean used by recent SfM papers).
//! - Intrinsics: focal-length error (%) per estimated camera against the GT camera of its
//!   images, scaled by the width ratio when the estimate used another resolution.
//! - Benchmark protocols ([`evaluate_protocol`]): COLMAP's reconstruction benchmark, the Image
//!   Matching Challenge's mAA and CO3D's RRA/RTA/AUC, each as its official code computes it
//!   (one file each; `protocol.rs` holds what they share).

mod co3d;
mod colmap_benchmark;
mod imc;
mod poses_report;
mod poses_summary;
mod protocol;

pub use co3d::Co3dResult;
pub use colmap_benchmark::ColmapResult;
pub use imc::ImcResult;
pub use poses_report::{POSES_SCHEMA, PosesReport, ProtocolResult, evaluate_protocol};
pub use poses_summary::SummaryRow;
pub use protocol::{
    Convention, PairError, PairRow, PairSet, Protocol, ProtocolOptions, ThresholdTest,
    TranslationSign,
};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::geometry::{Point3, norm, sub};
use crate::model::matching::{ImageMatches, match_images};
use crate::model::{Mat3, Reconstruction, mat_mul, rotation_angle_deg, transpose};
use crate::note::{Code, Note};
use crate::stats::{DEFAULT_BINS, Statistics};
use crate::transform::Similarity;

/// Options of [`evaluate_cameras`].
#[derive(Debug, Clone, PartialEq)]
pub struct PoseOptions {
    /// Thresholds (degrees) for RRA / RTA.
    pub thresholds_deg: Vec<f64>,
    /// Largest threshold (degrees) of the AUC; the curve is sampled every degree.
    pub auc_max_deg: f64,
    /// Histogram bins of the statistics blocks.
    pub bins: usize,
    /// At most this many image pairs are evaluated; beyond, every k-th pair (a warning says so).
    pub max_pairs: usize,
}

impl Default for PoseOptions {
    fn default() -> Self {
        PoseOptions {
            thresholds_deg: vec![5.0, 10.0, 15.0],
            auc_max_deg: 30.0,
            bins: DEFAULT_BINS,
            max_pairs: 5_000_000,
        }
    }
}

/// Relative accuracy at one threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct RelativeAccuracy {
    /// Threshold in degrees.
    pub threshold_deg: f64,
    /// Relative Rotation Accuracy: share of pairs with rotation error below the threshold.
    pub rra: f64,
    /// Relative Translation Accuracy: share of pairs with translation-direction error below.
    pub rta: f64,
    /// Share of pairs with both below.
    pub both: f64,
}

/// Relative-pose errors over all ground-truth image pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct RelativePoseReport {
    /// Number of pairs evaluated.
    pub pairs: usize,
    /// Pairs with at least one unregistered image (counted as 180°).
    pub pairs_unregistered: usize,
    /// Relative-rotation error statistics (degrees).
    pub rotation_error_deg: Statistics,
    /// Translation-direction error statistics (degrees).
    pub translation_error_deg: Statistics,
    /// RRA / RTA per threshold.
    pub accuracy: Vec<RelativeAccuracy>,
    /// Largest threshold of the AUC (degrees).
    pub auc_max_deg: f64,
    /// Area under the accuracy curve of `max(rotation, translation)` error, 0..1.
    pub auc: f64,
}

/// Focal-length error of one estimated camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct FocalError {
    /// Estimated camera id.
    pub camera_id: u64,
    /// Ground-truth camera id (the one most of its matched images use).
    pub gt_camera_id: u64,
    /// Ground-truth focal length (px, mean of fx and fy).
    pub focal_gt: f64,
    /// Estimated focal length (px), scaled to the GT image width when both widths are known.
    pub focal_est: f64,
    /// `(focal_est − focal_gt) / focal_gt`, in percent (signed).
    pub error_percent: f64,
    /// Matched images using this camera.
    pub images: usize,
}

/// Pose error of one matched image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ImagePoseError {
    /// Ground-truth image name.
    pub name: String,
    /// Name in the reconstruction.
    pub estimated_name: String,
    /// Rotation error (degrees).
    pub rotation_error_deg: f64,
    /// Camera-centre error (GT units).
    pub center_error: f64,
    /// Camera-centre error in % of the scene radius.
    pub center_error_percent: f64,
}

/// The report's `cameras` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CamerasReport {
    /// Ground-truth images.
    pub ground_truth: usize,
    /// Registered images of the (largest) estimated model.
    pub registered: usize,
    /// Registered images matched to a ground-truth image by name.
    pub matched: usize,
    /// Separate models the SfM tool produced (the largest is evaluated).
    pub models: usize,
    /// Estimated images whose name matches no ground-truth image.
    pub unmatched_estimated: usize,
    /// Rotation error statistics (degrees).
    pub rotation_error_deg: Statistics,
    /// Camera-centre error statistics (GT units).
    pub center_error: Statistics,
    /// Camera-centre error statistics in % of [`Self::scene_radius`].
    pub center_error_percent: Statistics,
    /// Mean distance of the GT camera centres from their centroid.
    pub scene_radius: f64,
    /// Absolute trajectory error: RMS of the centre errors (GT units).
    pub ate_rmse: f64,
    /// Relative-pose errors over all GT image pairs.
    pub relative: RelativePoseReport,
    /// Focal-length error per estimated camera.
    pub focal: Vec<FocalError>,
    /// Per matched image.
    pub images: Vec<ImagePoseError>,
    /// Problems worth a line in the report.
    pub notes: Vec<Note>,
}

/// Mean distance of points from their centroid (0 for fewer than 2 points).
pub(crate) fn scene_radius(centers: &[Point3]) -> f64 {
    if centers.len() < 2 {
        return 0.0;
    }
    let n = centers.len() as f64;
    let mut c = [0.0; 3];
    for p in centers {
        for k in 0..3 {
            c[k] += p[k] / n;
        }
    }
    centers.iter().map(|p| norm(sub(*p, c))).sum::<f64>() / n
}

/// Angle in degrees between two vectors, `[0, 180]`; 0 when both are zero, 180 when only one is.
pub(crate) fn vector_angle_deg(a: Point3, b: Point3) -> f64 {
    let (na, nb) = (norm(a), norm(b));
    let tiny = 1e-300;
    match (na > tiny, nb > tiny) {
        (false, false) => 0.0,
        (true, true) => {
            // Unit vectors when the products could overflow (the angle does not change).
            let (a, b) = if na > 1e100 || nb > 1e100 {
                (a.map(|v| v / na), b.map(|v| v / nb))
            } else {
                (a, b)
            };
            let c = crate::geometry::cross(a, b);
            libm::atan2(norm(c), crate::geometry::dot(a, b)).to_degrees()
        }
        _ => 180.0,
    }
}

/// AUC of the accuracy curve up to `max_deg`, sampled every degree: the mean over
/// `k = 1..=max_deg` of the share of errors below `k` (numpy: `mean(cumsum(histogram(errors,
/// bins=arange(max+1))) / n)`; the last bin includes its right edge).
pub(crate) fn auc(errors: &[f64], max_deg: f64) -> f64 {
    let bins = max_deg.floor().max(1.0) as usize;
    if errors.is_empty() {
        return 0.0;
    }
    let mut hist = vec![0usize; bins];
    for &e in errors {
        if e.is_nan() || e < 0.0 || e > bins as f64 {
            continue;
        }
        let b = (e.floor() as usize).min(bins - 1);
        if let Some(h) = hist.get_mut(b) {
            *h += 1;
        }
    }
    let n = errors.len() as f64;
    let mut cum = 0usize;
    let mut sum = 0.0;
    for h in hist {
        cum += h;
        sum += cum as f64 / n;
    }
    sum / bins as f64
}

/// A relative pose `cam_j_from_cam_i` (rotation, translation).
fn relative(ri: &Mat3, ti: Point3, rj: &Mat3, tj: Point3) -> (Mat3, Point3) {
    let r = mat_mul(rj, &transpose(ri));
    let rti = crate::model::mat_vec(&r, ti);
    (r, [tj[0] - rti[0], tj[1] - rti[1], tj[2] - rti[2]])
}

/// Camera-pose metrics of `est` against `gt` after `gt_from_recon` (see the module docs).
///
/// Errors: [`Error::Empty`] when the ground truth has no images or no estimated image matches a
/// ground-truth name; [`Error::InvalidContent`] for a non-finite or degenerate similarity. Fewer
/// than 3 matches, non-finite estimated poses (treated as unregistered) and unmatched names are
/// warnings.
pub fn evaluate_cameras(
    gt: &Reconstruction,
    est: &Reconstruction,
    gt_from_recon: &Similarity,
    options: &PoseOptions,
) -> Result<CamerasReport> {
    let matches = match_images(gt, est);
    evaluate_cameras_matched(gt, est, &matches, gt_from_recon, options)
}

/// [`evaluate_cameras`] with a given image matching.
pub(crate) fn evaluate_cameras_matched(
    gt: &Reconstruction,
    est: &Reconstruction,
    matches: &ImageMatches,
    gt_from_recon: &Similarity,
    options: &PoseOptions,
) -> Result<CamerasReport> {
    if gt.images.is_empty() {
        return Err(Error::Empty {
            what: "ground-truth cameras (no images)".into(),
        });
    }
    gt.check_finite("cameras.json")?;
    if gt_from_recon
        .matrix
        .iter()
        .flatten()
        .any(|v| !v.is_finite())
    {
        return Err(Error::InvalidContent(
            "gt_from_recon has non-finite entries".into(),
        ));
    }
    let scale = gt_from_recon.scale();
    if !(scale.is_finite() && scale > 0.0) {
        return Err(Error::InvalidContent(format!(
            "gt_from_recon has scale {scale}, not a similarity"
        )));
    }
    let mut warnings = matches.notes.clone();
    // Drop matches with non-finite estimated poses.
    let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(matches.pairs.len());
    let mut non_finite = 0usize;
    for &(g, e) in &matches.pairs {
        match (gt.images.get(g), est.images.get(e)) {
            (Some(_), Some(im)) if im.cam_from_world.is_finite() => pairs.push((g, e)),
            (Some(_), Some(_)) => non_finite += 1,
            _ => {}
        }
    }
    if non_finite > 0 {
        warnings.push(
            Note::new(
                Code::NonFinitePoses,
                format!("{non_finite} estimated pose(s) are NaN/infinite; counted as unregistered"),
            )
            .with("count", non_finite),
        );
    }
    if pairs.is_empty() {
        let example = match (gt.images.first(), est.images.first()) {
            (Some(g), Some(e)) => {
                format!(" (e.g. ground truth '{}', estimate '{}')", g.name, e.name)
            }
            _ => String::new(),
        };
        return Err(Error::Empty {
            what: format!(
                "matched cameras: none of the {} estimated image(s) matches one of the {} ground-truth image names{example}",
                est.images.len(),
                gt.images.len()
            ),
        });
    }
    if pairs.len() < 3 {
        warnings.push(
            Note::new(
                Code::FewMatchedCameras,
                format!(
                    "only {} camera(s) matched the ground truth: pose statistics are not meaningful",
                    pairs.len()
                ),
            )
            .with("matched", pairs.len()),
        );
    }
    if !matches.unmatched_est.is_empty() {
        warnings.push(
            Note::new(
                Code::UnmatchedEstimatedImages,
                format!(
                    "{} estimated image(s) have no ground-truth image of the same name",
                    matches.unmatched_est.len()
                ),
            )
            .with("count", matches.unmatched_est.len()),
        );
    }

    let gt_centers = gt.camera_centers();
    let radius = scene_radius(&gt_centers);
    if radius <= 0.0 {
        warnings.push(
            Note::new(
                Code::SceneRadiusDegenerate,
                "scene radius is 0 (one ground-truth camera): centre errors in % are not given",
            )
            .with_number("scene_radius", radius),
        );
    }
    let rs = gt_from_recon.rotation();

    // Absolute errors.
    let mut images = Vec::with_capacity(pairs.len());
    // Per GT image: estimated pose in the GT frame (rotation, translation up to scale).
    let mut est_in_gt: Vec<Option<(Mat3, Point3)>> = vec![None; gt.images.len()];
    let mut unusable = 0usize;
    for &(g, e) in &pairs {
        let (Some(gi), Some(ei)) = (gt.images.get(g), est.images.get(e)) else {
            continue;
        };
        // cam_from_gt = cam_from_recon ∘ recon_from_gt: R = R_est · R_sᵀ.
        let r_est_gt = mat_mul(&ei.cam_from_world.rotation, &transpose(&rs));
        let c_est_gt = gt_from_recon.apply(ei.center());
        if c_est_gt.iter().any(|v| !v.is_finite()) {
            // Out of f64 range once aligned: as unusable as a NaN pose.
            unusable += 1;
            continue;
        }
        let rot_err =
            rotation_angle_deg(&mat_mul(&gi.cam_from_world.rotation, &transpose(&r_est_gt)));
        let center_err = norm(sub(c_est_gt, gi.center()));
        let t = crate::model::mat_vec(&r_est_gt, c_est_gt);
        if let Some(slot) = est_in_gt.get_mut(g) {
            *slot = Some((r_est_gt, [-t[0], -t[1], -t[2]]));
        }
        images.push(ImagePoseError {
            name: gi.name.clone(),
            estimated_name: ei.name.clone(),
            rotation_error_deg: rot_err,
            center_error: center_err,
            center_error_percent: if radius > 0.0 {
                100.0 * center_err / radius
            } else {
                0.0
            },
        });
    }
    if unusable > 0 {
        warnings.push(
            Note::new(
                Code::CentresOutOfRange,
                format!(
                    "{unusable} estimated camera centre(s) leave the f64 range once aligned; counted as unregistered"
                ),
            )
            .with("count", unusable),
        );
    }
    // A scene radius so small that a centre error in % of it leaves the f64 range.
    let pct_usable = radius > 0.0 && images.iter().all(|i| i.center_error_percent.is_finite());
    if radius > 0.0 && !pct_usable {
        warnings.push(
            Note::new(
                Code::SceneRadiusDegenerate,
                format!(
                    "scene radius is {radius:e}: centre errors in % of it are out of range and not given"
                ),
            )
            .with_number("scene_radius", radius),
        );
        for i in &mut images {
            i.center_error_percent = 0.0;
        }
    }
    let rot: Vec<f64> = images.iter().map(|i| i.rotation_error_deg).collect();
    let cen: Vec<f64> = images.iter().map(|i| i.center_error).collect();
    let cen_pct: Vec<f64> = if pct_usable {
        images.iter().map(|i| i.center_error_percent).collect()
    } else {
        Vec::new()
    };
    let center_error = Statistics::of(&cen, options.bins);
    let ate_rmse = center_error.rms;

    let relative = relative_errors(gt, &est_in_gt, options, &mut warnings);
    let focal = focal_errors(gt, est, &pairs);

    Ok(CamerasReport {
        ground_truth: gt.images.len(),
        registered: est.images.len(),
        matched: pairs.len(),
        models: est.num_models(),
        unmatched_estimated: matches.unmatched_est.len(),
        rotation_error_deg: Statistics::of(&rot, options.bins),
        center_error,
        center_error_percent: Statistics::of(&cen_pct, options.bins),
        scene_radius: radius,
        ate_rmse,
        relative,
        focal,
        images,
        notes: warnings,
    })
}

fn relative_errors(
    gt: &Reconstruction,
    est_in_gt: &[Option<(Mat3, Point3)>],
    options: &PoseOptions,
    warnings: &mut Vec<Note>,
) -> RelativePoseReport {
    let n = gt.images.len();
    let total = n.saturating_mul(n.saturating_sub(1)) / 2;
    let step = if options.max_pairs > 0 && total > options.max_pairs {
        let s = total.div_ceil(options.max_pairs);
        warnings.push(
            Note::new(
                Code::RelativePairsSubsampled,
                format!("{total} image pairs: relative errors use every {s}-th pair"),
            )
            .with("pairs", total)
            .with("every", s),
        );
        s
    } else {
        1
    };
    let mut rot = Vec::with_capacity(total / step + 1);
    let mut trans = Vec::with_capacity(total / step + 1);
    let mut unregistered = 0usize;
    let mut k = 0usize;
    for i in 0..n {
        for j in (i + 1)..n {
            k += 1;
            if !(k - 1).is_multiple_of(step) {
                continue;
            }
            let (Some(gi), Some(gj)) = (gt.images.get(i), gt.images.get(j)) else {
                continue;
            };
            match (
                est_in_gt.get(i).copied().flatten(),
                est_in_gt.get(j).copied().flatten(),
            ) {
                (Some((ri, ti)), Some((rj, tj))) => {
                    let (rg, tg) = relative(
                        &gi.cam_from_world.rotation,
                        gi.cam_from_world.translation,
                        &gj.cam_from_world.rotation,
                        gj.cam_from_world.translation,
                    );
                    let (re, te) = relative(&ri, ti, &rj, tj);
                    rot.push(rotation_angle_deg(&mat_mul(&transpose(&rg), &re)));
                    trans.push(vector_angle_deg(tg, te));
                }
                _ => {
                    unregistered += 1;
                    rot.push(180.0);
                    trans.push(180.0);
                }
            }
        }
    }
    let m = rot.len().max(1) as f64;
    let accuracy = options
        .thresholds_deg
        .iter()
        .map(|&t| {
            let r = rot.iter().filter(|&&e| e < t).count();
            let tr = trans.iter().filter(|&&e| e < t).count();
            let both = rot
                .iter()
                .zip(&trans)
                .filter(|(a, b)| **a < t && **b < t)
                .count();
            RelativeAccuracy {
                threshold_deg: t,
                rra: r as f64 / m,
                rta: tr as f64 / m,
                both: both as f64 / m,
            }
        })
        .collect();
    let worst: Vec<f64> = rot.iter().zip(&trans).map(|(a, b)| a.max(*b)).collect();
    RelativePoseReport {
        pairs: rot.len(),
        pairs_unregistered: unregistered,
        rotation_error_deg: Statistics::of(&rot, options.bins),
        translation_error_deg: Statistics::of(&trans, options.bins),
        accuracy,
        auc_max_deg: options.auc_max_deg,
        auc: auc(&worst, options.auc_max_deg),
    }
}

fn focal_errors(
    gt: &Reconstruction,
    est: &Reconstruction,
    pairs: &[(usize, usize)],
) -> Vec<FocalError> {
    let mut out = Vec::new();
    for cam in &est.cameras {
        // GT cameras of the matched images using this camera, by count.
        let mut counts: Vec<(u64, usize)> = Vec::new();
        for &(g, e) in pairs {
            let (Some(gi), Some(ei)) = (gt.images.get(g), est.images.get(e)) else {
                continue;
            };
            if ei.camera_id != cam.id {
                continue;
            }
            match counts.iter_mut().find(|(id, _)| *id == gi.camera_id) {
                Some((_, n)) => *n += 1,
                None => counts.push((gi.camera_id, 1)),
            }
        }
        let Some((gt_id, _)) = counts.iter().max_by_key(|(_, n)| *n).copied() else {
            continue;
        };
        let images: usize = counts.iter().map(|(_, n)| n).sum();
        let Some(gcam) = gt.cameras.iter().find(|c| c.id == gt_id) else {
            continue;
        };
        let (fg, mut fe) = (gcam.focal(), cam.focal());
        if !(fg > 0.0 && fe > 0.0 && fg.is_finite() && fe.is_finite()) {
            continue;
        }
        if cam.width > 0 && gcam.width > 0 && cam.width != gcam.width {
            fe *= gcam.width as f64 / cam.width as f64;
        }
        out.push(FocalError {
            camera_id: cam.id,
            gt_camera_id: gt_id,
            focal_gt: fg,
            focal_est: fe,
            error_percent: 100.0 * (fe - fg) / fg,
            images,
        });
    }
    out
}

#[cfg(test)]
mod tests;
