// Section 1, the inputs: reading picked or dropped files into the worker (ground truth,
// reconstruction, ground-truth cameras, depth maps), their info lines, and the demo.
import { $, esc, alignedTransform } from './util.js';
import { call, MSG } from './core.js';
import { state, sources, viewer } from './state.js';
import { showError, markStale, setBusy, hideProgress } from './ui.js';
import { refreshPoints, updatePairs } from './points.js';
import { scheduleKept, currentCrop } from './crop.js';
import { dropZone, entryFiles } from './files.js';

/** Reads dropped/picked files; a picked folder's files are keyed relative to that folder. */
const MAX_BYTES = 1.5e9; // wasm32 memory is 4 GB at most; inputs are copied into it
export async function readFiles(fileList) {
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
export function setInputInfo(kind, text, { error = false, notes } = {}) {
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
export function inputFailed(kind, e) {
  const label = INPUT_LABEL[kind];
  const msg = e.message.startsWith(label) ? e.message : `${label}: ${e.message}`;
  setInputInfo(kind, `✗ not loaded — ${e.message}`, { error: true, notes: [] });
  showError(msg, INPUT_CONTROLS[kind][0]);
}

/**
 * Resets what belonged to the earlier files: the ground-truth cameras, depth maps and crop. Called
 * when a ground truth replaces another (they described that one; cameras or depth maps loaded while
 * no ground truth was loaded are kept for the new one) and when the user's own ground truth or
 * reconstruction follows the demo (its cameras would otherwise align the user's images named like
 * the demo's, 0000.jpg…, and give wrong numbers). Says what was reset in one line under the input
 * `kind` (`data-reset` lists it: cameras, depth, crop) and returns that list.
 */
async function resetEarlier(kind, { afterDemo, hadGt = false }) {
  const reset = [];
  const earlier = (src) => src && ((afterDemo && src.demo) || src.gtGen > 0);
  if (earlier(sources.cams)) {
    await call(MSG.clearCameras);
    reset.push(['cams', `the ground-truth cameras '${state.camerasName}'`]);
    state.camerasName = null;
    sources.cams = null;
    setInputInfo('cams', '—');
  }
  if (earlier(sources.depth)) {
    await call(MSG.clearDepth);
    reset.push(['depth', `${state.depthCount} depth maps`]);
    state.depthCount = 0;
    sources.depth = null;
    setInputInfo('depth', '—');
  }
  const crop = currentCrop();
  if ((afterDemo || hadGt) && (crop.volume || crop.max_distance !== undefined)) {
    viewer.setCropKind('none');
    $('crop-kind').value = 'none';
    $('max-distance').value = '';
    reset.push(['crop', 'the crop']);
  }
  // what stays now belongs to the ground truth about to be loaded
  for (const src of [sources.cams, sources.depth]) if (src) src.gtGen = 0;
  if (reset.length) {
    const words = reset.map(([, w]) => w);
    const list = words.length > 1 ? `${words.slice(0, -1).join(', ')} and ${words[words.length - 1]}` : words[0];
    const line = document.createElement('div');
    line.className = 'info';
    line.dataset.reset = reset.map(([k]) => k).join(',');
    line.textContent = `reset: ${list}, which belonged to the ${afterDemo ? "demo's files" : 'earlier ground truth'}`;
    $(`notes-${kind}`).appendChild(line);
  }
  return reset.map(([k]) => k);
}

async function loadGt(fileList, { demo = false } = {}) {
  showError('');
  setBusy(true);
  setInputInfo('gt', 'reading…');
  try {
    const { files, transfer } = await readFiles(fileList);
    const maxTriangles = Number($('max-triangles').value) || undefined;
    const gt = await call(MSG.loadGt, { files, maxTriangles }, transfer);
    const afterDemo = state.demoLoaded && !demo;
    const hadGt = (state.gtGen || 0) > 0;
    state.gtGen = (state.gtGen || 0) + 1;
    state.demoLoaded = false;
    state.gtFromDemo = demo;
    state.gt = gt;
    sources.gt = { files: Array.from(fileList) };
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    viewer.setGroundTruth(gt.vertices, gt.triangles, gt.bounds);
    setInputInfo('gt', `${gt.name} (${gt.format}): ${gt.vertexCount} vertices, ${gt.triangleCount} triangles`, { notes: gt.warnings });
    viewer.framedCameras = false;
    await resetEarlier('gt', { afterDemo, hadGt });
    markStale(`the ground truth is now '${gt.name}'`, { comparison: true });
    refreshPoints();
    return true;
  } catch (e) {
    state.gt = null;
    sources.gt = null;
    state.result = null;
    viewer.setCoverage(null);
    viewer.clearGroundTruth();
    inputFailed('gt', e);
    markStale('the ground truth failed to load', { comparison: true });
    refreshPoints();
    return false;
  } finally { setBusy(false); }
}

async function loadRecon(fileList, name, { demo = false } = {}) {
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
        r = await call(MSG.loadRecon, { file: single, name });
      } finally { hideProgress(); }
    } else {
      const { files, transfer, folder } = await readFiles(fileList);
      const names = Object.keys(files);
      // The report names a reconstruction as the CLI does: the file, or the model's folder.
      if (!name) name = folder ?? (names.length === 1 ? names[0] : 'model');
      r = await call(MSG.loadRecon, { files, name }, transfer);
    }
    const afterDemo = state.demoLoaded && !demo;
    state.demoLoaded = false;
    state.recon = r;
    sources.recon = { files: Array.from(fileList), name };
    state.beside = null;
    state.result = null;
    viewer.setCoverage(null);
    state.pairs = [];
    updatePairs();
    setInputInfo('recon', `${r.name} (${r.format}): ${r.count} points${r.images ? `, ${r.images} images` : ''}`, { notes: r.warnings });
    if (afterDemo) await resetEarlier('recon', { afterDemo });
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

async function loadCams(fileList, { demo = false } = {}) {
  showError('');
  setBusy(true);
  try {
    const { files, transfer } = await readFiles(fileList);
    const c = await call(MSG.loadCameras, { files }, transfer);
    state.camerasName = Object.keys(files)[0];
    sources.cams = { files: Array.from(fileList), gtGen: loadedWith(), demo };
    setInputInfo('cams', `${state.camerasName}: ${c.images} images`);
    markStale(`the ground-truth cameras are now '${state.camerasName}'`, { comparison: true });
    return true;
  } catch (e) {
    // nothing half-loaded: the page and the worker both have no cameras now
    state.camerasName = null;
    sources.cams = null;
    await call(MSG.clearCameras).catch(() => {});
    inputFailed('cams', e);
    markStale('the ground-truth cameras failed to load', { comparison: true });
    return false;
  } finally { setBusy(false); }
}

/**
 * The ground truth cameras or depth maps loaded now belong to (its load's number), 0 for none: a
 * later ground truth resets them. Not the demo's ground truth once the user's own files follow it
 * (they are loaded for the user's coming ground truth).
 */
const loadedWith = () => (state.gt && !(state.gtFromDemo && !state.demoLoaded) ? state.gtGen : 0);

async function loadDepth(fileList) {
  showError('');
  const npy = Array.from(fileList).filter((f) => /\.npy$/i.test(f.name));
  if (!npy.length) { inputFailed('depth', new Error('no .npy file among the dropped files')); return; }
  setBusy(true);
  setInputInfo('depth', 'reading…');
  try {
    const { files, transfer } = await readFiles(npy);
    const d = await call(MSG.loadDepth, { files }, transfer);
    state.depthCount = d.count;
    sources.depth = { files: npy, gtGen: loadedWith() };
    setInputInfo('depth', `${d.count} depth maps${d.checked ? '' : ' (checked against cameras.json when evaluating)'}`);
    markStale(`${d.count} depth maps were loaded`, { comparison: true });
  } catch (e) {
    state.depthCount = 0;
    sources.depth = null;
    await call(MSG.clearDepth).catch(() => {});
    inputFailed('depth', e);
    markStale('the depth maps failed to load', { comparison: true });
  } finally { setBusy(false); }
}

/** Loads the inputs again from their files into a fresh worker (after a cancel). */
export async function reloadInputs() {
  const reload = async (type, src, extra = {}) => {
    if (!src) return;
    const { files, transfer } = await readFiles(src.files);
    await call(type, { files, ...extra }, transfer);
  };
  await reload(MSG.loadGt, sources.gt, { maxTriangles: Number($('max-triangles').value) || undefined });
  const single = sources.recon && sources.recon.files.length === 1 && !sources.recon.files[0].webkitRelativePath
    && /\.ply$/i.test(sources.recon.files[0].name) ? sources.recon.files[0] : null;
  if (single) await call(MSG.loadRecon, { file: single, name: sources.recon.name });
  else await reload(MSG.loadRecon, sources.recon, { name: sources.recon && sources.recon.name });
  await reload(MSG.loadCameras, sources.cams);
  await reload(MSG.loadDepth, sources.depth);
}

$('dir-recon').addEventListener('change', (e) => handleFiles('recon', e.target.files));
$('dir-depth').addEventListener('change', (e) => handleFiles('depth', e.target.files));
for (const [kind, input] of [['recon', 'file-recon'], ['gt', 'file-gt'], ['cams', 'file-cams'], ['depth', 'file-depth']]) {
  $(input).addEventListener('change', (e) => handleFiles(kind, e.target.files));
  dropZone($(`drop-${kind}`), async (entries, files) => {
    if ((kind === 'recon' || kind === 'depth') && entries.length === 1 && entries[0].isDirectory) {
      try { handleFiles(kind, await folderFiles(kind, entries[0])); } catch (err) { inputFailed(kind, err); }
    } else {
      handleFiles(kind, files);
    }
  });
}
/**
 * The model files (the core's rule, `isModelFile`) or the depth maps (`.npy`) under a dropped
 * folder, with webkitRelativePath-like names.
 */
async function folderFiles(kind, dir) {
  const files = await entryFiles(dir);
  if (kind === 'depth') return files.filter((f) => /\.npy$/i.test(f.name));
  const { paths } = await call(MSG.modelFiles, { paths: files.map((f) => f.webkitRelativePath) });
  const keep = new Set(paths);
  return files.filter((f) => keep.has(f.webkitRelativePath));
}

function handleFiles(kind, files) {
  if (!files || !files.length) return;
  const p = kind === 'gt' ? loadGt(files) : kind === 'recon' ? loadRecon(files) : kind === 'depth' ? loadDepth(files) : loadCams(files);
  p.catch((e) => inputFailed(kind, e));
}
$('clear-cams').onclick = async () => {
  await call(MSG.clearCameras);
  const had = !!sources.cams;
  state.camerasName = null;
  sources.cams = null;
  setInputInfo('cams', '—');
  if (had) markStale('the ground-truth cameras were cleared', { comparison: true });
};
$('clear-depth').onclick = async () => {
  await call(MSG.clearDepth);
  const had = !!sources.depth;
  state.depthCount = 0;
  sources.depth = null;
  setInputInfo('depth', '—');
  if (had) markStale('the depth maps were cleared', { comparison: true });
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
    if (!await loadGt(gtFiles, { demo: true }) || !await loadRecon(reconFiles, m.reconstruction_name, { demo: true })) return;
    if (m.gt_cameras) {
      if (!await loadCams([await fetchFile(m.gt_cameras)], { demo: true })) return;
    } else {
      await $('clear-cams').onclick();
    }
    // the next ground truth or reconstruction of the user's own resets what came with the demo
    state.demoLoaded = true;
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
