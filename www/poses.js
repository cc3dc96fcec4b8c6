// Section 7, the camera-pose benchmarks: the ground-truth cameras and the estimated model
// dropped on their own zones, a protocol (colmap, imc, co3d) and COLMAP's position accuracy,
// then the core's `sfmeval poses` in the worker: the summary's rows (counts, AUC / mAA / RRA /
// RTA, the convention, worded by the core) as a table, the report (`sfmeval.poses/1`, byte for
// byte the CLI's `--json`) and the pairs CSV for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { onFiles, runButton } from './benchmark.js';

/** The label and text cells of the core's summary rows, into `tbody`. */
function fillRows(tbody, rows) {
  tbody.innerHTML = '';
  for (const { label, text } of rows) {
    const tr = document.createElement('tr');
    const th = document.createElement('th');
    th.scope = 'row';
    th.textContent = label;
    const td = document.createElement('td');
    td.textContent = text;
    tr.append(th, td);
    tbody.appendChild(tr);
  }
}

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker.
 */
export function setupPoses({ call, showError, download, setRunning }) {
  const state = { gt: null, est: null, result: null };
  const ready = () => { $('poses-run').disabled = !(state.gt && state.est); };
  // each zone holds one set of files: a new drop replaces it (a model is several files at once)
  const zone = (kind, key) => {
    const take = (list) => {
      const files = Array.from(list);
      if (!files.length) return;
      state[key] = files;
      $(`info-poses-${kind}`).textContent = files.map((f) => f.webkitRelativePath || f.name).join(', ');
      $('poses-status').textContent = '';
      ready();
    };
    onFiles($(`file-poses-${kind}`), $(`drop-poses-${kind}`), take, (err) => showError(`poses: ${err.message}`, `file-poses-${kind}`));
  };
  zone('gt', 'gt');
  zone('est', 'est');

  const named = async (files, transfer) => {
    const out = {};
    for (const f of files) {
      const b = await f.arrayBuffer();
      // a dropped folder's files by their path inside it, loose files by name
      out[(f.webkitRelativePath || f.name).split('/').slice(1).join('/') || f.name] = b;
      transfer.push(b);
    }
    return out;
  };

  runButton({
    key: 'poses', label: 'poses', setRunning, showError, ready: () => Boolean(state.gt && state.est),
    errorTarget: 'file-poses-est',
    evaluate: async () => {
      const transfer = [];
      const gtFiles = await named(state.gt, transfer);
      const reconFiles = await named(state.est, transfer);
      const options = { protocol: $('poses-protocol').value, position_accuracy: Number($('poses-position-accuracy').value) || 0 };
      const r = await call(MSG.poses, { gtFiles, reconFiles, options }, transfer);
      return { ...r, protocol: options.protocol };
    },
    show: (r) => {
      state.result = r;
      fillRows($('poses-table').tBodies[0], r.rows);
      $('poses-result').hidden = false;
    },
    clear: () => { state.result = null; $('poses-result').hidden = true; },
  });
  $('poses-dl-report').onclick = () => { if (state.result) download(`poses_${state.result.protocol}.json`, state.result.reportJson, 'application/json'); };
  $('poses-dl-pairs').onclick = () => { if (state.result) download(`poses_${state.result.protocol}_pairs.csv`, state.result.pairsCsv, 'text/csv'); };
  return state;
}
