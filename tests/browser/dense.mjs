// A dense binary PLY cloud in the page: streamed into the worker a piece at a time (progress
// shown, the page answering throughout), evaluated to the CLI's report byte for byte; and a
// cloud too large for the page refused from its header with a clear message, the page still
// usable after it.
// Usage: node dense.mjs --url http://127.0.0.1:PORT/ --cli target/release/sfmeval --out DIR
//        [--points N]   (default 2 500 000; the benchmark uses 10 000 000)
// Prints "ok NAME" / "FAILED NAME: why" lines and "note:" lines with the times.
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { closeSync, openSync, readFileSync, writeSync, ftruncateSync, mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { sameReport } from './same-report.mjs';

/** The viewer's MAX_DRAWN_POINTS (www/viewer.js imports three.js, which Node cannot load here). */
const MAX_DRAWN_POINTS = Number(/export const MAX_DRAWN_POINTS = ([\d_]+);/.exec(
  readFileSync(new URL('../../www/viewer.js', import.meta.url), 'utf8'))[1].replaceAll('_', ''));

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const cli = resolve(args.cli);
const out = resolve(args.out);
// (the default is past the viewer's cap of drawn points, so that the cap is exercised)
const points = Number(args.points ?? 2_500_000);
mkdirSync(out, { recursive: true });
const root = resolve(new URL('../..', import.meta.url).pathname);
const demo = (f) => join(root, 'data/demo', f);

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};

/** The demo's sparse cloud (binary, x y z float, red green blue uchar) as [x, y, z, r, g, b]. */
function demoPoints() {
  const bytes = readFileSync(demo('sparse.ply'));
  const end = bytes.indexOf('end_header\n') + 'end_header\n'.length;
  const n = Number(/element vertex (\d+)/.exec(bytes.subarray(0, end).toString())[1]);
  const v = new DataView(bytes.buffer, bytes.byteOffset + end);
  return Array.from({ length: n }, (_, i) => [0, 4, 8].map((o) => v.getFloat32(15 * i + o, true))
    .concat([12, 13, 14].map((o) => v.getUint8(15 * i + o))));
}

/** Writes `n` points around the demo's cloud (deterministic jitter) as a binary PLY. */
function writeDense(path, n) {
  const src = demoPoints();
  const header = Buffer.from(`ply\nformat binary_little_endian 1.0\ncomment sfmeval dense test\nelement vertex ${n}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n`);
  const fd = openSync(path, 'w');
  writeSync(fd, header);
  const per = 1 << 16;
  const buf = Buffer.alloc(15 * per);
  let h = 0x9e3779b9;
  const rnd = () => { h ^= h << 13; h >>>= 0; h ^= h >>> 17; h ^= h << 5; h >>>= 0; return h / 4294967296 - 0.5; };
  for (let start = 0; start < n; start += per) {
    const m = Math.min(per, n - start);
    for (let k = 0; k < m; k++) {
      const p = src[(start + k) % src.length];
      for (let a = 0; a < 3; a++) buf.writeFloatLE(p[a] + 0.004 * rnd(), 15 * k + 4 * a);
      for (let a = 0; a < 3; a++) buf.writeUInt8(p[3 + a], 15 * k + 12 + a);
    }
    writeSync(fd, buf, 0, 15 * m);
  }
  closeSync(fd);
}

/** A file declaring `n` points of 15 bytes at its full size, its body never written (sparse). */
function writeHuge(path, n) {
  const header = Buffer.from(`ply\nformat binary_little_endian 1.0\nelement vertex ${n}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n`);
  const fd = openSync(path, 'w');
  writeSync(fd, header);
  ftruncateSync(fd, header.length + 15 * n);
  closeSync(fd);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage'],
});
const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
const consoleErrors = [];
page.on('pageerror', (e) => consoleErrors.push(String(e)));

try {
  const densePath = join(out, `dense_${points}.ply`);
  writeDense(densePath, points);
  const identity = join(out, 'identity.txt');
  execFileSync('sh', ['-c', `printf '1 0 0 0\\n0 1 0 0\\n0 0 1 0\\n0 0 0 1\\n' > '${identity}'`]);

  await page.goto(args.url);
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
  await page.setInputFiles('#file-gt', demo('ground_truth.glb'));
  await page.waitForFunction(() => /ground_truth\.glb/.test(document.getElementById('info-gt').textContent));

  // Record what the progress line says while the file streams in.
  await page.evaluate(() => {
    window.__progressSeen = [];
    new MutationObserver(() => window.__progressSeen.push(document.getElementById('progress-text').textContent))
      .observe(document.getElementById('progress-text'), { childList: true, characterData: true, subtree: true });
  });
  const t0 = Date.now();
  await page.setInputFiles('#file-recon', densePath);
  // The main thread keeps answering while the worker reads: the slowest round trip of a
  // trivial call during the load.
  let slowest = 0;
  for (;;) {
    const s = Date.now();
    const info = await page.evaluate(() => document.getElementById('info-recon').textContent);
    slowest = Math.max(slowest, Date.now() - s);
    if (/points/.test(info) || await page.textContent('#error')) break;
    if (Date.now() - t0 > 600000) throw new Error('the dense cloud did not load in 10 minutes');
    await new Promise((r) => setTimeout(r, 50));
  }
  const loadMs = Date.now() - t0;
  // ...and while the loaded cloud is first drawn (the next frames)
  for (const until = Date.now() + 2000; Date.now() < until;) {
    const s = Date.now();
    await page.evaluate(() => document.getElementById('info-recon').textContent);
    slowest = Math.max(slowest, Date.now() - s);
    await new Promise((r) => setTimeout(r, 50));
  }
  const err = await page.textContent('#error');
  check('dense-loads', !err && new RegExp(`${points} points`).test(await page.textContent('#info-recon')), err || await page.textContent('#info-recon'));
  const seen = await page.evaluate(() => window.__progressSeen);
  check('dense-progress-shown', seen.some((t) => /^reading/.test(t)), JSON.stringify(seen.slice(0, 5)));
  check('dense-page-answers-while-reading', slowest < 1000, `slowest round trip ${slowest} ms`);
  // past the viewer's cap every k-th point is drawn (the fewest k that fit), and the page says so
  const drawn = await page.evaluate(() => ({ ...window.sfmevalViewer.drawn, note: document.getElementById('drawn-note').textContent }));
  const stride = Math.ceil(points / MAX_DRAWN_POINTS);
  check('dense-drawn-within-the-cap', drawn.total === points && drawn.stride === stride && drawn.count === Math.ceil(points / stride)
    && drawn.count <= MAX_DRAWN_POINTS && (stride > 1 ? drawn.note.includes(`of ${points.toLocaleString('en')}`) : drawn.note === ''), JSON.stringify(drawn));

  await page.check('input[name=align][value=given]');
  await page.fill('#transform', readFileSync(identity, 'utf8'));
  const before = Number(await page.evaluate(() => document.body.dataset.evaluated || 0));
  await page.evaluate(() => { window.__progressSeen = []; });
  const t1 = Date.now();
  await page.click('#run');
  await page.waitForFunction((n) => Number(document.body.dataset.evaluated || 0) > n || document.getElementById('error').textContent, before, { timeout: 1200000 });
  const evalMs = Date.now() - t1;
  const runErr = await page.textContent('#error');
  check('dense-evaluates', !runErr, runErr);
  // progress moves during the run, also in the threaded build (whose pool's threads write
  // shared counters the page reads): some stage seen part-way
  const during = await page.evaluate(() => window.__progressSeen);
  const partway = during.map((t) => /^(.*\S) (\d+)\/(\d+)$/.exec(t)).filter((m) => m && Number(m[2]) > 0 && Number(m[2]) < Number(m[3]));
  check('dense-progress-during-evaluation', partway.length > 0, JSON.stringify(during.slice(0, 8)));
  const threads = await page.textContent('#version');
  console.log(`note: dense evaluation on ${threads}; progress seen part-way ${partway.length} times (${[...new Set(partway.map((m) => m[1]))].join(', ')})`);
  const pageReport = await page.evaluate(() => window.sfmeval.state.result.reportJson);
  const cliReport = join(out, 'cli-dense.json');
  const tc = Date.now();
  execFileSync(cli, ['eval', '--gt', demo('ground_truth.glb'), '--recon', densePath, '--transform', identity, '--quiet', '--report', cliReport]);
  const cliMs = Date.now() - tc;
  const same = sameReport(pageReport, readFileSync(cliReport, 'utf8'));
  check('dense-report-equals-cli', same.ok, same.detail);
  console.log(`note: dense ${points} points: page read ${(loadMs / 1000).toFixed(1)} s + evaluate ${(evalMs / 1000).toFixed(1)} s = ${((loadMs + evalMs) / 1000).toFixed(1)} s; CLI whole process ${(cliMs / 1000).toFixed(1)} s; ratio ${((loadMs + evalMs) / cliMs).toFixed(2)}`);

  // Too large for the page: refused from the header, before reading the points.
  const hugeN = 40_000_000;
  const hugePath = join(out, 'huge_40m.ply');
  writeHuge(hugePath, hugeN);
  const t2 = Date.now();
  await page.setInputFiles('#file-recon', hugePath);
  await page.waitForFunction(() => document.getElementById('error').textContent, null, { timeout: 60000 });
  const hugeErr = await page.textContent('#error');
  check('huge-refused-clearly', /40\.0 M points do not fit this page/.test(hugeErr) && /sfmeval eval/.test(hugeErr), hugeErr);
  check('huge-refused-fast', Date.now() - t2 < 20000, `${Date.now() - t2} ms`);
  check('huge-not-fatal', !(await page.evaluate(() => document.body.dataset.fatal)), 'the worker died');
  // and the page goes on: the demo cloud loads again
  await page.setInputFiles('#file-recon', demo('sparse.ply'));
  await page.waitForFunction(() => /sparse\.ply/.test(document.getElementById('info-recon').textContent), null, { timeout: 60000 });
  check('page-usable-after-refusal', true);
  check('no-page-errors', consoleErrors.length === 0, consoleErrors.join(' | '));
} catch (e) {
  check('dense', false, e.stack || String(e));
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
