// The `sfmeval.dtu/1` report's types, generated from the Rust types of
// crates/sfmeval-dtu (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.

/**
 * One evaluation's report.
 */
export type DtuReport = {
/**
 * [`DTU_SCHEMA`].
 */
schema: "sfmeval.dtu/1",
/**
 * The scan number.
 */
scan: number,
/**
 * The reconstruction's name.
 */
reconstruction: string,
/**
 * `"mesh"` (sampled) or `"pcd"`.
 */
mode: "mesh" | "pcd",
/**
 * The options (mm).
 */
options: DtuReportOptions,
/**
 * Mean accuracy (reconstruction to STL, mm), `null` when no distance is below `max_dist`.
 */
mean_accuracy: number | null,
/**
 * Mean completeness (STL to reconstruction, mm), `null` likewise.
 */
mean_completeness: number | null,
/**
 * The mean of the two.
 */
overall: number | null,
/**
 * The counts behind the numbers.
 */
counts: DtuCounts, };

/**
 * The counts of a report.
 */
export type DtuCounts = {
/**
 * Points before down-sampling (a mesh's vertices and samples).
 */
points: number,
/**
 * After down-sampling.
 */
downsampled: number,
/**
 * In the bounding box widened by the patch size.
 */
in_bounding_box: number,
/**
 * Of those, in an observed cell: the accuracy's points.
 */
observed: number,
/**
 * Accuracy distances below `max_dist` (averaged).
 */
accuracy_below_max_dist: number,
/**
 * STL points.
 */
stl_points: number,
/**
 * STL points above the ground plane: the completeness's points.
 */
stl_above_plane: number,
/**
 * Completeness distances below `max_dist` (averaged).
 */
completeness_below_max_dist: number, };

/**
 * The options of a report.
 */
export type DtuReportOptions = {
/**
 * Down-sampling density (mm).
 */
downsample_density: number,
/**
 * Patch size (mm).
 */
patch_size: number,
/**
 * Distance cap (mm).
 */
max_dist: number,
/**
 * Visualisation threshold (mm).
 */
visualize_threshold: number,
/**
 * The shuffle's seed; `null` when the input's order was kept.
 */
shuffle_seed: number | null, };
