// The results of one evaluation: the summary and statistics tables, the alignment stages and
// matrix, the notes, the plots and τ readout, the colour bars, and the downloads.
import { $, esc, g, numList, download, matrixText } from './util.js';
import { call, MSG } from './core.js';
import { state } from './state.js';
import { clearStale, showView } from './ui.js';
import { refreshPoints } from './points.js';
import { reportNotes, notesHtml } from './notes.js';
import { histogramPlot, curvesPlot } from './plots.js';

/** The alignment stages (`alignment.stages[].method`) in words. */
const STAGE_LABEL = { cameras: 'camera centres', points: 'point pairs', global: 'global search', icp: 'ICP', given: 'given', none: 'none' };
function showStages(report) {
  const a = report.alignment;
  // a stage's warnings (by their `values.stage`) mark its row; a rejected refinement says so
  const notes = reportNotes(report);
  const rows = (a.stages || []).map((s) => {
    const own = notes.filter((n) => n.stage === s.method && n.level === 'warn');
    const rejected = own.some((n) => n.code === 'alignment.icp_rejected');
    const mark = own.length ? ` <span class="warn" data-stage-warnings="${own.length}" title="${own.length} warning(s) below">⚠</span>` : '';
    return `<tr data-stage="${esc(s.method)}"><td>${esc(STAGE_LABEL[s.method] ?? s.method)}${mark}</td><td>${g(s.scale)}</td><td>${s.rmse == null ? '—' : g(s.rmse)}</td><td>${s.inlier_ratio == null ? '—' : s.inlier_ratio.toFixed(4)}</td><td>${s.iterations}</td><td>${rejected ? 'rejected' : s.converged ? 'yes' : 'no'}</td></tr>`;
  }).join('');
  $('stages').innerHTML = `<tr><th>stage</th><th>scale</th><th>rmse</th><th>inliers</th><th>iter</th><th>conv.</th></tr>${rows}`;
  $('matrix').textContent = matrixText(a.gt_from_recon);
  $('matrix').title = `gt_from_recon, full precision:\n${a.gt_from_recon.map((r) => r.join(' ')).join('\n')}`;
  $('matrix-wrap').hidden = false;
}

/** The statistics rows' headings (the report's keys stay in `data-row`). */
const ROW_LABEL = { accuracy: 'accuracy', completeness: 'completeness', signed: 'signed accuracy', completeness_visible: 'completeness (visible)', track_error: 'track error' };
/** The accuracy's distance (`accuracy.metric`) in words. */
const METRIC = { point_to_triangle: 'to the nearest triangle', point_to_point: 'to the nearest ground-truth point' };
/** The crop kinds (`crop.kind`) in words. */
const CROP_KIND = { none: 'none', box: 'box', sphere: 'sphere', polygon_prism: 'polygon prism' };
function statRow(label, st, extra) {
  const cells = [st.count, g(st.mean), g(st.median), g(st.rms), g(st.std), g(st.percentiles.p90), g(st.percentiles.p99), g(st.max)];
  return `<tr data-row="${label}"><th>${esc(ROW_LABEL[label] ?? label)}</th>${cells.map((c, i) => `<td data-k="${['count', 'mean', 'median', 'rms', 'std', 'p90', 'p99', 'max'][i]}">${c}</td>`).join('')}<td class="muted">${esc(extra)}</td></tr>`;
}
export function showResults(r) {
  const rep = r.report;
  state.shownResult = true;
  clearStale();
  const i = rep.inputs;
  const c = rep.crop;
  const a = rep.alignment;
  let h = `<div class="line">${esc(i.reconstruction.name)} (${esc(i.reconstruction.format)}, ${i.reconstruction.points} points) vs ${esc(i.ground_truth.name)} (${esc(i.ground_truth.format)}, ${i.ground_truth.vertices} vertices, ${i.ground_truth.triangles} triangles, bbox diagonal <span id="diag">${g(i.ground_truth.diagonal)}</span>) — ${r.ms.toFixed(0)} ms</div>`;
  h += `<div class="line">crop <b>${esc(CROP_KIND[c.kind] ?? c.kind)}</b>: kept <b id="r-kept">${c.kept}</b>, discarded <span id="r-discarded">${c.discarded}</span> (outside volume ${c.discarded_outside_volume}, farther than max distance ${c.discarded_farther_than_max_distance})</div>`;
  h += `<div class="line">alignment <b id="r-align">${esc(a.method)}</b> (scale <span id="r-scale">${g(a.scale)}</span>${a.rmse != null ? `, rmse ${g(a.rmse)}` : ''})</div>`;
  h += '<table id="stats"><tr><td></td><th>count</th><th>mean</th><th>median</th><th>rms</th><th>std</th><th>p90</th><th>p99</th><th>max</th><th class="muted">notes</th></tr>';
  h += statRow('accuracy', rep.accuracy, `recon → GT, ${METRIC[rep.accuracy.metric] ?? rep.accuracy.metric}`);
  h += statRow('completeness', rep.completeness, `GT → recon, ${rep.completeness.samples} samples`);
  if (rep.accuracy.signed) h += statRow('signed', rep.accuracy.signed, 'signed accuracy');
  const cv = rep.completeness_visible;
  if (cv) h += statRow('completeness_visible', cv, `GT → recon, ${cv.visible_samples} of ${cv.samples} samples seen by ≥ ${cv.min_views} images`);
  const te = rep.track_error;
  if (te && te.count) h += statRow('track_error', te, `true error through ${te.measured} of ${te.points} tracks`);
  const vis = cv ? new Map(cv.thresholds.map((t) => [t.tau, t])) : null;
  const sl = te ? new Map(te.thresholds.map((t) => [t.tau, t])) : null;
  h += `</table><table id="thresholds"><tr><th>tau</th><th>% diag</th><th>precision</th><th>recall</th><th>F-score</th>${vis ? '<th>recall (visible)</th><th>F (visible)</th>' : ''}${sl ? '<th>sliding</th>' : ''}</tr>`;
  for (const t of rep.thresholds) {
    const v = vis && vis.get(t.tau);
    const s = sl && sl.get(t.tau);
    h += `<tr><td>${g(t.tau)}</td><td>${t.tau_percent_of_diagonal.toFixed(3)}</td><td>${t.precision.toFixed(4)}</td><td>${t.recall.toFixed(4)}</td><td>${t.f_score.toFixed(4)}</td>`
      + `${vis ? `<td data-k="recall_visible">${v ? v.recall_visible.toFixed(4) : '—'}</td><td>${v ? v.f_score_visible.toFixed(4) : '—'}</td>` : ''}${sl ? `<td data-k="sliding">${s ? s.sliding_fraction.toFixed(4) : '—'}</td>` : ''}</tr>`;
  }
  h += '</table>';
  if (cv) h += `<div class="line" id="r-visible">visible surface: <b id="r-visible-fraction">${(100 * cv.visible_fraction).toFixed(2)} %</b> of the ground truth (seen by ≥ ${cv.min_views} of ${cv.views} images); coverage colours at τ = ${g(cv.labels_tau)}</div>`;
  if (rep.cameras) h += `<div class="line" id="r-cameras">${cameraLine(rep.cameras)}</div>`;
  h += notesHtml(reportNotes(rep));
  $('summary').innerHTML = h;
  showStages(rep);
  for (const b of ['dl-report', 'dl-ply', 'dl-csv']) $(b).disabled = false;
  // the curves and the τ slider read the sorted distances (sorted by the worker; a NaN
  // completeness distance, last, is never below τ and counts as missed)
  r.compTotal = r.completeness.length;
  r.tauMax = Math.max(rep.accuracy.percentiles.p95, rep.completeness.percentiles.p95, ...rep.thresholds.map((t) => t.tau)) * 1.5 || 1;
  histogramPlot($('hist'), rep.accuracy.histogram);
  state.curves = curvesPlot($('pr'), r);
  updateTau();
  drawColorbar(r.clip);
  showView('evaluation');
}

/** The camera section's counts and headline errors in words (the report's keys are for programs). */
function cameraLine(c) {
  const parts = [`${c.registered} of ${c.ground_truth} ground-truth images registered`, `${c.matched} matched by name`];
  if (c.unmatched_estimated) parts.push(`${c.unmatched_estimated} estimated without a ground-truth image`);
  if (c.models > 1) parts.push(`${c.models} models (the largest measured)`);
  if (c.matched) {
    parts.push(`ATE (RMSE) ${g(c.ate_rmse)}`);
    if (c.rotation_error_deg) parts.push(`rotation error median ${g(c.rotation_error_deg.median)}°`);
    if (c.center_error) parts.push(`centre error median ${g(c.center_error.median)}`);
  }
  return `cameras: ${parts.join(', ')}`;
}

// share strictly below tau in a sorted array (the core's share_below)
function below(sorted, tau, total) {
  let lo = 0, hi = sorted.length;
  while (lo < hi) { const mid = (lo + hi) >> 1; if (sorted[mid] < tau) lo = mid + 1; else hi = mid; }
  return total ? lo / total : 0;
}
export function prAt(r, tau) {
  const p = below(r.sortedKept, tau, r.sortedKept.length);
  const rc = below(r.sortedComp, tau, r.compTotal);
  return [p, rc, p + rc > 0 ? 2 * p * rc / (p + rc) : 0];
}
function updateTau() {
  const r = state.result;
  if (!r) return;
  const tau = r.tauMax * Number($('tau-slider').value) / 1000;
  const [p, rc, f] = prAt(r, tau);
  $('tau-value').textContent = g(tau);
  $('tau-readout').textContent = `precision ${p.toFixed(4)}  recall ${rc.toFixed(4)}  F ${f.toFixed(4)}`;
  if (state.curves) state.curves.mark(tau);
}
$('tau-slider').addEventListener('input', updateTau);
$('tau-add').onclick = () => {
  const r = state.result;
  if (!r) return;
  const tau = r.tauMax * Number($('tau-slider').value) / 1000;
  if (!(tau > 0)) return;
  $('tau').value = [...numList($('tau').value), Number(tau.toPrecision(6))].join(',');
  // keep the relative defaults when only absolute thresholds would remain
  if (!$('tau-rel').value.trim()) $('tau-rel').value = '0.5,1,2';
};

// colours
let colormap = null; // the core's colours, one per column of the colour bar (low end to top)
function drawColorbar(clip) {
  $('cb-hi').textContent = `≥ ${Number(clip.toPrecision(3))}`;
  $('cb-hi').title = `clip ${g(clip)}: this distance and larger are yellow`;
  $('colorbar').style.display = 'flex';
  const cv = $('colorbar-canvas');
  // the core's own map (the points' colours), one column each: no copy of it here
  const ready = colormap && colormap.length === 3 * cv.width ? Promise.resolve()
    : call(MSG.colormap, { n: cv.width }).then((r) => { colormap = r.colors; });
  ready.then(() => {
    const ctx = cv.getContext('2d');
    const img = ctx.createImageData(cv.width, cv.height);
    for (let i = 0; i < cv.width * cv.height; i++) {
      img.data.set(colormap.subarray(3 * (i % cv.width), 3 * (i % cv.width) + 3), 4 * i);
      img.data[4 * i + 3] = 255;
    }
    ctx.putImageData(img, 0, 0);
    cv.dataset.drawn = String(Number(cv.dataset.drawn || 0) + 1);
  }).catch(() => {}); // a worker stopped by Cancel: the next evaluation draws it
}
$('clip').addEventListener('change', async () => {
  const clip = Number($('clip').value);
  if (!state.result || !(clip > 0) || document.body.dataset.stale) return;
  const { colors } = await call(MSG.colors, { clip });
  state.result.colors = colors;
  state.result.clip = clip;
  drawColorbar(clip);
  refreshPoints();
});
/** The estimated cameras' colour scale beside the points' colour bar. */
export function showCameraScale(cams) {
  const el = $('cb-cams');
  el.hidden = !(cams && cams.estPoses);
  if (!el.hidden) el.textContent = `cameras: centre error 0 → ≥ ${Number(cams.camClip.toPrecision(3))} (same colours)`;
}

// downloads
const stem = () => (state.result ? state.result.report.inputs.reconstruction.name.replace(/\.[^.]*$/, '') : 'sfmeval');
$('dl-report').onclick = () => download(`${stem()}.report.json`, state.result.reportJson, 'application/json');
$('dl-ply').onclick = async () => {
  const { bytes } = await call(MSG.coloredPly, { clip: state.result.clip });
  download(`${stem()}.errors.ply`, bytes, 'application/octet-stream');
};
$('dl-csv').onclick = async () => {
  const { text } = await call(MSG.csv);
  download(`${stem()}.distances.csv`, text, 'text/csv');
};
