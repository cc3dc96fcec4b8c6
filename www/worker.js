// The sfmeval core runs here, off the main thread. Messages in: {id, type, ...}; out: replies
// {id, ok, ...} or {id, ok: false, error}, and {type: 'progress', id, stage, done, total}.
// Two builds of the core: `sfmeval-mt/` (rayon threads over shared memory, SIMD128) where the
// page is cross-origin isolated and the browser has WebAssembly SIMD, else `sfmeval/` (one
// thread, scalar). Both are the npm package's API; `init` picks one.
let api = null;
let version, loadGroundTruth, loadReconstruction, loadReconstructionFile, loadCameras, raw, cropFile, parseCrop,
  parseTransform, parsePointPairs, errorColors, POSE_STRIDE, comparisonTables, compareTable, runReconstructionFiles, runRow,
  isModelFile, dtuFiles, evaluateDtu, evaluatePoses, eth3dFiles, evaluateEth3d, tntFiles, evaluateTnt;

// (module (func (result v128) i32.const 0 i8x16.splat i8x16.popcnt)): valid only with SIMD128
const SIMD_PROBE = new Uint8Array([0, 97, 115, 109, 1, 0, 0, 0, 1, 5, 1, 96, 0, 1, 123, 3, 2, 1, 0,
  10, 10, 1, 8, 0, 65, 0, 253, 15, 253, 98, 11]);

/** Why the threaded build cannot run here (a short phrase), or null. */
function threadsMissing() {
  if (!self.crossOriginIsolated) return 'the page is not cross-origin isolated';
  if (typeof SharedArrayBuffer !== 'function') return 'no SharedArrayBuffer';
  if (!WebAssembly.validate(SIMD_PROBE)) return 'no WebAssembly SIMD';
  return null;
}

/**
 * Loads the threaded build with a pool of `threads` workers when it can run here and more than
 * one thread is asked for (default: the machine's cores), else the single-thread build.
 * Returns the build and, when threads were wanted but are off, why.
 */
async function loadCore(threads) {
  const want = threads ?? navigator.hardwareConcurrency ?? 1;
  let note = null;
  if (want >= 2) {
    const missing = threadsMissing();
    if (missing) note = missing;
    else {
      try {
        const mt = await import('./sfmeval-mt/index.js');
        await mt.init();
        await mt.raw.initThreadPool(want);
        return { core: mt, note };
      } catch (e) {
        note = `the threaded build did not load: ${e && e.message ? e.message : e}`;
      }
    }
  }
  const st = await import('./sfmeval/index.js');
  await st.init();
  return { core: st, note };
}
let gt = null;
let recon = null;
let cameraFiles = null; // attached to each new ground truth
let depthFiles = null; // attached after the cameras
let last = null; // the last raw Evaluation
let lastTnt = null; // the last Tanks and Temples evaluation (its files are made on demand)
let lastEth3d = null; // the last ETH3D evaluation (its clouds are made on demand)

/**
 * Camera poses (`POSE_STRIDE` numbers each, reconstruction frame) mapped into the ground-truth
 * frame by the row-major similarity `m` of scale `s`.
 */
function posesInGt(poses, m, s) {
  const out = new Float64Array(poses.length);
  for (let i = 0; i < poses.length; i += POSE_STRIDE) {
    for (let r = 0; r < 3; r++) {
      out[i + r] = m[4 * r] * poses[i] + m[4 * r + 1] * poses[i + 1] + m[4 * r + 2] * poses[i + 2] + m[4 * r + 3];
      for (let c = 0; c < 3; c++) {
        let v = 0;
        for (let k = 0; k < 3; k++) v += m[4 * r + k] * poses[i + 3 + 3 * k + c];
        out[i + 3 + 3 * r + c] = v / s;
      }
    }
    out[i + 12] = poses[i + 12];
    out[i + 13] = poses[i + 13];
  }
  return out;
}

/**
 * The frusta of an evaluation `e` of reconstruction `r`: the ground-truth cameras, and the
 * estimated ones after the alignment their errors were measured after (the report's
 * `cameras.alignment`), with their centre errors, colours and colour clip as the core gives them
 * (`cameraErrors`, `cameraColors`, `cameraClip`). Null parts without cameras.
 */
function cameraData(e, r, report) {
  const gtPoses = gt.hasCameras ? gt.cameraPoses() : null;
  const cams = report.cameras;
  const poses = r.cameraPoses();
  if (!cams || !poses.length) return { gtPoses, estPoses: null, estColors: null, estErrors: null, camClip: null };
  const m = cams.alignment.gt_from_recon.flat();
  const estPoses = posesInGt(poses, m, cams.alignment.scale);
  return { gtPoses, estPoses, estErrors: e.cameraErrors(r), estColors: e.cameraColors(r), camClip: e.cameraClip() };
}

/**
 * A progress callback `(stage, done, total)` for call `id` that posts at most one message each
 * `ms` milliseconds (and always the last, `done === total`).
 */
function progressPoster(id, ms) {
  let lastPost = 0;
  return (stage, done, total) => {
    const now = performance.now();
    if (now - lastPost > ms || done === total) {
      lastPost = now;
      postMessage({ type: 'progress', id, stage, done, total });
    }
  };
}

const handlers = {
  async init({ threads }) {
    if (!api) {
      const { core, note } = await loadCore(threads);
      api = { core, note };
      ({
        version, loadGroundTruth, loadReconstruction, loadReconstructionFile, loadCameras, raw, cropFile, parseCrop,
        parseTransform, parsePointPairs, errorColors, POSE_STRIDE, comparisonTables, compareTable, runReconstructionFiles, runRow,
        isModelFile, dtuFiles, evaluateDtu, evaluatePoses, eth3dFiles, evaluateEth3d, tntFiles, evaluateTnt,
      } = core);
    }
    // threads: the pool's size (1: the single-thread build); threadsOff: why threads are off;
    // progress: the shared counters the page reads while this worker is blocked in a call
    // whose work runs on the pool (null for the single-thread build, which calls back)
    return {
      version: version(), threads: raw.threadCount(), threadsOff: api.note,
      progress: api.core.sharedProgress ? api.core.sharedProgress() : null,
    };
  },
  loadGt({ files, maxTriangles }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const g = loadGroundTruth(bytes, { maxTriangles });
    if (gt) gt.free();
    gt = g;
    const vertices = new Float32Array(g.vertices());
    const triangles = g.triangles();
    return {
      reply: {
        name: g.name, format: g.format, isMesh: g.isMesh, bounds: Array.from(g.bounds()),
        vertexCount: vertices.length / 3, triangleCount: triangles.length / 3,
        warnings: g.warnings, vertices, triangles,
      },
      transfer: [vertices.buffer, triangles.buffer],
    };
  },
  async loadRecon({ files, file, name, id }) {
    let r;
    if (file) {
      // One file: a binary PLY cloud streams in pieces (a dense cloud never sits in memory
      // twice), with progress; anything else is read whole.
      const post = progressPoster(id, 100);
      r = await loadReconstructionFile(file, { name, onProgress: (done, total) => post('reading', done, total) });
    } else {
      const bytes = {};
      for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
      r = loadReconstruction(bytes, name);
    }
    if (recon) recon.free();
    recon = r;
    // float32 files hand over their own values (exact, half the bytes of a dense cloud)
    const positions = r.positionsAreF32 ? r.positionsF32() : r.positions();
    const colors = r.colors() ?? null;
    return {
      reply: {
        name: r.name, format: r.format, count: r.pointCount, images: r.images,
        warnings: r.warnings, positions, colors,
      },
      transfer: [positions.buffer, ...(colors ? [colors.buffer] : [])],
    };
  },
  loadCameras({ files }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const c = loadCameras(bytes);
    const images = c.images;
    cameraFiles = bytes;
    if (gt) gt.setCameras(c); else c.free();
    if (gt && depthFiles) gt.setDepthMaps(depthFiles);
    return { images };
  },
  clearCameras() {
    cameraFiles = null;
    if (gt) gt.clearCameras();
    return {};
  },
  loadDepth({ files }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    // checked now (sizes against the cameras) when the cameras are there
    if (gt && gt.hasCameras) gt.setDepthMaps(bytes);
    depthFiles = bytes;
    return { count: Object.keys(bytes).length, checked: !!(gt && gt.hasCameras) };
  },
  clearDepth() {
    depthFiles = null;
    if (gt) gt.clearDepthMaps();
    return {};
  },
  evaluate({ options, id }) {
    if (!gt) throw new Error('load a ground truth first');
    if (!recon) throw new Error('load a reconstruction first');
    const progress = progressPoster(id, 50);
    const t0 = performance.now();
    if (cameraFiles && !gt.hasCameras) gt.setCameras(loadCameras(cameraFiles));
    if (depthFiles && !gt.hasDepthMaps) {
      if (!gt.hasCameras) throw new Error('depth maps need the ground-truth cameras (cameras.json)');
      gt.setDepthMaps(depthFiles);
    }
    const e = raw.evaluate(gt, recon, options, progress);
    const ms = performance.now() - t0;
    if (last) last.free();
    last = e;
    const pointsInGt = e.pointsInGt();
    const distances = e.distances();
    const status = e.status();
    const completeness = e.completenessDistances();
    const clip = e.defaultClip();
    const colors = e.colors(clip);
    // sorted here (in the core's threads), not on the page's UI thread: 10M points took seconds
    const sortedKept = e.sortedKeptDistances();
    const sortedComp = e.sortedCompletenessDistances();
    const sampleLabels = e.sampleLabels() ?? null;
    const samplePoints = sampleLabels ? e.completenessPointsF32() : null;
    const extra = sampleLabels ? [sampleLabels.buffer, samplePoints.buffer] : [];
    const reportJson = e.reportJson();
    const cameras = cameraData(e, recon, JSON.parse(reportJson));
    return {
      reply: {
        reportJson, pointsInGt, distances, status, completeness, colors, clip, sortedKept, sortedComp,
        gtFromRecon: Array.from(e.gtFromRecon()), ms, sampleLabels, samplePoints, cameras,
      },
      transfer: [pointsInGt.buffer, distances.buffer, status.buffer, completeness.buffer, colors.buffer,
        sortedKept.buffer, sortedComp.buffer, ...extra],
    };
  },
  /**
   * Compare: reads one reconstruction of the comparison, evaluates it against the loaded ground
   * truth (its index prepared once and reused) and returns its report, its table row (from
   * `runJson`, the run's run.json text, or a row made from the reconstruction for loose
   * files), what the viewer and the curves need, and frees it.
   */
  compareRun({ files, name, runJson, dataset, options, id }) {
    if (!gt) throw new Error('load a ground truth first');
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const r = loadReconstruction(bytes, name);
    const progress = (stage, done, total) => postMessage({ type: 'progress', id, stage, done, total });
    try {
      if (cameraFiles && !gt.hasCameras) gt.setCameras(loadCameras(cameraFiles));
      if (depthFiles && gt.hasCameras && !gt.hasDepthMaps) gt.setDepthMaps(depthFiles);
      const t0 = performance.now();
      const e = raw.evaluate(gt, r, options, progress);
      try {
        const reportJson = e.reportJson();
        const report = JSON.parse(reportJson);
        const run = runJson ?? JSON.stringify({
          dataset, pipeline: name, tool: 'file', version: null, status: 'ok', reason: null,
          wall_seconds: 0, cpu_seconds: 0, peak_memory_bytes: 0,
          images_total: report.cameras ? report.cameras.ground_truth : 0,
          images_registered: r.images, points: r.pointCount,
        });
        const row = JSON.parse(e.runRow(run));
        const kept = e.sortedKeptDistances();
        const comp = e.sortedCompletenessDistances();
        const pointsInGt = e.pointsInGtF32();
        const clip = e.defaultClip();
        const colors = e.colors(clip);
        const cameras = cameraData(e, r, report);
        return {
          reply: { reportJson, row, kept, comp, pointsInGt, colors, clip, cameras, ms: performance.now() - t0 },
          transfer: [kept.buffer, comp.buffer, pointsInGt.buffer, colors.buffer],
        };
      } finally { e.free(); }
    } finally { r.free(); }
  },
  /** Which of a run folder's files (paths relative to it) form its reconstruction: `[[path, name]]`. */
  runFiles({ paths }) {
    return { files: runReconstructionFiles(paths) };
  },
  /** Which of `paths` are model files (the core's rule, `isModelFile`): the model files Compare reads. */
  modelFiles({ paths }) {
    return { paths: paths.filter((p) => isModelFile(p)) };
  },
  /** What the DTU evaluation makes of these file names (the core's recognition): roles, scan, what is missing. */
  dtuFiles({ names }) {
    return { found: dtuFiles(names) };
  },
  /**
   * The DTU evaluation of the dropped scan files (`{name: ArrayBuffer}`), as `sfmeval dtu`: the
   * `sfmeval.dtu/1` report, the summary and its result lines, and the two error clouds.
   */
  dtu({ files, options }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const t0 = performance.now();
    const r = evaluateDtu(bytes, options);
    try {
      const d2s = r.d2sPly(), s2d = r.s2dPly();
      return {
        reply: { reportJson: r.reportJson, summary: r.summary, counts: r.countsLine, lines: r.resultLines, visNames: r.visNames, d2s, s2d, ms: performance.now() - t0 },
        transfer: [d2s.buffer, s2d.buffer],
      };
    } finally { r.free(); }
  },
  /**
   * One pose protocol on the dropped ground-truth cameras and estimated model (`{name:
   * ArrayBuffer}` each), as `sfmeval poses`: the `sfmeval.poses/1` report, the summary's rows
   * and the pairs CSV, all from the core.
   */
  poses({ gtFiles, reconFiles, options }) {
    const bytes = (files) => Object.fromEntries(Object.entries(files).map(([n, b]) => [n, new Uint8Array(b)]));
    const t0 = performance.now();
    const r = evaluatePoses({ gtCameras: bytes(gtFiles), recon: bytes(reconFiles) }, options);
    return { reportJson: r.reportJson, rows: r.summaryRows, pairsCsv: r.pairsCsv, ms: performance.now() - t0 };
  },
  /** What the ETH3D evaluation makes of these file names (and the project's bytes, once known). */
  eth3dFiles({ names, project }) {
    return { found: eth3dFiles(names, project ? new Uint8Array(project) : undefined) };
  },
  /**
   * ETH3D's evaluation of the dropped scene files (`{name: ArrayBuffer}`), as `sfmeval eth3d`:
   * the `sfmeval.eth3d/1` report, the headline, the per-tolerance table and the tolerances; the
   * result stays here for its coloured clouds (`eth3dCloud`), made when one is asked for.
   */
  eth3d({ files, options }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const t0 = performance.now();
    const r = evaluateEth3d(bytes, options);
    if (lastEth3d) lastEth3d.free();
    lastEth3d = r;
    return { reportJson: r.reportJson, headline: r.headline, table: r.table, tolerances: r.tolerances, ms: performance.now() - t0 };
  },
  /** Tolerance `t`'s coloured cloud of the last ETH3D evaluation (`kind`: accuracy or completeness), as the tool writes it. */
  eth3dCloud({ t, kind }) {
    if (!lastEth3d) throw new Error('no ETH3D evaluation yet');
    const [accName, compName] = lastEth3d.cloudNames(t);
    const bytes = kind === 'accuracy' ? lastEth3d.accuracyPly(t) : lastEth3d.completenessPly(t);
    return { reply: { name: kind === 'accuracy' ? accName : compName, bytes }, transfer: [bytes.buffer] };
  },
  /** What the Tanks and Temples evaluation makes of these file names (the core's recognition). */
  tntFiles({ names }) {
    return { found: tntFiles(names) };
  },
  /**
   * The Tanks and Temples protocol on the dropped files (`{name: ArrayBuffer}`), as `sfmeval tnt`:
   * the report, the summary's lines, the plot's SVG and the output files' names; the result
   * stays here for those files (`tntFile`), made when one is asked for.
   */
  tnt({ files, options }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const t0 = performance.now();
    const r = evaluateTnt(bytes, options);
    if (lastTnt) lastTnt.free();
    lastTnt = r;
    return { reportJson: r.reportJson, lines: r.summaryLines, svg: r.plotSvg, fileNames: r.fileNames, ms: performance.now() - t0 };
  },
  /** One output file of the last Tanks and Temples evaluation, by name. */
  tntFile({ name }) {
    if (!lastTnt) throw new Error('no Tanks and Temples evaluation yet');
    const bytes = lastTnt.file(name);
    return { reply: { name, bytes }, transfer: [bytes.buffer] };
  },
  /** The row of a run that did not end ok, from its run.json text. */
  runRowOnly({ runJson }) {
    return { row: runRow(runJson) };
  },
  /**
   * The comparison tables' texts (`sfmeval-runner report`'s files) of the entries' rows, and the
   * Compare table the page shows (columns, cell texts, best marks: the core's catalogue).
   */
  comparisonTables({ entries }) {
    return { tables: comparisonTables(entries.map((e) => e.row)), table: compareTable(entries) };
  },
  /** `n` colours (r,g,b) of the core's colour map from its low end to its top (the colour bar). */
  colormap({ n }) {
    const colors = errorColors(Array.from({ length: n }, (_, i) => i / (n - 1)), 1);
    return { reply: { colors }, transfer: [colors.buffer] };
  },
  colors({ clip }) {
    if (!last) throw new Error('no evaluation yet');
    const colors = last.colors(clip);
    return { reply: { colors }, transfer: [colors.buffer] };
  },
  coloredPly({ clip }) {
    if (!last) throw new Error('no evaluation yet');
    const bytes = last.coloredPly(clip);
    return { reply: { bytes }, transfer: [bytes.buffer] };
  },
  csv() {
    if (!last) throw new Error('no evaluation yet');
    return { text: last.csv() };
  },
  cropFile({ crop }) {
    return { text: cropFile(crop) };
  },
  parseCrop({ text }) {
    return { crop: parseCrop(text) };
  },
  parseTransform({ text }) {
    return { matrix: parseTransform(text) };
  },
  parsePointPairs({ text }) {
    return { pairs: parsePointPairs(text) };
  },
};

onmessage = async (ev) => {
  const msg = ev.data;
  try {
    const out = await handlers[msg.type](msg);
    if (out && out.reply) postMessage({ id: msg.id, ok: true, ...out.reply }, out.transfer ?? []);
    else postMessage({ id: msg.id, ok: true, ...(out ?? {}) });
  } catch (err) {
    let error = err && err.message ? err.message : String(err);
    if (err instanceof WebAssembly.RuntimeError || /memory/i.test(error) && !(err instanceof Error && err.name === 'Error')) {
      // A trap (usually out of memory: wasm32 has at most 4 GB) leaves the module unusable.
      error = `the WebAssembly core stopped (${error}): the input is probably too large for a browser tab; reload the page, or use the sfmeval CLI for this size`;
      postMessage({ id: msg.id, ok: false, error, fatal: true });
      return;
    }
    postMessage({ id: msg.id, ok: false, error });
  }
};
