// Section 2, the alignment choice and what the viewer shows of the reconstruction: the points
// after the last evaluation, a given transform's preview or the raw cloud beside the ground
// truth, and the clicked point pairs.
import { $, ordinal, parseMatrixLoose, alignedTransform } from './util.js';
import { state, viewer } from './state.js';
import { scheduleKept } from './crop.js';

export const alignMethod = () => document.querySelector('input[name=align]:checked').value;
export const viewMode = () => document.querySelector('input[name=view]:checked').value;
$('file-transform').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (f) { $('transform').value = alignedTransform(await f.text()); document.querySelector('input[name=align][value=given]').checked = true; refreshPoints(); }
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

export function refreshPoints() {
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
export function updatePairs() {
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
