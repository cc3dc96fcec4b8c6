// Section 6, the DTU benchmark: the scan's files dropped together (recognised by name by the
// core: `stlNNN_total.ply`, `ObsMaskN_10.mat`, `PlaneN.mat`, any other PLY the reconstruction),
// what is missing said before a run, then the core's `sfmeval dtu` evaluation in the worker:
// its summary lines (mean accuracy, mean completeness, overall, worded by the core), the report
// (`sfmeval.dtu/1`, byte for byte the CLI's) and the error clouds for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { dropZone, entryFiles } from './files.js';

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker (false when an
 * evaluation or Compare is under way).
 */
export function setupDtu({ call, showError, download, setRunning }) {
  const state = { files: {}, found: null, result: null };
  const info = $('info-dtu');
  let picks = 0;
  const take = async (list) => {
    const pick = ++picks;
    // a later drop adds to (or replaces by name) what was dropped before: the four files may
    // come from different folders
    for (const f of Array.from(list)) state.files[f.name] = f;
    let found;
    try {
      ({ found } = await call(MSG.dtuFiles, { names: Object.keys(state.files) }));
    } catch (err) { showError(`DTU: ${err.message}`, 'file-dtu'); return; }
    if (pick !== picks) return;
    state.found = found;
    const have = [['STL points', found.stl], ['observation mask', found.obs_mask], ['ground plane', found.plane], ['reconstruction', found.reconstruction]]
      .filter(([, n]) => n).map(([k, n]) => `${k}: ${n}`);
    const lines = [];
    if (found.scan != null) lines.push(`scan ${found.scan}`);
    if (have.length) lines.push(have.join(', '));
    if (found.problems.length) lines.push(found.problems.join(' '));
    if (found.missing.length) lines.push(`still needed: ${found.missing.join('; ')}`);
    if (found.ignored.length) lines.push(`not used: ${found.ignored.join(', ')}`);
    info.textContent = lines.join(' · ');
    info.classList.toggle('error', found.problems.length > 0);
    info.dataset.complete = found.missing.length || found.problems.length ? '0' : '1';
    $('dtu-run').disabled = info.dataset.complete !== '1';
    $('dtu-status').textContent = found.problems.length ? 'these files do not fit together: see above'
      : found.missing.length ? `${found.missing.length} file${found.missing.length === 1 ? '' : 's'} missing: see above` : 'ready';
  };
  $('file-dtu').addEventListener('change', (e) => { take(e.target.files); });
  dropZone($('drop-dtu'), async (entries, dropped) => {
    try {
      const files = [];
      for (const en of entries) files.push(...(await entryFiles(en)));
      await take(files.length ? files : dropped);
    } catch (err) { showError(`DTU: ${err.message}`, 'file-dtu'); }
  });

  $('dtu-run').onclick = async () => {
    const f = state.found;
    if (!f || $('dtu-run').disabled) return;
    if (!setRunning(true)) { showError('DTU: wait for the evaluation under way to end (or cancel it)', 'dtu-run'); return; }
    $('dtu-run').disabled = true;
    showError('');
    $('dtu-status').textContent = 'evaluating…';
    try {
      const files = {};
      const transfer = [];
      for (const n of [f.stl, f.obs_mask, f.plane, f.reconstruction]) {
        const b = await state.files[n].arrayBuffer();
        files[n] = b;
        transfer.push(b);
      }
      const r = await call(MSG.dtu, { files, options: {} }, transfer);
      state.result = r;
      $('dtu-lines').innerHTML = '';
      for (const line of r.lines) {
        const li = document.createElement('li');
        li.textContent = line;
        $('dtu-lines').appendChild(li);
      }
      $('dtu-counts').textContent = r.summary.split('\n')[0];
      $('dtu-result').hidden = false;
      $('dtu-status').textContent = `done in ${(r.ms / 1000).toFixed(1)} s`;
      document.body.dataset.dtu = String(Number(document.body.dataset.dtu || 0) + 1);
    } catch (err) {
      if (err.name !== 'Cancelled') {
        showError(`DTU evaluation failed: ${err.message}`, 'file-dtu');
        $('dtu-status').textContent = '✗ failed: see the message at the top';
      } else $('dtu-status').textContent = 'cancelled';
    } finally {
      setRunning(false);
      $('dtu-run').disabled = !(state.found && info.dataset.complete === '1');
    }
  };
  $('dtu-dl-report').onclick = () => { if (state.result) download(`dtu_scan${state.found.scan}.json`, state.result.reportJson, 'application/json'); };
  $('dtu-dl-d2s').onclick = () => { if (state.result) download(state.result.visNames[0], state.result.d2s, 'application/octet-stream'); };
  $('dtu-dl-s2d').onclick = () => { if (state.result) download(state.result.visNames[1], state.result.s2d, 'application/octet-stream'); };
  return state;
}
