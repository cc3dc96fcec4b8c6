// Section 9, Tanks and Temples: a scene's files dropped together (the core recognises them by the
// benchmark's names: SCENE.ply, SCENE.json, SCENE_trans.txt, SCENE_COLMAP_SfM.log; any other
// .log the reconstruction's trajectory, any other PLY the reconstruction), what is missing said
// before a run, then the core's `sfmeval tnt` in the worker: its summary lines (worded by the
// core), the precision/recall plot the core draws (SVG), the report (byte for byte the CLI's) and
// each file the CLI writes beside it for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { dropZone, entryFiles } from './files.js';

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker.
 */
export function setupTnt({ call, showError, download, setRunning }) {
  const state = { files: {}, found: null, result: null, plotUrl: null };
  const info = $('info-tnt');
  let picks = 0;
  const take = async (list) => {
    const pick = ++picks;
    // a later drop adds to (or replaces by name) what was dropped before
    for (const f of Array.from(list)) state.files[f.name] = f;
    let found;
    try {
      ({ found } = await call(MSG.tntFiles, { names: Object.keys(state.files) }));
    } catch (err) { showError(`Tanks and Temples: ${err.message}`, 'file-tnt'); return; }
    if (pick !== picks) return;
    state.found = found;
    const have = [['ground truth', found.ground_truth], ['crop', found.crop], ['alignment', found.alignment],
      ['reference trajectory', found.reference_trajectory], ['mapping', found.mapping],
      ['trajectory', found.trajectory], ['reconstruction', found.reconstruction]].filter(([, n]) => n).map(([k, n]) => `${k}: ${n}`);
    const lines = [];
    if (found.scene) lines.push(`scene ${found.scene}`);
    if (have.length) lines.push(have.join(', '));
    if (found.problems.length) lines.push(found.problems.join(' '));
    if (found.missing.length) lines.push(`still needed: ${found.missing.join('; ')}`);
    if (found.ignored.length) lines.push(`not used: ${found.ignored.join(', ')}`);
    info.textContent = lines.join(' · ');
    info.classList.toggle('error', found.problems.length > 0);
    const complete = !found.missing.length && !found.problems.length;
    info.dataset.complete = complete ? '1' : '0';
    $('tnt-run').disabled = !complete;
    $('tnt-status').textContent = found.problems.length ? 'these files do not fit together: see above'
      : found.missing.length ? `${found.missing.length} file${found.missing.length === 1 ? '' : 's'} missing: see above` : 'ready';
  };
  $('file-tnt').addEventListener('change', (e) => { take(e.target.files); });
  dropZone($('drop-tnt'), async (entries, dropped) => {
    try {
      const files = [];
      for (const en of entries) files.push(...(await entryFiles(en)));
      await take(files.length ? files : dropped);
    } catch (err) { showError(`Tanks and Temples: ${err.message}`, 'file-tnt'); }
  });

  $('tnt-run').onclick = async () => {
    const f = state.found;
    if (!f || $('tnt-run').disabled) return;
    if (!setRunning(true)) { showError('Tanks and Temples: wait for the evaluation under way to end (or cancel it)', 'tnt-run'); return; }
    $('tnt-run').disabled = true;
    showError('');
    $('tnt-status').textContent = 'evaluating…';
    try {
      const files = {};
      const transfer = [];
      for (const n of [f.ground_truth, f.crop, f.alignment, f.reference_trajectory, f.mapping, f.trajectory, f.reconstruction].filter(Boolean)) {
        const b = await state.files[n].arrayBuffer();
        files[n] = b;
        transfer.push(b);
      }
      const tau = $('tnt-tau').value.trim();
      const options = tau ? { tau: Number(tau) } : {};
      const r = await call(MSG.tnt, { files, options }, transfer);
      state.result = r;
      $('tnt-lines').replaceChildren(...r.lines.map((line) => {
        const li = document.createElement('li');
        li.textContent = line;
        return li;
      }));
      if (state.plotUrl) URL.revokeObjectURL(state.plotUrl);
      state.plotUrl = URL.createObjectURL(new Blob([r.svg], { type: 'image/svg+xml' }));
      const img = document.createElement('img');
      img.src = state.plotUrl;
      img.alt = 'precision and recall against the distance threshold, as the toolbox plots them';
      $('tnt-plot').replaceChildren(img);
      $('tnt-file').replaceChildren(...r.fileNames.map((n) => new Option(n, n)));
      $('tnt-result').hidden = false;
      $('tnt-status').textContent = `done in ${(r.ms / 1000).toFixed(1)} s`;
      document.body.dataset.tnt = String(Number(document.body.dataset.tnt || 0) + 1);
    } catch (err) {
      state.result = null;
      $('tnt-result').hidden = true;
      if (err.name !== 'Cancelled') {
        showError(`Tanks and Temples evaluation failed: ${err.message}`, 'file-tnt');
        $('tnt-status').textContent = '✗ failed: see the message at the top';
      } else $('tnt-status').textContent = 'cancelled';
    } finally {
      setRunning(false);
      $('tnt-run').disabled = !(state.found && info.dataset.complete === '1');
    }
  };
  $('tnt-dl-report').onclick = () => { if (state.result) download('report.json', state.result.reportJson, 'application/json'); };
  $('tnt-dl-file').onclick = async () => {
    if (!state.result) return;
    try {
      const r = await call(MSG.tntFile, { name: $('tnt-file').value });
      download(r.name, r.bytes, 'application/octet-stream');
    } catch (err) { showError(`Tanks and Temples: ${err.message}`, 'tnt-dl-file'); }
  };
  return state;
}
