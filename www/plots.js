// Plots with uPlot: the accuracy histogram and precision/recall/F against τ.
import uPlot from 'uplot';

const plots = new Map();
function replace(el, plot) {
  const old = plots.get(el);
  if (old) old.destroy();
  plots.set(el, plot);
}
const width = (el) => Math.max(260, el.clientWidth || 360);

/**
 * Draws `{edges, counts}` as bars; values beyond the last edge (`overflow`, a long tail past
 * p99) or below the first (`underflow`) are named in a caption under the plot.
 */
export function histogramPlot(el, hist) {
  const centers = hist.counts.map((_, i) => (hist.edges[i] + hist.edges[i + 1]) / 2);
  const opts = {
    width: width(el), height: 200,
    legend: { show: false },
    scales: { x: { time: false } },
    axes: [{ label: 'distance' }, { label: 'points' }],
    series: [{}, { label: 'points', stroke: '#4fc3f7', fill: 'rgba(79,195,247,0.35)', paths: uPlot.paths.bars({ size: [1, Infinity], gap: 1 }), points: { show: false } }],
  };
  const plot = new uPlot(opts, [centers, hist.counts], el);
  replace(el, plot);
  const fmt = (v) => Number(v).toPrecision(3);
  const notes = [];
  if (hist.underflow) notes.push(`${hist.underflow} below ${fmt(hist.edges[0])}`);
  if (hist.overflow) notes.push(`${hist.overflow} beyond ${fmt(hist.edges[hist.edges.length - 1])} (the long tail past p99)`);
  let cap = el.parentElement && el.parentElement.querySelector('.hist-tail');
  if (!cap && el.parentElement) {
    cap = document.createElement('div');
    cap.className = 'hist-tail';
    el.parentElement.appendChild(cap);
  }
  if (cap) cap.textContent = notes.length ? `not shown: ${notes.join(', ')}` : '';
  return plot;
}

/**
 * Precision, recall and F against τ from the sorted kept distances and completeness distances
 * of an evaluation (`r.sortedKept`, `r.sortedComp`, `r.compTotal`, `r.tauMax`). Returns an
 * object with `mark(tau)` that moves the τ cursor.
 */
export function curvesPlot(el, r) {
  const n = 200;
  const xs = [], ps = [], rs = [], fs = [];
  const below = (s, tau, total) => {
    let lo = 0, hi = s.length;
    while (lo < hi) { const m = (lo + hi) >> 1; if (s[m] < tau) lo = m + 1; else hi = m; }
    return total ? lo / total : 0;
  };
  for (let i = 0; i <= n; i++) {
    const tau = (r.tauMax * i) / n;
    const p = below(r.sortedKept, tau, r.sortedKept.length);
    const rc = below(r.sortedComp, tau, r.compTotal);
    xs.push(tau); ps.push(p); rs.push(rc); fs.push(p + rc > 0 ? (2 * p * rc) / (p + rc) : 0);
  }
  let marked = null;
  const opts = {
    width: width(el), height: 200,
    // a key of the three curves only: the values at τ are the slider's readout under the plot
    legend: { live: false },
    scales: { x: { time: false }, y: { range: [0, 1] } },
    axes: [{ label: 'τ' }, {}],
    series: [{ label: 'τ' },
      { label: 'precision', stroke: '#ff7043', width: 2 },
      { label: 'recall', stroke: '#66bb6a', width: 2 },
      { label: 'F', stroke: '#ffee58', width: 2 }],
    hooks: {
      draw: [(u) => {
        if (marked == null) return;
        const x = u.valToPos(marked, 'x', true);
        const ctx = u.ctx;
        ctx.save();
        ctx.strokeStyle = '#ffffff';
        ctx.setLineDash([4, 4]);
        ctx.beginPath();
        ctx.moveTo(x, u.bbox.top);
        ctx.lineTo(x, u.bbox.top + u.bbox.height);
        ctx.stroke();
        ctx.restore();
      }],
    },
  };
  const plot = new uPlot(opts, [xs, ps, rs, fs], el);
  replace(el, plot);
  return { plot, mark(tau) { marked = tau; plot.redraw(false); } };
}
