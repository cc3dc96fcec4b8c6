// The `sfmeval.eth3d/1` report's types, generated from the Rust types of
// crates/sfmeval-eth3d (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.

/**
 * One evaluation's report.
 */
export type Eth3dReport = {
/**
 * `sfmeval.eth3d/1` ([`ETH3D_SCHEMA`] in Rust).
 */
schema: "sfmeval.eth3d/1",
/**
 * The MeshLab project's name.
 */
ground_truth: string,
/**
 * The reconstruction's name.
 */
reconstruction: string,
/**
 * The options.
 */
options: Eth3dReportOptions,
/**
 * Points of the reconstruction.
 */
reconstruction_points: number,
/**
 * The scans in the project's order.
 */
scans: Array<Eth3dReportScan>,
/**
 * Voxel cells (both grids) holding scan points: the completeness's denominator.
 */
completeness_cells: number,
/**
 * One entry per tolerance, smallest first.
 */
tolerances: Array<Eth3dTolerance>, };

/**
 * The tool's options.
 */
export type Eth3dReportOptions = {
/**
 * Voxel size (m).
 */
voxel_size: number,
/**
 * Beam radius at the scanner (m).
 */
beam_start_radius: number,
/**
 * Beam divergence half-angle (degrees).
 */
beam_divergence_halfangle_deg: number, };

/**
 * One scan.
 */
export type Eth3dReportScan = {
/**
 * Its label in the project, if any.
 */
label: string | null,
/**
 * Its file.
 */
file: string,
/**
 * Its points.
 */
points: number, };

/**
 * One tolerance's results.
 */
export type Eth3dTolerance = {
/**
 * The tolerance (m).
 */
tolerance: number,
/**
 * Accuracy in [0, 1]: the mean over voxel cells of accurate / (accurate + inaccurate).
 */
accuracy: number,
/**
 * Completeness in [0, 1]: the mean over voxel cells of complete / scan points.
 */
completeness: number,
/**
 * F1 of the two.
 */
f1: number,
/**
 * Reconstruction points within the tolerance of a scan point on whose beam they lie.
 */
accurate_points: number,
/**
 * Reconstruction points in front of scan points (seen through), not accurate.
 */
inaccurate_points: number,
/**
 * Reconstruction points neither: left out of the accuracy.
 */
unobserved_points: number,
/**
 * Scan points with a reconstruction point within the tolerance.
 */
complete_points: number,
/**
 * Voxel cells (both grids) with an accurate or inaccurate point: the accuracy's
 * denominator.
 */
accuracy_cells: number, };
