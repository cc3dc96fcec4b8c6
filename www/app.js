// The page: inputs, alignment, crop, evaluation in a worker, results and downloads.
import { Viewer } from './viewer.js';
import { histogramPlot, curvesPlot, VIRIDIS } from './plots.js';

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
};

// ---- worker ----------------------------------------------------------------------------
const worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
let nextId = 1;
const pending = new Map();
worker.onmessage = (ev) => {
  const m = ev.data;
  if (m.type === 'progress') { showProgress(m.stage, m.done, m.total); return; }
  const p = pending.get(m.id);
  if (!p) return;
  pending.delete(m.id);
  if (m.ok) p.resolve(m); else p.reject(new Error(m.error));
  if (m.fatal) document.body.dataset.fatal = '1';
};
worker.onerror = (e) => { showError(`worker failed: ${e.message || 'unknown error'}`); };
function call(type, payload = {}, transfer = []) {
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    worker.postMessage({ id, type, ...payload }, transfer);
  });
}

// ---- UI helpers ------------------------------------------------------------------------
function showError(msg) {
  $('error').textContent = msg;
  $('error').style.display = msg ? 'block' : 'none';
}
function showProgress(stage, done, total) {
  const frac = total > 0 ? done / total : 0;
  $('progress').style.display = 'block';
  $('progress-bar').style.width = `${(100 * frac).toFixed(1)}%`;
  $('progress-text').textContent = stage ? `${stage} ${total > 1 ? `${done}/${total}` : ''}` : '';
}
function hideProgress() { $('progress').style.display = 'none'; }
function setBusy(b) {
  document.body.classList.toggle('busy', b);
  $('run').disabled = b || !(state.gt && state.recon);
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

async function loadGt(fileList) {
  showError('');
  const { files, transfer } = await readFiles(fileList);
  setBusy(true);
  $('info-gt').textContent = 'reading…';
  try {
    const gt = await call('loadGt', { files }, transfer);
    state.gt = gt;
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    viewer.setGroundTruth(gt.vertices, gt.triangles, gt.bounds);
    $('info-gt').textContent = `${gt.name} (${gt.format}): ${gt.vertexCount} vertices, ${gt.triangleCount} triangles`;
    showWarnings(gt.warnings);
    refreshPoints();
  } catch (e) {
    state.gt = null;
    $('info-gt').textContent = '—';
    showError(e.message);
  } finally { setBusy(false); }
}

async function loadRecon(fileList, name) {
  showError('');
  const { files, transfer, folder } = await readFiles(fileList);
  const names = Object.keys(files);
  // The report names a reconstruction as the CLI does: the file, or the model's folder.
  if (!name) name = folder ?? (names.length === 1 ? names[0] : 'model');
  setBusy(true);
  $('info-recon').textContent = 'reading…';
  try {
    const r = await call('loadRecon', { files, name }, transfer);
    state.recon = r;
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    state.pairs = [];
    updatePairs();
    $('info-recon').textContent = `${r.name} (${r.format}): ${r.count} points${r.images ? `, ${r.images} images` : ''}`;
    showWarnings(r.warnings);
    refreshPoints();
  } catch (e) {
    state.recon = null;
    $('info-recon').textContent = '—';
    showError(e.message);
  } finally { setBusy(false); }
}

async function loadCams(fileList) {
  showError('');
  const { files, transfer } = await readFiles(fileList);
  try {
    const c = await call('loadCameras', { files }, transfer);
    state.camerasName = Object.keys(files)[0];
    $('info-cams').textContent = `${state.camerasName}: ${c.images} images`;
  } catch (e) {
    $('info-cams').textContent = '—';
    showError(e.message);
  }
}

async function loadDepth(fileList) {
  showError('');
  const npy = Array.from(fileList).filter((f) => /\.npy$/i.test(f.name));
  if (!npy.length) { showError('depth maps: no .npy file among the dropped files'); return; }
  const { files, transfer } = await readFiles(npy);
  $('info-depth').textContent = 'reading…';
  try {
    const d = await call('loadDepth', { files }, transfer);
    state.depthCount = d.count;
    $('info-depth').textContent = `${d.count} depth maps${d.checked ? '' : ' (checked against cameras.json when evaluating)'}`;
  } catch (e) {
    state.depthCount = 0;
    await call('clearDepth');
    $('info-depth').textContent = '—';
    showError(e.message);
  }
}

function showWarnings(list) {
  $('warnings').innerHTML = (list || []).map((w) => `<div class="warn">warning: ${esc(w)}</div>`).join('');
}

$('dir-recon').addEventListener('change', (e) => handleFiles('recon', e.target.files));
$('dir-depth').addEventListener('change', (e) => handleFiles('depth', e.target.files));
for (const [kind, input] of [['recon', 'file-recon'], ['gt', 'file-gt'], ['cams', 'file-cams'], ['depth', 'file-depth']]) {
  $(input).addEventListener('change', (e) => handleFiles(kind, e.target.files));
  const zone = $(`drop-${kind}`);
  zone.addEventListener('dragover', (e) => { e.preventDefault(); zone.classList.add('over'); });
  zone.addEventListener('dragleave', () => zone.classList.remove('over'));
  zone.addEventListener('drop', async (e) => {
    e.preventDefault();
    zone.classList.remove('over');
    const entries = Array.from(e.dataTransfer.items || []).map((i) => i.webkitGetAsEntry && i.webkitGetAsEntry()).filter(Boolean);
    if ((kind === 'recon' || kind === 'depth') && entries.length === 1 && entries[0].isDirectory) {
      try { handleFiles(kind, await folderFiles(entries[0])); } catch (err) { showError(err.message); }
    } else {
      handleFiles(kind, e.dataTransfer.files);
    }
  });
}
/** The files under a dropped folder, with webkitRelativePath-like names. */
async function folderFiles(dir) {
  const out = [];
  const walk = async (entry, path) => {
    if (entry.isFile) {
      const f = await new Promise((res, rej) => entry.file(res, rej));
      out.push(new File([f], f.name));
      Object.defineProperty(out[out.length - 1], 'webkitRelativePath', { value: `${path}${f.name}` });
    } else if (entry.isDirectory) {
      const reader = entry.createReader();
      for (;;) {
        const batch = await new Promise((res, rej) => reader.readEntries(res, rej));
        if (!batch.length) break;
        for (const c of batch) await walk(c, `${path}${entry.name}/`.replace(/^\//, ''));
      }
    }
  };
  const reader = dir.createReader();
  for (;;) {
    const batch = await new Promise((res, rej) => reader.readEntries(res, rej));
    if (!batch.length) break;
    for (const c of batch) await walk(c, `${dir.name}/`);
  }
  return out.filter((f) => /\.(bin|txt|nvm|out|json|ply|npy)$/i.test(f.name));
}

function handleFiles(kind, files) {
  if (!files || !files.length) return;
  const p = kind === 'gt' ? loadGt(files) : kind === 'recon' ? loadRecon(files) : kind === 'depth' ? loadDepth(files) : loadCams(files);
  p.catch((e) => showError(e.message));
}
$('clear-cams').onclick = async () => { await call('clearCameras'); state.camerasName = null; $('info-cams').textContent = '—'; };
$('clear-depth').onclick = async () => { await call('clearDepth'); state.depthCount = 0; $('info-depth').textContent = '—'; };

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
    await loadGt(gtFiles);
    await loadRecon(reconFiles, m.reconstruction_name);
    if (m.gt_cameras) await loadCams([await fetchFile(m.gt_cameras)]);
    else await $('clear-cams').onclick();
    if (m.transform) {
      const t = await (await fetchFile(m.transform)).text();
      $('transform').value = t;
      document.querySelector('input[name=align][value=given]').checked = true;
    } else {
      document.querySelector(`input[name=align][value="${m.align ?? 'auto'}"]`).checked = true;
    }
    refreshPoints();
  } catch (e) { showError(e.message); }
};

// ---- alignment --------------------------------------------------------------------------
const alignMethod = () => document.querySelector('input[name=align]:checked').value;
const viewMode = () => document.querySelector('input[name=view]:checked').value;
$('file-transform').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (f) { $('transform').value = await f.text(); document.querySelector('input[name=align][value=given]').checked = true; refreshPoints(); }
});
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

function refreshPoints() {
  const pos = displayedPositions();
  if (!pos) return;
  const f32 = new Float32Array(pos);
  let colors = null;
  const useHeat = state.result && $('heat').checked && viewMode() === 'after' && !state.picking;
  if (useHeat) colors = state.result.colors;
  else if (state.recon.colors) colors = state.recon.colors;
  viewer.setPoints(f32, colors);
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
  const rows = (a.stages || []).map((s) => `<tr><td>${esc(s.method)}</td><td>${g(s.scale)}</td><td>${s.rmse == null ? '—' : g(s.rmse)}</td><td>${s.inlier_ratio == null ? '—' : s.inlier_ratio.toFixed(4)}</td><td>${s.iterations}</td><td>${s.converged ? 'yes' : 'no'}</td></tr>`).join('');
  const m = a.gt_from_recon.map((r) => r.map((v) => g(v)).join(' ')).join('\n');
  $('stages').innerHTML = `<tr><th>stage</th><th>scale</th><th>rmse</th><th>inliers</th><th>iter</th><th>conv.</th></tr>${rows}
    <tr><td colspan="6"><pre id="matrix" title="gt_from_recon">${esc(m)}</pre></td></tr>`;
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
function contains(v, x, y, z) {
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
  } catch (err) { showError(`crop file '${f.name}': ${err.message}`); }
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

async function runEvaluation() {
  showError('');
  if (state.picking) $('pick').click();
  setBusy(true);
  showProgress('starting', 0, 1);
  try {
    const r = await call('evaluate', { options: options() });
    r.report = JSON.parse(r.reportJson);
    state.result = r;
    document.querySelector('input[name=view][value=after]').checked = true;
    $('clip').value = r.clip;
    showResults(r);
    refreshPoints();
    viewer.setCoverage(r.samplePoints, r.sampleLabels);
    $('show-coverage').disabled = !r.sampleLabels;
    $('show-coverage').checked = !!r.sampleLabels;
    viewer.setVisible('coverage', $('show-coverage').checked);
    document.body.dataset.evaluated = String(Number(document.body.dataset.evaluated || 0) + 1);
  } catch (e) {
    showError(e.message);
  } finally {
    hideProgress();
    setBusy(false);
  }
}
$('run').onclick = runEvaluation;

function statRow(label, st, extra) {
  const cells = [st.count, g(st.mean), g(st.median), g(st.rms), g(st.std), g(st.percentiles.p90), g(st.percentiles.p99), g(st.max)];
  return `<tr data-row="${label}"><th>${label}</th>${cells.map((c, i) => `<td data-k="${['count', 'mean', 'median', 'rms', 'std', 'p90', 'p99', 'max'][i]}">${c}</td>`).join('')}<td class="muted">${esc(extra)}</td></tr>`;
}
function showResults(r) {
  const rep = r.report;
  const i = rep.inputs;
  const c = rep.crop;
  const a = rep.alignment;
  let h = `<div class="line">${esc(i.reconstruction.name)} (${esc(i.reconstruction.format)}, ${i.reconstruction.points} points) vs ${esc(i.ground_truth.name)} (${esc(i.ground_truth.format)}, ${i.ground_truth.vertices} vertices, ${i.ground_truth.triangles} triangles, bbox diagonal <span id="diag">${g(i.ground_truth.diagonal)}</span>) — ${r.ms.toFixed(0)} ms</div>`;
  h += `<div class="line">crop <b>${esc(c.kind)}</b>: kept <b id="r-kept">${c.kept}</b>, discarded <span id="r-discarded">${c.discarded}</span> (outside volume ${c.discarded_outside_volume}, farther than max distance ${c.discarded_farther_than_max_distance})</div>`;
  h += `<div class="line">alignment <b id="r-align">${esc(a.method)}</b> (scale <span id="r-scale">${g(a.scale)}</span>${a.rmse != null ? `, rmse ${g(a.rmse)}` : ''})</div>`;
  h += '<table id="stats"><tr><th></th><th>count</th><th>mean</th><th>median</th><th>rms</th><th>std</th><th>p90</th><th>p99</th><th>max</th><th></th></tr>';
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
  for (const w of rep.warnings) h += `<div class="warn">warning: ${esc(w)}</div>`;
  $('summary').innerHTML = h;
  showStages(rep);
  for (const b of ['dl-report', 'dl-ply', 'dl-csv']) $(b).disabled = false;
  // sorted distances for the curves and the τ slider
  const kept = [];
  for (let k = 0; k < r.distances.length; k++) if (r.status[k] === 0) kept.push(r.distances[k]);
  r.sortedKept = Float64Array.from(kept).sort();
  r.sortedComp = Float64Array.from(r.completeness.filter(Number.isFinite)).sort();
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
  $('cb-hi').textContent = `≥ ${g(clip)}`;
  $('colorbar').style.display = 'flex';
}
$('clip').addEventListener('change', async () => {
  const clip = Number($('clip').value);
  if (!state.result || !(clip > 0)) return;
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
call('init').then((m) => {
  $('version').textContent = `core ${m.version}`;
  document.body.dataset.ready = '1';
}).catch((e) => showError(`could not load the WebAssembly core: ${e.message}`));
hideProgress();
showError('');
// for tests and scripting
window.sfmeval = { state, call, currentCrop, cropText, prAt };
