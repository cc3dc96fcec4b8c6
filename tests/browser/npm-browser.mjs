// The packed npm tarball in a bundler-free browser page: unpacks it next to a tiny index.html,
// serves that folder on 127.0.0.1, evaluates the demo in headless Chromium and compares the
// report with the CLI's; then runs the README's browser example as the package ships it
// (readme.html beside the demo's ground_truth.glb and sparse.ply) and compares the report it
// shows with the package's in Node for the same inputs and options.
// Usage: node npm-browser.mjs TARBALL CLI_REPORT.json WORKDIR
import { sameReport } from './same-report.mjs';
import { chromium } from 'playwright-core';
import { execFileSync, spawn } from 'node:child_process';
import { cpSync, mkdirSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [tarball, cliReport, workArg] = process.argv.slice(2).map((p) => resolve(p));
const root = resolve(new URL('../..', import.meta.url).pathname);
const work = join(workArg, 'npm-browser');
rmSync(work, { recursive: true, force: true });
mkdirSync(join(work, 'node_modules/sfmeval'), { recursive: true });
execFileSync('tar', ['xzf', tarball, '-C', join(work, 'node_modules/sfmeval'), '--strip-components=1']);
cpSync(join(root, 'data/demo'), join(work, 'demo'), { recursive: true });
const model = readdirSync(join(root, 'data/demo/sparse'));
writeFileSync(join(work, 'index.html'), `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,">
<pre id="out"></pre>
<script type="module">
import { init, evaluate, loadReconstruction } from './node_modules/sfmeval/index.js';
const bytes = async (u) => new Uint8Array(await (await fetch(u)).arrayBuffer());
try {
  await init();
  const model = {};
  for (const f of ${JSON.stringify(model)}) model[f] = await bytes('demo/sparse/' + f);
  const r = evaluate({
    gt: { 'ground_truth.glb': await bytes('demo/ground_truth.glb') },
    recon: loadReconstruction(model, 'sparse'),
    gtCameras: { 'cameras.json': await bytes('demo/cameras.json') },
  });
  document.getElementById('out').textContent = r.reportJson;
} catch (e) { document.getElementById('out').textContent = 'ERROR ' + e.message; }
document.body.dataset.done = '1';
</script>`);

// the README's browser example: its first ```html block, as a page of its own
const readme = readFileSync(join(work, 'node_modules/sfmeval/README.md'), 'utf8');
const section = readme.split('\n## Example (browser, no bundler)\n')[1]?.split('\n## ')[0] ?? '';
const htmlExample = section.match(/```html\n([\s\S]*?\n)```\n/)?.[1];
if (htmlExample) writeFileSync(join(work, 'readme.html'), htmlExample);
cpSync(join(root, 'data/demo/ground_truth.glb'), join(work, 'ground_truth.glb'));
cpSync(join(root, 'data/demo/sparse.ply'), join(work, 'sparse.ply'));

const port = 20000 + Math.floor(Math.random() * 20000);
const server = spawn('python3', ['-m', 'http.server', String(port), '--bind', '127.0.0.1', '--directory', work], { stdio: 'ignore' });
let failed = 0;
const check = (name, ok, why = '') => { if (ok) console.log(`ok ${name}`); else { failed++; console.log(`FAILED ${name}: ${why}`); } };
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: ['--no-sandbox'] });
try {
  const page = await browser.newPage();
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  for (let i = 0; i < 50; i++) {
    try { await page.goto(`http://127.0.0.1:${port}/`); break; } catch { await new Promise((r) => setTimeout(r, 100)); }
  }
  await page.waitForFunction(() => document.body.dataset.done === '1', null, { timeout: 120000 });
  const text = await page.textContent('#out');
  const expected = readFileSync(cliReport, 'utf8');
  check('npm-tarball-in-browser-runs', !text.startsWith('ERROR'), text.slice(0, 300));
  const diff = text.split('\n').filter((l, i) => l !== expected.split('\n')[i]);
  const same = sameReport(text, expected);
  console.log(`note: npm-tarball-in-browser: ${same.detail}`);
  check('npm-tarball-in-browser-report-equals-cli', same.ok, `${diff.length} lines differ, first: ${diff[0]?.trim()}`);
  check('npm-tarball-in-browser-local-only', requests.every((u) => u.startsWith(`http://127.0.0.1:${port}/`) || u.startsWith('data:')), requests.join(' '));

  check('npm-readme-browser-example-found', htmlExample?.includes("from './node_modules/sfmeval/index.js'"), String(htmlExample));
  if (htmlExample) {
    const errors = [];
    const thrown = new Promise((done) => page.on('pageerror', (e) => { errors.push(e.message); done(); }));
    await page.goto(`http://127.0.0.1:${port}/readme.html`);
    // it writes the report into the body; an exception ends it without
    await Promise.race([thrown, page.waitForFunction(() => document.body?.textContent.trim().endsWith('}'), null, { timeout: 120000 })
      .catch((e) => errors.push(e.message))]);
    const shown = errors.length ? '' : await page.evaluate(() => document.body.textContent);
    // the same evaluation with the same package in Node (same wasm, same bytes)
    const sfmeval = await import(pathToFileURL(join(work, 'node_modules/sfmeval/index.js')).href);
    await sfmeval.init();
    const r = sfmeval.evaluate({
      gt: { 'ground_truth.glb': readFileSync(join(root, 'data/demo/ground_truth.glb')) },
      recon: { 'sparse.ply': readFileSync(join(root, 'data/demo/sparse.ply')) },
      options: { align: 'auto' },
    });
    check('npm-readme-browser-example-shows-the-report', !errors.length && shown === r.reportJson && r.report.accuracy.count > 0,
      errors.join('; ') || `shown ${shown.length} bytes vs the package's ${r.reportJson.length} in Node: ${shown.slice(0, 200)}`);
    r.free();
  }
} finally {
  await browser.close();
  server.kill();
}
process.exit(failed ? 1 : 0);
