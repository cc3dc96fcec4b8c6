// Speed of the page's wasm core in headless Chromium against the native CLI, in the same run:
// the page with threads off (`?threads=0`, the single-thread scalar build) and on (`?threads=N`,
// the threaded + SIMD128 build, N = --threads, default 2) against `sfmeval eval --threads 1` and
// `--threads N`. Workloads: 100k points near the demo ground truth (written here, seeded) and
// bench/data's cloud_1m.ply against mesh_1m.glb (bench/generate.py). Alignment none, default
// options (1M completeness samples); median of --rounds (default 1). Not a test: prints a table.
// The page must be served cross-origin isolated (scripts/serve_site.py).
// Usage: node bench.mjs --url http://127.0.0.1:PORT/ --cli target/release/sfmeval [--threads N] [--rounds R]
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
const threads = Number(args.threads ?? 2);
const rounds = Number(args.rounds ?? 1);
const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const pages = {};
for (const [key, n] of [['off', 0], ['on', threads]]) {
  const page = await browser.newPage();
  await page.goto(new URL(`?threads=${n}`, args.url).href);
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
  const got = await page.evaluate(() => document.body.dataset.threads);
  if (Number(got) !== Math.max(n, 1)) throw new Error(`page with ?threads=${n} runs ${got} threads (is the server cross-origin isolated?)`);
  pages[key] = page;
}
// native, wall time of the whole command (read + index + measure + report)
function native(c, n) {
  const t0 = process.hrtime.bigint();
  execFileSync(cli, ['eval', '--gt', c.gt, '--recon', c.recon, '--align', 'none', '--threads', String(n), '--quiet', '--report', join(work, 'native.json')]);
  return Number(process.hrtime.bigint() - t0) / 1e6;
}
// browser: the worker reads the bytes, then evaluates (what the page does)
async function inPage(page, c, files) {
  return page.evaluate(async ({ gtName, reconName, gtB64, reconB64 }) => {
    const dec = (b) => Uint8Array.from(atob(b), (ch) => ch.charCodeAt(0)).buffer;
    const call = window.sfmeval.call;
    const g = dec(gtB64), r = dec(reconB64);
    const t1 = performance.now();
    await call('loadGt', { files: { [gtName]: g } }, [g]);
    await call('loadRecon', { files: { [reconName]: r }, name: reconName }, [r]);
    const t2 = performance.now();
    const res = await call('evaluate', { options: { align: 'none' } });
    const t3 = performance.now();
    return { read: t2 - t1, evaluate: t3 - t2, report: res.reportJson };
  }, { gtName: c.gt.split('/').pop(), reconName: c.recon.split('/').pop(), gtB64: files.gt.toString('base64'), reconB64: files.recon.toString('base64') });
}
const rows = [];
for (const c of cases) {
  const files = { gt: readFileSync(c.gt), recon: readFileSync(c.recon) };
  const t = { native1: [], nativeN: [], off: [], on: [] };
  let same = true;
  for (let k = 0; k < rounds; k++) {
    t.native1.push(native(c, 1));
    const want = readFileSync(join(work, 'native.json'), 'utf8');
    t.nativeN.push(native(c, threads));
    same &&= readFileSync(join(work, 'native.json'), 'utf8') === want;
    for (const key of ['off', 'on']) {
      const ms = await inPage(pages[key], c, files);
      t[key].push(ms.read + ms.evaluate);
      same &&= ms.report === want;
    }
  }
  const m = Object.fromEntries(Object.entries(t).map(([k, v]) => [k, median(v)]));
  rows.push({
    case: c.name, threads, rounds, native_1t_ms: Math.round(m.native1), [`native_${threads}t_ms`]: Math.round(m.nativeN),
    chromium_off_ms: Math.round(m.off), [`chromium_on_${threads}t_ms`]: Math.round(m.on),
    off_vs_native_1t: (m.off / m.native1).toFixed(2), off_vs_native_nt: (m.off / m.nativeN).toFixed(2),
    on_vs_native_nt: (m.on / m.nativeN).toFixed(2), same_report: same,
  });
}
await browser.close();
const sizes = {};
for (const [key, dir] of [['single', 'pkg'], ['threaded', 'pkg-mt']]) {
  const wasm = join(root, `target/web/${dir}/sfmeval_wasm_bg.wasm`);
  if (!existsSync(wasm)) continue;
  sizes[key] = { bytes: statSync(wasm).size, gzip_bytes: gzipSync(readFileSync(wasm), { level: 9 }).length };
  console.log(`bench: ${key} wasm ${sizes[key].bytes} bytes raw, ${sizes[key].gzip_bytes} bytes gzipped`);
}
for (const r of rows) console.log(`bench: ${JSON.stringify(r)}`);
writeFileSync(join(work, 'bench.json'), JSON.stringify({ wasm: sizes, rows }, null, 2));
