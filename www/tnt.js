// Section 9, Tanks and Temples: a scene's files dropped together (the core recognises them by the
// benchmark's names: SCENE.ply, SCENE.json, SCENE_trans.txt, SCENE_COLMAP_SfM.log; any other
// .log the reconstruction's trajectory, any other PLY the reconstruction), what is missing said
// before a run, then the core's `sfmeval tnt` in the worker: its summary lines (worded by the
// core), the precision/recall plot the core draws (SVG), the report (byte for byte the CLI's) and
// each file the CLI writes beside it for download.
import { $ } from './util.js';
import { MSG } from './core.js';
import { droppedFiles, namedBytes, runButton } from './benchmark.js';

/**
 * Sets up the section. `call` talks to the worker, `showError(msg, target)` the banner,
 * `download(name, data, type)` saves a file, `setRunning(b)` claims the worker.
 */
export function setupTnt({ call, showError, download, setRunning }) {
  const label = 'Tanks and Temples';
  const state = droppedFiles({
    key: 'tnt', label, showError,
    recognise: async (names) => (await call(MSG.tntFiles, { names })).found,
  });
  Object.assign(state, { result: null, plotUrl: null });
  runButton({
    key: 'tnt', label, setRunning, showError, ready: state.ready,
    evaluate: async () => {
      const { files, transfer } = await namedBytes(state.files, state.found.inputs);
      const tau = $('tnt-tau').value.trim();
      const options = tau ? { tau: Number(tau) } : {};
      return call(MSG.tnt, { files, options }, transfer);
    },
    show: (r) => {
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
    },
    clear: () => { state.result = null; $('tnt-result').hidden = true; },
  });
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
