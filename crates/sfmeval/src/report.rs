//! The `sfmeval.report/3` JSON report (see `schemas/report.schema.json`). Every front end writes
//! this shape; fields may be added, none renamed without a schema bump.
//!
//! `/3` differs from `/2` in one place: the report's `warnings` (strings) became `notes`, typed
//! [`Note`]s (`{code, level, message, values}`, `crate::note`) that also carry what the alignment
//! stages' `note` strings said and the final fit's verdict, so front ends choose notes by code.
//!
//! `/2` differs from `/1` in three places: `options.align` is the requested mode (what ran is
//! `alignment.method`), thresholds give `tau_percent_of_diagonal` in percent (was
//! `tau_relative_to_diagonal`, a fraction), and `cameras` is a typed section whose keys come in
//! declaration order like every other section.

use serde::{Deserialize, Serialize};

use crate::note::Note;
use crate::pose::CamerasReport;
use crate::stats::Statistics;

/// Schema id of reports.
pub(crate) const REPORT_SCHEMA: &str = "sfmeval.report/3";

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Report {
    /// Always `"sfmeval.report/3"`.
    #[cfg_attr(feature = "ts", ts(type = "\"sfmeval.report/3\""))]
    pub schema: String,
    /// The program that wrote it.
    pub tool: Tool,
    /// What was measured.
    pub inputs: Inputs,
    /// Every option that changes a number.
    pub options: ReportOptions,
    /// The crop applied.
    pub crop: CropReport,
    /// The transform that took the reconstruction into the ground-truth frame.
    pub alignment: AlignmentReport,
    /// Reconstruction → ground truth distances.
    pub accuracy: AccuracyReport,
    /// Ground truth → reconstruction distances.
    pub completeness: CompletenessReport,
    /// Precision / recall / F-score per threshold.
    pub thresholds: Vec<ThresholdReport>,
    /// Camera pose errors (null when no cameras were given).
    pub cameras: Option<CamerasSection>,
    /// Completeness over the part of the surface the ground-truth images see (only when depth
    /// maps were given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "ts", ts(optional))]
    pub completeness_visible: Option<VisibleCompletenessReport>,
    /// Track-based true error of the reconstructed points (only when depth maps were given and
    /// the reconstruction has tracks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "ts", ts(optional))]
    pub track_error: Option<TrackErrorReport>,
    /// What the reader should know besides the numbers, typed (`crate::note`).
    pub notes: Vec<Note>,
}

/// Name and version of the writer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Tool {
    /// `"sfmeval"`.
    pub name: String,
    /// Crate version.
    pub version: String,
}

impl Default for Tool {
    fn default() -> Self {
        Tool {
            name: "sfmeval".into(),
            version: env!("CARGO_PKG_VERSION").into(),
        }
    }
}

/// Both inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct Inputs {
    /// The reconstruction.
    pub reconstruction: ReconstructionInput,
    /// The ground truth.
    pub ground_truth: GroundTruthInput,
}

/// The reconstruction as read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ReconstructionInput {
    /// File name (no folders).
    pub name: String,
    /// `ply`, `colmap`, `nvm`, ...
    pub format: String,
    /// Points read.
    pub points: u64,
    /// Registered images (0 for a bare cloud).
    pub images: u64,
}

/// The ground truth as read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct GroundTruthInput {
    /// File name (no folders).
    pub name: String,
    /// `glb`, `gltf`, `ply`, `obj`.
    pub format: String,
    /// Vertices (or points of a cloud).
    pub vertices: u64,
    /// Triangles (0 for a cloud).
    pub triangles: u64,
    /// Length of the bounding-box diagonal, in ground-truth units.
    pub diagonal: f64,
    /// Surface area (0 for a cloud).
    pub area: f64,
}

/// Options that change numbers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ReportOptions {
    /// Completeness samples requested on a mesh.
    pub samples: u64,
    /// Seed of the surface sampler.
    pub seed: u64,
    /// Whether signed accuracy was computed.
    pub signed: bool,
    /// Histogram bins.
    pub histogram_bins: u64,
    /// Thresholds given in ground-truth units.
    pub tau: Vec<f64>,
    /// Thresholds given in percent of the ground-truth bounding-box diagonal.
    pub tau_percent_of_diagonal: Vec<f64>,
    /// The requested alignment mode (`auto`, `cameras+icp`, `given`, ...); what ran is
    /// `alignment.method`.
    pub align: String,
    /// Images a surface sample must be seen in to count as visible (only with depth maps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "ts", ts(optional))]
    pub min_views: Option<u64>,
}

/// What the crop did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CropReport {
    /// `none`, `box`, `oriented_box`, `sphere`, `max_distance`, or `<volume>+max_distance`.
    pub kind: String,
    /// Reconstructed points kept.
    pub kept: u64,
    /// Reconstructed points discarded (all reasons).
    pub discarded: u64,
    /// Discarded because outside the volume.
    pub discarded_outside_volume: u64,
    /// Discarded because farther than `max_distance` from the ground truth.
    pub discarded_farther_than_max_distance: u64,
    /// The volume, as in the crop file.
    pub volume: Option<crate::crop::Volume>,
    /// The distance limit.
    pub max_distance: Option<f64>,
    /// Ground-truth samples inside the volume (used for completeness).
    pub ground_truth_samples_kept: u64,
}

/// One stage of the alignment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct AlignmentStage {
    /// `given`, `cameras`, `points`, `global`, `icp`.
    pub method: String,
    /// The transform after this stage.
    pub gt_from_recon: [[f64; 4]; 4],
    /// Its scale.
    pub scale: f64,
    /// Root mean square residual of the stage's correspondences.
    pub rmse: Option<f64>,
    /// Share of correspondences kept as inliers.
    pub inlier_ratio: Option<f64>,
    /// Iterations run.
    pub iterations: u64,
    /// Whether the stage met its stopping criterion.
    pub converged: bool,
}

/// The final transform and how it was found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct AlignmentReport {
    /// `none`, `given`, `cameras`, `icp`, `global`, `cameras+icp`, ...
    pub method: String,
    /// Row-major 4×4 mapping the reconstruction into the ground-truth frame.
    pub gt_from_recon: [[f64; 4]; 4],
    /// Scale of the transform.
    pub scale: f64,
    /// Residual of the last stage (null when no stage measured one).
    pub rmse: Option<f64>,
    /// Inlier share of the last stage.
    pub inlier_ratio: Option<f64>,
    /// Iterations over all stages.
    pub iterations: u64,
    /// Whether every stage converged.
    pub converged: bool,
    /// One entry per stage.
    pub stages: Vec<AlignmentStage>,
}

/// Reconstruction → ground-truth distance statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct AccuracyReport {
    /// Always `reconstruction_to_ground_truth`.
    pub direction: String,
    /// `point_to_triangle` (mesh GT) or `point_to_point` (cloud GT).
    pub metric: String,
    /// Statistics of the unsigned distances of kept points.
    #[serde(flatten)]
    pub stats: Statistics,
    /// Statistics of signed distances (by the closest triangle's normal), when asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "ts", ts(optional))]
    pub signed: Option<Statistics>,
}

/// Ground-truth → reconstruction distance statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CompletenessReport {
    /// Always `ground_truth_to_reconstruction`.
    pub direction: String,
    /// `surface_samples` (mesh GT) or `ground_truth_points` (cloud GT).
    pub source: String,
    /// Ground-truth points measured (inside the crop volume).
    pub samples: u64,
    /// Seed of the surface sampler.
    pub seed: u64,
    /// Statistics of the distances.
    #[serde(flatten)]
    pub stats: Statistics,
}

/// Precision, recall and F-score at one threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct ThresholdReport {
    /// Threshold in ground-truth units.
    pub tau: f64,
    /// The same threshold in percent of the ground-truth bounding-box diagonal.
    pub tau_percent_of_diagonal: f64,
    /// Share of kept reconstructed points closer than tau to the ground truth.
    pub precision: f64,
    /// Share of ground-truth samples closer than tau to the reconstruction.
    pub recall: f64,
    /// 2PR / (P + R), 0 when both are 0.
    pub f_score: f64,
}

/// Completeness over the visible part of the surface: the completeness samples seen in at least
/// `min_views` ground-truth images (`crate::visibility`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct VisibleCompletenessReport {
    /// Always `ground_truth_to_reconstruction`.
    pub direction: String,
    /// Images a sample must be seen in.
    pub min_views: u64,
    /// Ground-truth images with a depth map.
    pub views: u64,
    /// Completeness samples considered (inside the crop volume).
    pub samples: u64,
    /// Of those, the visible ones.
    pub visible_samples: u64,
    /// `visible_samples / samples`: the visible share of the (cropped) surface.
    pub visible_fraction: f64,
    /// Visible area in squared ground-truth units (mesh ground truth without crop volume only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "ts", ts(optional))]
    pub visible_area: Option<f64>,
    /// The threshold of the per-sample labels covered / missed / unseen (the first threshold).
    pub labels_tau: f64,
    /// Statistics of the visible samples' distances to the reconstruction.
    #[serde(flatten)]
    pub stats: Statistics,
    /// Recall over the whole surface and over the visible part, per threshold.
    pub thresholds: Vec<VisibleThresholdReport>,
}

/// Recall at one threshold, over all samples and over the visible ones.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct VisibleThresholdReport {
    /// Threshold in ground-truth units.
    pub tau: f64,
    /// Share of all samples closer than tau to the reconstruction (as in `thresholds`).
    pub recall: f64,
    /// Share of visible samples closer than tau to the reconstruction.
    pub recall_visible: f64,
    /// F-score of the precision and `recall_visible`.
    pub f_score_visible: f64,
}

/// Track-based true error (`crate::track_error`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct TrackErrorReport {
    /// Always `reconstruction_to_track_truth`: from each aligned point to the robust mean of its
    /// observations back-projected on the ground-truth depth maps.
    pub direction: String,
    /// How the observations were read: `colmap_pixels`, `centered_y_down`, `centered_y_up`.
    pub observation_convention: String,
    /// Kept back-projections a point needs to be measured.
    pub min_observations: u64,
    /// Points of the model kept by the crop.
    pub points: u64,
    /// Of those, the points measured.
    pub measured: u64,
    /// Observations of the kept points.
    pub observations: u64,
    /// Observations whose back-projection entered a robust mean.
    pub observations_used: u64,
    /// Back-projections trimmed as outliers of their track.
    pub observations_trimmed: u64,
    /// Observations in images without a ground-truth image of the same name.
    pub rejected_unmatched_image: u64,
    /// Observations outside the ground-truth image.
    pub rejected_outside_image: u64,
    /// Observations on a silhouette (a background pixel in the neighbourhood).
    pub rejected_background: u64,
    /// Observations on a depth step.
    pub rejected_discontinuity: u64,
    /// Statistics of the true errors of the measured points.
    #[serde(flatten)]
    pub stats: Statistics,
    /// Statistics of the nearest-surface distances of the same points, for comparison.
    pub surface_distance: Statistics,
    /// Sliding points per threshold.
    pub thresholds: Vec<SlidingThresholdReport>,
}

/// Sliding points at one threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct SlidingThresholdReport {
    /// Threshold in ground-truth units.
    pub tau: f64,
    /// Share of measured points whose true error exceeds their surface distance by more than
    /// tau: on (or near) the surface, but not where their features are.
    pub sliding_fraction: f64,
    /// Share of measured points whose true error is below tau (a track-based precision).
    pub true_error_below: f64,
}

/// The report's `cameras` section: the pose errors and the transform they were measured after.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CamerasSection {
    /// The pose errors.
    #[serde(flatten)]
    pub errors: CamerasReport,
    /// The transform the poses were measured after.
    pub alignment: CamerasAlignment,
}

/// Which transform the camera poses were measured after.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "ts", derive(ts_rs::TS))]
pub struct CamerasAlignment {
    /// `cameras` (the camera stage's transform, before any point refinement) or the
    /// alignment method when no camera stage ran.
    pub stage: String,
    /// Row-major 4×4 mapping the reconstruction into the ground-truth frame.
    pub gt_from_recon: [[f64; 4]; 4],
    /// Its scale.
    pub scale: f64,
}

impl Report {
    /// Pretty JSON with a trailing newline; the same report always gives the same bytes.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }
}

/// The TypeScript declarations of [`Report`] and every type it holds, generated by ts-rs from
/// the types above (serde's renames, flattening and skips included), and the check that the
/// npm package ships them (`crates/sfmeval-wasm/js/report.d.ts`, imported by its `index.d.ts`).
/// `scripts/gen-report-types.sh` rewrites the file (`SFMEVAL_WRITE_REPORT_TYPES=1`); without
/// that variable the test fails when the file is stale.
#[cfg(all(test, feature = "ts"))]
mod typescript {
    use super::{REPORT_SCHEMA, Report};
    use crate::ts_declarations::{Declarations, check_committed};

    #[test]
    fn report_types_are_the_committed_ones() {
        let text = Declarations::new().add::<Report>().file_text(
            REPORT_SCHEMA,
            "crates/sfmeval",
            "Report",
            None,
        );
        let file = "../sfmeval-wasm/js/report.d.ts";
        check_committed(env!("CARGO_MANIFEST_DIR"), file, REPORT_SCHEMA, &text);
    }
}
