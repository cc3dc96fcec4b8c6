// Type declarations of the `sfmeval` npm package.
import type {
  GroundTruth as RawGroundTruth,
  Reconstruction as RawReconstruction,
  Cameras as RawCameras,
} from './sfmeval_wasm.js';
import * as rawBindings from './sfmeval_wasm.js';
import type { Report, Volume } from './report.js';
import type { DtuReport } from './dtu-report.js';
import type { PosesReport, SummaryRow } from './poses-report.js';
import type { Eth3dReport } from './eth3d-report.js';
import type { TntReport } from './tnt-report.js';

/** The report's types (`Report`, its sections, `Note`, the note `Code`s, ...), generated from the
 * core's Rust types (`report.d.ts`, `scripts/gen-report-types.sh`). */
export * from './report.js';
/** The DTU report's types (`DtuReport`, `DtuReportOptions`, `DtuCounts`), generated likewise
 * (`dtu-report.d.ts`). */
export * from './dtu-report.js';
/** The poses report's types (`PosesReport`, `ProtocolResult`, `Convention`, ...), generated likewise
 * (`poses-report.d.ts`; its `Note` is the report's). */
export * from './poses-report.js';
/** The ETH3D report's types (`Eth3dReport`, `Eth3dTolerance`, ...), generated likewise
 * (`eth3d-report.d.ts`). */
export * from './eth3d-report.js';
/** The Tanks and Temples report's types (`TntReport`, its sections), generated likewise
 * (`tnt-report.d.ts`; its `Tool` and `Note` are the report's). */
export * from './tnt-report.js';

/** File contents by (relative) file name. */
export type Files = Record<string, Uint8Array | ArrayBuffer | ArrayBufferView | string>;

/** A 3D point. */
export type Vec3 = [number, number, number];

/** A crop: an optional volume (`Volume`, as in the report: `box`, `oriented_box`, `sphere`,
 * `polygon_prism`) and an optional maximum distance to the ground truth. */
export interface Crop {
  schema?: 'sfmeval.crop/1';
  volume?: Volume;
  max_distance?: number;
}

/** One correspondence for the `points` alignment stage. */
export interface PointPair {
  recon: Vec3;
  gt: Vec3;
}

/** Options of an evaluation, named as in the report (same meaning as the CLI's flags). */
export interface EvalOptions {
  /** Thresholds in ground-truth units. */
  tau?: number[];
  /** Thresholds in percent of the ground-truth bounding-box diagonal (default 0.5, 1, 2). */
  tau_percent_of_diagonal?: number[];
  /** Completeness samples on a mesh ground truth (default 1 000 000). */
  samples?: number;
  /** Seed of the surface sampler and the randomised alignment stages. */
  seed?: number;
  /** Also compute distances signed by the closest triangle's normal. */
  signed?: boolean;
  /** Histogram bins (default 50). */
  histogram_bins?: number;
  /** With depth maps: images a surface sample must be seen in to count as visible (default 2). */
  min_views?: number;
  /** The crop, applied in the ground-truth frame after the transform. */
  crop?: Crop;
  /** Alignment mode (see {@link alignModes}): default `given` with a transform, else `auto`. */
  align?: AlignModeName;
  /** `gt_from_recon`: a row-major 4×4, 16 numbers, or the text of a transform file. */
  transform?: number[][] | number[] | string;
  /** Point pairs for `align: 'points'` and `'points+icp'`. */
  pairs?: PointPair[];
}

/** The alignment modes, as the CLI's `--align` takes them. */
export type AlignModeName =
  | 'auto' | 'cameras' | 'points' | 'global' | 'icp'
  | 'cameras+icp' | 'points+icp' | 'global+icp' | 'given' | 'none';

/** One alignment mode and what it needs. */
export interface AlignModeInfo {
  name: AlignModeName;
  /** One line on what it does. */
  description: string;
  /** `given`: cannot run without `transform`. */
  needsTransform: boolean;
  /** `points`, `points+icp`: cannot run without `pairs`. */
  needsPairs: boolean;
  /** `cameras`, `cameras+icp`: cannot run without cameras on both sides. */
  needsCameras: boolean;
}

/** Every alignment mode, in menu order, from the core's single list. */
export function alignModes(): AlignModeInfo[];

/** Progress callback: stage label, units done, units total. */
export type ProgressCallback = (stage: string, done: number, total: number) => void;

/** The result of {@link evaluate}. */
export interface EvaluationResult {
  /** The `sfmeval.report/3` JSON text, byte for byte what `sfmeval eval --report` writes. */
  readonly reportJson: string;
  /** The parsed report (`JSON.parse(reportJson)`). */
  readonly report: Report;
  /** Every reconstructed point in the ground-truth frame, `x0, y0, z0, ...`. */
  pointsInGt(): Float64Array;
  /** The same as 32-bit floats (WebGL). */
  pointsInGtF32(): Float32Array;
  /** Unsigned distance of every point. */
  distances(): Float64Array;
  /** Signed distances when `signed` was set and the ground truth is a mesh. */
  signedDistances(): Float64Array | undefined;
  /** Per point: 0 kept, 1 outside the crop volume, 2 farther than `max_distance`. */
  status(): Uint8Array;
  /** Distances of the completeness samples to the kept points. */
  completenessDistances(): Float64Array;
  /** The kept points' distances, ascending (NaN last): precision at any τ by a binary search. */
  sortedKeptDistances(): Float64Array;
  /** The completeness distances, ascending (NaN last). */
  sortedCompletenessDistances(): Float64Array;
  /** The completeness samples themselves, `x0, y0, z0, ...` as 32-bit floats (WebGL). */
  completenessPointsF32(): Float32Array;
  /** Per completeness sample: 0 covered, 1 missed, 2 unseen (with depth maps only). */
  sampleLabels(): Uint8Array | undefined;
  /** Per point, the track-based true error, NaN where not measured (depth maps + tracks only). */
  trackErrors(): Float64Array | undefined;
  /** Viridis heat-map colours `r, g, b` per point, saturating at `clip` (default: accuracy p95). */
  colors(clip?: number): Uint8Array;
  /** Binary PLY of the kept points coloured by error, as `sfmeval eval --colored`. */
  coloredPly(clip?: number): Uint8Array;
  /** Per-point distances CSV, as `sfmeval eval --csv`. */
  csv(): string;
  /** `gt_from_recon`, row-major, 16 numbers. */
  gtFromRecon(): Float64Array;
  /** This run's row of the comparison tables (as in the runner's summary.json), from its
   * run.json text. */
  runRow(runJson: string): RunRow;
  /** The accuracy 95th percentile (the CLI's default colour clip). */
  defaultClip(): number;
  /** The estimated cameras' colour clip (the centre errors' 95th percentile), undefined without
   * pose errors. */
  cameraClip(): number | undefined;
  /** Per registered image of `recon` (its `cameraPoses()` order), the camera-centre error (NaN:
   * no ground-truth image of that name). */
  cameraErrors(recon: RawReconstruction): Float64Array;
  /** The estimated frusta's colours `r, g, b` in `recon`'s `cameraPoses()` order: the centre
   * error in the points' colour map clipped at `cameraClip()`, grey without a ground-truth image. */
  cameraColors(recon: RawReconstruction): Uint8Array;
  /** Frees the wasm memory of this result. */
  free(): void;
}

/** Loads the WebAssembly module (browser: fetched next to this file; Node: read from disk). */
export function init(input?: RequestInfo | URL | Response | BufferSource | WebAssembly.Module): Promise<void>;
/** Synchronous initialisation from bytes or a compiled module. */
export function initSync(module: BufferSource | WebAssembly.Module): void;
/** The core's version. */
export function version(): string;
/** Reads a ground truth (GLB, glTF + buffers, OBJ, PLY mesh or cloud). */
export function loadGroundTruth(
  files: Files | RawGroundTruth,
  options?: {
    /** Refuse a mesh with more triangles than this once every glTF node instance is expanded
     * (default 10 000 000), before anything is allocated. */
    maxTriangles?: number;
  },
): RawGroundTruth;
/** Reads a reconstruction (PLY, or an SfM model's files). */
export function loadReconstruction(files: Files | RawReconstruction, name?: string): RawReconstruction;
/** Where a running evaluation's progress can be read from another thread when the module's
 * memory is shared (the page's threaded build), else `null`: `new BigUint64Array(buffer, ptr, 3)`
 * holds the stage index into `stages`, done and total. */
export function sharedProgress(): { buffer: SharedArrayBuffer; ptr: number; stages: string[] } | null;
/** Bytes of WebAssembly memory a streamed reconstruction point needs through an evaluation. */
export const BYTES_PER_POINT: number;
/** WebAssembly memory a reconstruction may take (bytes). */
export const RECONSTRUCTION_BUDGET: number;
/** Reads a reconstruction from a `File`/`Blob` a piece at a time (a binary PLY cloud streams;
 * anything else is read whole); refuses a cloud of more than `maxPoints` points before
 * reading them. */
export function loadReconstructionFile(
  file: Blob & { name?: string },
  options?: {
    name?: string;
    onProgress?: (bytesRead: number, bytesTotal: number) => void;
    pieceBytes?: number;
    maxPoints?: number;
  },
): Promise<RawReconstruction>;
/** Reads ground-truth cameras. */
export function loadCameras(files: Files | RawCameras): RawCameras;
/** Aligns and measures, as `sfmeval eval`. Throws an `Error` with the core's message. */
export function evaluate(args: {
  gt: Files | RawGroundTruth;
  recon: Files | RawReconstruction;
  gtCameras?: Files | RawCameras;
  /** The dataset's depth maps, `depth/<image stem>.npy` by name (needs `gtCameras`). */
  depth?: Files;
  options?: EvalOptions;
  onProgress?: ProgressCallback;
}): EvaluationResult;
/** Parses and validates the text of a crop file. */
export function parseCrop(text: string): Crop;
/** Validates a crop and returns its crop-file text. */
export function cropFile(crop: Crop): string;
/** Parses a transform file's text into a row-major 4×4. */
export function parseTransform(text: string): number[][];
/** Parses a point-pairs file. */
export function parsePointPairs(text: string): PointPair[];

/** One threshold of a run row. */
export interface RunPrf {
  tau: number;
  tau_percent_of_diagonal: number;
  precision: number;
  recall: number;
  f_score: number;
}

/** One run's row of the comparison tables (`sfmeval-runner report`'s summary.json rows). */
export interface RunRow {
  dataset: string;
  pipeline: string;
  tool: string;
  version: string | null;
  /** `ok`, `failed`, `timeout`, `not installed`, `evaluation failed`. */
  status: string;
  reason: string | null;
  images_total: number;
  images_registered: number;
  points: number;
  wall_seconds: number;
  cpu_seconds: number;
  peak_memory_mb: number;
  mean: number | null;
  median: number | null;
  rms: number | null;
  completeness_mean: number | null;
  thresholds: RunPrf[];
  rotation_median_deg: number | null;
  center_median: number | null;
  center_median_percent: number | null;
  center_max_percent: number | null;
  /** `[distance, share]` points of the cumulative distribution of the kept points. */
  cdf: [number, number][];
  /** `reports/<dataset>/<pipeline>.json`. */
  report: string | null;
}

/** The row of a run that was not evaluated, from its run.json text. */
export function runRow(runJson: string): RunRow;

/** The texts of the files `sfmeval-runner report` writes for these rows. */
export interface ComparisonTables {
  table1_md: string;
  table1_csv: string;
  runs_csv: string;
  table_md: string;
  summary_json: string;
}

export function comparisonTables(rows: RunRow[]): ComparisonTables;

/** A metric of the comparison (the core's catalogue). */
export interface Metric {
  /** JSON path into `{report, run}` (`report.accuracy.mean`); `[*]`: one per threshold. */
  key: string;
  /** Short id (`mean`; per threshold with its index: `f0`). */
  id: string;
  /** Header without the unit. */
  header: string;
  unit: string | null;
  /** Long name (chart titles). */
  name: string;
  /** Which end is best; null for text. */
  best: 'lower' | 'higher' | null;
  /** Decimals in the Markdown tables; null for text. */
  digits: number | null;
}

/** Which of a run folder's files (paths relative to it) form its reconstruction: `[path, name]`. */
export function runReconstructionFiles(paths: string[]): [string, string][];

/** The comparison's metrics. */
export function metricCatalogue(): Metric[];

/** A column of the Compare table. */
export interface CompareColumn {
  id: string;
  key: string;
  header: string;
  unit: string | null;
  best: 'lower' | 'higher' | null;
  text: boolean;
}

/** A cell of the Compare table: its number (null for text or none), text, best of its column. */
export interface CompareCell {
  value: number | null;
  text: string;
  best: boolean;
}

/** The Compare table of some runs: columns and each entry's cells. */
export interface CompareTable {
  columns: CompareColumn[];
  rows: CompareCell[][];
}

/** The Compare table of these runs (`report`: the evaluation's report, null when not evaluated). */
export function compareTable(entries: { row: RunRow; report?: Report | null }[]): CompareTable;

/** Viewer colours: r,g,b per value, viridis saturating at `clip` (the points' map), NaN grey. */
export function errorColors(values: ArrayLike<number>, clip: number): Uint8Array;

/** Whether a file can be part of an SfM model or a cloud, by its extension (the core's rule). */
export function isModelFile(path: string): boolean;

/** What a front end says of a benchmark's dropped files, worded by the core. */
export interface FilesSummary {
  /** One line: what each file is, what does not fit together, what is still needed, what is not used (joined by ` · `). */
  line: string;
  /** `ready`, `N files missing: see above` or `these files do not fit together: see above`. */
  status: string;
  /** Whether the evaluation can run. */
  complete: boolean;
  /** Whether some files do not fit together (show the line as an error). */
  problem: boolean;
}
/** What the DTU evaluation makes of a set of file names (`dtuFiles`). */
export interface DtuFiles {
  /** The scan number the ground-truth files' names give, null when none or when they disagree. */
  scan: number | null;
  /** `stl{NNN}_total.ply`. */
  stl: string | null;
  /** `ObsMask{N}_10.mat`. */
  obs_mask: string | null;
  /** `Plane{N}.mat`. */
  plane: string | null;
  /** Any other `.ply`. */
  reconstruction: string | null;
  /** What is still needed, one sentence each. */
  missing: string[];
  /** What does not fit together (two scans, two reconstructions), one sentence each. */
  problems: string[];
  /** Names that are none of the above. */
  ignored: string[];
  /** The files recognised that the evaluation reads, in the order of the fields above: the names to pass its evaluate function. */
  inputs: string[];
  /** What to show of these files. */
  summary: FilesSummary;
}
/** Sorts file names into the DTU scan's files. */
export function dtuFiles(names: string[]): DtuFiles;

/** The options of `evaluateDtu`, as `sfmeval dtu`'s flags (mm). */
export interface DtuOptions {
  mode?: 'auto' | 'mesh' | 'pcd';
  downsample_density?: number;
  patch_size?: number;
  max_dist?: number;
  visualize_threshold?: number;
  /** The shuffle's seed (default 0). */
  seed?: number;
  /** Down-sample in the input's order instead (`--no-shuffle`). */
  no_shuffle?: boolean;
}
/** One DTU evaluation. */
export interface DtuResult {
  /** The `sfmeval.dtu/1` JSON, byte for byte what `sfmeval dtu --report` writes. */
  readonly reportJson: string;
  /** The parsed report. */
  readonly report: DtuReport;
  /** The summary `sfmeval dtu` prints. */
  readonly summary: string;
  /** Its first line: the scan, the input's kind and the point counts. */
  readonly countsLine: string;
  /** Its mean accuracy, mean completeness and overall lines. */
  readonly resultLines: string[];
  /** The error clouds' names, `[vis_NNN_d2s.ply, vis_NNN_s2d.ply]`. */
  readonly visNames: string[];
  /** The accuracy error cloud (`sfmeval dtu --vis-out`). */
  d2sPly(): Uint8Array;
  /** The completeness error cloud. */
  s2dPly(): Uint8Array;
  /** Frees the wasm memory of this result. */
  free(): void;
}
/** The DTU MVS evaluation of a scan's files (STL points, ObsMask, Plane, reconstruction PLY). */
export function evaluateDtu(files: Files, options?: DtuOptions): DtuResult;

/** One scan of an ETH3D project and the file holding it. */
export interface Eth3dScanFile {
  /** The scan's `filename` in the project, as written (the report's name for it). */
  filename: string;
  /** The dropped file's name. */
  file: string;
}
/** What the ETH3D evaluation makes of a set of file names (`eth3dFiles`). */
export interface Eth3dFiles {
  /** The MeshLab project (`.mlp`). */
  project: string | null;
  /** The project's scans found, in its order (empty until the project's bytes are given). */
  scans: Eth3dScanFile[];
  /** The one `.ply` that is no scan. */
  reconstruction: string | null;
  /** What is still needed, one sentence each. */
  missing: string[];
  /** What does not fit together, one sentence each. */
  problems: string[];
  /** Names that are none of the above. */
  ignored: string[];
  /** The files recognised that the evaluation reads, in the order of the fields above: the names to pass its evaluate function. */
  inputs: string[];
  /** What to show of these files. */
  summary: FilesSummary;
}
/** Sorts file names into an ETH3D scene's files; `project` the project's bytes once known. */
export function eth3dFiles(names: string[], project?: Uint8Array | ArrayBuffer | string): Eth3dFiles;

/** The options of `evaluateEth3d`, as `sfmeval eth3d`'s flags. */
export interface Eth3dOptions {
  /** Tolerances (m); the benchmark's 0.01 … 0.5 by default. */
  tolerances?: number[];
  /** Voxel size (m). */
  voxel_size?: number;
  /** Laser beam radius at the scanner (m). */
  beam_start_radius?: number;
  /** Laser beam divergence half-angle (degrees). */
  beam_divergence_halfangle_deg?: number;
}
/** A table of cell texts made by the core. */
export interface TextTable {
  columns: string[];
  rows: string[][];
}
/** One ETH3D evaluation. */
export interface Eth3dResult {
  /** The `sfmeval.eth3d/1` JSON, byte for byte what `sfmeval eth3d --json` prints. */
  readonly reportJson: string;
  /** The parsed report. */
  readonly report: Eth3dReport;
  /** The summary `sfmeval eth3d` prints. */
  readonly summary: string;
  /** Its first line (points, scans, voxel size). */
  readonly headline: string;
  /** The per-tolerance table: accuracy, completeness, F1 and the point counts. */
  readonly table: TextTable;
  /** The tolerances, smallest first (the index `t` below). */
  readonly tolerances: number[];
  /** Tolerance `t`'s clouds' names, `[accuracy.tolerance_T.ply, completeness.tolerance_T.ply]`. */
  cloudNames(t: number): string[];
  /** Tolerance `t`'s accuracy cloud (the reconstruction coloured as the tool colours it). */
  accuracyPly(t: number): Uint8Array;
  /** Tolerance `t`'s completeness cloud (the scan points coloured). */
  completenessPly(t: number): Uint8Array;
  /** Frees the wasm memory of this result. */
  free(): void;
}
/** ETH3D's multi-view evaluation of a scene's files (MeshLab project, scan PLYs, reconstruction PLY). */
export function evaluateEth3d(files: Files, options?: Eth3dOptions): Eth3dResult;

/** What the Tanks and Temples evaluation makes of a set of file names (`tntFiles`). */
export interface TntFiles {
  /** The scene's name, from `SCENE_trans.txt`, `SCENE_COLMAP_SfM.log`, `SCENE_mapping_reference.txt`. */
  scene: string | null;
  ground_truth: string | null;
  crop: string | null;
  alignment: string | null;
  reference_trajectory: string | null;
  /** Video scenes only. */
  mapping: string | null;
  /** The reconstruction's camera trajectory (`.log`). */
  trajectory: string | null;
  /** The reconstruction (`.ply`). */
  reconstruction: string | null;
  /** What is still needed, one sentence each. */
  missing: string[];
  /** What does not fit together, one sentence each. */
  problems: string[];
  /** Names that are none of the above. */
  ignored: string[];
  /** The files recognised that the evaluation reads, in the order of the fields above: the names to pass its evaluate function. */
  inputs: string[];
  /** What to show of these files. */
  summary: FilesSummary;
}
/** Sorts file names into a Tanks and Temples scene's files. */
export function tntFiles(names: string[]): TntFiles;

/** The options of `evaluateTnt`, as `sfmeval tnt`'s flags. */
export interface TntOptions {
  /** τ in ground-truth units (default: the scene's, from the benchmark's table). */
  tau?: number;
  /** The trajectory alignment's RANSAC seed (default 0). */
  seed?: number;
}
/** One Tanks and Temples evaluation. */
export interface TntResult {
  /** The `sfmeval.tanksandtemples/2` JSON, byte for byte what `sfmeval tnt --json` prints. */
  readonly reportJson: string;
  /** The parsed report. */
  readonly report: TntReport;
  /** The summary `sfmeval tnt` prints (without where the files went). */
  readonly summary: string;
  /** Its lines. */
  readonly summaryLines: string[];
  /** The precision/recall plot, SVG text. */
  readonly plotSvg: string;
  /** The files `sfmeval tnt` writes beside the report (no PNG). */
  readonly fileNames: string[];
  /** One of them, made when asked for. */
  file(name: string): Uint8Array;
  /** Frees the wasm memory of this result. */
  free(): void;
}
/** The Tanks and Temples protocol on a scene's files, the reconstruction's trajectory and PLY. */
export function evaluateTnt(files: Files, options?: TntOptions): TntResult;

/** The options of `evaluatePoses`, as `sfmeval poses`' flags. */
export interface PosesOptions {
  /** The protocol (docs/poses.md). */
  protocol: 'colmap' | 'imc' | 'co3d';
  /** COLMAP: the ground truth's position accuracy (GT units; default 0, off). */
  position_accuracy?: number;
}
/** One pose protocol's evaluation (plain values). */
export interface PosesResult {
  /** The `sfmeval.poses/1` JSON, byte for byte what `sfmeval poses --json` prints. */
  readonly reportJson: string;
  /** The parsed report. */
  readonly report: PosesReport;
  /** The summary `sfmeval poses` prints. */
  readonly summary: string;
  /** The summary's lines: counts, the protocol's numbers, the convention, the notes. */
  readonly summaryRows: SummaryRow[];
  /** Every scored ground-truth pair's errors (`sfmeval poses --pairs`). */
  readonly pairsCsv: string;
}
/** One camera-pose protocol on the ground-truth cameras' and the estimated model's files. */
export function evaluatePoses(files: { gtCameras: Files; recon: Files }, options: PosesOptions): PosesResult;

/** Numbers per camera of `cameraPoses()`: centre (3), world_from_cam row-major (9), tangents of
 * the half field of view in x and y (0 when unknown). */
export const POSE_STRIDE: 14;

export const GroundTruth: typeof rawBindings.GroundTruth;
export type GroundTruth = RawGroundTruth;
export const Reconstruction: typeof rawBindings.Reconstruction;
export type Reconstruction = RawReconstruction;
export const ReconstructionStream: typeof rawBindings.ReconstructionStream;
export const Cameras: typeof rawBindings.Cameras;
export type Cameras = RawCameras;
/** The raw wasm-bindgen bindings. */
export const raw: typeof rawBindings;
