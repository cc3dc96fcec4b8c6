// The `sfmeval.poses/1` report's types, generated from the Rust types of
// crates/sfmeval (feature `ts`, ts-rs) by scripts/gen-report-types.sh: do not edit.
import type { Code, JsonValue, Level, Note } from './report.js';

/**
 * A poses report (`sfmeval.poses/1`).
 */
export type PosesReport = {
/**
 * `sfmeval.poses/1`.
 */
schema: "sfmeval.poses/1",
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
 * Registered images whose name matches no ground-truth image.
 */
unmatched_estimated: number,
/**
 * Estimated poses that are NaN or infinite.
 */
non_finite: number,
/**
 * Separate models the SfM tool produced (the largest is evaluated).
 */
models: number,
/**
 * The protocol's convention.
 */
convention: Convention,
/**
 * The protocol's numbers.
 */
result: ProtocolResult,
/**
 * Problems worth a line.
 */
notes: Array<Note>, };

/**
 * The CO3D numbers.
 */
export type Co3dResult = {
/**
 * RRA / RTA thresholds, degrees.
 */
thresholds_deg: Array<number>,
/**
 * Relative Rotation Accuracy at each threshold, percent.
 */
rra_percent: Array<number>,
/**
 * Relative Translation Accuracy at each threshold, percent.
 */
rta_percent: Array<number>,
/**
 * Largest threshold of the AUC, degrees.
 */
auc_max_deg: number,
/**
 * AUC of `max(rotation, translation)` error up to [`Self::auc_max_deg`], percent.
 */
auc_percent: number,
/**
 * Pairs scored (unordered ground-truth pairs).
 */
pairs: number,
/**
 * Pairs with an unregistered image (180° each).
 */
pairs_unregistered: number, };

/**
 * COLMAP's benchmark numbers.
 */
export type ColmapResult = {
/**
 * Thresholds in degrees.
 */
thresholds_deg: Array<number>,
/**
 * AUC at each threshold, percent.
 */
auc_percent: Array<number>,
/**
 * Recall (share of errors `≤` the threshold) at each threshold, percent.
 */
recall_percent: Array<number>,
/**
 * The position accuracy used (GT units; 0: off).
 */
position_accuracy: number,
/**
 * Errors scored (ordered pairs).
 */
pairs: number,
/**
 * Ground-truth pairs with an unregistered image (180° each).
 */
pairs_unregistered: number,
/**
 * Registered pairs outside the ground truth (180° each).
 */
pairs_outside_gt: number,
/**
 * Median of the errors, degrees.
 */
median_error_deg: number, };

/**
 * A protocol's convention, written into its report.
 */
export type Convention = {
/**
 * The official code this protocol follows (repository, file, function).
 */
source: string,
/**
 * Which pairs are scored.
 */
pairs: PairSet,
/**
 * How rotation and translation errors combine.
 */
pair_error: PairError,
/**
 * The translation-direction sign.
 */
translation_sign: TranslationSign,
/**
 * How thresholds compare.
 */
threshold_test: ThresholdTest,
/**
 * What a pair with an unregistered image counts as, in words.
 */
unregistered: string,
/**
 * The rotation-error formula, in words.
 */
rotation_error: string, };

/**
 * The IMC numbers.
 */
export type ImcResult = {
/**
 * The thresholds of [`Self::accuracy`], degrees (1 … 10).
 */
thresholds_deg: Array<number>,
/**
 * Share of pairs under each threshold (cumulative histogram), 0..1.
 */
accuracy: Array<number>,
/**
 * mAA up to 5° (`qt_auc_colmap_05`), 0..1.
 */
maa_5: number,
/**
 * mAA up to 10° (`qt_auc_colmap_10`), 0..1.
 */
maa_10: number,
/**
 * Pairs scored (unordered ground-truth pairs).
 */
pairs: number,
/**
 * Pairs with an unregistered image (all pairs when the model is invalid).
 */
pairs_unregistered: number,
/**
 * False when the model holds a non-finite pose (the benchmark then fails every pair).
 */
model_valid: boolean, };

/**
 * How a pair's rotation and translation errors make its score.
 */
export type PairError = "max" | "separate_accuracies_max_auc";

/**
 * Which image pairs a protocol scores.
 */
export type PairSet = "ordered_gt_and_registered" | "unordered_gt";

/**
 * The result of one protocol.
 */
export type ProtocolResult = { "protocol": "colmap" } & ColmapResult | { "protocol": "imc" } & ImcResult | { "protocol": "co3d" } & Co3dResult;

/**
 * One line of the summary: a label (`AUC`, `mAA@5`, `convention`, ...) and its text.
 */
export type SummaryRow = {
/**
 * What the line is about.
 */
label: string,
/**
 * The numbers or words, units included.
 */
text: string, };

/**
 * How a pair is compared with a threshold.
 */
export type ThresholdTest = "at_most" | "below" | "histogram_bins";

/**
 * How the translation-direction error treats the sign of the direction.
 */
export type TranslationSign = "signed" | "folded";
