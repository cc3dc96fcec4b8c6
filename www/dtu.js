// Section 6, the DTU benchmark: the scan's files dropped together (recognised by name by the
// core: `stlNNN_total.ply`, `ObsMaskN_10.mat`, `PlaneN.mat`, any other PLY the reconstruction),
// what is missing said before a run, then the core's `sfmeval dtu` evaluation in the worker:
// its summary lines (mean accuracy, mean completeness, overall, worded by the core), the report
// (`sfmeval.dtu/1`, byte for byte the CLI's) and the error clouds for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { droppedFiles, namedBytes, runButton } from './benchmark.js';

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker (false when an
 * evaluation or Compare is under way).
 */
export function setupDtu({ call, showError, download, setRunning }) {
  const state = droppedFiles({
    key: 'dtu', label: 'DTU', showError,
    recognise: async (names) => (await call(MSG.dtuFiles, { names })).found,
  });
  state.result = null;
  runButton({
    key: 'dtu', label: 'DTU', setRunning, showError, ready: state.ready,
    evaluate: async () => {
      const { files, transfer } = await namedBytes(state.files, state.found.inputs);
      return call(MSG.dtu, { files, options: {} }, transfer);
    },
    show: (r) => {
      state.result = r;
      $('dtu-lines').replaceChildren(...r.lines.map((line) => {
        const li = document.createElement('li');
        li.textContent = line;
        return li;
      }));
      $('dtu-counts').textContent = r.counts;
      $('dtu-result').hidden = false;
    },
    clear: () => { state.result = null; $('dtu-result').hidden = true; },
  });
  $('dtu-dl-report').onclick = () => { if (state.result) download(`dtu_scan${state.found.scan}.json`, state.result.reportJson, 'application/json'); };
  $('dtu-dl-d2s').onclick = () => { if (state.result) download(state.result.visNames[0], state.result.d2s, 'application/octet-stream'); };
  $('dtu-dl-s2d').onclick = () => { if (state.result) download(state.result.visNames[1], state.result.s2d, 'application/octet-stream'); };
  return state;
}
