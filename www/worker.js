// The sfmeval core runs here, off the main thread. Messages in: {id, type, ...}; out: replies
// {id, ok, ...} or {id, ok: false, error}, and {type: 'progress', id, stage, done, total}.
import {
  init, version, loadGroundTruth, loadReconstruction, loadCameras, raw, cropFile, parseCrop,
  parseTransform, parsePointPairs,
} from './sfmeval/index.js';

let gt = null;
let recon = null;
let cameraFiles = null; // attached to each new ground truth
let depthFiles = null; // attached after the cameras
let last = null; // the last raw Evaluation

const handlers = {
  async init() {
    await init();
    return { version: version() };
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
  loadRecon({ files, name }) {
    const bytes = {};
    for (const [n, b] of Object.entries(files)) bytes[n] = new Uint8Array(b);
    const r = loadReconstruction(bytes, name);
    if (recon) recon.free();
    recon = r;
    const positions = r.positions();
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
    let lastPost = 0;
    const progress = (stage, done, total) => {
      const now = performance.now();
      if (now - lastPost > 50 || done === total) {
        lastPost = now;
        postMessage({ type: 'progress', id, stage, done, total });
      }
    };
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
    const sampleLabels = e.sampleLabels() ?? null;
    const samplePoints = sampleLabels ? e.completenessPointsF32() : null;
    const extra = sampleLabels ? [sampleLabels.buffer, samplePoints.buffer] : [];
    return {
      reply: {
        reportJson: e.reportJson(), pointsInGt, distances, status, completeness, colors, clip,
        gtFromRecon: Array.from(e.gtFromRecon()), ms, sampleLabels, samplePoints,
      },
      transfer: [pointsInGt.buffer, distances.buffer, status.buffer, completeness.buffer, colors.buffer, ...extra],
    };
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
