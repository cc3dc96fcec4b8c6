//! The camera-pose benchmark protocols, each as its official code computes it (one file each:
//! [`super::colmap_benchmark`], [`super::imc`], [`super::co3d`]), on an estimated
//! [`Reconstruction`] and ground-truth cameras paired by image name. Relative poses need no
//! alignment: every protocol here compares `cam_j_from_cam_i` of the estimate with that of the
//! ground truth, so the estimate's gauge (similarity) does not matter.
//!
//! The report (`sfmeval.poses/1`, `schemas/poses.schema.json`) names each protocol's convention
//! ([`Convention`]): which pairs, how a pair's rotation and translation errors combine (the
//! larger of the two, or each alone), whether the translation direction's sign is folded, which
//! comparison a threshold uses and what a pair with an unregistered image counts as.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::model::matching::match_images;
use crate::model::{Mat3, Reconstruction, mat_mul, mat_vec, transpose};
use crate::note::{Code, Note};

/// A pose benchmark protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Protocol {
    /// COLMAP's reconstruction benchmark (`benchmark/reconstruction/evaluation/utils.py`).
    Colmap,
    /// The Image Matching Challenge's multiview mAA (ubc-vision/image-matching-benchmark).
    Imc,
    /// RRA/RTA@θ and AUC@30 as CO3D evaluations compute them (VGGSfM / PoseDiffusion).
    Co3d,
}

impl Protocol {
    /// Every protocol, in the order the CLI lists them.
    pub const ALL: [Protocol; 3] = [Protocol::Colmap, Protocol::Imc, Protocol::Co3d];

    /// The protocol's name (`colmap`, `imc`, `co3d`).
    pub fn name(self) -> &'static str {
        match self {
            Protocol::Colmap => "colmap",
            Protocol::Imc => "imc",
            Protocol::Co3d => "co3d",
        }
    }

    /// The protocol of a name, or an [`Error::InvalidOption`] listing the names.
    pub fn parse(name: &str) -> Result<Protocol> {
        Protocol::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                Error::InvalidOption(format!(
                    "unknown pose protocol '{name}' (expected one of: colmap, imc, co3d)"
                ))
            })
    }
}

/// Options of [`super::evaluate_protocol`]; the defaults are each protocol's official ones.
#[derive(Debug, Clone, PartialEq)]
pub struct ProtocolOptions {
    /// COLMAP: AUC and recall thresholds in degrees (official default 0.5, 1, 5, 10).
    pub colmap_thresholds_deg: Vec<f64>,
    /// COLMAP: the dataset's ground-truth position accuracy (`position_accuracy_gt`, GT
    /// units): pairs whose GT baseline is shorter get translation error 0, and it is the AUC's
    /// `min_error`. The benchmark sets it per dataset; 0 turns both off.
    pub colmap_position_accuracy: f64,
    /// CO3D: RRA / RTA thresholds in degrees (official 5, 15, 30).
    pub co3d_thresholds_deg: Vec<f64>,
    /// CO3D: the AUC's largest threshold in degrees (official 30).
    pub co3d_auc_max_deg: f64,
}

impl Default for ProtocolOptions {
    fn default() -> Self {
        ProtocolOptions {
            colmap_thresholds_deg: vec![0.5, 1.0, 5.0, 10.0],
            colmap_position_accuracy: 0.0,
            co3d_thresholds_deg: vec![5.0, 15.0, 30.0],
            co3d_auc_max_deg: 30.0,
        }
    }
}

/// Which image pairs a protocol scores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum PairSet {
    /// Every ordered pair `(i, j)`, `i ≠ j`, of the ground-truth images, plus every ordered pair
    /// involving a registered image that is not in the ground truth.
    OrderedGtAndRegistered,
    /// Every unordered pair `i < j` of the ground-truth images, in ground-truth order.
    UnorderedGt,
}

/// How a pair's rotation and translation errors make its score.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum PairError {
    /// `max(rotation error, translation error)` is compared with each threshold.
    Max,
    /// Accuracies compare each error alone (RRA, RTA); the AUC uses the maximum.
    SeparateAccuraciesMaxAuc,
}

/// How the translation-direction error treats the sign of the direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum TranslationSign {
    /// The angle between the directions, 0–180°.
    Signed,
    /// The angle between the lines, 0–90° (`acos(|cos|)`): a reversed direction is no error.
    Folded,
}

/// How a pair is compared with a threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub enum ThresholdTest {
    /// `error <= threshold`.
    AtMost,
    /// `error < threshold`.
    Below,
    /// The histogram of `numpy.histogram(errors, bins=arange(max + 1))`: bins `[k, k+1)`, the
    /// last closed; the accuracy at `k` counts the bins below it.
    HistogramBins,
}

/// A protocol's convention, written into its report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Convention {
    /// The official code this protocol follows (repository, file, function).
    pub source: String,
    /// Which pairs are scored.
    pub pairs: PairSet,
    /// How rotation and translation errors combine.
    pub pair_error: PairError,
    /// The translation-direction sign.
    pub translation_sign: TranslationSign,
    /// How thresholds compare.
    pub threshold_test: ThresholdTest,
    /// What a pair with an unregistered image counts as, in words.
    pub unregistered: String,
    /// The rotation-error formula, in words.
    pub rotation_error: String,
}

/// One scored ground-truth pair (the CLI's `--pairs` CSV; not in the JSON report).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PairRow {
    /// First image (COLMAP: `src`), an index into the ground-truth images.
    pub i: usize,
    /// Second image (COLMAP: `tgt`).
    pub j: usize,
    /// Both images registered (else the errors are the protocol's failure value).
    pub registered: bool,
    /// Rotation error, degrees.
    pub rotation_deg: f64,
    /// Translation-direction error, degrees.
    pub translation_deg: f64,
    /// The pair's error as the protocol combines them, degrees.
    pub error_deg: f64,
}

/// The inputs every protocol shares: ground-truth poses in GT order, the matched estimated
/// pose of each (`None`: unregistered, absent or non-finite) and the estimated images outside
/// the ground truth.
pub(crate) struct PairedPoses {
    /// `(rotation, translation)` of each GT image's `cam_from_world`.
    pub gt: Vec<(Mat3, Point3)>,
    /// The estimate of each GT image.
    pub est: Vec<Option<(Mat3, Point3)>>,
    /// Registered images (finite) not in the ground truth.
    pub outliers: usize,
    /// Estimated poses that are not finite.
    pub non_finite: usize,
}

/// `cam_j_from_cam_i` of two `cam_from_world` poses: `(R_j R_iᵀ, t_j − R_j R_iᵀ t_i)`.
pub(crate) fn relative(ri: &Mat3, ti: Point3, rj: &Mat3, tj: Point3) -> (Mat3, Point3) {
    let r = mat_mul(rj, &transpose(ri));
    let rti = mat_vec(&r, ti);
    (r, [tj[0] - rti[0], tj[1] - rti[1], tj[2] - rti[2]])
}

/// A unit quaternion `(w, x, y, z)` of a rotation matrix, `w ≥ 0` (Shepperd's method).
pub(crate) fn quaternion(r: &Mat3) -> [f64; 4] {
    let (m00, m11, m22) = (r[0][0], r[1][1], r[2][2]);
    let tr = m00 + m11 + m22;
    let q = if tr >= m00.max(m11).max(m22) {
        let s = (1.0 + tr).max(0.0).sqrt() * 2.0;
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if m00 >= m11 && m00 >= m22 {
        let s = (1.0 + m00 - m11 - m22).max(0.0).sqrt() * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if m11 >= m22 {
        let s = (1.0 + m11 - m00 - m22).max(0.0).sqrt() * 2.0;
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m22 - m00 - m11).max(0.0).sqrt() * 2.0;
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let s = if q[0] < 0.0 { -1.0 / n } else { 1.0 / n };
    q.map(|v| v * s)
}

/// The `eps`-floored quaternion rotation error of IMC's `evaluate_R_t`, in radians:
/// `acos(1 − 2·max(eps, 1 − (q·q_gt)²))` of the quaternions divided by `norm + eps`,
/// `eps = 1e-15`.
pub(crate) fn quaternion_error_rad(r_gt: &Mat3, r_est: &Mat3) -> f64 {
    let eps = 1e-15;
    let unit = |q: [f64; 4]| {
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt() + eps;
        q.map(|v| v / n)
    };
    let (a, b) = (unit(quaternion(r_gt)), unit(quaternion(r_est)));
    let dot = b[0] * a[0] + b[1] * a[1] + b[2] * a[2] + b[3] * a[3];
    let loss = (1.0 - dot * dot).max(eps);
    libm::acos(1.0 - 2.0 * loss)
}

/// PyTorch3D's `matrix_to_quaternion` (VGGSfM's `minipytorch3d`): the best-conditioned of the
/// four candidates (largest `q_abs`, the first on ties), **not normalized**, `w ≥ 0`.
pub(crate) fn quaternion_pytorch3d(r: &Mat3) -> [f64; 4] {
    let [[m00, m01, m02], [m10, m11, m12], [m20, m21, m22]] = *r;
    let pos = |x: f64| if x > 0.0 { x.sqrt() } else { 0.0 };
    let q_abs = [
        pos(1.0 + m00 + m11 + m22),
        pos(1.0 + m00 - m11 - m22),
        pos(1.0 - m00 + m11 - m22),
        pos(1.0 - m00 - m11 + m22),
    ];
    let by_rijk = [
        [q_abs[0] * q_abs[0], m21 - m12, m02 - m20, m10 - m01],
        [m21 - m12, q_abs[1] * q_abs[1], m10 + m01, m02 + m20],
        [m02 - m20, m10 + m01, q_abs[2] * q_abs[2], m12 + m21],
        [m10 - m01, m20 + m02, m21 + m12, q_abs[3] * q_abs[3]],
    ];
    let mut best = 0usize;
    for k in 1..4 {
        if q_abs[k] > q_abs[best] {
            best = k;
        }
    }
    let den = 2.0 * q_abs[best].max(0.1);
    let q = by_rijk[best].map(|v| v / den);
    if q[0] < 0.0 { q.map(|v| -v) } else { q }
}

/// VGGSfM's `rotation_angle` in radians: `acos(1 − 2·max(eps, 1 − (q_pred·q_gt)²))` of PyTorch3D
/// quaternions ([`quaternion_pytorch3d`], not normalized), `eps = 1e-15`.
pub(crate) fn quaternion_error_pytorch3d_rad(r_gt: &Mat3, r_est: &Mat3) -> f64 {
    let (a, b) = (quaternion_pytorch3d(r_gt), quaternion_pytorch3d(r_est));
    let dot = b[0] * a[0] + b[1] * a[1] + b[2] * a[2] + b[3] * a[3];
    let loss = (1.0 - dot * dot).max(1e-15);
    libm::acos(1.0 - 2.0 * loss)
}

/// The sign-folded translation-direction error of IMC's `evaluate_R_t` and VGGSfM's
/// `compare_translation_by_angle`, in radians: `acos(sqrt(1 − max(eps, 1 − (t̂·t̂_gt)²)))`, each
/// direction divided by `norm + eps`, `eps = 1e-15`.
pub(crate) fn folded_translation_error_rad(t_gt: Point3, t_est: Point3) -> f64 {
    let eps = 1e-15;
    let unit = |t: Point3| {
        let n = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt() + eps;
        t.map(|v| v / n)
    };
    let (a, b) = (unit(t_gt), unit(t_est));
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let loss = (1.0 - dot * dot).max(eps);
    libm::acos((1.0 - loss).sqrt())
}

/// Pairs `est` with `gt` by image name; errors for an empty ground truth, a non-finite one and
/// no common image.
pub(super) fn pair_poses(
    gt: &Reconstruction,
    est: &Reconstruction,
    notes: &mut Vec<Note>,
) -> Result<(PairedPoses, usize)> {
    if gt.images.is_empty() {
        return Err(Error::Empty {
            what: "ground-truth cameras (no images)".into(),
        });
    }
    gt.check_finite("ground-truth cameras")?;
    let matches = match_images(gt, est);
    notes.extend(matches.notes.iter().cloned());
    let pose = |r: &crate::model::Rigid| (r.rotation, r.translation);
    let mut paired = PairedPoses {
        gt: gt.images.iter().map(|i| pose(&i.cam_from_world)).collect(),
        est: vec![None; gt.images.len()],
        outliers: 0,
        non_finite: 0,
    };
    let mut matched = 0usize;
    for &(g, e) in &matches.pairs {
        let Some(im) = est.images.get(e) else {
            continue;
        };
        if !im.cam_from_world.is_finite() {
            paired.non_finite += 1;
            continue;
        }
        if let Some(slot) = paired.est.get_mut(g) {
            *slot = Some(pose(&im.cam_from_world));
            matched += 1;
        }
    }
    for &e in &matches.unmatched_est {
        match est.images.get(e) {
            Some(im) if im.cam_from_world.is_finite() => paired.outliers += 1,
            Some(_) => paired.non_finite += 1,
            None => {}
        }
    }
    if matches.pairs.is_empty() {
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
    if paired.non_finite > 0 {
        notes.push(
            Note::new(
                Code::NonFinitePoses,
                format!(
                    "{} estimated pose(s) are NaN/infinite; counted as unregistered",
                    paired.non_finite
                ),
            )
            .with("count", paired.non_finite),
        );
    }
    if !matches.unmatched_est.is_empty() {
        notes.push(
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
    Ok((paired, matched))
}
