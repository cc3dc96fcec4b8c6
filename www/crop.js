// Section 3, the crop: the volume and max distance as the core's crop file, and the live
// preview of the kept count (the core's rules; the report's count is authoritative).
import { $, download } from './util.js';
import { call, MSG } from './core.js';
import { state, viewer } from './state.js';
import { showError } from './ui.js';
import { viewMode } from './points.js';

export function currentCrop() {
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
export function scheduleKept() {
  // whoever measured with the crop (Compare) checks whether it changed
  document.dispatchEvent(new Event('sfmeval-crop-change'));
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
viewer.onCropChange = () => scheduleKept();
$('crop-kind').onchange = () => {
  viewer.setCropKind($('crop-kind').value);
  if (state.gt) viewer.fitCrop(state.gt.bounds);
  viewer.setGizmoMode($('gizmo-mode').value);
  scheduleKept();
};
$('gizmo-mode').onchange = () => viewer.setGizmoMode($('gizmo-mode').value);
$('crop-fit').onclick = () => { if (state.gt) viewer.fitCrop(state.gt.bounds); scheduleKept(); };
$('max-distance').addEventListener('input', scheduleKept);
/** The crop as the core writes its file (`sfmeval.crop/1`). */
export async function cropText() {
  return (await call(MSG.cropFile, { crop: currentCrop() })).text;
}
$('crop-export').onclick = async () => {
  try { download('crop.json', await cropText(), 'application/json'); } catch (e) { showError(e.message); }
};
$('dl-crop').onclick = $('crop-export').onclick;
$('crop-import').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  try {
    const { crop } = await call(MSG.parseCrop, { text: await f.text() });
    $('crop-kind').value = viewer.setCropVolume(crop.volume);
    $('max-distance').value = crop.max_distance ?? '';
    scheduleKept();
  } catch (err) { showError(`crop file '${f.name}': ${err.message}`, 'crop-import'); }
  e.target.value = '';
});
