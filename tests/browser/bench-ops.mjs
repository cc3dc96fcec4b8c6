// Per-operation speed of the npm package (wasm, one thread) in Node and in headless Chromium
// against native sfmeval with one thread, in the same run and on the same files. Not a test:
// prints a markdown table. (`--no-chromium` skips the browser column.)
//
//   node tests/browser/bench-ops.mjs [--mesh bench/data/mesh_1m.ply] [--cloud bench/data/cloud_1m.ply]
//        [--samples 1000000] [--npm target/web/npm] [--bench-op target/release/examples/bench_op]
//        [--cli target/release/sfmeval]
//
// Needs scripts/build-web.sh (the npm package) and the native binaries (bench/compare.py builds
// them). Wasm stages are timed through the package's progress callback (a stage runs from its
// first call, at its start, to its last, at its finish):
//   load          loadGroundTruth + loadReconstruction (bytes already in memory; native `bench_op load`
//                 reads the files too)
//   bvh           "indexing ground truth"                       vs `bench_op bvh`
//   accuracy      bvh + "accuracy"                              vs `bench_op accuracy` (BVH build included)
//   completeness  sampling + k-d tree + completeness queries    vs `bench_op completeness`
//   eval          load + evaluate                               vs `sfmeval eval --threads 1` wall time
import { execFileSync, spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, join as pjoin, resolve } from 'node:path';

const root = resolve(new URL('../..', import.meta.url).pathname);
const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const mesh = resolve(args.mesh ?? join('bench/data/mesh_1m.ply'));
const cloud = resolve(args.cloud ?? join('bench/data/cloud_1m.ply'));
const samples = Number(args.samples ?? 1000000);
const npm = resolve(args.npm ?? join('target/web/npm'));
const benchOp = resolve(args['bench-op'] ?? join('target/release/examples/bench_op'));
const cli = resolve(args.cli ?? join('target/release/sfmeval'));
function join(p) { return resolve(root, p); }

const { init, loadGroundTruth, loadReconstruction, evaluate } = await import(resolve(npm, 'index.js'));
await init();

// ---- wasm in Node ------------------------------------------------------------------------
const bytes = { gt: readFileSync(mesh), recon: readFileSync(cloud) };
let t = performance.now();
const gt = loadGroundTruth({ [basename(mesh)]: bytes.gt });
const recon = loadReconstruction({ [basename(cloud)]: bytes.recon });
const loadMs = performance.now() - t;
const span = {}; // stage → [first call, last call]: start() and finish() both call back
t = performance.now();
const ev = evaluate({
  gt, recon, options: { align: 'none', samples },
  onProgress: (stage) => { const now = performance.now(); span[stage] = [span[stage]?.[0] ?? now, now]; },
});
const evalMs = performance.now() - t;
const stageMs = Object.fromEntries(Object.entries(span).map(([k, [a, b]]) => [k, b - a]));
const report = ev.report;
const get = (re) => Object.entries(stageMs).filter(([k]) => re.test(k)).reduce((s, [, v]) => s + v, 0);
const wasm = {
  load: loadMs,
  bvh: get(/indexing ground/),
  accuracy: get(/indexing ground|accuracy/),
  completeness: get(/sampling|indexing reconstruction|completeness/),
  eval: loadMs + evalMs,
};

// ---- the same stages through the same package in headless Chromium --------------------------
// The measuring code runs in the page; the files are served from 127.0.0.1 with the package.
async function inChromium() {
  const { chromium } = await import('playwright-core');
  const dir = mkdtempSync(pjoin(tmpdir(), 'sfmeval-bench-ops-web-'));
  symlinkSync(npm, pjoin(dir, 'sfmeval'));
  symlinkSync(mesh, pjoin(dir, 'gt.' + mesh.split('.').pop()));
  symlinkSync(cloud, pjoin(dir, 'recon.' + cloud.split('.').pop()));
  writeFileSync(pjoin(dir, 'index.html'), `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,">
<script type="module">
import { init, loadGroundTruth, loadReconstruction, evaluate } from './sfmeval/index.js';
const bytes = async (u) => new Uint8Array(await (await fetch(u)).arrayBuffer());
try {
  await init();
  const g = await bytes('gt.${mesh.split('.').pop()}'), c = await bytes('recon.${cloud.split('.').pop()}');
  let t = performance.now();
  const gt = loadGroundTruth({ '${basename(mesh)}': g });
  const recon = loadReconstruction({ '${basename(cloud)}': c });
  const loadMs = performance.now() - t;
  const span = {};
  t = performance.now();
  const ev = evaluate({ gt, recon, options: { align: 'none', samples: ${samples} },
    onProgress: (stage) => { const now = performance.now(); span[stage] = [span[stage]?.[0] ?? now, now]; } });
  window.result = { loadMs, evalMs: performance.now() - t, span, acc: ev.report.accuracy.mean, comp: ev.report.completeness.mean };
} catch (e) { window.result = { error: String(e && e.message || e) }; }
</script>`);
  const port = 20000 + Math.floor(Math.random() * 20000);
  const server = spawn('python3', ['-m', 'http.server', String(port), '--bind', '127.0.0.1', '--directory', dir], { stdio: 'ignore' });
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
  try {
    const page = await browser.newPage();
    for (let i = 0; i < 50; i++) {
      try { await page.goto(`http://127.0.0.1:${port}/`); break; } catch { await new Promise((r) => setTimeout(r, 100)); }
    }
    await page.waitForFunction(() => window.result, null, { timeout: 600000 });
    const r = await page.evaluate(() => window.result);
    if (r.error) throw new Error(`in Chromium: ${r.error}`);
    const ms = Object.fromEntries(Object.entries(r.span).map(([k, [a, b]]) => [k, b - a]));
    const sum = (re) => Object.entries(ms).filter(([k]) => re.test(k)).reduce((s, [, v]) => s + v, 0);
    return {
      ms: { load: r.loadMs, bvh: sum(/indexing ground/), accuracy: sum(/indexing ground|accuracy/),
        completeness: sum(/sampling|indexing reconstruction|completeness/), eval: r.loadMs + r.evalMs },
      same: r.acc === report.accuracy.mean && r.comp === report.completeness.mean,
    };
  } finally {
    await browser.close();
    server.kill();
    rmSync(dir, { recursive: true, force: true });
  }
}
const chrome = process.argv.includes('--no-chromium') ? null : await inChromium();

// ---- native, one thread --------------------------------------------------------------------
const op = (name) => JSON.parse(execFileSync(benchOp, [name, '--mesh', mesh, '--cloud', cloud, '--samples', String(samples), '--threads', '1']).toString().trim().split('\n').pop());
const native = {};
const nativeResult = {};
for (const name of ['load', 'bvh', 'accuracy', 'completeness']) {
  const r = op(name);
  native[name] = r.seconds * 1000;
  nativeResult[name] = r.result;
}
// The CLI writes its report atomically (temporary file + rename): never point it at /dev/null.
const scratch = mkdtempSync(pjoin(tmpdir(), 'sfmeval-bench-ops-'));
t = performance.now();
execFileSync(cli, ['eval', '--gt', mesh, '--recon', cloud, '--samples', String(samples), '--threads', '1', '--align', 'none', '--quiet', '--report', pjoin(scratch, 'report.json')]);
native.eval = performance.now() - t;
rmSync(scratch, { recursive: true, force: true });

// ---- table ---------------------------------------------------------------------------------
const same = Math.abs(report.accuracy.mean - nativeResult.accuracy.mean) <= 1e-12 * nativeResult.accuracy.mean
  && Math.abs(report.completeness.mean - nativeResult.completeness.mean) <= 1e-12 * nativeResult.completeness.mean;
console.log(`\nwasm (Node ${process.version}${chrome ? ' and headless Chromium' : ''}, one thread) vs native sfmeval --threads 1: \`${basename(cloud)}\` vs \`${basename(mesh)}\`, ${samples} samples; `
  + `accuracy/completeness means ${same && (!chrome || chrome.same) ? 'identical' : 'DIFFER'} (${report.accuracy.mean} / ${report.completeness.mean})\n`);
console.log(`| operation | wasm in Node ms | ${chrome ? 'wasm in Chromium ms | ' : ''}native 1 thread ms | Node ÷ native |${chrome ? ' Chromium ÷ native |' : ''}`);
console.log(`|---|---|${chrome ? '---|' : ''}---|---|${chrome ? '---|' : ''}`);
for (const k of Object.keys(wasm)) {
  const c = chrome ? ` ${chrome.ms[k].toFixed(0)} |` : '';
  const cr = chrome ? ` ${(chrome.ms[k] / native[k]).toFixed(2)}× |` : '';
  console.log(`| ${k} | ${wasm[k].toFixed(0)} |${c} ${native[k].toFixed(0)} | ${(wasm[k] / native[k]).toFixed(2)}× |${cr}`);
}
if (!same || (chrome && !chrome.same)) process.exit(1);
