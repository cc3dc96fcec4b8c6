// The page's entry: wires the modules together, runs and cancels an evaluation, the viewer's
// options and the start-up. Modules by concern: core.js (the worker and its named messages),
// state.js, ui.js (banner, run line, progress, out of date), inputs.js (section 1 and the demo),
// points.js (section 2 and the shown points), crop.js (section 3), results.js, notes.js,
// compare.js (section 5), dtu.js (section 6), poses.js (section 7), eth3d.js (section 8), tnt.js (section 9), util.js.
import { $, numList, download, matrixText, alignedTransform } from './util.js';
import { call, MSG, Cancelled, initCore, onWorkerEvents, pollSharedProgress, restartWorker } from './core.js';
import { state, viewer } from './state.js';
import { showError, setRunNote, updateRunButton, showProgress, hideProgress, markStale, showView } from './ui.js';
import { reloadInputs } from './inputs.js';
import { alignMethod, refreshPoints } from './points.js';
import { currentCrop, cropText } from './crop.js';
import { showResults, showCameraScale, prAt } from './results.js';
import { reportNotes } from './notes.js';
import { setupCompare, drawCameras } from './compare.js';
import { setupDtu } from './dtu.js';
import { setupPoses } from './poses.js';
import { setupEth3d } from './eth3d.js';
import { setupTnt } from './tnt.js';

onWorkerEvents({
  onProgress: (m) => {
    if (state.running) showProgress(m.stage, m.done, m.total);
    else if (m.stage === 'reading') showProgress('reading (MB)', Math.round(m.done / 1e6), Math.max(2, Math.round(m.total / 1e6)));
  },
  onError: (msg) => showError(msg),
});

// ---- evaluation -------------------------------------------------------------------------
function options() {
  const o = {
    tau: numList($('tau').value),
    tau_percent_of_diagonal: numList($('tau-rel').value),
    samples: Number($('samples').value),
    seed: Number($('seed').value),
    signed: $('signed').checked,
    histogram_bins: Number($('bins').value),
    crop: currentCrop(),
  };
  const method = alignMethod();
  o.align = method;
  if (method === 'given') o.transform = $('transform').value;
  if (method.startsWith('points')) o.pairs = state.pairs.filter((p) => p.gt && p.recon);
  return o;
}

async function runEvaluation() {
  showError('');
  if (state.picking) $('pick').click();
  state.running = true;
  setRunNote('');
  showProgress('starting', 0, 1);
  const poll = pollSharedProgress(() => state.running, showProgress);
  try {
    const r = await call(MSG.evaluate, { options: options() });
    r.report = JSON.parse(r.reportJson);
    state.result = r;
    document.querySelector('input[name=view][value=after]').checked = true;
    $('clip').value = r.clip;
    showResults(r);
    refreshPoints();
    viewer.setCoverage(r.samplePoints, r.sampleLabels);
    drawCameras(viewer, r.cameras);
    // the first evaluation with cameras frames them (they stand well outside the object)
    if (r.cameras && r.cameras.gtPoses && !viewer.framedCameras) { viewer.fitCameras(); viewer.framedCameras = true; }
    showCameraScale(r.cameras);
    $('show-coverage').disabled = !r.sampleLabels;
    $('show-coverage').checked = !!r.sampleLabels;
    viewer.setVisible('coverage', $('show-coverage').checked);
    document.body.dataset.evaluated = String(Number(document.body.dataset.evaluated || 0) + 1);
    setRunNote(`Done in ${(r.ms / 1000).toFixed(1)} s: results on the right.`);
  } catch (e) {
    if (e instanceof Cancelled) {
      // the worker that held the previous evaluation is gone: its downloads with it
      markStale('the last evaluation was cancelled (downloads need a new run)');
    } else {
      showError(`evaluation failed: ${e.message}`, 'run');
      setRunNote('✗ The evaluation failed: see the message at the top.', true);
    }
  } finally {
    if (poll) clearInterval(poll);
    state.running = false;
    hideProgress();
    updateRunButton();
  }
}
$('run').onclick = runEvaluation;
/** Cancel: stops the worker mid-run, then reloads the inputs into a fresh one. */
$('cancel').onclick = async () => {
  if (!state.running || state.restoring) return;
  state.restoring = true;
  setRunNote('Cancelling: restarting the core and reloading the inputs…');
  try {
    await restartWorker(reloadInputs);
    setRunNote('Evaluation cancelled.');
  } catch (e) {
    showError(`could not reload the inputs after cancelling: ${e.message}; load them again`);
    setRunNote('✗ Cancelled, but the inputs could not be reloaded.', true);
  } finally {
    state.restoring = false;
    updateRunButton();
    document.body.dataset.cancelled = String(Number(document.body.dataset.cancelled || 0) + 1);
    if (!$('run').disabled) $('run').focus();
  }
};

// ---- viewer options ---------------------------------------------------------------------
$('point-size').addEventListener('input', (e) => viewer.setPointSize(Number(e.target.value)));
$('show-gt').addEventListener('change', (e) => viewer.setVisible('gt', e.target.checked));
$('show-recon').addEventListener('change', (e) => viewer.setVisible('recon', e.target.checked));
$('show-coverage').addEventListener('change', (e) => viewer.setVisible('coverage', e.target.checked));
for (const [box, kind] of [['show-gt-cams', 'gtCams'], ['show-est-cams', 'estCams']]) {
  $(box).addEventListener('change', (e) => {
    viewer.setVisible(kind, e.target.checked);
    if (window.sfmevalViewer2) window.sfmevalViewer2.setVisible(kind, e.target.checked);
  });
}
$('fit-cams').onclick = () => viewer.fitCameras();
$('heat').addEventListener('change', refreshPoints);

// ---- start ------------------------------------------------------------------------------
initCore().then((m) => {
  $('version').textContent = `core ${m.version} · ${m.threads === 1 ? '1 thread' : `${m.threads} threads`}`;
  // threads wanted but off: say why (a static host must send the COOP/COEP headers)
  const note = $('threads-note');
  note.hidden = !m.threadsOff;
  if (m.threadsOff) {
    note.textContent = `single thread: ${m.threadsOff}`;
    note.title = 'Multi-threading needs a cross-origin isolated page (the server sends Cross-Origin-Opener-Policy: same-origin and Cross-Origin-Embedder-Policy: require-corp) and WebAssembly SIMD; scripts/serve.sh sends both headers.';
  }
  document.body.dataset.threads = String(m.threads);
  document.body.dataset.ready = '1';
}).catch((e) => showError(`could not load the WebAssembly core: ${e.message}`));
hideProgress();
showError('');
updateRunButton();
/** Claims the worker for a Compare or a DTU evaluation (false while another run is under way). */
const setRunning = (b) => {
  if (b && (state.running || state.restoring)) return false;
  state.running = b;
  if (b) setRunNote('Running: progress below; Cancel stops it.');
  else { hideProgress(); if (!state.restoring) setRunNote(''); }
  updateRunButton();
  return true;
};
const compare = setupCompare({
  call, viewer, measureOptions: options, showError, download,
  gtName: () => (state.gt ? state.gt.name : null),
  showComparison: () => showView('comparison'),
  setRunning: (b) => {
    const ok = setRunning(b);
    if (ok && b) setRunNote('Comparing: progress below; Cancel stops it.');
    return ok;
  },
});
const dtu = setupDtu({ call, showError, download, setRunning });
const poses = setupPoses({ call, showError, download, setRunning });
const eth3d = setupEth3d({ call, showError, download, setRunning });
const tnt = setupTnt({ call, showError, download, setRunning });
// for tests and scripting
window.sfmeval = { compare, dtu, poses, eth3d, tnt, state, call, currentCrop, cropText, prAt, reportNotes, matrixText, alignedTransform };
