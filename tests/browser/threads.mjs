// The page's two WebAssembly builds in headless Chromium. On a cross-origin isolated server
// (scripts/serve_site.py) the page must load the threaded + SIMD128 build with the pool size
// asked for, and its reports must equal the CLI's byte for byte on the alignment paths of
// same-everywhere.mjs; on a server without the COOP/COEP headers it must fall back to the
// single-thread build, say why in the header, and still give the CLI's report.
// Usage: node threads.mjs --url ISOLATED_URL --plain-url NOT_ISOLATED_URL --cli target/release/sfmeval
//   --out DIR [--depth DIR]   (DIR holds same-everywhere.mjs's same-pairs.json and same-crop.json)
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const cli = resolve(args.cli);
const out = resolve(args.out);
const root = resolve(new URL('../..', import.meta.url).pathname);
const demo = (f) => join(root, 'data/demo', f);

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};
const firstDiff = (a, b) => {
  const x = a.split('\n'), y = b.split('\n');
  const i = x.findIndex((l, k) => l !== y[k]);
  return i < 0 ? 'lengths differ' : `line ${i + 1}: ${x[i]?.trim()} vs ${y[i]?.trim()}`;
};

const b64 = (buf) => buf.toString('base64');
const gtFiles = { 'ground_truth.glb': b64(readFileSync(demo('ground_truth.glb'))) };
const camFiles = { 'cameras.json': b64(readFileSync(demo('cameras.json'))) };
const model = {};
for (const f of readdirSync(demo('sparse'))) model[f] = b64(readFileSync(demo(`sparse/${f}`)));
const ply = { 'sparse.ply': b64(readFileSync(demo('sparse.ply'))) };
const depth = {};
if (args.depth) for (const f of readdirSync(args.depth)) depth[`depth/${f}`] = b64(readFileSync(join(args.depth, f)));
const pairsFile = join(out, 'same-pairs.json'), cropFile = join(out, 'same-crop.json');
const { pairs } = JSON.parse(readFileSync(pairsFile, 'utf8'));
const crop = JSON.parse(readFileSync(cropFile, 'utf8'));

// name, reconstruction, with GT cameras, CLI flags, page options (as same-everywhere.mjs)
const cases = [
  ['auto-model', 'model', true, [], {}],
  ['cameras+icp-model', 'model', true, ['--align', 'cameras+icp'], { align: 'cameras+icp' }],
  ['auto-ply-crop', 'ply', false, ['--align', 'auto', '--crop', cropFile], { align: 'auto', crop }],
  ['global-ply', 'ply', false, ['--align', 'global'], { align: 'global' }],
  ['points+icp-ply', 'ply', false, ['--align', 'points+icp', '--pairs', pairsFile], { align: 'points+icp', pairs }],
  ['none-ply-signed', 'ply', false, ['--align', 'none', '--signed'], { align: 'none', signed: true }],
];
if (args.depth) cases.push(['depth-model-min-views-3', 'model', true, ['--depth', resolve(args.depth), '--min-views', '3'], { min_views: 3 }]);

function cliJson(kind, withCams, flags) {
  const recon = kind === 'model' ? demo('sparse') : demo('sparse.ply');
  return execFileSync(cli, ['eval', '--gt', demo('ground_truth.glb'), '--recon', recon,
    ...(withCams ? ['--gt-cameras', demo('cameras.json')] : []), ...flags,
    '--samples', '200000', '--seed', '3', '--json', '--quiet'], { maxBuffer: 1 << 28 }).toString();
}

/** One evaluation through the page's worker (`window.sfmeval.call`), its report JSON text. */
async function pageReport(page, kind, withCams, withDepth, options) {
  return page.evaluate(async ({ gt, recon, name, cams, depthFiles, options }) => {
    const dec = (files) => Object.fromEntries(Object.entries(files).map(([n, b]) => [n, Uint8Array.from(atob(b), (c) => c.charCodeAt(0)).buffer]));
    const call = window.sfmeval.call;
    await call('loadGt', { files: dec(gt) });
    if (cams) await call('loadCameras', { files: dec(cams) }); else await call('clearCameras');
    if (depthFiles) await call('loadDepth', { files: dec(depthFiles) }); else await call('clearDepth');
    await call('loadRecon', { files: dec(recon), name });
    const r = await call('evaluate', { options: { ...options, samples: 200000, seed: 3 } });
    return r.reportJson;
  }, { gt: gtFiles, recon: kind === 'model' ? model : ply, name: kind === 'model' ? 'sparse' : 'sparse.ply', cams: withCams ? camFiles : null, depthFiles: withDepth ? depth : null, options });
}

/** What the page says about its core: threads, the note, isolation. */
async function pageState(page) {
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 120000 });
  return page.evaluate(() => ({
    isolated: self.crossOriginIsolated,
    threads: document.body.dataset.threads,
    version: document.getElementById('version').textContent,
    noteHidden: document.getElementById('threads-note').hidden,
    note: document.getElementById('threads-note').textContent,
  }));
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage'],
});
const errors = [];
const requested = [];
const open = async (url) => {
  const page = await browser.newPage();
  page.context().on('request', (r) => requested.push(new URL(r.url()).pathname));
  page.on('request', (r) => requested.push(new URL(r.url()).pathname));
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(url);
  return page;
};
try {
  // isolated, 2 threads: the threaded build, reports equal to the CLI's
  const page = await open(new URL('?threads=2', args.url).href);
  const s = await pageState(page);
  check('threads-isolated-loads-threaded-build', s.isolated === true && s.threads === '2' && s.noteHidden && /2 threads/.test(s.version), JSON.stringify(s));
  check('threads-isolated-fetches-sfmeval-mt', requested.some((p) => p.endsWith('/sfmeval-mt/sfmeval_wasm_bg.wasm')) && !requested.some((p) => p.endsWith('/sfmeval/sfmeval_wasm_bg.wasm')), requested.filter((p) => /\.(wasm|js)$/.test(p)).join(' '));
  for (const [name, kind, withCams, flags, options] of cases) {
    const want = cliJson(kind, withCams, flags).trimEnd();
    let got;
    try {
      got = (await pageReport(page, kind, withCams, flags.includes('--depth'), options)).trimEnd();
    } catch (e) { check(`threads-same-${name}`, false, `page failed: ${e.message}`); continue; }
    if (got !== want) {
      writeFileSync(join(out, `threads-${name}.page.json`), got);
      writeFileSync(join(out, `threads-${name}.cli.json`), want);
    }
    check(`threads-same-${name}`, got === want, firstDiff(got, want));
  }
  await page.close();

  // isolated, ?threads=0: the single-thread build, no note (threads were not asked for)
  const one = await open(new URL('?threads=0', args.url).href);
  const s1 = await pageState(one);
  check('threads-0-runs-single-thread-build', s1.isolated === true && s1.threads === '1' && s1.noteHidden, JSON.stringify(s1));
  await one.close();

  // no COOP/COEP: the fallback, with the note, and still the CLI's report
  const plain = await open(new URL('?threads=2', args['plain-url']).href);
  const s2 = await pageState(plain);
  check('threads-not-isolated-falls-back', s2.isolated === false && s2.threads === '1' && !s2.noteHidden && /not cross-origin isolated/.test(s2.note), JSON.stringify(s2));
  const want = cliJson('model', true, []).trimEnd();
  const got = (await pageReport(plain, 'model', true, false, {})).trimEnd();
  check('threads-not-isolated-same-auto-model', got === want, firstDiff(got, want));
  await plain.close();
  check('threads-no-page-errors', errors.length === 0, errors.slice(0, 3).join(' | '));
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
