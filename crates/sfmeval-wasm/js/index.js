// sfmeval: the WebAssembly build of the sfmeval core with a small JS API.
// Every number comes from the Rust core; this file only moves bytes and names around.
import initWasm, * as wasm from './sfmeval_wasm.js';

let ready = null;
let exports = null; // the instance's exports (its memory)

const isNode = typeof process !== 'undefined' && !!(process.versions && process.versions.node);

/**
 * Loads the WebAssembly module. Call once (later calls return the same promise).
 * In browsers the .wasm is fetched next to this file; in Node it is read from disk.
 * `input` may be a URL, a Response, bytes or a compiled WebAssembly.Module.
 */
export function init(input) {
  if (!ready) {
    ready = (async () => {
      let source = input;
      if (source === undefined && isNode) {
        const fs = await import('node:fs/promises');
        source = await fs.readFile(new URL('./sfmeval_wasm_bg.wasm', import.meta.url));
      }
      exports = await initWasm(source === undefined ? undefined : { module_or_path: source });
    })();
  }
  return ready;
}

/** Synchronous initialisation from bytes or a compiled module (e.g. inside a worker). */
export function initSync(module) {
  exports = wasm.initSync({ module });
  ready = Promise.resolve();
}

/**
 * Where a running evaluation's progress can be read from another thread, when the module's
 * memory is shared (the page's threaded build; `null` otherwise): `{buffer, ptr, stages}`;
 * `new BigUint64Array(buffer, ptr, 3)` holds the stage index into `stages`, done and total
 * (read them with `Atomics.load`).
 */
export function sharedProgress() {
  const memory = exports && exports.memory;
  if (!memory || typeof SharedArrayBuffer === 'undefined' || !(memory.buffer instanceof SharedArrayBuffer)) return null;
  return { buffer: memory.buffer, ptr: wasm.progressCounters(), stages: wasm.progressStages() };
}

/** The core's version (the report's `tool.version`). */
export function version() {
  return wasm.version();
}

function toBytes(v, name) {
  if (v instanceof Uint8Array) return v;
  if (v instanceof ArrayBuffer) return new Uint8Array(v);
  if (ArrayBuffer.isView(v)) return new Uint8Array(v.buffer, v.byteOffset, v.byteLength);
  if (typeof v === 'string') return new TextEncoder().encode(v);
  throw new TypeError(`file '${name}' must be a Uint8Array, ArrayBuffer or string`);
}

function fileMap(files) {
  const out = {};
  for (const [name, bytes] of Object.entries(files)) out[name] = toBytes(bytes, name);
  return out;
}

const isBuffer = (n) => /\.bin$/i.test(n) && !/^(cameras|images|points3D|frames|rigs)\.bin$/i.test(n.split('/').pop());

/**
 * Reads a ground truth. `files` maps file names to bytes: one GLB/glTF/OBJ/PLY file, plus the
 * external buffers of a `.gltf` by their URI. `maxTriangles` (default 10 M) refuses a mesh with
 * more triangles once every glTF node instance is expanded, before anything is allocated: raise
 * it for a trusted large file.
 */
export function loadGroundTruth(files, { maxTriangles } = {}) {
  if (files instanceof wasm.GroundTruth) return files;
  const map = fileMap(files);
  const names = Object.keys(map);
  const main = names.find((n) => /\.(glb|gltf|ply|obj)$/i.test(n)) ?? names.find((n) => !isBuffer(n)) ?? names[0];
  if (main === undefined) throw new Error('ground truth: no file given');
  const external = {};
  for (const n of names) if (n !== main) external[n] = map[n];
  return new wasm.GroundTruth(main.split('/').pop(), map[main], external, maxTriangles);
}

/**
 * Reads a reconstruction. `files` maps (relative) file names to bytes: one PLY, or the files
 * of an SfM model (COLMAP cameras/images/points3D .bin or .txt, .nvm, Bundler .out + list.txt,
 * sfm_data.json, cameras.json). `name` is shown in the report (default: the only file's name).
 */
export function loadReconstruction(files, name) {
  if (files instanceof wasm.Reconstruction) return files;
  const map = fileMap(files);
  const names = Object.keys(map);
  if (name === undefined) {
    name = names.length === 1 ? names[0].split('/').pop() : (names[0] ?? 'reconstruction').split('/')[0];
  }
  return new wasm.Reconstruction(name, map);
}

/**
 * Bytes of WebAssembly memory one point of a streamed reconstruction needs through an
 * evaluation, about: its position as the file's float32 (12), the evaluation's own copy (12),
 * distances, input order, status and k-d tree boxes (15), 16 while the tree order is computed,
 * and the GT-frame points the viewer reads (24 + 12), with room to spare.
 */
export const BYTES_PER_POINT = 100;
/** WebAssembly memory a reconstruction may take: wasm32 memory is 4 GiB at most, shared with
 * the ground truth and the evaluation's other buffers. */
export const RECONSTRUCTION_BUDGET = 3e9;

/**
 * Reads a reconstruction from a `File` or `Blob` (browser) a piece at a time, so the file's
 * bytes never enter WebAssembly memory: a binary PLY point cloud (a dense cloud) streams;
 * anything else (ascii PLY, a mesh) is read whole. Refuses, before reading the points, a
 * cloud with more than `maxPoints` points (default `RECONSTRUCTION_BUDGET / BYTES_PER_POINT`,
 * 30 M), which would not fit the page's memory. `onProgress(bytesRead, bytesTotal)` is called
 * after every piece (`pieceBytes`, default 8 MiB).
 */
export async function loadReconstructionFile(file, { name, onProgress, pieceBytes = 8 << 20, maxPoints } = {}) {
  const fileName = file.name ?? 'reconstruction.ply';
  name = name ?? fileName;
  const head = new Uint8Array(await file.slice(0, 1 << 16).arrayBuffer());
  const stream = /\.ply$/i.test(fileName) ? wasm.ReconstructionStream.start(name, fileName, head, file.size) : undefined;
  if (!stream) return loadReconstruction({ [fileName]: await file.arrayBuffer() }, name);
  const limit = maxPoints ?? Math.floor(RECONSTRUCTION_BUDGET / BYTES_PER_POINT);
  if (stream.declaredPoints > limit) {
    const n = stream.declaredPoints;
    stream.free();
    const m = (v) => `${(v / 1e6).toFixed(1)} M`;
    throw new Error(`reconstruction '${name}': ${m(n)} points do not fit this page (up to ${m(limit)}: about ${BYTES_PER_POINT} bytes a point of WebAssembly memory, which is at most 4 GB); evaluate it with the sfmeval CLI, which reads clouds of any size: sfmeval eval --gt GT --recon ${fileName}`);
  }
  try {
    let at = stream.bodyStart;
    while (!stream.isComplete && at < file.size) {
      const end = Math.min(at + pieceBytes, file.size);
      stream.push(new Uint8Array(await file.slice(at, end).arrayBuffer()));
      at = end;
      if (onProgress) onProgress(at, file.size);
    }
  } catch (e) {
    stream.free();
    throw e;
  }
  return stream.finish();
}

/** Reads ground-truth cameras (a dataset's cameras.json or any model in the ground-truth frame). */
export function loadCameras(files) {
  if (files instanceof wasm.Cameras) return files;
  return new wasm.Cameras(fileMap(files));
}

function wrap(e) {
  const r = {
    /** The report JSON text, byte for byte what `sfmeval eval --report` writes. */
    reportJson: e.reportJson(),
    get report() { return JSON.parse(this.reportJson); },
    pointsInGt: () => e.pointsInGt(),
    pointsInGtF32: () => e.pointsInGtF32(),
    distances: () => e.distances(),
    signedDistances: () => e.signedDistances(),
    status: () => e.status(),
    completenessDistances: () => e.completenessDistances(),
    sortedKeptDistances: () => e.sortedKeptDistances(),
    sortedCompletenessDistances: () => e.sortedCompletenessDistances(),
    completenessPointsF32: () => e.completenessPointsF32(),
    sampleLabels: () => e.sampleLabels(),
    trackErrors: () => e.trackErrors(),
    colors: (clip = e.defaultClip()) => e.colors(clip),
    coloredPly: (clip = e.defaultClip()) => e.coloredPly(clip),
    csv: () => e.csv(),
    gtFromRecon: () => e.gtFromRecon(),
    /** This run's row of the comparison tables (`summary.json`'s), from its run.json text. */
    runRow: (runJson) => JSON.parse(e.runRow(runJson)),
    defaultClip: () => e.defaultClip(),
    cameraClip: () => e.cameraClip(),
    cameraErrors: (recon) => e.cameraErrors(recon),
    cameraColors: (recon) => e.cameraColors(recon),
    free: () => e.free(),
  };
  return r;
}

/**
 * Aligns and measures a reconstruction against a ground truth, as `sfmeval eval`.
 * `gt` and `recon` are loaded objects or file maps `{name: bytes}`; `gtCameras` (optional, files
 * or a loaded `Cameras`, which is consumed) are attached to the ground truth; `depth` (optional,
 * needs `gtCameras`) maps the dataset's `depth/<image stem>.npy` file names to bytes and adds
 * visibility-aware completeness and the track-based error, as `sfmeval eval --depth`.
 * `options` uses the report's option names: `tau`, `tau_percent_of_diagonal`, `samples`, `seed`,
 * `signed`, `histogram_bins`, `crop` (a crop-file object), plus `align` (a mode name of
 * `alignModes()`), `transform` (4×4 or transform-file text) and
 * `pairs` (`[{recon: [x,y,z], gt: [x,y,z]}, ...]`).
 * `onProgress(stage, done, total)` is called during the long steps.
 */
export function evaluate({ gt, recon, gtCameras, depth, options, onProgress } = {}) {
  if (!gt) throw new TypeError('evaluate: gt is required');
  if (!recon) throw new TypeError('evaluate: recon is required');
  const g = loadGroundTruth(gt);
  const r = loadReconstruction(recon);
  if (gtCameras) g.setCameras(loadCameras(gtCameras));
  if (depth) g.setDepthMaps(fileMap(depth));
  try {
    return wrap(wasm.evaluate(g, r, options ?? {}, onProgress));
  } finally {
    if (g !== gt) g.free();
    if (r !== recon) r.free();
  }
}

/** Parses and validates the text of a crop file (`sfmeval.crop/1`). */
/** Every alignment mode with what it needs (`[{name, description, needsTransform, needsPairs,
 * needsCameras}]`), from the core's single list. */
export function alignModes() {
  return wasm.alignModes();
}

export function parseCrop(text) {
  return wasm.parseCrop(text);
}

/** Validates a crop object and returns its crop-file text (what `sfmeval eval --crop` reads). */
export function cropFile(crop) {
  return wasm.cropFile(crop);
}

/** Parses a transform (16 numbers as text, or JSON) into a row-major 4×4 array. */
export function parseTransform(text) {
  const m = wasm.parseTransform(text);
  return [0, 1, 2, 3].map((i) => Array.from(m.slice(4 * i, 4 * i + 4)));
}

/** Parses a point-pairs file. */
export function parsePointPairs(text) {
  return wasm.parsePointPairs(text);
}

/** The row of a run that was not evaluated (status not ok), from its run.json text. */
export function runRow(runJson) {
  return JSON.parse(wasm.runRow(runJson));
}

/**
 * The comparison tables of `rows` (rows of `runRow` / `evaluation.runRow`), each the text of the
 * file `sfmeval-runner report` writes: `{table1_md, table1_csv, runs_csv, table_md, summary_json}`.
 */
export function comparisonTables(rows) {
  return wasm.comparisonTables(JSON.stringify(rows));
}

/**
 * The Compare table of `entries` (`[{row, report}]`: a row of `runRow` / `evaluation.runRow` and
 * its report object, or null when not evaluated): `{columns: [{id, key, header, unit, best, text}],
 * rows: [[{value, text, best}]]}`, its columns, cell texts and best marks from the core's
 * catalogue of metrics.
 */
export function compareTable(entries) {
  return wasm.compareTable(JSON.stringify(entries.map((e) => ({ row: e.row, report: e.report ?? null }))));
}

/**
 * Which of a run folder's files form its reconstruction, as the runner reads a run folder
 * (`model/`'s model files, else `sparse.ply`): `paths` relative to the folder in, `[[path, name]]`
 * out, `name` as `loadReconstruction` wants it keyed.
 */
export function runReconstructionFiles(paths) {
  return wasm.runReconstructionFiles(JSON.stringify(paths));
}

/** The comparison's metrics: `[{key, id, header, unit, name, best, digits}]`. */
export function metricCatalogue() {
  return wasm.metricCatalogue();
}

/** Viewer colours (`Uint8Array` r,g,b per value: viridis saturating at `clip`, NaN grey). */
export function errorColors(values, clip) {
  return wasm.errorColors(Float64Array.from(values), clip);
}

/**
 * Whether a file can be part of an SfM model or a cloud, by its extension (the core's rule): the
 * model files of a folder, as `sfmeval eval --recon DIR` and the runner read them.
 */
export function isModelFile(path) {
  return wasm.isModelFile(path);
}

/**
 * What the DTU evaluation makes of these file names: `{scan, stl, obs_mask, plane,
 * reconstruction, missing, problems, ignored, inputs, summary: {line, status, complete, problem}}` (`stl{NNN}_total.ply`, `ObsMask{N}_10.mat`,
 * `Plane{N}.mat`, any other `.ply` the reconstruction; `missing` and `problems` are sentences).
 */
export function dtuFiles(names) {
  return wasm.dtuFiles(JSON.stringify(names));
}

/**
 * The DTU MVS evaluation of a scan, as `sfmeval dtu`: `files` maps the names of the STL points,
 * the observation mask, the ground plane and the reconstruction PLY to their bytes (recognised
 * by `dtuFiles`); `options`: `{mode, downsample_density, patch_size, max_dist,
 * visualize_threshold, seed, no_shuffle}` as the CLI's flags. Returns `{reportJson, report,
 * summary, resultLines, visNames, d2sPly(), s2dPly(), free()}`: `reportJson` byte for byte what
 * `sfmeval dtu --report` writes.
 */
export function evaluateDtu(files, options) {
  const e = wasm.evaluateDtu(fileMap(files), options ?? {});
  return {
    reportJson: e.reportJson,
    get report() { return JSON.parse(this.reportJson); },
    summary: e.summary,
    countsLine: e.countsLine,
    resultLines: e.resultLines,
    visNames: e.visNames(),
    d2sPly: () => e.d2sPly(),
    s2dPly: () => e.s2dPly(),
    free: () => e.free(),
  };
}

/**
 * What the ETH3D evaluation makes of these file names: `{project, scans: [{filename, file}],
 * reconstruction, missing, problems, ignored, inputs, summary: {line, status, complete, problem}}` (the one `.mlp` the project; given its bytes as
 * `project`, the scans it names matched by file name and the one other `.ply` the
 * reconstruction; `missing` and `problems` are sentences).
 */
export function eth3dFiles(names, project) {
  return wasm.eth3dFiles(JSON.stringify(names), project === undefined ? undefined : toBytes(project, 'project'));
}

/**
 * ETH3D's multi-view evaluation, as `sfmeval eth3d`: `files` maps the names of the MeshLab
 * project (`.mlp`), the scan PLYs it names and the reconstruction PLY to their bytes (recognised
 * by `eth3dFiles`); `options`: `{tolerances, voxel_size, beam_start_radius,
 * beam_divergence_halfangle_deg}` as the CLI's flags. Returns `{reportJson, report, summary,
 * headline, table, tolerances, cloudNames(t), accuracyPly(t), completenessPly(t), free()}`:
 * `reportJson` byte for byte what `sfmeval eth3d --json` prints (the CLI run in the project's
 * folder), `table` the per-tolerance `{columns, rows}` of cell texts.
 */
export function evaluateEth3d(files, options) {
  const e = wasm.evaluateEth3d(fileMap(files), options ?? {});
  return {
    reportJson: e.reportJson,
    get report() { return JSON.parse(this.reportJson); },
    summary: e.summary,
    headline: e.headline,
    table: e.table,
    tolerances: Array.from(e.tolerances),
    cloudNames: (t) => e.cloudNames(t),
    accuracyPly: (t) => e.accuracyPly(t),
    completenessPly: (t) => e.completenessPly(t),
    free: () => e.free(),
  };
}

/**
 * What the Tanks and Temples evaluation makes of these file names: `{scene, ground_truth, crop,
 * alignment, reference_trajectory, mapping, trajectory, reconstruction, missing, problems,
 * ignored, inputs, summary}` (`SCENE.ply`, `SCENE.json`, `SCENE_trans.txt`, `SCENE_COLMAP_SfM.log`,
 * `SCENE_mapping_reference.txt`; any other `.log` the reconstruction's trajectory, any other
 * `.ply` the reconstruction; `missing` and `problems` are sentences).
 */
export function tntFiles(names) {
  return wasm.tntFiles(JSON.stringify(names));
}

/**
 * The Tanks and Temples protocol, as `sfmeval tnt --scene SCENE`: `files` maps the names of the
 * scene's files, the reconstruction's trajectory and the reconstruction PLY to their bytes
 * (recognised by `tntFiles`); `options`: `{tau, seed}` as the CLI's flags. Returns `{reportJson,
 * report, summary, summaryLines, plotSvg, fileNames, file(name), free()}`: `reportJson` byte for
 * byte what `sfmeval tnt --json` prints, `file(name)` the bytes of each file it writes beside the
 * report (coloured clouds, curves, the plot's SVG).
 */
export function evaluateTnt(files, options) {
  const e = wasm.evaluateTnt(fileMap(files), options ?? {});
  return {
    reportJson: e.reportJson,
    get report() { return JSON.parse(this.reportJson); },
    summary: e.summary,
    summaryLines: e.summaryLines,
    get plotSvg() { return e.plotSvg; },
    fileNames: e.fileNames(),
    file: (name) => e.file(name),
    free: () => e.free(),
  };
}

/**
 * One camera-pose benchmark protocol, as `sfmeval poses`: `gtCameras` maps the ground-truth
 * cameras' file names to bytes (a dataset's `cameras.json`, or any model the core reads),
 * `recon` the estimated model's files (COLMAP `cameras/images/points3D` `.bin` or `.txt`, `.nvm`,
 * Bundler `.out` + `list.txt`, `sfm_data.json`, `cameras.json`); `options`: `{protocol:
 * 'colmap' | 'imc' | 'co3d', position_accuracy}` as the CLI's flags. Returns `{reportJson,
 * report, summary, summaryRows, pairsCsv}` (plain values: nothing to free): `reportJson` byte
 * for byte what `sfmeval poses --json` prints, `summaryRows` the summary's `{label, text}` lines.
 */
export function evaluatePoses({ gtCameras, recon } = {}, options) {
  if (!gtCameras) throw new Error('evaluatePoses: give gtCameras, the ground-truth cameras\' files');
  if (!recon) throw new Error('evaluatePoses: give recon, the estimated model\'s files');
  const e = wasm.evaluatePoses(fileMap(gtCameras), fileMap(recon), options ?? {});
  try {
    return {
      reportJson: e.reportJson,
      get report() { return JSON.parse(this.reportJson); },
      summary: e.summary,
      summaryRows: e.summaryRows,
      pairsCsv: e.pairsCsv,
    };
  } finally { e.free(); }
}

/** Numbers per camera in `GroundTruth.cameraPoses()` / `Reconstruction.cameraPoses()`:
 * centre (3), world_from_cam row-major (9), tan of the half field of view in x and y. */
export const POSE_STRIDE = 14;

export const GroundTruth = wasm.GroundTruth;
export const Reconstruction = wasm.Reconstruction;
export const ReconstructionStream = wasm.ReconstructionStream;
export const Cameras = wasm.Cameras;
/** The raw wasm-bindgen bindings. */
export const raw = wasm;
