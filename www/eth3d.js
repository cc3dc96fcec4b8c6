// Section 8, the ETH3D benchmark: a scene's files dropped together (the core recognises them:
// the MeshLab project, the scans it names, the reconstruction PLY), what is missing said before a
// run, then the core's `sfmeval eth3d` in the worker: its headline and per-tolerance table
// (accuracy, completeness, F1, point counts; cell texts from the core), the report
// (`sfmeval.eth3d/1`, byte for byte the CLI's) and each tolerance's coloured clouds for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { dropZone, entryFiles } from './files.js';

/** A header row and body rows of cell texts, into `table`. */
function fillTable(table, { columns, rows }) {
  const head = document.createElement('tr');
  for (const c of columns) {
    const th = document.createElement('th');
    th.scope = 'col';
    th.textContent = c;
    head.appendChild(th);
  }
  table.tHead.replaceChildren(head);
  table.tBodies[0].replaceChildren(...rows.map((r) => {
    const tr = document.createElement('tr');
    for (const text of r) {
      const td = document.createElement('td');
      td.textContent = text;
      tr.appendChild(td);
    }
    return tr;
  }));
}

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker.
 */
export function setupEth3d({ call, showError, download, setRunning }) {
  const state = { files: {}, found: null, result: null };
  const info = $('info-eth3d');
  let picks = 0;
  const take = async (list) => {
    const pick = ++picks;
    // a later drop adds to (or replaces by name) what was dropped before
    for (const f of Array.from(list)) state.files[f.name] = f;
    let found;
    try {
      const names = Object.keys(state.files);
      ({ found } = await call(MSG.eth3dFiles, { names }));
      // the project found: its scans and the reconstruction are known once the core reads it
      if (found.project) {
        const project = await state.files[found.project].arrayBuffer();
        ({ found } = await call(MSG.eth3dFiles, { names, project }, [project]));
      }
    } catch (err) { showError(`ETH3D: ${err.message}`, 'file-eth3d'); return; }
    if (pick !== picks) return;
    state.found = found;
    const lines = [];
    if (found.project) lines.push(`project: ${found.project}`);
    if (found.scans.length) lines.push(`scans: ${found.scans.map((s) => s.file).join(', ')}`);
    if (found.reconstruction) lines.push(`reconstruction: ${found.reconstruction}`);
    if (found.problems.length) lines.push(found.problems.join(' '));
    if (found.missing.length) lines.push(`still needed: ${found.missing.join('; ')}`);
    if (found.ignored.length) lines.push(`not used: ${found.ignored.join(', ')}`);
    info.textContent = lines.join(' · ');
    info.classList.toggle('error', found.problems.length > 0);
    const complete = !found.missing.length && !found.problems.length;
    info.dataset.complete = complete ? '1' : '0';
    $('eth3d-run').disabled = !complete;
    $('eth3d-status').textContent = found.problems.length ? 'these files do not fit together: see above'
      : found.missing.length ? `${found.missing.length} file${found.missing.length === 1 ? '' : 's'} missing: see above` : 'ready';
  };
  $('file-eth3d').addEventListener('change', (e) => { take(e.target.files); });
  dropZone($('drop-eth3d'), async (entries, dropped) => {
    try {
      const files = [];
      for (const en of entries) files.push(...(await entryFiles(en)));
      await take(files.length ? files : dropped);
    } catch (err) { showError(`ETH3D: ${err.message}`, 'file-eth3d'); }
  });

  $('eth3d-run').onclick = async () => {
    const f = state.found;
    if (!f || $('eth3d-run').disabled) return;
    if (!setRunning(true)) { showError('ETH3D: wait for the evaluation under way to end (or cancel it)', 'eth3d-run'); return; }
    $('eth3d-run').disabled = true;
    showError('');
    $('eth3d-status').textContent = 'evaluating…';
    try {
      const files = {};
      const transfer = [];
      for (const n of [f.project, ...f.scans.map((s) => s.file), f.reconstruction]) {
        const b = await state.files[n].arrayBuffer();
        files[n] = b;
        transfer.push(b);
      }
      const r = await call(MSG.eth3d, { files, options: {} }, transfer);
      state.result = r;
      $('eth3d-headline').textContent = r.headline;
      fillTable($('eth3d-table'), r.table);
      $('eth3d-tolerance').replaceChildren(...r.table.rows.map((row, t) => new Option(row[0], String(t))));
      $('eth3d-result').hidden = false;
      $('eth3d-status').textContent = `done in ${(r.ms / 1000).toFixed(1)} s`;
      document.body.dataset.eth3d = String(Number(document.body.dataset.eth3d || 0) + 1);
    } catch (err) {
      state.result = null;
      $('eth3d-result').hidden = true;
      if (err.name !== 'Cancelled') {
        showError(`ETH3D evaluation failed: ${err.message}`, 'file-eth3d');
        $('eth3d-status').textContent = '✗ failed: see the message at the top';
      } else $('eth3d-status').textContent = 'cancelled';
    } finally {
      setRunning(false);
      $('eth3d-run').disabled = !(state.found && info.dataset.complete === '1');
    }
  };
  $('eth3d-dl-report').onclick = () => { if (state.result) download('eth3d.json', state.result.reportJson, 'application/json'); };
  const cloud = (kind) => async () => {
    if (!state.result) return;
    try {
      const r = await call(MSG.eth3dCloud, { t: Number($('eth3d-tolerance').value), kind });
      download(r.name, r.bytes, 'application/octet-stream');
    } catch (err) { showError(`ETH3D: ${err.message}`, 'eth3d-dl-acc'); }
  };
  $('eth3d-dl-acc').onclick = cloud('accuracy');
  $('eth3d-dl-comp').onclick = cloud('completeness');
  return state;
}
