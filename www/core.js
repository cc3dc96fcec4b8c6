// The WebAssembly core on its worker (worker.js): named message types, calls as promises, the
// progress it posts, and a restart that stops whatever it computes (Cancel).

/** The worker's message types (worker.js `handlers`), one name each. */
export const MSG = Object.freeze({
  init: 'init',
  loadGt: 'loadGt',
  loadRecon: 'loadRecon',
  loadCameras: 'loadCameras',
  clearCameras: 'clearCameras',
  loadDepth: 'loadDepth',
  clearDepth: 'clearDepth',
  evaluate: 'evaluate',
  compareRun: 'compareRun',
  runRowOnly: 'runRowOnly',
  runFiles: 'runFiles',
  modelFiles: 'modelFiles',
  dtuFiles: 'dtuFiles',
  dtu: 'dtu',
  poses: 'poses',
  eth3dFiles: 'eth3dFiles',
  eth3d: 'eth3d',
  eth3dCloud: 'eth3dCloud',
  tntFiles: 'tntFiles',
  tnt: 'tnt',
  tntFile: 'tntFile',
  comparisonTables: 'comparisonTables',
  colormap: 'colormap',
  colors: 'colors',
  coloredPly: 'coloredPly',
  csv: 'csv',
  cropFile: 'cropFile',
  parseCrop: 'parseCrop',
  parseTransform: 'parseTransform',
  parsePointPairs: 'parsePointPairs',
});
const KNOWN = new Set(Object.values(MSG));

/** The rejection of calls that were under way when the worker was stopped (Cancel). */
export class Cancelled extends Error {
  constructor() { super('cancelled'); this.name = 'Cancelled'; }
}

/** `?threads=N`: the worker pool's size (0 or 1: the single-thread build); default all cores. */
export const threadsParam = (() => {
  const v = new URLSearchParams(location.search).get('threads');
  return v !== null && /^\d+$/.test(v) ? Number(v) : undefined;
})();

let worker = null;
let nextId = 1;
const pending = new Map();
/** What the page does with the worker's progress messages and its failure. */
const hooks = { progress: () => {}, error: () => {} };
/** `onProgress({stage, done, total})` for each progress message, `onError(message)` if the worker dies. */
export function onWorkerEvents({ onProgress, onError }) {
  if (onProgress) hooks.progress = onProgress;
  if (onError) hooks.error = onError;
}

function startWorker() {
  worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  worker.onmessage = (ev) => {
    const m = ev.data;
    if (m.type === 'progress') { hooks.progress(m); return; }
    const p = pending.get(m.id);
    if (!p) return;
    pending.delete(m.id);
    if (m.ok) p.resolve(m); else p.reject(new Error(m.error));
    if (m.fatal) document.body.dataset.fatal = '1';
  };
  worker.onerror = (e) => hooks.error(`worker failed: ${e.message || 'unknown error'}`);
}
startWorker();

/** Sends a message of type `type` (one of `MSG`) and resolves with the worker's reply. */
export function call(type, payload = {}, transfer = []) {
  if (!KNOWN.has(type)) return Promise.reject(new Error(`unknown worker message '${type}'`));
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    worker.postMessage({ id, type, ...payload }, transfer);
  });
}

/**
 * The threaded build's progress counters in its shared memory (`sharedProgress()` of the
 * package), read while a run is under way: the worker that runs the call is blocked in it and
 * its pool's threads cannot post messages. Null with the single-thread build, which posts.
 */
let sharedProgress = null;

/** Starts the core (`init`) and keeps its shared progress counters; resolves with the reply. */
export async function initCore() {
  const m = await call(MSG.init, { threads: threadsParam });
  sharedProgress = m.progress;
  return m;
}

/** Polls the shared counters every 100 ms while `running()`; returns the interval (or null). */
export function pollSharedProgress(running, show) {
  if (!sharedProgress) return null;
  const { buffer, ptr, stages } = sharedProgress;
  const counters = new BigUint64Array(buffer, ptr, 3);
  return setInterval(() => {
    if (!running()) return;
    const [stage, done, total] = [0, 1, 2].map((k) => Number(Atomics.load(counters, k)));
    if (total > 0) show(stages[stage] ?? '', done, total);
  }, 100);
}

/**
 * Stops the worker (and whatever it computes), rejects its pending calls with `Cancelled`,
 * starts a fresh one, initialises it and lets `reload()` load the inputs into it again.
 */
export async function restartWorker(reload) {
  worker.terminate();
  const stopped = [...pending.values()];
  pending.clear();
  for (const p of stopped) p.reject(new Cancelled());
  startWorker();
  await initCore();
  await reload();
}
