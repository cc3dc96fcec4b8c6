//! RRA / RTA at thresholds and AUC@30 as CO3D evaluations compute them (facebookresearch/vggsfm
//! `vggsfm/utils/metric.py`: `camera_to_rel_deg`, `rotation_angle`, `translation_angle`,
//! `compare_translation_by_angle`, `calculate_auc_np`; the thresholds and `<` of
//! facebookresearch/PoseDiffusion `pose_diffusion/test.py`):
//!
//! - every unordered pair `i < j` of ground-truth images (`batched_all_pairs`), the relative
//!   pose `cam_j_from_cam_i` of the estimate and of the ground truth;
//! - rotation error `acos(1 − 2·max(eps, 1 − (q·q_gt)²))` in degrees, the quaternions PyTorch3D's
//!   `matrix_to_quaternion` (not normalized), translation error the
//!   sign-folded angle `acos(sqrt(1 − max(eps, 1 − (t̂·t̂_gt)²)))`, then `min(θ, |180 − θ|)`,
//!   `eps = 1e-15`;
//! - RRA@θ / RTA@θ: share of pairs with the rotation / translation error `< θ`, in percent,
//!   each error **alone**; AUC@30: the mean over `k = 1…30` of the share of pairs whose
//!   **larger** error lies below `k` (`numpy.histogram` bins), in percent;
//! - a pair with an unregistered image (the CO3D code has none: every frame gets a pose) counts
//!   180° for both errors, failing every threshold.

use serde::{Deserialize, Serialize};

use super::protocol::{
    Convention, PairError, PairRow, PairSet, PairedPoses, ProtocolOptions, ThresholdTest,
    TranslationSign, folded_translation_error_rad, quaternion_error_pytorch3d_rad, relative,
};

/// The CO3D numbers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Co3dResult {
    /// RRA / RTA thresholds, degrees.
    pub thresholds_deg: Vec<f64>,
    /// Relative Rotation Accuracy at each threshold, percent.
    pub rra_percent: Vec<f64>,
    /// Relative Translation Accuracy at each threshold, percent.
    pub rta_percent: Vec<f64>,
    /// Largest threshold of the AUC, degrees.
    pub auc_max_deg: f64,
    /// AUC of `max(rotation, translation)` error up to [`Self::auc_max_deg`], percent.
    pub auc_percent: f64,
    /// Pairs scored (unordered ground-truth pairs).
    pub pairs: usize,
    /// Pairs with an unregistered image (180° each).
    pub pairs_unregistered: usize,
}

/// The protocol on paired poses.
pub(crate) fn evaluate(
    paired: &PairedPoses,
    options: &ProtocolOptions,
    rows: &mut Vec<PairRow>,
) -> (Convention, Co3dResult) {
    let n = paired.gt.len();
    let mut r_err = Vec::with_capacity(n * n.saturating_sub(1) / 2);
    let mut t_err = Vec::with_capacity(r_err.capacity());
    let mut unregistered = 0usize;
    let to_deg = |rad: f64| rad * 180.0 / std::f64::consts::PI;
    for i in 0..n {
        for j in (i + 1)..n {
            let (Some(&(ri, ti)), Some(&(rj, tj))) = (paired.gt.get(i), paired.gt.get(j)) else {
                continue;
            };
            match (
                paired.est.get(i).copied().flatten(),
                paired.est.get(j).copied().flatten(),
            ) {
                (Some((ei_r, ei_t)), Some((ej_r, ej_t))) => {
                    let (r_gt, t_gt) = relative(&ri, ti, &rj, tj);
                    let (r_est, t_est) = relative(&ei_r, ei_t, &ej_r, ej_t);
                    let r = to_deg(quaternion_error_pytorch3d_rad(&r_gt, &r_est));
                    let t = to_deg(folded_translation_error_rad(t_gt, t_est));
                    let t = t.min((180.0 - t).abs());
                    r_err.push(r);
                    t_err.push(t);
                    rows.push(PairRow {
                        i,
                        j,
                        registered: true,
                        rotation_deg: r,
                        translation_deg: t,
                        error_deg: r.max(t),
                    });
                }
                _ => {
                    unregistered += 1;
                    r_err.push(180.0);
                    t_err.push(180.0);
                    rows.push(PairRow {
                        i,
                        j,
                        registered: false,
                        rotation_deg: 180.0,
                        translation_deg: 180.0,
                        error_deg: 180.0,
                    });
                }
            }
        }
    }
    let m = r_err.len().max(1) as f64;
    let share = |v: &[f64], th: f64| 100.0 * v.iter().filter(|&&e| e < th).count() as f64 / m;
    let thresholds = options.co3d_thresholds_deg.clone();
    let worst: Vec<f64> = r_err.iter().zip(&t_err).map(|(a, b)| a.max(*b)).collect();
    let convention = Convention {
        source: "facebookresearch/vggsfm vggsfm/utils/metric.py camera_to_rel_deg, calculate_auc_np; facebookresearch/PoseDiffusion pose_diffusion/test.py thresholds".into(),
        pairs: PairSet::UnorderedGt,
        pair_error: PairError::SeparateAccuraciesMaxAuc,
        translation_sign: TranslationSign::Folded,
        threshold_test: ThresholdTest::Below,
        unregistered: "180 degrees for both errors of a pair with an unregistered image (not in the official code, where every frame has a pose)".into(),
        rotation_error: "acos(1 - 2 max(1e-15, 1 - (q.q_gt)^2)) of the relative rotations' unit quaternions".into(),
    };
    (
        convention,
        Co3dResult {
            rra_percent: thresholds.iter().map(|&t| share(&r_err, t)).collect(),
            rta_percent: thresholds.iter().map(|&t| share(&t_err, t)).collect(),
            thresholds_deg: thresholds,
            auc_max_deg: options.co3d_auc_max_deg,
            auc_percent: 100.0 * super::auc(&worst, options.co3d_auc_max_deg),
            pairs: r_err.len(),
            pairs_unregistered: unregistered,
        },
    )
}
