// Compare: several reconstructions against the one loaded ground truth (indexed once in the
// worker). A runner `runs/` folder (`<dataset>/<pipeline>/run.json` or `<pipeline>/run.json`)
// becomes one row per run, evaluated as `sfmeval-runner report` evaluates it (`auto` alignment,
// the Measure section's τ, samples and seed); loose files and model folders become one row
// each. The table, its exports (the runner's own table text, from the same Rust code), the
// overlaid P/R/F curves and the viewers' choice of reconstruction live here.
import uPlot from 'uplot';
import { Viewer } from './viewer.js';
import { dropZone, entryFiles } from './files.js';
import { $, esc } from './util.js';
import { MSG } from './core.js';
import { clearComparisonStale, markComparisonStale } from './ui.js';

/** A COLMAP model's files: together they are one model (as the Reconstruction input reads them). */
const COLMAP_FILE = /^(cameras|images|points3D|rigs|frames)\.(txt|bin)$/i;

/**
 * Groups picked or dropped files (with `webkitRelativePath`-like names) into the items to
 * compare: `{pipeline, runJson (File|null), files: {relName: File}, path}`. A folder holding
 * `run.json` files is a runs folder: each run folder is one item named by its pipeline, with
 * the files `runFiles(paths)` (the core's run-folder layout, as the runner reads it: `model/`,
 * else `sparse.ply`) picks from the folder's paths. Otherwise each folder's COLMAP files
 * (cameras/images/points3D .txt or .bin) are one model named by that folder (`model` for loose
 * files, as the Reconstruction input names them), and every other model file (PLY, NVM, Bundler
 * .out, sfm_data.json) is one item named by the file; a name that repeats is prefixed by the
 * file's own folder. Which files are model files is the core's rule: `modelFiles(paths)` gives
 * those of `paths` that are.
 */
export async function groupItems(fileList, runFiles, modelFiles) {
  const files = Array.from(fileList).map((f) => ({ f, path: (f.webkitRelativePath || f.name).replace(/^\/+/, '') }));
  const runs = files.filter((x) => x.path.split('/').pop() === 'run.json' && x.path.includes('/'));
  const items = [];
  if (runs.length) {
    for (const r of runs) {
      const dir = r.path.slice(0, -'run.json'.length); // ends with '/'
      const inRun = files.filter((x) => x.path.startsWith(dir) && x.path !== r.path);
      const byRel = new Map(inRun.map((x) => [x.path.slice(dir.length), x.f]));
      const model = Object.fromEntries((await runFiles([...byRel.keys()])).map(([p, name]) => [name, byRel.get(p)]));
      const parts = dir.split('/').filter(Boolean);
      items.push({ pipeline: parts[parts.length - 1], runJson: r.f, files: model, path: dir });
    }
  } else {
    // by each file's own folder ('' for loose files)
    const byFolder = new Map();
    const models = new Set(await modelFiles(files.map((x) => x.path)));
    for (const x of files) {
      const cut = x.path.lastIndexOf('/');
      const dir = cut < 0 ? '' : x.path.slice(0, cut);
      const name = x.path.slice(cut + 1);
      if (!models.has(x.path)) continue;
      if (!byFolder.has(dir)) byFolder.set(dir, []);
      byFolder.get(dir).push({ name, f: x.f });
    }
    for (const [dir, list] of byFolder) {
      // COLMAP's sub-models sit in numbered folders (sparse/0): those keep their parent's name
      const parts = dir ? dir.split('/') : [];
      const folderName = parts.length > 1 && /^\d+$/.test(parts[parts.length - 1]) ? parts.slice(-2).join('/') : parts.pop() || '';
      const colmap = list.filter((x) => COLMAP_FILE.test(x.name));
      if (colmap.length) {
        items.push({ pipeline: folderName || 'model', folder: dir, runJson: null, files: Object.fromEntries(colmap.map((x) => [x.name, x.f])), path: dir ? `${dir}/` : 'model/' });
      }
      for (const x of list.filter((y) => !COLMAP_FILE.test(y.name))) {
        items.push({ pipeline: x.name, folder: dir, runJson: null, files: { [x.name]: x.f }, path: dir ? `${dir}/${x.name}` : x.name });
      }
    }
    // a name that repeats (two folders' sfm_data.json, two folders called sparse) gets its folder
    const count = new Map();
    for (const it of items) count.set(it.pipeline, (count.get(it.pipeline) || 0) + 1);
    for (const it of items) {
      if (count.get(it.pipeline) > 1 && it.folder) {
        const parts = it.folder.split('/');
        it.pipeline = it.files[it.pipeline] ? `${parts[parts.length - 1]}/${it.pipeline}` : parts.slice(-2).join('/');
      }
    }
    for (const it of items) delete it.folder;
  }
  items.sort((a, b) => (a.path < b.path ? -1 : a.path > b.path ? 1 : 0));
  return items;
}

/** Draws the P/R/F curves of every entry over one τ axis; returns the uPlot. */
function curves(el, entries) {
  const ok = entries.filter((e) => e.kept);
  el.innerHTML = '';
  if (!ok.length) return null;
  const tauMax = Math.max(...ok.map((e) => Math.max(...e.report.thresholds.map((t) => t.tau)))) * 1.5 || 1;
  const n = 200;
  const xs = [];
  const below = (s, tau, total) => {
    let lo = 0, hi = s.length;
    while (lo < hi) { const m = (lo + hi) >> 1; if (s[m] < tau) lo = m + 1; else hi = m; }
    return total ? lo / total : 0;
  };
  for (let i = 0; i <= n; i++) xs.push((tauMax * i) / n);
  const data = [xs];
  const series = [{ label: 'τ' }];
  ok.forEach((e, j) => {
    const hue = Math.round((360 * j) / ok.length);
    const p = xs.map((t) => below(e.kept, t, e.kept.length));
    const r = xs.map((t) => below(e.comp, t, e.comp.length));
    const f = p.map((pv, i) => (pv + r[i] > 0 ? (2 * pv * r[i]) / (pv + r[i]) : 0));
    data.push(p, r, f);
    series.push({ label: `${e.row.pipeline} P`, stroke: `hsl(${hue},70%,60%)`, width: 1, dash: [6, 4] },
      { label: `${e.row.pipeline} R`, stroke: `hsl(${hue},70%,60%)`, width: 1, dash: [2, 3] },
      { label: `${e.row.pipeline} F`, stroke: `hsl(${hue},70%,60%)`, width: 2 });
  });
  const plot = new uPlot({
    width: Math.max(300, el.clientWidth || 500), height: 220, legend: { live: false },
    scales: { x: { time: false }, y: { range: [0, 1] } }, axes: [{ label: 'τ' }, {}], series,
  }, data, el);
  el.dataset.series = String(series.length - 1);
  return plot;
}

/**
 * Sets up the compare section. `call` talks to the worker, `viewer` is the page's viewer,
 * `options()` the Measure section's options, `showError(msg, target)` the banner and
 * `download(name, data, type)` saves a file, `setRunning(b)` tells the page a compare is under way
 * (progress bar and Cancel in the action bar) and returns false when another run already is,
 * `showComparison()` turns the results pane to the comparison.
 */
export function setupCompare({ call, viewer, measureOptions, showError, download, gtName, setRunning, showComparison }) {
  const state = { items: [], entries: [], sort: null, tables: null, table: null, viewer2: null };
  const info = $('info-runs');
  const setItems = (items) => {
    state.items = items;
    const runs = items.filter((i) => i.runJson).length;
    info.textContent = items.length
      ? `${items.length} reconstruction${items.length === 1 ? '' : 's'}${runs ? ` (${runs} runner run${runs === 1 ? '' : 's'})` : ''}: ${items.map((i) => i.pipeline).join(', ')}`
      : '—';
    info.classList.toggle('error', false);
    $('compare').disabled = !items.length;
  };
  const fail = (msg) => {
    info.textContent = msg;
    info.classList.add('error');
    showError(msg, 'file-runs');
  };
  const runFiles = async (paths) => (await call(MSG.runFiles, { paths })).files;
  const modelFiles = async (paths) => (await call(MSG.modelFiles, { paths })).paths;
  let picks = 0; // the latest pick wins over an earlier one still being grouped
  const take = async (files) => {
    const pick = ++picks;
    let items;
    try { items = await groupItems(files, runFiles, modelFiles); } catch (err) { if (pick === picks) fail(`compare: ${err.message}`); return; }
    if (pick !== picks) return;
    if (!items.length) fail('compare: no reconstruction found (a runs folder needs <pipeline>/run.json; a model folder its model files)');
    else setItems(items);
  };
  $('file-runs').addEventListener('change', (e) => take(e.target.files));
  $('dir-runs').addEventListener('change', (e) => take(e.target.files));
  dropZone($('drop-runs'), async (entries, dropped) => {
    try {
      const files = [];
      for (const en of entries) files.push(...(await entryFiles(en)));
      await take(files.length ? files : dropped);
    } catch (err) { fail(`compare: ${err.message}`); }
  });

  /**
   * What of the Measure and Crop sections a comparison was measured with; when one of them
   * changes after a Compare, the comparison goes out of date (as for the ground truth).
   */
  const measured = () => {
    const b = measureOptions();
    return { 'τ': JSON.stringify([b.tau, b.tau_percent_of_diagonal]), samples: String(b.samples), seed: String(b.seed), crop: JSON.stringify(b.crop) };
  };
  const checkMeasured = () => {
    if (!state.measuredWith) return;
    const now = measured();
    const changed = Object.keys(now).filter((k) => now[k] !== state.measuredWith[k]);
    if (changed.length) markComparisonStale(`${changed.join(', ')} changed since this comparison`);
  };
  for (const id of ['tau', 'tau-rel', 'samples', 'seed', 'max-distance', 'crop-kind']) {
    $(id).addEventListener('input', checkMeasured);
    $(id).addEventListener('change', checkMeasured);
  }
  // the crop volume moved in the viewer, fitted or imported (crop.js announces every change)
  document.addEventListener('sfmeval-crop-change', checkMeasured);

  async function run() {
    if (!state.items.length) return;
    const name = gtName();
    if (!name) { fail('compare: load the ground truth first (section 1)'); return; }
    if (!setRunning(true)) { fail('compare: wait for the evaluation under way to end (or cancel it)'); return; }
    $('compare').disabled = true;
    showError('');
    const entries = [];
    const problems = [];
    const base = measureOptions();
    const options = { tau: base.tau, tau_percent_of_diagonal: base.tau_percent_of_diagonal, samples: base.samples, seed: base.seed, crop: base.crop, align: 'auto' };
    const with_ = measured();
    try {
      for (const [k, it] of state.items.entries()) {
        $('compare-status').textContent = `evaluating ${k + 1}/${state.items.length}: ${it.pipeline}…`;
        const runText = it.runJson ? await it.runJson.text() : null;
        let run = null;
        if (runText) {
          try { run = JSON.parse(runText); } catch (err) { throw new Error(`${it.path}run.json: ${err.message}`); }
        }
        if (run && run.status !== 'ok') {
          const { row } = await call(MSG.runRowOnly, { runJson: runText });
          entries.push({ row, report: null, path: it.path });
          continue;
        }
        const files = {};
        const transfer = [];
        for (const [n, f] of Object.entries(it.files)) { const b = await f.arrayBuffer(); files[n] = b; transfer.push(b); }
        const recName = run ? `${run.dataset}/${run.pipeline}` : it.pipeline;
        try {
          if (!transfer.length) throw new Error('no model files (model/ or sparse.ply)');
          const r = await call(MSG.compareRun, { files, name: recName, runJson: runText, dataset: name, options }, transfer);
          entries.push({ ...r, report: JSON.parse(r.reportJson), path: it.path });
        } catch (err) {
          if (err.name === 'Cancelled') throw err;
          // as the runner: the run stays in the table, "evaluation failed" with the reason
          problems.push(`${it.path}: ${err.message}`);
          const record = runText ?? JSON.stringify({
            dataset: name, pipeline: it.pipeline, tool: 'file', version: null, status: 'failed', reason: null,
            wall_seconds: 0, cpu_seconds: 0, peak_memory_bytes: 0, images_total: 0, images_registered: 0, points: 0,
          });
          const { row } = await call(MSG.runRowOnly, { runJson: record });
          entries.push({ row: { ...row, status: 'evaluation failed', reason: err.message }, report: null, path: it.path });
        }
      }
      state.entries = entries;
      const { tables, table } = await call(MSG.comparisonTables, { entries: entries.map((e) => ({ row: e.row, report: e.report })) });
      state.tables = tables;
      state.table = table;
      state.measuredWith = with_;
      clearComparisonStale();
      render();
      // the results pane now shows the comparison, its table at the top (in view)
      showComparison();
      $('compare-status').textContent = `compared ${entries.length} reconstruction${entries.length === 1 ? '' : 's'}${problems.length ? ` (${problems.length} could not be evaluated)` : ''}`;
      if (problems.length) {
        showError(`compare: ${problems.length} of ${entries.length} could not be evaluated (marked "evaluation failed" in the table): ${problems.join('; ')}`, 'file-runs');
      }
      document.body.dataset.compared = String(Number(document.body.dataset.compared || 0) + 1);
    } catch (err) {
      if (err.name === 'Cancelled') {
        $('compare-status').textContent = 'compare cancelled (press Compare to run it again)';
      } else {
        fail(`compare failed: ${err.message}`);
        $('compare-status').textContent = '✗ compare failed: see the message at the top';
      }
    } finally {
      $('compare').disabled = !state.items.length;
      setRunning(false);
    }
  }
  $('compare').onclick = run;

  function render() {
    $('compare-results').hidden = false;
    // columns, cell texts and best marks come from the core (its catalogue of metrics); the
    // page only sorts the rows
    const { columns: cols, rows } = state.table;
    let order = state.entries.map((_, i) => i);
    if (state.sort) {
      const c = cols.findIndex((x) => x.id === state.sort.key);
      if (c >= 0) {
        const text = cols[c].text;
        const v = (i) => (text ? rows[i][c].text : rows[i][c].value);
        order.sort((a, b) => {
          const x = v(a), y = v(b);
          if (x == null && y == null) return a - b;
          if (x == null) return 1;
          if (y == null) return -1;
          const d = text ? String(x).localeCompare(String(y)) : x - y;
          return (state.sort.dir === 'asc' ? d : -d) || a - b;
        });
      }
    }
    let h = '<table id="cmp-table"><thead><tr>';
    for (const c of cols) {
      const s = state.sort && state.sort.key === c.id ? state.sort.dir : null;
      h += `<th data-k="${c.id}" aria-sort="${s === 'asc' ? 'ascending' : s === 'desc' ? 'descending' : 'none'}"><button class="sort small" data-k="${c.id}" title="sort by ${esc(c.header)}${c.best ? ` (best: ${c.best === 'lower' ? 'lowest' : 'highest'})` : ''}">${esc(c.header)}${s === 'asc' ? ' ▲' : s === 'desc' ? ' ▼' : ''}</button></th>`;
    }
    h += '</tr></thead><tbody>';
    for (const i of order) {
      const e = state.entries[i];
      h += `<tr data-i="${i}" data-pipeline="${esc(e.row.pipeline)}">`;
      cols.forEach((c, j) => {
        const cell = rows[i][j];
        h += `<td data-k="${c.id}"${c.text ? ' class="text"' : ''}${cell.best ? ' data-best="1" class="best" title="best of this column"' : ''}${cell.value != null ? ` data-v="${cell.value}"` : ''}>${esc(cell.text)}${cell.best ? ' ★' : ''}</td>`;
      });
      h += '</tr>';
    }
    h += '</tbody></table>';
    $('cmp-table-wrap').innerHTML = h;
    for (const b of document.querySelectorAll('#cmp-table button.sort')) {
      b.onclick = () => {
        const k = b.dataset.k;
        state.sort = state.sort && state.sort.key === k ? { key: k, dir: state.sort.dir === 'asc' ? 'desc' : 'asc' } : { key: k, dir: 'asc' };
        render();
        const again = document.querySelector(`#cmp-table button.sort[data-k="${k}"]`);
        if (again) again.focus();
      };
    }
    curves($('cmp-curves'), state.entries);
    // viewer choices
    for (const id of ['cmp-view-a', 'cmp-view-b']) {
      const sel = $(id);
      const keep = sel.value;
      sel.innerHTML = (id === 'cmp-view-b' ? '<option value="">—</option>' : '')
        + state.entries.map((e, i) => (e.pointsInGt ? `<option value="${i}">${esc(e.row.pipeline)}</option>` : '')).join('');
      if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
    }
    showIn(viewer, $('cmp-view-a').value);
    updateSide();
  }

  /** A caption in the corner of a viewer naming the reconstruction it shows. */
  function label(v, text) {
    let el = v.container.querySelector(':scope > .view-label');
    if (!el) {
      el = document.createElement('div');
      el.className = 'view-label';
      v.container.appendChild(el);
    }
    el.textContent = text;
    el.hidden = !text;
  }
  function showIn(v, value) {
    const e = state.entries[Number(value)];
    if (value === '' || !e || !e.pointsInGt) return;
    label(v, e.row.pipeline);
    v.setPoints(e.pointsInGt, $('heat') && $('heat').checked ? e.colors : null);
    drawCameras(v, e.cameras);
    // the first time cameras are shown here, frame them (they stand well outside the object)
    if (e.cameras && e.cameras.gtPoses && !v.framedCameras) { v.fitCameras(); v.framedCameras = true; }
  }
  function updateSide() {
    const b = $('cmp-view-b').value;
    const center = $('viewer');
    if (b === '') {
      center.classList.remove('split');
      if (state.viewer2) state.viewer2.container.hidden = true;
      return;
    }
    center.classList.add('split');
    if (!state.viewer2) {
      const box = document.createElement('div');
      box.id = 'viewer2';
      center.appendChild(box);
      state.viewer2 = new Viewer(box);
      state.viewer2.renderer.domElement.id = 'view3d-b';
      // the two views look from the same place
      const sync = (from, to) => from.orbit.addEventListener('change', () => {
        if (sync.busy) return;
        sync.busy = true;
        to.camera.position.copy(from.camera.position);
        to.orbit.target.copy(from.orbit.target);
        to.orbit.update();
        sync.busy = false;
      });
      sync(viewer, state.viewer2);
      sync(state.viewer2, viewer);
      window.sfmevalViewer2 = state.viewer2;
    }
    state.viewer2.container.hidden = false;
    const gtv = viewer.gtMesh;
    if (gtv && state.viewer2.gtSource !== gtv) {
      state.viewer2.setGroundTruth(gtv.geometry.attributes.position.array, gtv.geometry.index ? gtv.geometry.index.array : new Uint32Array(0), gtBounds(viewer));
      state.viewer2.gtSource = gtv;
    }
    state.viewer2.resize();
    viewer.resize();
    showIn(state.viewer2, b);
    state.viewer2.camera.position.copy(viewer.camera.position);
    state.viewer2.orbit.target.copy(viewer.orbit.target);
    state.viewer2.orbit.update();
  }
  $('cmp-view-a').addEventListener('change', () => showIn(viewer, $('cmp-view-a').value));
  $('cmp-view-b').addEventListener('change', updateSide);

  for (const [id, key, name, type] of [
    ['cmp-dl-table-md', 'table_md', 'table.md', 'text/markdown'],
    ['cmp-dl-table1-md', 'table1_md', 'table1.md', 'text/markdown'],
    ['cmp-dl-table1-csv', 'table1_csv', 'table1.csv', 'text/csv'],
    ['cmp-dl-runs-csv', 'runs_csv', 'runs.csv', 'text/csv'],
  ]) {
    $(id).onclick = () => { if (state.tables) download(name, state.tables[key], type); };
  }
  $('cmp-dl-reports').onclick = () => {
    // one report per evaluated run, named as the runner's reports/<dataset>/<pipeline>.json
    for (const e of state.entries) if (e.reportJson) download(`${e.row.dataset}.${e.row.pipeline}.report.json`, e.reportJson, 'application/json');
  };
  return state;
}

/** The ground truth's bounds as `setGroundTruth` wants them, from the viewer's offset/diag. */
function gtBounds(v) {
  const g = v.gtMesh.geometry;
  g.computeBoundingBox();
  const b = g.boundingBox;
  return [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
}

/** The ground-truth (white) and estimated (coloured by centre error) frusta of an evaluation. */
export function drawCameras(v, cams) {
  if (!cams) { v.setCameras('gtCams', null); v.setCameras('estCams', null); return; }
  v.setCameras('gtCams', cams.gtPoses, null, 0xe0e0e0);
  v.setCameras('estCams', cams.estPoses, cams.estColors);
  const gtBox = document.getElementById('show-gt-cams');
  const estBox = document.getElementById('show-est-cams');
  if (gtBox) v.setVisible('gtCams', gtBox.checked);
  if (estBox) v.setVisible('estCams', estBox.checked);
}
