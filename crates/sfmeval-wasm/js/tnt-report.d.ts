// The `sfmeval.tanksandtemples/2` report's types, generated from the Rust types of
// crates/sfmeval-tnt (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.
import type { Code, JsonValue, Level, Note, Tool } from './report.js';

/**
 * The whole report.
 */
export type TntReport = {
/**
 * `sfmeval.tanksandtemples/2` ([`TNT_SCHEMA`] in Rust).
 */
schema: "sfmeval.tanksandtemples/2",
/**
 * The program that wrote it.
 */
tool: Tool,
/**
 * What was run, with every parameter.
 */
protocol: ProtocolSection,
/**
 * What was read.
 */
inputs: InputsSection,
/**
 * How the reconstruction was brought into the ground-truth frame.
 */
registration: RegistrationSection,
/**
 * Reconstruction → ground truth.
 */
precision: SideSection,
/**
 * Ground truth → reconstruction.
 */
recall: SideSection,
/**
 * `2PR / (P + R)`.
 */
f_score: number,
/**
 * Cumulative distance curves (the toolbox's `cum_source` / `cum_target`).
 */
curves: CurvesSection,
/**
 * What the reader should know besides the numbers: typed notes (`sfmeval::note`), the
 * reading's and the protocol's (`/1` had them as strings, in `warnings`).
 */
notes: Array<Note>, };

/**
 * The crop of the scene.
 */
export type CropSection = {
/**
 * The crop file.
 */
file: string,
/**
 * `"polygon_prism"` for the benchmark's files.
 */
kind: string,
/**
 * The axis across the polygon.
 */
axis: string,
/**
 * Range along it.
 */
axis_min: number,
/**
 * Range along it.
 */
axis_max: number,
/**
 * Polygon vertices.
 */
polygon_vertices: number, };

/**
 * The cumulative curves.
 */
export type CurvesSection = {
/**
 * Bin edges.
 */
edges: Array<number>,
/**
 * Cumulative share of reconstruction points below each edge after the first.
 */
precision: Array<number>,
/**
 * Cumulative share of ground-truth points below each edge after the first.
 */
recall: Array<number>, };

/**
 * The evaluation step's parameters.
 */
export type EvaluationParams = {
/**
 * Both clouds are voxel down-sampled at this edge (τ/2) after the crop.
 */
voxel_size: number,
/**
 * τ.
 */
threshold: number,
/**
 * The curves run to `threshold · plot_stretch`.
 */
plot_stretch: number,
/**
 * Curve bin width (τ/100).
 */
bin_width: number,
/**
 * The coloured clouds saturate at this distance (3τ).
 */
color_max_distance: number,
/**
 * Their colour map.
 */
colormap: string, };

/**
 * The inputs.
 */
export type InputsSection = {
/**
 * The reconstructed cloud.
 */
reconstruction: NamedCount,
/**
 * Its `.log` trajectory (absent when the final transform was given).
 */
trajectory: TrajectoryInput | null,
/**
 * The ground-truth cloud.
 */
ground_truth: NamedCount,
/**
 * The reference trajectory's frame count.
 */
reference_frames: number,
/**
 * `<scene>_trans.txt`.
 */
gt_from_reference: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]], };

/**
 * A file and its point count.
 */
export type NamedCount = {
/**
 * As the front end named it.
 */
name: string,
/**
 * Points read.
 */
points: number, };

/**
 * The protocol's parameters.
 */
export type ProtocolSection = {
/**
 * `"tanksandtemples"`.
 */
name: string,
/**
 * Which implementation it follows.
 */
reference: string,
/**
 * The scene's name.
 */
scene: string,
/**
 * τ in ground-truth units.
 */
tau: number,
/**
 * `"scene table"` (the toolbox's τ of the scene) or `"option"`.
 */
tau_source: string,
/**
 * The crop volume (an Open3D `SelectionPolygonVolume`).
 */
crop: CropSection,
/**
 * The trajectory alignment's parameters (absent when the final transform was given).
 */
trajectory_alignment: TrajectoryParams | null,
/**
 * The three ICP refinements (empty when the final transform was given).
 */
refinement: Array<StageParams>,
/**
 * The evaluation step's parameters.
 */
evaluation: EvaluationParams, };

/**
 * How the reconstruction reached the ground-truth frame.
 */
export type RegistrationSection = {
/**
 * `"protocol"` (trajectory alignment + three ICP refinements) or `"given"`.
 */
mode: string,
/**
 * The trajectory alignment's result.
 */
trajectory_alignment: TrajectoryAlignment | null,
/**
 * Each refinement's result.
 */
refinement: Array<StageResult>,
/**
 * The transform the evaluation used.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]], };

/**
 * One direction's result.
 */
export type SideSection = {
/**
 * The share within τ.
 */
value: number,
/**
 * Points inside the crop.
 */
cropped_points: number,
/**
 * Points measured (after the τ/2 voxel down-sampling).
 */
points: number,
/**
 * Mean distance of the measured points.
 */
mean_distance: number,
/**
 * Median distance.
 */
median_distance: number, };

/**
 * One refinement stage's parameters.
 */
export type StageParams = {
/**
 * `"voxel"` (both clouds cropped and voxel down-sampled) or `"uniform"` (cropped, every
 * k-th point kept above `max_points`).
 */
downsample: string,
/**
 * Voxel edge for `"voxel"`.
 */
voxel_size: number | null,
/**
 * Point budget for `"uniform"`.
 */
max_points: number | null,
/**
 * ICP correspondence distance.
 */
max_correspondence_distance: number,
/**
 * Stop rule (Open3D's `ICPConvergenceCriteria` as the toolbox sets it).
 */
relative_fitness: number,
/**
 * Stop rule.
 */
relative_rmse: number,
/**
 * Stop rule.
 */
max_iterations: number, };

/**
 * One refinement's result.
 */
export type StageResult = {
/**
 * Reconstruction points the ICP used (after crop and down-sampling).
 */
source_points: number,
/**
 * Ground-truth points it used.
 */
target_points: number,
/**
 * ICP updates made.
 */
iterations: number,
/**
 * Matched share at the end.
 */
fitness: number,
/**
 * RMSE of the matches at the end.
 */
inlier_rmse: number,
/**
 * `gt_from_recon` after this stage.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]], };

/**
 * The best sample's similarity and score.
 */
export type TrajectoryAlignment = {
/**
 * `gt_from_recon` of the best sample.
 */
gt_from_recon: [[number, number, number, number], [number, number, number, number], [number, number, number, number], [number, number, number, number]],
/**
 * Share of reconstruction centres with a reference centre within the distance.
 */
fitness: number,
/**
 * RMSE of those matches.
 */
inlier_rmse: number,
/**
 * Samples drawn.
 */
iterations: number, };

/**
 * The reconstruction's trajectory.
 */
export type TrajectoryInput = {
/**
 * As the front end named it.
 */
name: string,
/**
 * Frames read.
 */
frames: number,
/**
 * Frames whose metadata says the image was registered (second integer ≥ 0).
 */
registered: number,
/**
 * Whether the mapping file picked the reference frames out of a video trajectory.
 */
mapped: boolean, };

/**
 * Trajectory-alignment parameters.
 */
export type TrajectoryParams = {
/**
 * Correspondence distance in ground-truth units.
 */
max_correspondence_distance: number,
/**
 * Pairs per sample.
 */
ransac_n: number,
/**
 * Samples drawn and scored (all of them, as Open3D 0.9 did).
 */
max_iterations: number,
/**
 * Seed of the sample stream.
 */
seed: number,
/**
 * Above this many frames the trajectory is a video's, sampled through the mapping file.
 */
mapping_above_frames: number, };
