// The page: inputs, alignment, crop, evaluation in a worker, results and downloads.
import { Viewer } from './viewer.js';
import { histogramPlot, curvesPlot, VIRIDIS } from './plots.js';
import { setupCompare, drawCameras } from './compare.js';
import { dropZone, entryFiles } from './files.js';

const $ = (id) => document.getElementById(id);
const state = {
  gt: null, // {name, format, bounds, vertices, triangles, ...}
  recon: null, // {name, format, count, positions (Float64Array, recon frame), colors}
  camerasName: null,
  result: null, // {report, reportJson, pointsInGt, distances, status, completeness, colors, clip}
  pairs: [], // [{recon: [x,y,z], gt: [x,y,z]}]
  pendingRecon: null,
  picking: false,
  transformText: '',
  running: false, // an evaluation is under way
  restoring: false, // a fresh worker is reloading the inputs after a cancel
  loading: 0, // loads under way
  shownResult: false, // results are on screen (current or stale)
};
/** The files behind each loaded input, to reload them into a fresh worker after a cancel. */
const sources = { gt: null, recon: null, cams: null, depth: null };

// ---- worker ----------------------------------------------------------------------------
/** The rejection of calls that were under way when the worker was stopped (Cancel). */
class Cancelled extends Error {
  constructor() { super('cancelled'); this.name = 'Cancelled'; }
}
let worker = null;
let nextId = 1;
/** `?threads=N`: the worker pool's size (0 or 1: the single-thread build); default all cores. */
const threadsParam = (() => {
  const v = new URLSearchParams(location.search).get('threads');
  return v !== null && /^\d+$/.test(v) ? Number(v) : undefined;
})();
const pending = new Map();
function startWorker() {
  worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  worker.onmessage = (ev) => {
    const m = ev.data;
    if (m.type === 'progress') {
      if (state.running) showProgress(m.stage, m.done, m.total);
      else if (m.stage === 'reading') showProgress('reading (MB)', Math.round(m.done / 1e6), Math.max(2, Math.round(m.total / 1e6)));
      return;
    }
    const p = pending.get(m.id);
    if (!p) return;
    pending.delete(m.id);
    if (m.ok) p.resolve(m); else p.reject(new Error(m.error));
    if (m.fatal) document.body.dataset.fatal = '1';
  };
  worker.onerror = (e) => { showError(`worker failed: ${e.message || 'unknown error'}`); };
}
startWorker();
/**
 * Stops the worker (and whatever it computes), rejects its pending calls with `Cancelled`,
 * starts a fresh one and reloads the inputs into it from their files.
 */
async function restartWorker() {
  worker.terminate();
  const stopped = [...pending.values()];
  pending.clear();
  for (const p of stopped) p.reject(new Cancelled());
  startWorker();
  sharedProgress = (await call('init', { threads: threadsParam })).progress;
  const reload = async (type, src, extra = {}) => {
    if (!src) return;
    const { files, transfer } = await readFiles(src.files);
    await call(type, { files, ...extra }, transfer);
  };
  await reload('loadGt', sources.gt, { maxTriangles: Number($('max-triangles').value) || undefined });
  const single = sources.recon && sources.recon.files.length === 1 && !sources.recon.files[0].webkitRelativePath
    && /\.ply$/i.test(sources.recon.files[0].name) ? sources.recon.files[0] : null;
  if (single) await call('loadRecon', { file: single, name: sources.recon.name });
  else await reload('loadRecon', sources.recon, { name: sources.recon && sources.recon.name });
  await reload('loadCameras', sources.cams);
  await reload('loadDepth', sources.depth);
}
function call(type, payload = {}, transfer = []) {
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    worker.postMessage({ id, type, ...payload }, transfer);
  });
}

// ---- UI helpers ------------------------------------------------------------------------
/**
 * Shows `msg` in the banner under the header (always in view; empty hides it). `target` is
 * the id of the control the error belongs to: the banner offers to show it.
 */
let errorTarget = null;
function showError(msg, target = null) {
  $('error').textContent = msg;
  $('banner').hidden = !msg;
  errorTarget = msg ? target : null;
  $('banner-goto').hidden = !errorTarget;
}
$('banner-close').onclick = () => {
  const t = errorTarget && $(errorTarget);
  showError('');
  if (t) t.focus(); else $('run').focus();
};
$('banner-goto').onclick = () => {
  const t = errorTarget && $(errorTarget);
  if (!t) return;
  (t.closest('.drop') || t).scrollIntoView({ block: 'nearest' });
  t.focus();
};
/** The line under the run button: the last run's outcome, or what is missing to run. */
let runNote = { text: '', error: false };
function setRunNote(text, error = false) { runNote = { text, error }; updateRunButton(); }
function updateRunButton() {
  const ready = !!(state.gt && state.recon);
  $('run').disabled = state.running || state.restoring || state.loading > 0 || !ready;
  $('cancel').hidden = !state.running;
  $('cancel').disabled = state.restoring;
  document.body.classList.toggle('busy', state.running || state.loading > 0);
  let text = runNote.text;
  if (!text && !ready && !state.loading) {
    const missing = [!state.recon && 'a reconstruction', !state.gt && 'a ground truth'].filter(Boolean);
    text = `To evaluate, load ${missing.join(' and ')} (or try the demo).`;
  }
  $('run-status').textContent = text;
  $('run-status').classList.toggle('error', runNote.error);
}
function showProgress(stage, done, total) {
  const frac = total > 0 ? done / total : 0;
  $('progress').style.display = 'block';
  $('progress-bar').style.width = `${(100 * frac).toFixed(1)}%`;
  $('progress-text').textContent = stage ? `${stage} ${total > 1 ? `${done}/${total}` : ''}` : '';
}
function hideProgress() { $('progress').style.display = 'none'; }
/** Counts a load under way (true) or finished (false). */
function setBusy(b) {
  state.loading = Math.max(0, state.loading + (b ? 1 : -1));
  updateRunButton();
}
function download(name, data, type) {
  const blob = data instanceof Blob ? data : new Blob([data], { type });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
/** The CLI summary's number format (Rust `{:.6}` or `{:.4e}`). */
export function g(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e-3 && a < 1e5) return v.toFixed(6);
  return v.toExponential(4).replace('e+', 'e');
}
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));

// ---- viewer -----------------------------------------------------------------------------
const viewer = new Viewer($('viewer'));
window.sfmevalViewer = viewer;
viewer.onCropChange = () => scheduleKept();

// ---- inputs -----------------------------------------------------------------------------
/** Reads dropped/picked files; a picked folder's files are keyed relative to that folder. */
const MAX_BYTES = 1.5e9; // wasm32 memory is 4 GB at most; inputs are copied into it
async function readFiles(fileList) {
  const total = Array.from(fileList).reduce((n, f) => n + f.size, 0);
  if (total > MAX_BYTES) {
    throw new Error(`${(total / 1e9).toFixed(2)} GB is too large for this page (limit ${MAX_BYTES / 1e9} GB: WebAssembly memory is at most 4 GB); use the sfmeval CLI`);
  }
  const files = {};
  const transfer = [];
  let folder = null;
  for (const f of fileList) {
    const buf = await f.arrayBuffer();
    let key = f.name;
    if (f.webkitRelativePath) {
      const parts = f.webkitRelativePath.split('/');
      folder = parts[0];
      key = parts.slice(1).join('/') || f.name;
    }
    files[key] = buf;
    transfer.push(buf);
  }
  return { files, transfer, folder };
}

const INPUT_LABEL = { gt: 'ground truth', recon: 'reconstruction', cams: 'ground-truth cameras', depth: 'depth maps' };
const INPUT_CONTROLS = { gt: ['file-gt'], recon: ['file-recon', 'dir-recon'], cams: ['file-cams'], depth: ['file-depth', 'dir-depth'] };
/**
 * The info line beside an input: what is loaded, or why nothing is (`error`: marked in red,
 * the drop zone outlined, the file inputs `aria-invalid`). `notes` are the loader's warnings.
 */
function setInputInfo(kind, text, { error = false, notes } = {}) {
  const info = $(`info-${kind}`);
  info.textContent = text;
  info.classList.toggle('error', error);
  $(`drop-${kind}`).classList.toggle('failed', error);
  for (const id of INPUT_CONTROLS[kind]) {
    if (error) $(id).setAttribute('aria-invalid', 'true'); else $(id).removeAttribute('aria-invalid');
  }
  const box = $(`notes-${kind}`);
  if (box && notes !== undefined) box.innerHTML = (notes || []).map((w) => `<div class="warn">warning: ${esc(w)}</div>`).join('');
}
/** A failed load: said beside the input and in the banner (which offers to show the input). */
function inputFailed(kind, e) {
  const label = INPUT_LABEL[kind];
  const msg = e.message.startsWith(label) ? e.message : `${label}: ${e.message}`;
  setInputInfo(kind, `✗ not loaded — ${e.message}`, { error: true, notes: [] });
  showError(msg, INPUT_CONTROLS[kind][0]);
}

/**
 * Marks the results on screen as no longer current (dimmed under a note saying `why`),
 * disables their downloads and hides the colour bar. A new evaluation clears it.
 */
function markStale(why) {
  if (!state.shownResult) return;
  $('results').classList.add('stale');
  $('align-result').classList.add('stale');
  $('stale-note').hidden = false;
  $('stale-note').textContent = `Out of date: ${why}. These are the previous run's results; press Evaluate for new ones.`;
  for (const b of ['dl-report', 'dl-ply', 'dl-csv']) $(b).disabled = true;
  $('clip').disabled = true;
  $('colorbar').style.display = 'none';
  document.body.dataset.stale = '1';
  setRunNote('');
  if (state.result && state.recon) refreshPoints(); // without the error colours
}
function clearStale() {
  $('results').classList.remove('stale');
  $('align-result').classList.remove('stale');
  $('stale-note').hidden = true;
  $('stale-note').textContent = '';
  $('clip').disabled = false;
  delete document.body.dataset.stale;
}

async function loadGt(fileList) {
  showError('');
  setBusy(true);
  setInputInfo('gt', 'reading…');
  try {
    const { files, transfer } = await readFiles(fileList);
    const maxTriangles = Number($('max-triangles').value) || undefined;
    const gt = await call('loadGt', { files, maxTriangles }, transfer);
    state.gt = gt;
    sources.gt = { files: Array.from(fileList) };
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    viewer.setGroundTruth(gt.vertices, gt.triangles, gt.bounds);
    setInputInfo('gt', `${gt.name} (${gt.format}): ${gt.vertexCount} vertices, ${gt.triangleCount} triangles`, { notes: gt.warnings });
    markStale(`the ground truth is now '${gt.name}'`);
    refreshPoints();
    return true;
  } catch (e) {
    state.gt = null;
    sources.gt = null;
    state.result = null;
    viewer.setCoverage(null);
    viewer.clearGroundTruth();
    inputFailed('gt', e);
    markStale('the ground truth failed to load');
    refreshPoints();
    return false;
  } finally { setBusy(false); }
}

async function loadRecon(fileList, name) {
  showError('');
  setBusy(true);
  setInputInfo('recon', 'reading…');
  try {
    let r;
    const single = fileList.length === 1 && !fileList[0].webkitRelativePath ? fileList[0] : null;
    if (single && /\.ply$/i.test(single.name)) {
      // Read by the worker a piece at a time (a dense cloud streams; no size limit here: the
      // worker refuses a cloud that would not fit, from its header).
      if (!name) name = single.name;
      try {
        r = await call('loadRecon', { file: single, name });
      } finally { hideProgress(); }
    } else {
      const { files, transfer, folder } = await readFiles(fileList);
      const names = Object.keys(files);
      // The report names a reconstruction as the CLI does: the file, or the model's folder.
      if (!name) name = folder ?? (names.length === 1 ? names[0] : 'model');
      r = await call('loadRecon', { files, name }, transfer);
    }
    state.recon = r;
    sources.recon = { files: Array.from(fileList), name };
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    state.pairs = [];
    updatePairs();
    setInputInfo('recon', `${r.name} (${r.format}): ${r.count} points${r.images ? `, ${r.images} images` : ''}`, { notes: r.warnings });
    markStale(`the reconstruction is now '${r.name}'`);
    refreshPoints();
    return true;
  } catch (e) {
    state.recon = null;
    sources.recon = null;
    state.result = null;
    state.shown = null;
    viewer.setCoverage(null);
    viewer.clearPoints();
    $('drawn-note').textContent = '';
    state.pairs = [];
    updatePairs();
    inputFailed('recon', e);
    markStale('the reconstruction failed to load');
    scheduleKept();
    return false;
  } finally { setBusy(false); }
}

async function loadCams(fileList) {
  showError('');
  setBusy(true);
  try {
    const { files, transfer } = await readFiles(fileList);
    const c = await call('loadCameras', { files }, transfer);
    state.camerasName = Object.keys(files)[0];
    sources.cams = { files: Array.from(fileList) };
    setInputInfo('cams', `${state.camerasName}: ${c.images} images`);
    markStale(`the ground-truth cameras are now '${state.camerasName}'`);
    return true;
  } catch (e) {
    // nothing half-loaded: the page and the worker both have no cameras now
    state.camerasName = null;
    sources.cams = null;
    await call('clearCameras').catch(() => {});
    inputFailed('cams', e);
    markStale('the ground-truth cameras failed to load');
    return false;
  } finally { setBusy(false); }
}

async function loadDepth(fileList) {
  showError('');
  const npy = Array.from(fileList).filter((f) => /\.npy$/i.test(f.name));
  if (!npy.length) { inputFailed('depth', new Error('no .npy file among the dropped files')); return; }
  setBusy(true);
  setInputInfo('depth', 'reading…');
  try {
    const { files, transfer } = await readFiles(npy);
    const d = await call('loadDepth', { files }, transfer);
    state.depthCount = d.count;
    sources.depth = { files: npy };
    setInputInfo('depth', `${d.count} depth maps${d.checked ? '' : ' (checked against cameras.json when evaluating)'}`);
    markStale(`${d.count} depth maps were loaded`);
  } catch (e) {
    state.depthCount = 0;
    sources.depth = null;
    await call('clearDepth').catch(() => {});
    inputFailed('depth', e);
    markStale('the depth maps failed to load');
  } finally { setBusy(false); }
}

$('dir-recon').addEventListener('change', (e) => handleFiles('recon', e.target.files));
$('dir-depth').addEventListener('change', (e) => handleFiles('depth', e.target.files));
for (const [kind, input] of [['recon', 'file-recon'], ['gt', 'file-gt'], ['cams', 'file-cams'], ['depth', 'file-depth']]) {
  $(input).addEventListener('change', (e) => handleFiles(kind, e.target.files));
  dropZone($(`drop-${kind}`), async (entries, files) => {
    if ((kind === 'recon' || kind === 'depth') && entries.length === 1 && entries[0].isDirectory) {
      try { handleFiles(kind, await folderFiles(entries[0])); } catch (err) { inputFailed(kind, err); }
    } else {
      handleFiles(kind, files);
    }
  });
}
/** The model or depth-map files under a dropped folder, with webkitRelativePath-like names. */
async function folderFiles(dir) {
  return (await entryFiles(dir)).filter((f) => /\.(bin|txt|nvm|out|json|ply|npy)$/i.test(f.name));
}

function handleFiles(kind, files) {
  if (!files || !files.length) return;
  const p = kind === 'gt' ? loadGt(files) : kind === 'recon' ? loadRecon(files) : kind === 'depth' ? loadDepth(files) : loadCams(files);
  p.catch((e) => inputFailed(kind, e));
}
$('clear-cams').onclick = async () => {
  await call('clearCameras');
  const had = !!sources.cams;
  state.camerasName = null;
  sources.cams = null;
  setInputInfo('cams', '—');
  if (had) markStale('the ground-truth cameras were cleared');
};
$('clear-depth').onclick = async () => {
  await call('clearDepth');
  const had = !!sources.depth;
  state.depthCount = 0;
  sources.depth = null;
  setInputInfo('depth', '—');
  if (had) markStale('the depth maps were cleared');
};

// ---- demo -------------------------------------------------------------------------------
async function fetchFile(name) {
  const r = await fetch(`demo/${name}`);
  if (!r.ok) throw new Error(`demo file '${name}' is missing (${r.status})`);
  return new File([await r.arrayBuffer()], name.split('/').pop());
}
$('demo').onclick = async () => {
  showError('');
  try {
    const m = await (await fetch('demo/manifest.json')).json();
    const gtFiles = await Promise.all([].concat(m.ground_truth).map(fetchFile));
    const reconFiles = await Promise.all([].concat(m.reconstruction).map(fetchFile));
    // stop at the first failure, so that its message stays in the banner
    if (!await loadGt(gtFiles) || !await loadRecon(reconFiles, m.reconstruction_name)) return;
    if (m.gt_cameras) {
      if (!await loadCams([await fetchFile(m.gt_cameras)])) return;
    } else {
      await $('clear-cams').onclick();
    }
    if (m.transform) {
      const t = await (await fetchFile(m.transform)).text();
      $('transform').value = alignedTransform(t);
      document.querySelector('input[name=align][value=given]').checked = true;
    } else {
      document.querySelector(`input[name=align][value="${m.align ?? 'auto'}"]`).checked = true;
    }
    refreshPoints();
  } catch (e) { showError(`demo: ${e.message}`, 'demo'); }
};

// ---- alignment --------------------------------------------------------------------------
const alignMethod = () => document.querySelector('input[name=align]:checked').value;
const viewMode = () => document.querySelector('input[name=view]:checked').value;
$('file-transform').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (f) { $('transform').value = alignedTransform(await f.text()); document.querySelector('input[name=align][value=given]').checked = true; refreshPoints(); }
});
/**
 * A loaded transform's text as 4 rows of 4 right-aligned numbers, each printed exactly
 * (JavaScript's shortest round-trip form: the same doubles as the file); text that is not
 * 16 numbers stays as it is.
 */
export function alignedTransform(text) {
  const m = parseMatrixLoose(text);
  if (!m) return text;
  const cells = m.map((v) => (Object.is(v, -0) ? '-0' : String(v)));
  const w = Math.max(...cells.map((c) => c.length));
  return [0, 1, 2, 3].map((r) => cells.slice(4 * r, 4 * r + 4).map((c) => c.padStart(w)).join('  ')).join('\n');
}
$('transform').addEventListener('input', () => refreshPoints());
for (const r of document.querySelectorAll('input[name=align], input[name=view]')) r.addEventListener('change', () => refreshPoints());
for (const r of document.querySelectorAll('input[name=view]')) r.addEventListener('change', () => viewer.fit(viewMode() === 'before'));

/** A display-only similarity placing the raw reconstruction beside the ground truth. */
function besideTransform() {
  if (state.beside) return state.beside;
  // robust extent (2nd–98th percentile per axis): SfM clouds have far outliers
  const p = state.recon.positions;
  const n = p.length / 3, step = Math.max(1, Math.floor(n / 20000));
  const lo = [], hi = [];
  for (let k = 0; k < 3; k++) {
    const v = [];
    for (let i = 0; i < n; i += step) v.push(p[3 * i + k]);
    v.sort((a, b) => a - b);
    lo.push(v[Math.floor(0.02 * (v.length - 1))] ?? 0);
    hi.push(v[Math.ceil(0.98 * (v.length - 1))] ?? 1);
  }
  const d = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const b = state.gt ? state.gt.bounds : [0, 0, 0, 1, 1, 1];
  const gd = Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]) || 1;
  const s = gd / d;
  const gc = [0, 1, 2].map((k) => (b[k] + b[k + 3]) / 2);
  gc[0] += gd * 0.9;
  const rc = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
  state.beside = (x, y, z) => [gc[0] + s * (x - rc[0]), gc[1] + s * (y - rc[1]), gc[2] + s * (z - rc[2])];
  return state.beside;
}

function parseMatrixLoose(text) {
  const nums = text.replace(/#[^\n]*/g, '').split(/[\s,\[\]]+/).filter(Boolean).map(Number);
  return nums.length === 16 && nums.every(Number.isFinite) ? nums : null;
}

/** The points shown: the last evaluation's points in the GT frame, or a preview transform. */
function displayedPositions() {
  const r = state.recon;
  if (!r) return null;
  const p = r.positions;
  if (viewMode() === 'before' || state.picking) {
    const f = besideTransform();
    const out = new Float64Array(p.length);
    for (let i = 0; i < p.length; i += 3) { const q = f(p[i], p[i + 1], p[i + 2]); out[i] = q[0]; out[i + 1] = q[1]; out[i + 2] = q[2]; }
    return out;
  }
  if (state.result) return state.result.pointsInGt;
  const m = alignMethod() === 'given' ? parseMatrixLoose($('transform').value) : null;
  if (!m) return p;
  const out = new Float64Array(p.length);
  for (let i = 0; i < p.length; i += 3) {
    const x = p[i], y = p[i + 1], z = p[i + 2];
    out[i] = m[0] * x + m[1] * y + m[2] * z + m[3];
    out[i + 1] = m[4] * x + m[5] * y + m[6] * z + m[7];
    out[i + 2] = m[8] * x + m[9] * y + m[10] * z + m[11];
  }
  return out;
}

/** 2 → "2nd", 3 → "3rd", 11 → "11th", 21 → "21st". */
function ordinal(k) {
  const teen = k % 100 >= 11 && k % 100 <= 13;
  return `${k}${teen ? 'th' : ({ 1: 'st', 2: 'nd', 3: 'rd' }[k % 10] ?? 'th')}`;
}

function refreshPoints() {
  const pos = displayedPositions();
  if (!pos) return;
  let colors = null;
  const useHeat = state.result && !document.body.dataset.stale && $('heat').checked && viewMode() === 'after' && !state.picking;
  if (useHeat) colors = state.result.colors;
  else if (state.recon.colors) colors = state.recon.colors;
  viewer.setPoints(pos, colors);
  const { count, total, stride } = viewer.drawn;
  $('drawn-note').textContent = stride > 1
    ? `drawn: every ${ordinal(stride)} point (${count.toLocaleString('en')} of ${total.toLocaleString('en')}; all are measured)`
    : '';
  viewer.setVisible('recon', $('show-recon').checked);
  state.shown = pos;
  drawMarkers();
  scheduleKept();
}

// point pairs
function updatePairs() {
  const n = state.pairs.filter((p) => p.gt && p.recon).length;
  $('pairs-info').textContent = `${n} pair${n === 1 ? '' : 's'}${state.picking ? ` — click a ${state.nextPick === 'gt' ? 'ground-truth surface point' : 'reconstructed point'}` : ''}`;
}
function drawMarkers() {
  if (!state.recon) { viewer.setMarkers([]); return; }
  const f = besideTransform();
  const list = [];
  for (const p of state.pairs) {
    if (p.gt) list.push({ p: p.gt, color: 0x00e676 });
    if (p.recon && (viewMode() === 'before' || state.picking)) list.push({ p: f(...p.recon), color: 0xff1744 });
  }
  viewer.setMarkers(list);
}
$('pick').onclick = () => {
  state.picking = !state.picking;
  state.nextPick = 'recon';
  $('pick').textContent = state.picking ? 'done picking' : 'pick pairs';
  if (state.picking) document.querySelector('input[name=align][value="points+icp"]').checked = true;
  viewer.onPick = state.picking ? onPick : null;
  updatePairs();
  refreshPoints();
  viewer.fit(state.picking || viewMode() === 'before');
};
$('clear-pairs').onclick = () => { state.pairs = []; updatePairs(); drawMarkers(); };
function onPick(hit) {
  if (state.nextPick === 'recon' && hit.kind === 'recon') {
    const p = state.recon.positions;
    state.pairs.push({ recon: [p[3 * hit.index], p[3 * hit.index + 1], p[3 * hit.index + 2]], gt: null });
    state.nextPick = 'gt';
  } else if (state.nextPick === 'gt' && hit.kind === 'gt') {
    state.pairs[state.pairs.length - 1].gt = hit.point;
    state.nextPick = 'recon';
  }
  updatePairs();
  drawMarkers();
}

function showStages(report) {
  const a = report.alignment;
  // a stage's warnings (by their `values.stage`) mark its row; a rejected refinement says so
  const notes = reportNotes(report);
  const rows = (a.stages || []).map((s) => {
    const own = notes.filter((n) => n.stage === s.method && n.level === 'warn');
    const rejected = own.some((n) => n.code === 'alignment.icp_rejected');
    const mark = own.length ? ` <span class="warn" data-stage-warnings="${own.length}" title="${own.length} warning(s) below">⚠</span>` : '';
    return `<tr><td>${esc(s.method)}${mark}</td><td>${g(s.scale)}</td><td>${s.rmse == null ? '—' : g(s.rmse)}</td><td>${s.inlier_ratio == null ? '—' : s.inlier_ratio.toFixed(4)}</td><td>${s.iterations}</td><td>${rejected ? 'rejected' : s.converged ? 'yes' : 'no'}</td></tr>`;
  }).join('');
  $('stages').innerHTML = `<tr><th>stage</th><th>scale</th><th>rmse</th><th>inliers</th><th>iter</th><th>conv.</th></tr>${rows}`;
  $('matrix').textContent = matrixText(a.gt_from_recon);
  $('matrix').title = `gt_from_recon, full precision:\n${a.gt_from_recon.map((r) => r.join(' ')).join('\n')}`;
  $('matrix-wrap').hidden = false;
}

/**
 * A 4×4 matrix as an aligned monospace grid: 4 right-aligned columns, the same number of
 * decimals everywhere (6, fewer when the largest entry needs more integer digits).
 */
export function matrixText(m) {
  const flat = m.flat();
  const big = Math.max(...flat.map((v) => Math.abs(v)).filter(Number.isFinite), 0);
  const intDigits = big >= 1 ? Math.floor(Math.log10(big)) + 1 : 1;
  const decimals = Math.max(2, Math.min(6, 9 - intDigits));
  const cells = flat.map((v) => (v === 0 ? 0 : v).toFixed(decimals));
  const w = Math.max(...cells.map((c) => c.length));
  const rows = [];
  for (let r = 0; r < 4; r++) rows.push(cells.slice(4 * r, 4 * r + 4).map((c) => c.padStart(w)).join('  '));
  return rows.join('\n');
}

/**
 * The report's notes as the core wrote them (`rep.notes`: `{code, level, message, values}`,
 * docs/notes.md): the level picks the style, the code goes on the element (`data-code`) and
 * places stage notes beside their stage (`values.stage`); the message is shown as written. The
 * page never reads the message text. Returns [{code, level, stage, html}].
 */
export function reportNotes(rep) {
  return (rep.notes || []).map((n) => {
    const warning = n.level === 'warning';
    return {
      code: n.code,
      level: warning ? 'warn' : 'info',
      stage: (n.values && n.values.stage) || null,
      html: `${warning ? 'warning' : 'note'}: ${esc(n.message)}`,
    };
  });
}

// ---- crop -------------------------------------------------------------------------------
function currentCrop() {
  const crop = {};
  const v = viewer.cropVolume();
  if (v) crop.volume = v;
  const d = $('max-distance').value.trim();
  if (d !== '') crop.max_distance = Number(d);
  return crop;
}
/** Open3D's SelectionPolygonVolume test, as the core's `Volume::PolygonPrism`. */
function inPrism(v, p) {
  const [u, w, a] = { x: [1, 2, 0], y: [0, 2, 1], z: [0, 1, 2] }[v.axis];
  if (p[a] < v.axis_min || p[a] > v.axis_max) return false;
  let below = 0;
  const n = v.polygon.length;
  for (let i = 0; i < n; i++) {
    const s = v.polygon[i], e = v.polygon[(i + 1) % n];
    if ((s[w] < p[w] && e[w] >= p[w]) || (e[w] < p[w] && s[w] >= p[w])) {
      if (s[u] + (p[w] - s[w]) / (e[w] - s[w]) * (e[u] - s[u]) < p[u]) below++;
    }
  }
  return below % 2 === 1;
}
function contains(v, x, y, z) {
  if (v.kind === 'polygon_prism') return inPrism(v, [x, y, z]);
  if (v.kind === 'sphere') {
    const dx = x - v.center[0], dy = y - v.center[1], dz = z - v.center[2];
    return dx * dx + dy * dy + dz * dz <= v.radius * v.radius;
  }
  const dx = x - v.center[0], dy = y - v.center[1], dz = z - v.center[2];
  const r = v.rotation;
  for (let k = 0; k < 3; k++) {
    const local = r[0][k] * dx + r[1][k] * dy + r[2][k] * dz;
    if (!(Math.abs(local) <= v.half_extents[k])) return false;
  }
  return true;
}
let keptQueued = false;
function scheduleKept() {
  if (keptQueued) return;
  keptQueued = true;
  requestAnimationFrame(() => { keptQueued = false; updateKept(); });
}
/** Live preview of the crop's kept count (same rules as the core; the report is authoritative). */
function updateKept() {
  const pos = state.result && viewMode() === 'after' ? state.result.pointsInGt : (viewMode() === 'after' && !state.picking ? state.shown : null);
  if (!pos) { $('kept').textContent = '—'; return; }
  const crop = currentCrop();
  const dist = state.result ? state.result.distances : null;
  let kept = 0;
  const n = pos.length / 3;
  for (let i = 0; i < n; i++) {
    if (crop.volume && !contains(crop.volume, pos[3 * i], pos[3 * i + 1], pos[3 * i + 2])) continue;
    if (crop.max_distance !== undefined && dist && dist[i] > crop.max_distance) continue;
    kept++;
  }
  $('kept').textContent = `${kept} / ${n}`;
  $('kept-note').textContent = crop.max_distance !== undefined && !dist ? '(max distance applies after the first evaluation)' : '';
}
$('crop-kind').onchange = () => {
  viewer.setCropKind($('crop-kind').value);
  if (state.gt) viewer.fitCrop(state.gt.bounds);
  viewer.setGizmoMode($('gizmo-mode').value);
  scheduleKept();
};
$('gizmo-mode').onchange = () => viewer.setGizmoMode($('gizmo-mode').value);
$('crop-fit').onclick = () => { if (state.gt) viewer.fitCrop(state.gt.bounds); scheduleKept(); };
$('max-distance').addEventListener('input', scheduleKept);
async function cropText() {
  return (await call('cropFile', { crop: currentCrop() })).text;
}
$('crop-export').onclick = async () => {
  try { download('crop.json', await cropText(), 'application/json'); } catch (e) { showError(e.message); }
};
$('dl-crop').onclick = $('crop-export').onclick;
$('crop-import').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  try {
    const { crop } = await call('parseCrop', { text: await f.text() });
    $('crop-kind').value = viewer.setCropVolume(crop.volume);
    $('max-distance').value = crop.max_distance ?? '';
    scheduleKept();
  } catch (err) { showError(`crop file '${f.name}': ${err.message}`, 'crop-import'); }
  e.target.value = '';
});

// ---- evaluation -------------------------------------------------------------------------
const numList = (s) => s.split(',').map((w) => w.trim()).filter(Boolean).map(Number);
function options() {
  const o = {
    tau: numList($('tau').value),
    tau_percent_of_diagonal: numList($('tau-rel').value),
    samples: Number($('samples').value),
    seed: Number($('seed').value),
    signed: $('signed').checked,
    histogram_bins: Number($('bins').value),
    crop: currentCrop(),
  };
  const method = alignMethod();
  o.align = method;
  if (method === 'given') o.transform = $('transform').value;
  if (method.startsWith('points')) o.pairs = state.pairs.filter((p) => p.gt && p.recon);
  return o;
}

/**
 * The threaded build's progress counters in its shared memory (`sharedProgress()` of the
 * package), read while a run is under way: the worker that runs the call is blocked in it and
 * its pool's threads cannot post messages. Null with the single-thread build, which posts.
 */
let sharedProgress = null;
function pollSharedProgress() {
  if (!sharedProgress) return null;
  const { buffer, ptr, stages } = sharedProgress;
  const counters = new BigUint64Array(buffer, ptr, 3);
  return setInterval(() => {
    if (!state.running) return;
    const [stage, done, total] = [0, 1, 2].map((k) => Number(Atomics.load(counters, k)));
    if (total > 0) showProgress(stages[stage] ?? '', done, total);
  }, 100);
}

async function runEvaluation() {
  showError('');
  if (state.picking) $('pick').click();
  state.running = true;
  setRunNote('');
  showProgress('starting', 0, 1);
  const poll = pollSharedProgress();
  try {
    const r = await call('evaluate', { options: options() });
    r.report = JSON.parse(r.reportJson);
    state.result = r;
    document.querySelector('input[name=view][value=after]').checked = true;
    $('clip').value = r.clip;
    showResults(r);
    refreshPoints();
    viewer.setCoverage(r.samplePoints, r.sampleLabels);
    drawCameras(viewer, r.cameras);
    showCameraScale(r.cameras);
    $('show-coverage').disabled = !r.sampleLabels;
    $('show-coverage').checked = !!r.sampleLabels;
    viewer.setVisible('coverage', $('show-coverage').checked);
    document.body.dataset.evaluated = String(Number(document.body.dataset.evaluated || 0) + 1);
    setRunNote(`Done in ${(r.ms / 1000).toFixed(1)} s: results on the right.`);
  } catch (e) {
    if (e instanceof Cancelled) {
      // the worker that held the previous evaluation is gone: its downloads with it
      markStale('the last evaluation was cancelled (downloads need a new run)');
    } else {
      showError(`evaluation failed: ${e.message}`, 'run');
      setRunNote('✗ The evaluation failed: see the message at the top.', true);
    }
  } finally {
    if (poll) clearInterval(poll);
    state.running = false;
    hideProgress();
    updateRunButton();
  }
}
$('run').onclick = runEvaluation;
/** Cancel: stops the worker mid-run, then reloads the inputs into a fresh one. */
$('cancel').onclick = async () => {
  if (!state.running || state.restoring) return;
  state.restoring = true;
  setRunNote('Cancelling: restarting the core and reloading the inputs…');
  try {
    await restartWorker();
    setRunNote('Evaluation cancelled.');
  } catch (e) {
    showError(`could not reload the inputs after cancelling: ${e.message}; load them again`);
    setRunNote('✗ Cancelled, but the inputs could not be reloaded.', true);
  } finally {
    state.restoring = false;
    updateRunButton();
    document.body.dataset.cancelled = String(Number(document.body.dataset.cancelled || 0) + 1);
    if (!$('run').disabled) $('run').focus();
  }
};

function statRow(label, st, extra) {
  const cells = [st.count, g(st.mean), g(st.median), g(st.rms), g(st.std), g(st.percentiles.p90), g(st.percentiles.p99), g(st.max)];
  return `<tr data-row="${label}"><th>${label}</th>${cells.map((c, i) => `<td data-k="${['count', 'mean', 'median', 'rms', 'std', 'p90', 'p99', 'max'][i]}">${c}</td>`).join('')}<td class="muted">${esc(extra)}</td></tr>`;
}
function showResults(r) {
  const rep = r.report;
  state.shownResult = true;
  clearStale();
  const i = rep.inputs;
  const c = rep.crop;
  const a = rep.alignment;
  let h = `<div class="line">${esc(i.reconstruction.name)} (${esc(i.reconstruction.format)}, ${i.reconstruction.points} points) vs ${esc(i.ground_truth.name)} (${esc(i.ground_truth.format)}, ${i.ground_truth.vertices} vertices, ${i.ground_truth.triangles} triangles, bbox diagonal <span id="diag">${g(i.ground_truth.diagonal)}</span>) — ${r.ms.toFixed(0)} ms</div>`;
  h += `<div class="line">crop <b>${esc(c.kind)}</b>: kept <b id="r-kept">${c.kept}</b>, discarded <span id="r-discarded">${c.discarded}</span> (outside volume ${c.discarded_outside_volume}, farther than max distance ${c.discarded_farther_than_max_distance})</div>`;
  h += `<div class="line">alignment <b id="r-align">${esc(a.method)}</b> (scale <span id="r-scale">${g(a.scale)}</span>${a.rmse != null ? `, rmse ${g(a.rmse)}` : ''})</div>`;
  h += '<table id="stats"><tr><td></td><th>count</th><th>mean</th><th>median</th><th>rms</th><th>std</th><th>p90</th><th>p99</th><th>max</th><th class="muted">notes</th></tr>';
  h += statRow('accuracy', rep.accuracy, `recon → GT, ${rep.accuracy.metric}`);
  h += statRow('completeness', rep.completeness, `GT → recon, ${rep.completeness.samples} samples`);
  if (rep.accuracy.signed) h += statRow('signed', rep.accuracy.signed, 'signed accuracy');
  const cv = rep.completeness_visible;
  if (cv) h += statRow('completeness_visible', cv, `GT → recon, ${cv.visible_samples} of ${cv.samples} samples seen by ≥ ${cv.min_views} images`);
  const te = rep.track_error;
  if (te && te.count) h += statRow('track_error', te, `true error through ${te.measured} of ${te.points} tracks`);
  const vis = cv ? new Map(cv.thresholds.map((t) => [t.tau, t])) : null;
  const sl = te ? new Map(te.thresholds.map((t) => [t.tau, t])) : null;
  h += `</table><table id="thresholds"><tr><th>tau</th><th>% diag</th><th>precision</th><th>recall</th><th>F-score</th>${vis ? '<th>recall (visible)</th><th>F (visible)</th>' : ''}${sl ? '<th>sliding</th>' : ''}</tr>`;
  for (const t of rep.thresholds) {
    const v = vis && vis.get(t.tau);
    const s = sl && sl.get(t.tau);
    h += `<tr><td>${g(t.tau)}</td><td>${t.tau_percent_of_diagonal.toFixed(3)}</td><td>${t.precision.toFixed(4)}</td><td>${t.recall.toFixed(4)}</td><td>${t.f_score.toFixed(4)}</td>`
      + `${vis ? `<td data-k="recall_visible">${v ? v.recall_visible.toFixed(4) : '—'}</td><td>${v ? v.f_score_visible.toFixed(4) : '—'}</td>` : ''}${sl ? `<td data-k="sliding">${s ? s.sliding_fraction.toFixed(4) : '—'}</td>` : ''}</tr>`;
  }
  h += '</table>';
  if (cv) h += `<div class="line" id="r-visible">visible surface: <b id="r-visible-fraction">${(100 * cv.visible_fraction).toFixed(2)} %</b> of the ground truth (seen by ≥ ${cv.min_views} of ${cv.views} images); coverage colours at τ = ${g(cv.labels_tau)}</div>`;
  if (rep.cameras) {
    const cams = Object.entries(rep.cameras).filter(([, v]) => typeof v === 'number').map(([k, v]) => `${esc(k)} ${Number.isInteger(v) ? v : g(v)}`);
    h += `<div class="line" id="r-cameras">cameras: ${cams.join(', ')}</div>`;
  }
  for (const n of reportNotes(rep)) h += `<div class="${n.level}" data-code="${esc(n.code)}">${n.html}</div>`;
  $('summary').innerHTML = h;
  showStages(rep);
  for (const b of ['dl-report', 'dl-ply', 'dl-csv']) $(b).disabled = false;
  // the curves and the τ slider read the sorted distances (sorted by the worker; a NaN
  // completeness distance, last, is never below τ and counts as missed)
  r.compTotal = r.completeness.length;
  r.tauMax = Math.max(rep.accuracy.percentiles.p95, rep.completeness.percentiles.p95, ...rep.thresholds.map((t) => t.tau)) * 1.5 || 1;
  histogramPlot($('hist'), rep.accuracy.histogram);
  state.curves = curvesPlot($('pr'), r);
  updateTau();
  drawColorbar(r.clip);
}

// share strictly below tau in a sorted array (the core's share_below)
function below(sorted, tau, total) {
  let lo = 0, hi = sorted.length;
  while (lo < hi) { const mid = (lo + hi) >> 1; if (sorted[mid] < tau) lo = mid + 1; else hi = mid; }
  return total ? lo / total : 0;
}
export function prAt(r, tau) {
  const p = below(r.sortedKept, tau, r.sortedKept.length);
  const rc = below(r.sortedComp, tau, r.compTotal);
  return [p, rc, p + rc > 0 ? 2 * p * rc / (p + rc) : 0];
}
function updateTau() {
  const r = state.result;
  if (!r) return;
  const tau = r.tauMax * Number($('tau-slider').value) / 1000;
  const [p, rc, f] = prAt(r, tau);
  $('tau-value').textContent = g(tau);
  $('tau-readout').textContent = `precision ${p.toFixed(4)}  recall ${rc.toFixed(4)}  F ${f.toFixed(4)}`;
  if (state.curves) state.curves.mark(tau);
}
$('tau-slider').addEventListener('input', updateTau);
$('tau-add').onclick = () => {
  const r = state.result;
  if (!r) return;
  const tau = r.tauMax * Number($('tau-slider').value) / 1000;
  if (!(tau > 0)) return;
  $('tau').value = [...numList($('tau').value), Number(tau.toPrecision(6))].join(',');
  // keep the relative defaults when only absolute thresholds would remain
  if (!$('tau-rel').value.trim()) $('tau-rel').value = '0.5,1,2';
};

// colours
function drawColorbar(clip) {
  const cv = $('colorbar-canvas');
  const ctx = cv.getContext('2d');
  const grad = ctx.createLinearGradient(0, 0, cv.width, 0);
  VIRIDIS.forEach((c, i) => grad.addColorStop(i / (VIRIDIS.length - 1), `rgb(${c[0]},${c[1]},${c[2]})`));
  ctx.fillStyle = grad;
  ctx.fillRect(0, 0, cv.width, cv.height);
  $('cb-hi').textContent = `≥ ${Number(clip.toPrecision(3))}`;
  $('cb-hi').title = `clip ${g(clip)}: this distance and larger are yellow`;
  $('colorbar').style.display = 'flex';
}
$('clip').addEventListener('change', async () => {
  const clip = Number($('clip').value);
  if (!state.result || !(clip > 0) || document.body.dataset.stale) return;
  const { colors } = await call('colors', { clip });
  state.result.colors = colors;
  state.result.clip = clip;
  drawColorbar(clip);
  refreshPoints();
});

// viewer options
$('point-size').addEventListener('input', (e) => viewer.setPointSize(Number(e.target.value)));
$('show-gt').addEventListener('change', (e) => viewer.setVisible('gt', e.target.checked));
$('show-recon').addEventListener('change', (e) => viewer.setVisible('recon', e.target.checked));
$('show-coverage').addEventListener('change', (e) => viewer.setVisible('coverage', e.target.checked));
for (const [box, kind] of [['show-gt-cams', 'gtCams'], ['show-est-cams', 'estCams']]) {
  $(box).addEventListener('change', (e) => {
    viewer.setVisible(kind, e.target.checked);
    if (window.sfmevalViewer2) window.sfmevalViewer2.setVisible(kind, e.target.checked);
  });
}
$('fit-cams').onclick = () => viewer.fitCameras();
/** The estimated cameras' colour scale beside the points' colour bar. */
function showCameraScale(cams) {
  const el = $('cb-cams');
  el.hidden = !(cams && cams.estPoses);
  if (!el.hidden) el.textContent = `cameras: centre error 0 → ≥ ${Number(cams.camClip.toPrecision(3))} (same colours)`;
}
$('heat').addEventListener('change', refreshPoints);

// downloads
const stem = () => (state.result ? state.result.report.inputs.reconstruction.name.replace(/\.[^.]*$/, '') : 'sfmeval');
$('dl-report').onclick = () => download(`${stem()}.report.json`, state.result.reportJson, 'application/json');
$('dl-ply').onclick = async () => {
  const { bytes } = await call('coloredPly', { clip: state.result.clip });
  download(`${stem()}.errors.ply`, bytes, 'application/octet-stream');
};
$('dl-csv').onclick = async () => {
  const { text } = await call('csv');
  download(`${stem()}.distances.csv`, text, 'text/csv');
};

// ---- start ------------------------------------------------------------------------------
call('init', { threads: threadsParam }).then((m) => {
  sharedProgress = m.progress;
  $('version').textContent = `core ${m.version} · ${m.threads === 1 ? '1 thread' : `${m.threads} threads`}`;
  // threads wanted but off: say why (a static host must send the COOP/COEP headers)
  const note = $('threads-note');
  note.hidden = !m.threadsOff;
  if (m.threadsOff) {
    note.textContent = `single thread: ${m.threadsOff}`;
    note.title = 'Multi-threading needs a cross-origin isolated page (the server sends Cross-Origin-Opener-Policy: same-origin and Cross-Origin-Embedder-Policy: require-corp) and WebAssembly SIMD; scripts/serve.sh sends both headers.';
  }
  document.body.dataset.threads = String(m.threads);
  document.body.dataset.ready = '1';
}).catch((e) => showError(`could not load the WebAssembly core: ${e.message}`));
hideProgress();
showError('');
updateRunButton();
const compare = setupCompare({
  call, viewer, measureOptions: options, showError, download,
  gtName: () => (state.gt ? state.gt.name : null),
  setRunning: (b) => {
    if (b && (state.running || state.restoring)) return false;
    state.running = b;
    if (b) setRunNote('Comparing: progress below; Cancel stops it.');
    else { hideProgress(); if (!state.restoring) setRunNote(''); }
    updateRunButton();
    return true;
  },
});
// for tests and scripting
window.sfmeval = { compare, state, call, currentCrop, cropText, prAt, reportNotes, matrixText, alignedTransform };
