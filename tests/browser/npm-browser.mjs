// The packed npm tarball in a bundler-free browser page: unpacks it next to a tiny index.html,
// serves that folder on 127.0.0.1, evaluates the demo in headless Chromium and compares the
// report with the CLI's. Usage: node npm-browser.mjs TARBALL CLI_REPORT.json WORKDIR
import { sameReport } from './same-report.mjs';
import { chromium } from 'playwright-core';
import { execFileSync, spawn } from 'node:child_process';
import { cpSync, mkdirSync, readFileSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

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
} finally {
  await browser.close();
  server.kill();
}
process.exit(failed ? 1 : 0);
