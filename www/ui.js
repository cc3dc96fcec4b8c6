// The page's messages: the error banner, the line under Evaluate, the progress bar, and the
// "Out of date" state of results whose inputs changed.
import { $ } from './util.js';
import { state } from './state.js';
import { refreshPoints } from './points.js';

/**
 * Shows `msg` in the banner under the header (always in view; empty hides it). `target` is
 * the id of the control the error belongs to: the banner offers to show it.
 */
let errorTarget = null;
export function showError(msg, target = null) {
  $('error').textContent = msg;
  $('banner').hidden = !msg;
  errorTarget = msg ? target : null;
  $('banner-goto').hidden = !errorTarget;
}
$('banner-close').onclick = () => {
  const t = errorTarget && $(errorTarget);
  showError('');
  if (t) t.focus(); else $('run').focus();
};
$('banner-goto').onclick = () => {
  const t = errorTarget && $(errorTarget);
  if (!t) return;
  (t.closest('.drop') || t).scrollIntoView({ block: 'nearest' });
  t.focus();
};
/** The line under the run button: the last run's outcome, or what is missing to run. */
let runNote = { text: '', error: false };
export function setRunNote(text, error = false) { runNote = { text, error }; updateRunButton(); }
export function updateRunButton() {
  const ready = !!(state.gt && state.recon);
  $('run').disabled = state.running || state.restoring || state.loading > 0 || !ready;
  $('cancel').hidden = !state.running;
  $('cancel').disabled = state.restoring;
  document.body.classList.toggle('busy', state.running || state.loading > 0);
  let text = runNote.text;
  if (!text && !ready && !state.loading) {
    const missing = [!state.recon && 'a reconstruction', !state.gt && 'a ground truth'].filter(Boolean);
    text = `To evaluate, load ${missing.join(' and ')} (or try the demo).`;
  }
  $('run-status').textContent = text;
  $('run-status').classList.toggle('error', runNote.error);
}
export function showProgress(stage, done, total) {
  const frac = total > 0 ? done / total : 0;
  $('progress').style.display = 'block';
  $('progress-bar').style.width = `${(100 * frac).toFixed(1)}%`;
  $('progress-text').textContent = stage ? `${stage} ${total > 1 ? `${done}/${total}` : ''}` : '';
}
export function hideProgress() { $('progress').style.display = 'none'; }
/** Counts a load under way (true) or finished (false). */
export function setBusy(b) {
  state.loading = Math.max(0, state.loading + (b ? 1 : -1));
  updateRunButton();
}

/**
 * Marks the results on screen as no longer current (dimmed under a note saying `why`),
 * disables their downloads and hides the colour bar. A new evaluation clears it. With
 * `comparison` (the ground truth, its cameras or depth maps changed: what Compare measured
 * against) the comparison on screen goes out of date too, until the next Compare.
 */
export function markStale(why, { comparison = false } = {}) {
  if (comparison) markComparisonStale(why);
  if (!state.shownResult) return;
  $('results').classList.add('stale');
  $('align-result').classList.add('stale');
  $('stale-note').hidden = false;
  $('stale-note').textContent = `Out of date: ${why}. These are the previous run's results; press Evaluate for new ones.`;
  for (const b of ['dl-report', 'dl-ply', 'dl-csv']) $(b).disabled = true;
  $('clip').disabled = true;
  $('colorbar').style.display = 'none';
  document.body.dataset.stale = '1';
  setRunNote('');
  if (state.result && state.recon) refreshPoints(); // without the error colours
}
/**
 * The comparison on screen no longer matches the inputs: dimmed under its own note (above its
 * table, in the flow: it never covers the table's header).
 */
export function markComparisonStale(why) {
  if ($('compare-results').hidden) return;
  $('compare-results').classList.add('stale');
  $('cmp-stale-note').hidden = false;
  $('cmp-stale-note').textContent = `Out of date: ${why}. This is the previous comparison; press Compare for a new one.`;
  document.body.dataset.compareStale = '1';
}
export function clearComparisonStale() {
  $('compare-results').classList.remove('stale');
  $('cmp-stale-note').hidden = true;
  $('cmp-stale-note').textContent = '';
  delete document.body.dataset.compareStale;
}
export function clearStale() {
  $('results').classList.remove('stale');
  $('align-result').classList.remove('stale');
  $('stale-note').hidden = true;
  $('stale-note').textContent = '';
  $('clip').disabled = false;
  delete document.body.dataset.stale;
}

/**
 * Which results the pane shows: 'evaluation' (the last evaluation's) or 'comparison' (section 5's
 * table); tabs above switch when there are both. Scrolled to the top, so that what was chosen
 * starts in view.
 */
export function showView(which) {
  const res = $('results');
  res.dataset.view = which;
  const hasComparison = !$('compare-results').hidden;
  $('results-tabs').hidden = !(state.shownResult && hasComparison);
  $('tab-evaluation').setAttribute('aria-pressed', String(which === 'evaluation'));
  $('tab-comparison').setAttribute('aria-pressed', String(which === 'comparison'));
  res.scrollTop = 0;
}
$('tab-evaluation').onclick = () => showView('evaluation');
$('tab-comparison').onclick = () => showView('comparison');
