//! The Image Matching Challenge's multiview pose accuracy, mAA (ubc-vision/image-matching-benchmark:
//! `eval_colmap.py` `compute_pose_error`, `utils/colmap_helper.py`
//! `compute_stereo_metrics_from_colmap` and `is_colmap_img_valid`, `utils/eval_helper.py`
//! `evaluate_R_t`, `utils/pack_helper.py` `compute_qt_auc_colmap`), for one bag (the ground
//! truth's images):
//!
//! - every unordered pair `i < j` of ground-truth images; `dR = R_j R_iᵀ`, `dt = t_j − dR t_i`
//!   for the estimate and the ground truth;
//! - rotation error `acos(1 − 2·max(eps, 1 − (q·q_gt)²))` of the unit quaternions, translation
//!   error `acos(sqrt(1 − max(eps, 1 − (t̂·t̂_gt)²)))` (the sign folded), `eps = 1e-15`; the pair's
//!   error is the larger, in degrees;
//! - a pair with an unregistered image has error ∞ (counted as 1e6); a model holding any
//!   non-finite pose is invalid and every pair fails, as in `is_colmap_img_valid`;
//! - `numpy.histogram(errors, bins=arange(11))` over all pairs, its cumulative share at 1…10°
//!   (`accuracy`), mAA@10 = their mean and mAA@5 the mean of the first five.

use serde::{Deserialize, Serialize};

use super::protocol::{
    Convention, PairError, PairRow, PairSet, PairedPoses, ThresholdTest, TranslationSign,
    folded_translation_error_rad, quaternion_error_rad, relative,
};

/// The IMC numbers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ImcResult {
    /// The thresholds of [`Self::accuracy`], degrees (1 … 10).
    pub thresholds_deg: Vec<f64>,
    /// Share of pairs under each threshold (cumulative histogram), 0..1.
    pub accuracy: Vec<f64>,
    /// mAA up to 5° (`qt_auc_colmap_05`), 0..1.
    pub maa_5: f64,
    /// mAA up to 10° (`qt_auc_colmap_10`), 0..1.
    pub maa_10: f64,
    /// Pairs scored (unordered ground-truth pairs).
    pub pairs: usize,
    /// Pairs with an unregistered image (all pairs when the model is invalid).
    pub pairs_unregistered: usize,
    /// False when the model holds a non-finite pose (the benchmark then fails every pair).
    pub model_valid: bool,
}

/// The protocol on paired poses.
pub(crate) fn evaluate(paired: &PairedPoses, rows: &mut Vec<PairRow>) -> (Convention, ImcResult) {
    let n = paired.gt.len();
    let valid = paired.non_finite == 0;
    let mut errors = Vec::with_capacity(n * n.saturating_sub(1) / 2);
    let mut unregistered = 0usize;
    for i in 0..n {
        for j in (i + 1)..n {
            let (Some(&(ri, ti)), Some(&(rj, tj))) = (paired.gt.get(i), paired.gt.get(j)) else {
                continue;
            };
            let est = (
                paired.est.get(i).copied().flatten(),
                paired.est.get(j).copied().flatten(),
            );
            match est {
                (Some((ei_r, ei_t)), Some((ej_r, ej_t))) if valid => {
                    let (r_gt, t_gt) = relative(&ri, ti, &rj, tj);
                    let (r_est, t_est) = relative(&ei_r, ei_t, &ej_r, ej_t);
                    let err_q = quaternion_error_rad(&r_gt, &r_est);
                    let err_t = folded_translation_error_rad(t_gt, t_est);
                    let deg = |rad: f64| rad * 180.0 / std::f64::consts::PI;
                    errors.push(deg(err_q.max(err_t)));
                    rows.push(PairRow {
                        i,
                        j,
                        registered: true,
                        rotation_deg: deg(err_q),
                        translation_deg: deg(err_t),
                        error_deg: deg(err_q.max(err_t)),
                    });
                }
                _ => {
                    unregistered += 1;
                    errors.push(1e6);
                    rows.push(PairRow {
                        i,
                        j,
                        registered: false,
                        rotation_deg: f64::INFINITY,
                        translation_deg: f64::INFINITY,
                        error_deg: 1e6,
                    });
                }
            }
        }
    }
    let bins = 10usize;
    let mut hist = vec![0usize; bins];
    for &e in &errors {
        if e.is_nan() || !(0.0..=bins as f64).contains(&e) {
            continue;
        }
        let b = (e.floor() as usize).min(bins - 1);
        if let Some(h) = hist.get_mut(b) {
            *h += 1;
        }
    }
    let m = errors.len().max(1) as f64;
    let mut cum = 0.0;
    let accuracy: Vec<f64> = hist
        .iter()
        .map(|&h| {
            cum += h as f64 / m;
            cum
        })
        .collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let convention = Convention {
        source: "ubc-vision/image-matching-benchmark eval_colmap.py compute_pose_error, utils/eval_helper.py evaluate_R_t, utils/pack_helper.py compute_qt_auc_colmap".into(),
        pairs: PairSet::UnorderedGt,
        pair_error: PairError::Max,
        translation_sign: TranslationSign::Folded,
        threshold_test: ThresholdTest::HistogramBins,
        unregistered: "infinite error (fails every threshold) for a pair with an unregistered image; every pair when the model holds a non-finite pose".into(),
        rotation_error: "acos(1 - 2 max(1e-15, 1 - (q.q_gt)^2)) of the relative rotations' unit quaternions".into(),
    };
    (
        convention,
        ImcResult {
            thresholds_deg: (1..=bins).map(|k| k as f64).collect(),
            maa_5: mean(&accuracy[..5]),
            maa_10: mean(&accuracy),
            accuracy,
            pairs: errors.len(),
            pairs_unregistered: unregistered,
            model_valid: valid,
        },
    )
}
