//! COLMAP's reconstruction benchmark, relative metric (colmap/colmap
//! `benchmark/reconstruction/evaluation/utils.py`: `compute_grouped_rel_errors`,
//! `compute_rel_pose_error`, `compute_auc`, `compute_recall`; `geometry.py`:
//! `vec_angular_dist_deg`), for a scene with one ground-truth component:
//!
//! - every **ordered** pair `(src, tgt)` of ground-truth images is an edge; a pair in which both
//!   images are registered scores `max(dt, dR)` with `dR` the angle of `est⁻¹ · gt` of the two
//!   `tgt_from_src` poses and `dt` the angle between their translations (signed directions,
//!   `acos(clip(û·v̂))`, each divided by `max(1e-10, norm)`), `dt = 0` when the GT baseline is
//!   shorter than the position accuracy; a pair with an unregistered image scores 180°;
//! - every ordered pair of registered images that is not a ground-truth edge (an image outside
//!   the ground truth) scores 180°;
//! - AUC at each threshold `t`: the trapezoid area under the recall curve of the sorted errors
//!   (starting at `(0, 0)`, or at `(min_error, recall(min_error))` after `(0, recall)` when the
//!   position accuracy is positive), up to `t`, divided by `t`, in percent; recall: share of
//!   errors `≤ t`, in percent.
//!
//! The official code scores every sub-model of a run (a multiset of edges); sfmeval reads the
//! largest model, so a run with several models is scored on its largest (the report's `models`
//! says how many there were).

use serde::{Deserialize, Serialize};

use super::protocol::{
    Convention, PairError, PairRow, PairSet, PairedPoses, ProtocolOptions, ThresholdTest,
    TranslationSign, relative,
};
use crate::geometry::Point3;
use crate::model::{mat_mul, rotation_angle_deg, transpose};

/// COLMAP's benchmark numbers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ColmapResult {
    /// Thresholds in degrees.
    pub thresholds_deg: Vec<f64>,
    /// AUC at each threshold, percent.
    pub auc_percent: Vec<f64>,
    /// Recall (share of errors `≤` the threshold) at each threshold, percent.
    pub recall_percent: Vec<f64>,
    /// The position accuracy used (GT units; 0: off).
    pub position_accuracy: f64,
    /// Errors scored (ordered pairs).
    pub pairs: usize,
    /// Ground-truth pairs with an unregistered image (180° each).
    pub pairs_unregistered: usize,
    /// Registered pairs outside the ground truth (180° each).
    pub pairs_outside_gt: usize,
    /// Median of the errors, degrees.
    pub median_error_deg: f64,
}

/// `vec_angular_dist_deg`: `rad2deg(acos(clip(dot(v1/max(1e-10,|v1|), v2/max(1e-10,|v2|)), -1, 1)))`.
fn vec_angular_dist_deg(a: Point3, b: Point3) -> f64 {
    let unit = |v: Point3| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-10);
        v.map(|x| x / n)
    };
    let (a, b) = (unit(a), unit(b));
    let cos = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0);
    libm::acos(cos).to_degrees()
}

/// `compute_auc` (percent) at each threshold.
pub(crate) fn compute_auc(errors: &[f64], thresholds: &[f64], min_error: f64) -> Vec<f64> {
    let n = errors.len();
    if n == 0 {
        return vec![0.0; thresholds.len()];
    }
    let mut sorted = errors.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut recalls: Vec<f64> = (1..=n).map(|k| k as f64 / n as f64).collect();
    let (errs, recs) = if min_error > 0.0 {
        let min_index = sorted.partition_point(|&e| e <= min_error);
        let min_recall = min_index as f64 / n as f64;
        let mut e = vec![0.0, min_error];
        e.extend_from_slice(&sorted[min_index..]);
        let mut r = vec![min_recall, min_recall];
        r.extend_from_slice(&recalls[min_index..]);
        (e, r)
    } else {
        let mut e = vec![0.0];
        e.extend_from_slice(&sorted);
        recalls.insert(0, 0.0);
        (e, recalls)
    };
    thresholds
        .iter()
        .map(|&t| {
            let last = errs.partition_point(|&e| e <= t).max(1);
            let mut x: Vec<f64> = errs[..last].to_vec();
            x.push(t);
            let mut y: Vec<f64> = recs[..last].to_vec();
            y.push(recs[last - 1]);
            let area: f64 = x
                .windows(2)
                .zip(y.windows(2))
                .map(|(x, y)| (x[1] - x[0]) * (y[1] + y[0]) / 2.0)
                .sum();
            area / t * 100.0
        })
        .collect()
}

/// The protocol on paired poses.
pub(crate) fn evaluate(
    paired: &PairedPoses,
    options: &ProtocolOptions,
    rows: &mut Vec<PairRow>,
) -> (Convention, ColmapResult) {
    let n = paired.gt.len();
    let min_dist = options.colmap_position_accuracy;
    let mut errors = Vec::with_capacity(n * n.saturating_sub(1));
    let mut unregistered = 0usize;
    for src in 0..n {
        for tgt in 0..n {
            if src == tgt {
                continue;
            }
            let (Some(&(rs, ts)), Some(&(rt, tt))) = (paired.gt.get(src), paired.gt.get(tgt))
            else {
                continue;
            };
            match (
                paired.est.get(src).copied().flatten(),
                paired.est.get(tgt).copied().flatten(),
            ) {
                (Some((es_r, es_t)), Some((et_r, et_t))) => {
                    let (r_gt, t_gt) = relative(&rs, ts, &rt, tt);
                    let (r_est, t_est) = relative(&es_r, es_t, &et_r, et_t);
                    let baseline =
                        (t_gt[0] * t_gt[0] + t_gt[1] * t_gt[1] + t_gt[2] * t_gt[2]).sqrt();
                    let dt = if baseline < min_dist {
                        0.0
                    } else {
                        vec_angular_dist_deg(t_est, t_gt)
                    };
                    let dr = rotation_angle_deg(&mat_mul(&transpose(&r_est), &r_gt));
                    errors.push(dt.max(dr));
                    rows.push(PairRow {
                        i: src,
                        j: tgt,
                        registered: true,
                        rotation_deg: dr,
                        translation_deg: dt,
                        error_deg: dt.max(dr),
                    });
                }
                _ => {
                    unregistered += 1;
                    errors.push(180.0);
                    rows.push(PairRow {
                        i: src,
                        j: tgt,
                        registered: false,
                        rotation_deg: 180.0,
                        translation_deg: 180.0,
                        error_deg: 180.0,
                    });
                }
            }
        }
    }
    let registered = paired.est.iter().filter(|e| e.is_some()).count() + paired.outliers;
    let matched = registered - paired.outliers;
    let outside = registered * registered.saturating_sub(1) - matched * matched.saturating_sub(1);
    errors.extend(std::iter::repeat_n(180.0, outside));
    if errors.is_empty() {
        errors.push(180.0);
    }
    let thresholds = options.colmap_thresholds_deg.clone();
    let auc_percent = compute_auc(&errors, &thresholds, min_dist);
    let recall_percent = thresholds
        .iter()
        .map(|&t| 100.0 * errors.iter().filter(|&&e| e <= t).count() as f64 / errors.len() as f64)
        .collect();
    let mut sorted = errors.clone();
    sorted.sort_by(f64::total_cmp);
    let m = sorted.len();
    let median = if m % 2 == 1 {
        sorted[m / 2]
    } else {
        (sorted[m / 2 - 1] + sorted[m / 2]) / 2.0
    };
    let convention = Convention {
        source: "colmap/colmap benchmark/reconstruction/evaluation/utils.py: compute_grouped_rel_errors, compute_auc, compute_recall".into(),
        pairs: PairSet::OrderedGtAndRegistered,
        pair_error: PairError::Max,
        translation_sign: TranslationSign::Signed,
        threshold_test: ThresholdTest::AtMost,
        unregistered: "180 degrees for a ground-truth pair with an unregistered image and for a registered pair outside the ground truth".into(),
        rotation_error: "geodesic angle of est^-1 * gt of the tgt_from_src poses".into(),
    };
    (
        convention,
        ColmapResult {
            thresholds_deg: thresholds,
            auc_percent,
            recall_percent,
            position_accuracy: min_dist,
            pairs: errors.len(),
            pairs_unregistered: unregistered,
            pairs_outside_gt: outside,
            median_error_deg: median,
        },
    )
}
