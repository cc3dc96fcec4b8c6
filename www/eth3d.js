// Section 8, the ETH3D benchmark: a scene's files dropped together (the core recognises them:
// the MeshLab project, the scans it names, the reconstruction PLY), what is missing said before a
// run, then the core's `sfmeval eth3d` in the worker: its headline and per-tolerance table
// (accuracy, completeness, F1, point counts; cell texts from the core), the report
// (`sfmeval.eth3d/1`, byte for byte the CLI's) and each tolerance's coloured clouds for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { droppedFiles, namedBytes, runButton } from './benchmark.js';

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
  const state = droppedFiles({
    key: 'eth3d', label: 'ETH3D', showError,
    recognise: async (names, files) => {
      let { found } = await call(MSG.eth3dFiles, { names });
      // the project found: its scans and the reconstruction are known once the core reads it
      if (found.project) {
        const project = await files[found.project].arrayBuffer();
        ({ found } = await call(MSG.eth3dFiles, { names, project }, [project]));
      }
      return found;
    },
  });
  state.result = null;
  runButton({
    key: 'eth3d', label: 'ETH3D', setRunning, showError, ready: state.ready,
    evaluate: async () => {
      const { files, transfer } = await namedBytes(state.files, state.found.inputs);
      return call(MSG.eth3d, { files, options: {} }, transfer);
    },
    show: (r) => {
      state.result = r;
      $('eth3d-headline').textContent = r.headline;
      fillTable($('eth3d-table'), r.table);
      $('eth3d-tolerance').replaceChildren(...r.table.rows.map((row, t) => new Option(row[0], String(t))));
      $('eth3d-result').hidden = false;
    },
    clear: () => { state.result = null; $('eth3d-result').hidden = true; },
  });
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
