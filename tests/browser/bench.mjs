// Speed of the page's wasm core in headless Chromium against the native CLI with one thread,
// in the same run. Workloads: 100k points near the demo ground truth (written here, seeded) and
// bench/data's cloud_1m.ply against mesh_1m.glb (bench/generate.py). Alignment none, default
// options (1M completeness samples). Not a test: prints a table.
// Usage: node bench.mjs --url http://127.0.0.1:PORT/ --cli target/release/sfmeval
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync, statSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { gzipSync } from 'node:zlib';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const root = resolve(new URL('../..', import.meta.url).pathname);
const cli = resolve(args.cli);
const work = join(root, 'target/web/bench');
mkdirSync(work, { recursive: true });

// 100k points on the demo GT's triangles, jittered (seeded LCG), in the GT frame.
const { init, loadGroundTruth } = await import(join(root, 'target/web/npm/index.js'));
await init();
const gt = loadGroundTruth({ 'ground_truth.glb': readFileSync(join(root, 'data/demo/ground_truth.glb')) });
const v = gt.vertices(), t = gt.triangles(), b = gt.bounds();
const diag = Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]);
let s = 12345;
const rnd = () => { s = (s * 1103515245 + 12345) % 2147483648; return s / 2147483648; };
const n = 100000;
const buf = Buffer.alloc(n * 12);
for (let i = 0; i < n; i++) {
  const k = Math.floor(rnd() * (t.length / 3));
  let u = rnd(), w = rnd();
  if (u + w > 1) { u = 1 - u; w = 1 - w; }
  for (let c = 0; c < 3; c++) {
    const a = v[3 * t[3 * k] + c], bb = v[3 * t[3 * k + 1] + c], cc = v[3 * t[3 * k + 2] + c];
    const p = a + u * (bb - a) + w * (cc - a) + (rnd() - 0.5) * 0.01 * diag;
    buf.writeFloatLE(p, 12 * i + 4 * c);
  }
}
const demo100k = join(work, 'demo_100k.ply');
writeFileSync(demo100k, Buffer.concat([Buffer.from(`ply\nformat binary_little_endian 1.0\nelement vertex ${n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n`), buf]));

const cases = [
  { name: '100k points vs demo GT', gt: join(root, 'data/demo/ground_truth.glb'), recon: demo100k },
  { name: '1M points vs 1M-triangle mesh', gt: join(root, 'bench/data/mesh_1m.glb'), recon: join(root, 'bench/data/cloud_1m.ply') },
].filter((c) => existsSync(c.gt) && existsSync(c.recon));

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage'],
});
const page = await browser.newPage();
await page.goto(args.url);
await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
const rows = [];
for (const c of cases) {
  // native, one thread, wall time of the whole command (read + index + measure + report)
  const t0 = process.hrtime.bigint();
  execFileSync(cli, ['eval', '--gt', c.gt, '--recon', c.recon, '--align', 'none', '--threads', '1', '--quiet', '--report', join(work, 'native.json')]);
  const native = Number(process.hrtime.bigint() - t0) / 1e6;
  // browser: the worker reads the bytes, then evaluates (what the page does)
  const files = { gt: readFileSync(c.gt), recon: readFileSync(c.recon) };
  const ms = await page.evaluate(async ({ gtName, reconName, gtB64, reconB64 }) => {
    const dec = (b) => Uint8Array.from(atob(b), (ch) => ch.charCodeAt(0)).buffer;
    const call = window.sfmeval.call;
    const t0 = performance.now();
    const g = dec(gtB64), r = dec(reconB64);
    const t1 = performance.now();
    await call('loadGt', { files: { [gtName]: g } }, [g]);
    await call('loadRecon', { files: { [reconName]: r }, name: reconName }, [r]);
    const t2 = performance.now();
    const res = await call('evaluate', { options: { align: 'none' } });
    const t3 = performance.now();
    return { read: t2 - t1, evaluate: t3 - t2, evalInWorker: res.ms, report: res.reportJson };
  }, { gtName: c.gt.split('/').pop(), reconName: c.recon.split('/').pop(), gtB64: files.gt.toString('base64'), reconB64: files.recon.toString('base64') });
  const same = ms.report === readFileSync(join(work, 'native.json'), 'utf8');
  const wasmTotal = ms.read + ms.evaluate;
  rows.push({ case: c.name, native_ms: Math.round(native), wasm_read_ms: Math.round(ms.read), wasm_eval_ms: Math.round(ms.evaluate), wasm_total_ms: Math.round(wasmTotal), ratio: (wasmTotal / native).toFixed(2), same_report: same });
}
await browser.close();
const wasm = join(root, 'target/web/pkg/sfmeval_wasm_bg.wasm');
const raw = statSync(wasm).size, gz = gzipSync(readFileSync(wasm), { level: 9 }).length;
console.log(`bench: wasm ${raw} bytes raw, ${gz} bytes gzipped`);
for (const r of rows) console.log(`bench: ${JSON.stringify(r)}`);
writeFileSync(join(work, 'bench.json'), JSON.stringify({ wasm_bytes: raw, wasm_gzip_bytes: gz, rows }, null, 2));
