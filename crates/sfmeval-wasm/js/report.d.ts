// The `sfmeval.report/3` report's types, generated from the Rust types of
// crates/sfmeval (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.

/**
 * The whole report.
 */
export type Report = {
/**
 * Always `"sfmeval.report/3"`.
 */
schema: "sfmeval.report/3",
/**
 * The program that wrote it.
 */
tool: Tool,
/**
 * What was measured.
 */
inputs: Inputs,
/**
 * Every option that changes a number.
 */
options: ReportOptions,
/**
 * The crop applied.
 */
crop: CropReport,
/**
 * The transform that took the reconstruction into the ground-truth frame.
 */
alignment: AlignmentReport,
/**
 * Reconstruction → ground truth distances.
 */
accuracy: AccuracyReport,
/**
 * Ground truth → reconstruction distances.
 */
completeness: CompletenessReport,
/**
 * Precision / recall / F-score per threshold.
 */
thresholds: Array<ThresholdReport>,
/**
 * Camera pose errors (null when no cameras were given).
 */
cameras: CamerasSection | null,
/**
 * Completeness over the part of the surface the ground-truth images see (only when depth
 * maps were given).
 */
completeness_visible?: VisibleCompletenessReport,
/**
 * Track-based true error of the reconstructed points (only when depth maps were given and
 * the reconstruction has tracks).
 */
track_error?: TrackErrorReport,
/**
 * What the reader should know besides the numbers, typed (`crate::note`).
 */
notes: Array<Note>, };

/**
 * Reconstruction → ground-truth distance statistics.
 */
export type AccuracyReport = {
/**
 * Always `reconstruction_to_ground_truth`.
 */
direction: string,
/**
 * `point_to_triangle` (mesh GT) or `point_to_point` (cloud GT).
 */
metric: string,
/**
 * Statistics of signed distances (by the closest triangle's normal), when asked for.
 */
signed?: Statistics,
/**
 * Number of values.
 */
count: number,
/**
 * Smallest value.
 */
min: number,
/**
 * Largest value.
 */
max: number,
/**
 * Arithmetic mean.
 */
mean: number,
/**
 * Population standard deviation (divides by n).
 */
std: number,
/**
 * Median (= p50).
 */
median: number,
/**
 * Root mean square.
 */
rms: number,
/**
 * Percentiles.
 */
percentiles: Percentiles,
/**
 * Histogram.
 */
histogram: Histogram, };

/**
 * The final transform and how it was found.
 */
export type AlignmentReport = {
/**
 * `none`, `given`, `cameras`, `icp`, `global`, `cameras+icp`, ...
 */
method: string,
/**
 * Row-major 4×4 mapping the reconstruction into the ground-truth frame.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]],
/**
 * Scale of the transform.
 */
scale: number,
/**
 * Residual of the last stage (null when no stage measured one).
 */
rmse: number | null,
/**
 * Inlier share of the last stage.
 */
inlier_ratio: number | null,
/**
 * Iterations over all stages.
 */
iterations: number,
/**
 * Whether every stage converged.
 */
converged: boolean,
/**
 * One entry per stage.
 */
stages: Array<AlignmentStage>, };

/**
 * One stage of the alignment.
 */
export type AlignmentStage = {
/**
 * `given`, `cameras`, `points`, `global`, `icp`.
 */
method: string,
/**
 * The transform after this stage.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]],
/**
 * Its scale.
 */
scale: number,
/**
 * Root mean square residual of the stage's correspondences.
 */
rmse: number | null,
/**
 * Share of correspondences kept as inliers.
 */
inlier_ratio: number | null,
/**
 * Iterations run.
 */
iterations: number,
/**
 * Whether the stage met its stopping criterion.
 */
converged: boolean, };

/**
 * A coordinate axis.
 */
export type Axis = "x" | "y" | "z";

/**
 * Which transform the camera poses were measured after.
 */
export type CamerasAlignment = {
/**
 * `cameras` (the camera stage's transform, before any point refinement) or the
 * alignment method when no camera stage ran.
 */
stage: string,
/**
 * Row-major 4×4 mapping the reconstruction into the ground-truth frame.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]],
/**
 * Its scale.
 */
scale: number, };

/**
 * The report's `cameras` section: the pose errors and the transform they were measured after.
 */
export type CamerasSection = {
/**
 * The transform the poses were measured after.
 */
alignment: CamerasAlignment,
/**
 * Ground-truth images.
 */
ground_truth: number,
/**
 * Registered images of the (largest) estimated model.
 */
registered: number,
/**
 * Registered images matched to a ground-truth image by name.
 */
matched: number,
/**
 * Separate models the SfM tool produced (the largest is evaluated).
 */
models: number,
/**
 * Estimated images whose name matches no ground-truth image.
 */
unmatched_estimated: number,
/**
 * Rotation error statistics (degrees).
 */
rotation_error_deg: Statistics,
/**
 * Camera-centre error statistics (GT units).
 */
center_error: Statistics,
/**
 * Camera-centre error statistics in % of [`Self::scene_radius`].
 */
center_error_percent: Statistics,
/**
 * Mean distance of the GT camera centres from their centroid.
 */
scene_radius: number,
/**
 * Absolute trajectory error: RMS of the centre errors (GT units).
 */
ate_rmse: number,
/**
 * Relative-pose errors over all GT image pairs.
 */
relative: RelativePoseReport,
/**
 * Focal-length error per estimated camera.
 */
focal: Array<FocalError>,
/**
 * Per matched image.
 */
images: Array<ImagePoseError>,
/**
 * Problems worth a line in the report.
 */
notes: Array<Note>, };

/**
 * The stable code of a note (serialized as its text, e.g. `alignment.icp_rejected`).
 */
export type Code = "input.model_no_points" | "input.several_models" | "input.incomplete_model_ignored" | "input.several_model_files" | "input.trailing_content" | "input.dangling_references" | "input.no_image_list" | "input.unregistered_images" | "input.missing_intrinsics" | "input.no_principal_point" | "input.unknown_image_size" | "input.principal_point_outside" | "input.unknown_camera_frame" | "input.camera_centres_removed" | "input.cloud_with_model_cameras" | "input.no_point_at_camera_centres" | "input.mesh_vertices_only" | "input.degenerate_faces_skipped" | "input.non_surface_primitive_skipped" | "input.duplicate_image_names" | "input.images_matched_by_stem" | "cameras.reconstruction_has_no_cameras" | "cameras.no_image_in_common" | "cameras.non_finite_poses" | "cameras.few_matched" | "cameras.unmatched_estimated" | "cameras.scene_radius_degenerate" | "cameras.centres_out_of_range" | "cameras.relative_pairs_subsampled" | "cameras.poses_after_final_transform" | "alignment.non_finite_points_ignored" | "alignment.global_search_result" | "alignment.ambiguous_pose" | "alignment.icp_rejected" | "alignment.stage_failed" | "alignment.fell_back" | "alignment.icp_from_identity" | "alignment.camera_outliers" | "alignment.non_finite_camera_pairs" | "alignment.camera_centres_degenerate" | "alignment.few_inliers" | "alignment.unsettled_tight_fit" | "alignment.unsettled_loose_fit" | "measure.signed_needs_mesh" | "measure.crop_discarded_everything" | "measure.no_ground_truth_in_crop" | "measure.nothing_visible" | "measure.no_track_error" | "measure.no_track_measured" | "tanksandtemples.trajectory_poorly_aligned" | "tanksandtemples.nothing_in_crop";

/**
 * Ground-truth → reconstruction distance statistics.
 */
export type CompletenessReport = {
/**
 * Always `ground_truth_to_reconstruction`.
 */
direction: string,
/**
 * `surface_samples` (mesh GT) or `ground_truth_points` (cloud GT).
 */
source: string,
/**
 * Ground-truth points measured (inside the crop volume).
 */
samples: number,
/**
 * Seed of the surface sampler.
 */
seed: number,
/**
 * Number of values.
 */
count: number,
/**
 * Smallest value.
 */
min: number,
/**
 * Largest value.
 */
max: number,
/**
 * Arithmetic mean.
 */
mean: number,
/**
 * Population standard deviation (divides by n).
 */
std: number,
/**
 * Median (= p50).
 */
median: number,
/**
 * Root mean square.
 */
rms: number,
/**
 * Percentiles.
 */
percentiles: Percentiles,
/**
 * Histogram.
 */
histogram: Histogram, };

/**
 * What the crop did.
 */
export type CropReport = {
/**
 * `none`, `box`, `oriented_box`, `sphere`, `max_distance`, or `<volume>+max_distance`.
 */
kind: string,
/**
 * Reconstructed points kept.
 */
kept: number,
/**
 * Reconstructed points discarded (all reasons).
 */
discarded: number,
/**
 * Discarded because outside the volume.
 */
discarded_outside_volume: number,
/**
 * Discarded because farther than `max_distance` from the ground truth.
 */
discarded_farther_than_max_distance: number,
/**
 * The volume, as in the crop file.
 */
volume: Volume | null,
/**
 * The distance limit.
 */
max_distance: number | null,
/**
 * Ground-truth samples inside the volume (used for completeness).
 */
ground_truth_samples_kept: number, };

/**
 * Focal-length error of one estimated camera.
 */
export type FocalError = {
/**
 * Estimated camera id.
 */
camera_id: number,
/**
 * Ground-truth camera id (the one most of its matched images use).
 */
gt_camera_id: number,
/**
 * Ground-truth focal length (px, mean of fx and fy).
 */
focal_gt: number,
/**
 * Estimated focal length (px), scaled to the GT image width when both widths are known.
 */
focal_est: number,
/**
 * `(focal_est − focal_gt) / focal_gt`, in percent (signed).
 */
error_percent: number,
/**
 * Matched images using this camera.
 */
images: number, };

/**
 * The ground truth as read.
 */
export type GroundTruthInput = {
/**
 * File name (no folders).
 */
name: string,
/**
 * `glb`, `gltf`, `ply`, `obj`.
 */
format: string,
/**
 * Vertices (or points of a cloud).
 */
vertices: number,
/**
 * Triangles (0 for a cloud).
 */
triangles: number,
/**
 * Length of the bounding-box diagonal, in ground-truth units.
 */
diagonal: number,
/**
 * Surface area (0 for a cloud).
 */
area: number, };

/**
 * A histogram with `edges.len() == counts.len() + 1`; the last bin includes its right edge.
 * Values below the first edge or above the last are not in any bin but counted in
 * `underflow` / `overflow`, so `counts` + both always add up to the number of values.
 */
export type Histogram = {
/**
 * Bin edges, increasing.
 */
edges: Array<number>,
/**
 * Values per bin.
 */
counts: Array<number>,
/**
 * Values below the first edge.
 */
underflow: number,
/**
 * Values above the last edge.
 */
overflow: number, };

/**
 * Pose error of one matched image.
 */
export type ImagePoseError = {
/**
 * Ground-truth image name.
 */
name: string,
/**
 * Name in the reconstruction.
 */
estimated_name: string,
/**
 * Rotation error (degrees).
 */
rotation_error_deg: number,
/**
 * Camera-centre error (GT units).
 */
center_error: number,
/**
 * Camera-centre error in % of the scene radius.
 */
center_error_percent: number, };

/**
 * Both inputs.
 */
export type Inputs = {
/**
 * The reconstruction.
 */
reconstruction: ReconstructionInput,
/**
 * The ground truth.
 */
ground_truth: GroundTruthInput, };

export type JsonValue = number | string | boolean | Array<JsonValue> | { [key in string]: JsonValue } | null;

/**
 * How much a note matters.
 */
export type Level = "info" | "warning";

/**
 * One note of a report.
 */
export type Note = {
/**
 * Stable code.
 */
code: Code,
/**
 * `info` or `warning` (the code's level).
 */
level: Level,
/**
 * What happened, in words for people.
 */
message: string,
/**
 * The values the message states, by name (counts, shares, thresholds, the stage).
 */
values?: { [key in string]: JsonValue }, };

/**
 * Percentiles reported in every statistics block.
 */
export type Percentiles = {
/**
 * 50th percentile (the median).
 */
p50: number,
/**
 * 90th percentile.
 */
p90: number,
/**
 * 95th percentile.
 */
p95: number,
/**
 * 99th percentile.
 */
p99: number, };

/**
 * The reconstruction as read.
 */
export type ReconstructionInput = {
/**
 * File name (no folders).
 */
name: string,
/**
 * `ply`, `colmap`, `nvm`, ...
 */
format: string,
/**
 * Points read.
 */
points: number,
/**
 * Registered images (0 for a bare cloud).
 */
images: number, };

/**
 * Relative accuracy at one threshold.
 */
export type RelativeAccuracy = {
/**
 * Threshold in degrees.
 */
threshold_deg: number,
/**
 * Relative Rotation Accuracy: share of pairs with rotation error below the threshold.
 */
rra: number,
/**
 * Relative Translation Accuracy: share of pairs with translation-direction error below.
 */
rta: number,
/**
 * Share of pairs with both below.
 */
both: number, };

/**
 * Relative-pose errors over all ground-truth image pairs.
 */
export type RelativePoseReport = {
/**
 * Number of pairs evaluated.
 */
pairs: number,
/**
 * Pairs with at least one unregistered image (counted as 180°).
 */
pairs_unregistered: number,
/**
 * Relative-rotation error statistics (degrees).
 */
rotation_error_deg: Statistics,
/**
 * Translation-direction error statistics (degrees).
 */
translation_error_deg: Statistics,
/**
 * RRA / RTA per threshold.
 */
accuracy: Array<RelativeAccuracy>,
/**
 * Largest threshold of the AUC (degrees).
 */
auc_max_deg: number,
/**
 * Area under the accuracy curve of `max(rotation, translation)` error, 0..1.
 */
auc: number, };

/**
 * Options that change numbers.
 */
export type ReportOptions = {
/**
 * Completeness samples requested on a mesh.
 */
samples: number,
/**
 * Seed of the surface sampler.
 */
seed: number,
/**
 * Whether signed accuracy was computed.
 */
signed: boolean,
/**
 * Histogram bins.
 */
histogram_bins: number,
/**
 * Thresholds given in ground-truth units.
 */
tau: Array<number>,
/**
 * Thresholds given in percent of the ground-truth bounding-box diagonal.
 */
tau_percent_of_diagonal: Array<number>,
/**
 * The requested alignment mode (`auto`, `cameras+icp`, `given`, ...); what ran is
 * `alignment.method`.
 */
align: string,
/**
 * Images a surface sample must be seen in to count as visible (only with depth maps).
 */
min_views?: number, };

/**
 * Sliding points at one threshold.
 */
export type SlidingThresholdReport = {
/**
 * Threshold in ground-truth units.
 */
tau: number,
/**
 * Share of measured points whose true error exceeds their surface distance by more than
 * tau: on (or near) the surface, but not where their features are.
 */
sliding_fraction: number,
/**
 * Share of measured points whose true error is below tau (a track-based precision).
 */
true_error_below: number, };

/**
 * Statistics of a set of values. All zero when `count == 0`.
 */
export type Statistics = {
/**
 * Number of values.
 */
count: number,
/**
 * Smallest value.
 */
min: number,
/**
 * Largest value.
 */
max: number,
/**
 * Arithmetic mean.
 */
mean: number,
/**
 * Population standard deviation (divides by n).
 */
std: number,
/**
 * Median (= p50).
 */
median: number,
/**
 * Root mean square.
 */
rms: number,
/**
 * Percentiles.
 */
percentiles: Percentiles,
/**
 * Histogram.
 */
histogram: Histogram, };

/**
 * Precision, recall and F-score at one threshold.
 */
export type ThresholdReport = {
/**
 * Threshold in ground-truth units.
 */
tau: number,
/**
 * The same threshold in percent of the ground-truth bounding-box diagonal.
 */
tau_percent_of_diagonal: number,
/**
 * Share of kept reconstructed points closer than tau to the ground truth.
 */
precision: number,
/**
 * Share of ground-truth samples closer than tau to the reconstruction.
 */
recall: number,
/**
 * 2PR / (P + R), 0 when both are 0.
 */
f_score: number, };

/**
 * Name and version of the writer.
 */
export type Tool = {
/**
 * `"sfmeval"`.
 */
name: string,
/**
 * Crate version.
 */
version: string, };

/**
 * Track-based true error (`crate::track_error`).
 */
export type TrackErrorReport = {
/**
 * Always `reconstruction_to_track_truth`: from each aligned point to the robust mean of its
 * observations back-projected on the ground-truth depth maps.
 */
direction: string,
/**
 * How the observations were read: `colmap_pixels`, `centered_y_down`, `centered_y_up`.
 */
observation_convention: string,
/**
 * Kept back-projections a point needs to be measured.
 */
min_observations: number,
/**
 * Points of the model kept by the crop.
 */
points: number,
/**
 * Of those, the points measured.
 */
measured: number,
/**
 * Observations of the kept points.
 */
observations: number,
/**
 * Observations whose back-projection entered a robust mean.
 */
observations_used: number,
/**
 * Back-projections trimmed as outliers of their track.
 */
observations_trimmed: number,
/**
 * Observations in images without a ground-truth image of the same name.
 */
rejected_unmatched_image: number,
/**
 * Observations outside the ground-truth image.
 */
rejected_outside_image: number,
/**
 * Observations on a silhouette (a background pixel in the neighbourhood).
 */
rejected_background: number,
/**
 * Observations on a depth step.
 */
rejected_discontinuity: number,
/**
 * Statistics of the nearest-surface distances of the same points, for comparison.
 */
surface_distance: Statistics,
/**
 * Sliding points per threshold.
 */
thresholds: Array<SlidingThresholdReport>,
/**
 * Number of values.
 */
count: number,
/**
 * Smallest value.
 */
min: number,
/**
 * Largest value.
 */
max: number,
/**
 * Arithmetic mean.
 */
mean: number,
/**
 * Population standard deviation (divides by n).
 */
std: number,
/**
 * Median (= p50).
 */
median: number,
/**
 * Root mean square.
 */
rms: number,
/**
 * Percentiles.
 */
percentiles: Percentiles,
/**
 * Histogram.
 */
histogram: Histogram, };

/**
 * Completeness over the visible part of the surface: the completeness samples seen in at least
 * `min_views` ground-truth images (`crate::visibility`).
 */
export type VisibleCompletenessReport = {
/**
 * Always `ground_truth_to_reconstruction`.
 */
direction: string,
/**
 * Images a sample must be seen in.
 */
min_views: number,
/**
 * Ground-truth images with a depth map.
 */
views: number,
/**
 * Completeness samples considered (inside the crop volume).
 */
samples: number,
/**
 * Of those, the visible ones.
 */
visible_samples: number,
/**
 * `visible_samples / samples`: the visible share of the (cropped) surface.
 */
visible_fraction: number,
/**
 * Visible area in squared ground-truth units (mesh ground truth without crop volume only).
 */
visible_area?: number,
/**
 * The threshold of the per-sample labels covered / missed / unseen (the first threshold).
 */
labels_tau: number,
/**
 * Recall over the whole surface and over the visible part, per threshold.
 */
thresholds: Array<VisibleThresholdReport>,
/**
 * Number of values.
 */
count: number,
/**
 * Smallest value.
 */
min: number,
/**
 * Largest value.
 */
max: number,
/**
 * Arithmetic mean.
 */
mean: number,
/**
 * Population standard deviation (divides by n).
 */
std: number,
/**
 * Median (= p50).
 */
median: number,
/**
 * Root mean square.
 */
rms: number,
/**
 * Percentiles.
 */
percentiles: Percentiles,
/**
 * Histogram.
 */
histogram: Histogram, };

/**
 * Recall at one threshold, over all samples and over the visible ones.
 */
export type VisibleThresholdReport = {
/**
 * Threshold in ground-truth units.
 */
tau: number,
/**
 * Share of all samples closer than tau to the reconstruction (as in `thresholds`).
 */
recall: number,
/**
 * Share of visible samples closer than tau to the reconstruction.
 */
recall_visible: number,
/**
 * F-score of the precision and `recall_visible`.
 */
f_score_visible: number, };

/**
 * A crop volume in the ground-truth frame.
 */
export type Volume = { "kind": "box",
/**
 * Minimum corner.
 */
min: [number, number, number],
/**
 * Maximum corner.
 */
max: [number, number, number], } | { "kind": "oriented_box",
/**
 * Centre.
 */
center: [number, number, number],
/**
 * Half sizes along the box axes.
 */
half_extents: [number, number, number],
/**
 * Row-major `world_from_box` rotation (columns are the box axes in the world).
 */
rotation: [[number, number, number], [number, number, number], [number, number, number]], } | { "kind": "sphere",
/**
 * Centre.
 */
center: [number, number, number],
/**
 * Radius.
 */
radius: number, } | { "kind": "polygon_prism",
/**
 * The polygon's vertices in order (closed implicitly).
 */
polygon: Array<[number, number, number]>,
/**
 * The extrusion axis: `x`, `y` or `z`.
 */
axis: Axis,
/**
 * Lower bound along `axis`.
 */
axis_min: number,
/**
 * Upper bound along `axis`.
 */
axis_max: number, };
