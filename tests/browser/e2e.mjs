// End-to-end test of the page in Debian's Chromium driven by playwright-core.
// Usage: node e2e.mjs --url http://127.0.0.1:PORT/ --cli target/release/sfmeval --out DIR
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { chromium } from 'playwright-core';
import { execFileSync } from 'node:child_process';
import { readFileSync, readdirSync, writeFileSync, mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { sameReport } from './same-report.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const url = args.url;
const cli = resolve(args.cli);
const out = resolve(args.out);
mkdirSync(out, { recursive: true });
const root = resolve(new URL('../..', import.meta.url).pathname);
const demo = (f) => join(root, 'data/demo', f);
const origin = new URL(url).origin;

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};
const noteSame = (name, a, b) => {
  const r = sameReport(a, b);
  console.log(`note: ${name}: ${r.detail}`);
  return r.ok;
};
const cliReport = (extra, name) => {
  const file = join(out, name);
  execFileSync(cli, ['eval', '--gt', demo('ground_truth.glb'), '--quiet', '--report', file, ...extra]);
  return readFileSync(file, 'utf8');
};
/** The first differing line of two texts, for failure messages. */
function firstDiff(a, b) {
  const x = a.split('\n'), y = b.split('\n');
  const i = x.findIndex((l, k) => l !== y[k]);
  return i < 0 ? (x.length === y.length ? 'equal' : 'lengths differ') : `line ${i + 1}: ${x[i]?.trim()} vs ${y[i]?.trim()} (${x.filter((l, k) => l !== y[k]).length} lines differ)`;
}
/** The CLI summary's number format. */
function g(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e-3 && a < 1e5) return v.toFixed(6);
  return v.toExponential(4).replace('e+', 'e');
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage'],
});
const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1400, height: 900 } });
const page = await context.newPage();
const requests = [];
page.on('request', (r) => requests.push(r.url()));
context.on('request', (r) => requests.push(r.url()));
const consoleErrors = [];
page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
page.on('pageerror', (e) => consoleErrors.push(String(e)));

async function downloadText(buttonSel) {
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click(buttonSel)]);
  const p = join(out, dl.suggestedFilename());
  await dl.saveAs(p);
  return { path: p, text: readFileSync(p, 'utf8') };
}
async function evaluateAndWait() {
  const before = Number(await page.evaluate(() => document.body.dataset.evaluated || 0));
  const t0 = Date.now();
  await page.click('#run');
  await page.waitForFunction((n) => Number(document.body.dataset.evaluated || 0) > n || document.getElementById('error').textContent,
    before, { timeout: 600000 });
  const err = await page.textContent('#error');
  if (err) throw new Error(`page error: ${err}`);
  return Date.now() - t0;
}

try {
  await page.goto(url);
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
  check('page-loads-wasm', true);

  // 1. drop the demo files (a COLMAP model folder, the GT mesh, the GT cameras), align auto:
  //    the report equals the CLI's byte for byte, the DOM shows the CLI's numbers
  await page.setInputFiles('#file-gt', demo('ground_truth.glb'));
  await page.waitForFunction(() => /triangles/.test(document.getElementById('info-gt').textContent));
  await page.setInputFiles('#dir-recon', demo('sparse'));
  await page.waitForFunction(() => /points/.test(document.getElementById('info-recon').textContent));
  await page.setInputFiles('#file-cams', demo('cameras.json'));
  await page.waitForFunction(() => /images/.test(document.getElementById('info-cams').textContent));
  await page.check('input[name=align][value=auto]');
  const msModel = await evaluateAndWait();
  const modelArgs = ['--recon', demo('sparse'), '--gt-cameras', demo('cameras.json')];
  const expectedModel = cliReport(modelArgs, 'cli-model.json');
  const pageModel = await downloadText('#dl-report');
  // the model's cameras as frusta: one per registered image, and the ground truth's
  const frusta = await page.evaluate(() => window.sfmevalViewer.cameraCounts());
  check('frusta-drawn', frusta.estCams && frusta.estCams.count === 36 && frusta.gtCams && frusta.gtCams.count === 36 && frusta.estCams.colors.length === 3 * 36, JSON.stringify({ est: frusta.estCams && frusta.estCams.count, gt: frusta.gtCams && frusta.gtCams.count }));
  // one evaluation frames the frusta: every frustum's corners project inside the view
  const framed = await page.evaluate(() => {
    const v = window.sfmevalViewer;
    v.camera.updateMatrixWorld();
    let outside = 0, total = 0;
    for (const o of [v.cams.gtCams, v.cams.estCams]) {
      o.updateMatrixWorld(true);
      const p = o.geometry.attributes.position.array;
      for (let i = 0; i < p.length; i += 3) {
        const q = v.camera.position.clone().set(p[i], p[i + 1], p[i + 2]).applyMatrix4(o.matrixWorld).project(v.camera);
        total++;
        if (!(Math.abs(q.x) <= 1 && Math.abs(q.y) <= 1 && q.z < 1)) outside++;
      }
    }
    return { outside, total };
  });
  check('frusta-framed-after-one-evaluation', framed.total > 0 && framed.outside === 0, JSON.stringify(framed));
  check('report-model-auto-equals-cli', noteSame('report-model-auto-equals-cli', pageModel.text, expectedModel), `page ${pageModel.path} vs cli-model.json: ${firstDiff(pageModel.text, expectedModel)}`);
  const rep = JSON.parse(expectedModel);
  const cell = (row, k) => page.textContent(`#stats tr[data-row=${row}] td[data-k=${k}]`);
  const dom = {
    mean: await cell('accuracy', 'mean'), median: await cell('accuracy', 'median'), p90: await cell('accuracy', 'p90'),
    cmean: await cell('completeness', 'mean'), count: await cell('accuracy', 'count'),
  };
  const want = {
    mean: g(rep.accuracy.mean), median: g(rep.accuracy.median), p90: g(rep.accuracy.percentiles.p90),
    cmean: g(rep.completeness.mean), count: String(rep.accuracy.count),
  };
  check('dom-numbers-equal-cli', JSON.stringify(dom) === JSON.stringify(want), `${JSON.stringify(dom)} vs ${JSON.stringify(want)}`);
  const thr = await page.$$eval('#thresholds tr', (rows) => rows.slice(1).map((r) => Array.from(r.children).map((c) => c.textContent)));
  const wantThr = rep.thresholds.map((t) => [g(t.tau), t.tau_percent_of_diagonal.toFixed(3), t.precision.toFixed(4), t.recall.toFixed(4), t.f_score.toFixed(4)]);
  check('dom-thresholds-equal-cli', JSON.stringify(thr) === JSON.stringify(wantThr), `${JSON.stringify(thr)} vs ${JSON.stringify(wantThr)}`);
  const stages = await page.$$eval('#stages tr', (r) => r.length);
  check('alignment-stages-shown', stages >= 3 && (await page.textContent('#r-align')) === rep.alignment.method, `${stages} rows`);
  check('camera-metrics-shown', !rep.cameras || /cameras:/.test(await page.textContent('#summary')));
  // the histogram's long tail (far SfM background points) is named under the plot, not drawn
  const h = rep.accuracy.histogram;
  const tail = (await page.textContent('.hist-tail')) || '';
  check('histogram-tail-caption', h.overflow > 0 ? tail.includes(`${h.overflow} beyond`) : tail === '', `overflow ${h.overflow}, caption "${tail}"`);
  const ply = await (async () => { const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#dl-ply')]); const p = join(out, 'page.errors.ply'); await dl.saveAs(p); return readFileSync(p); })();
  execFileSync(cli, ['eval', '--gt', demo('ground_truth.glb'), ...modelArgs, '--quiet', '--colored', join(out, 'cli.errors.ply'), '--csv', join(out, 'cli.csv')]);
  check('colored-ply-equals-cli', ply.equals(readFileSync(join(out, 'cli.errors.ply'))));
  const csv = await downloadText('#dl-csv');
  check('csv-equals-cli', csv.text === readFileSync(join(out, 'cli.csv'), 'utf8'));

  // 1b. the PLY cloud with a pasted 4x4 (the alignment just found)
  await page.click('#clear-cams');
  await page.setInputFiles('#file-recon', demo('sparse.ply'));
  await page.waitForFunction(() => /sparse\.ply/.test(document.getElementById('info-recon').textContent));
  const matrixText = rep.alignment.gt_from_recon.map((r) => r.join(' ')).join('\n');
  writeFileSync(join(out, 'transform.txt'), `${matrixText}\n`);
  await page.check('input[name=align][value=given]');
  await page.fill('#transform', matrixText);
  await evaluateAndWait();
  const expectedGiven = cliReport(['--recon', demo('sparse.ply'), '--transform', join(out, 'transform.txt')], 'cli-given.json');
  const pageGiven = await downloadText('#dl-report');
  check('report-ply-given-equals-cli', noteSame('report-ply-given-equals-cli', pageGiven.text, expectedGiven), `page ${pageGiven.path} vs cli-given.json: ${firstDiff(pageGiven.text, expectedGiven)}`);

  // 1c. point pairs (as if clicked): recon points and where the found alignment puts them
  const pairs = await page.evaluate((m) => {
    const st = window.sfmeval.state;
    const p = st.recon.positions;
    const out = [];
    for (const i of [0, 400, 900, 1500, 2100]) {
      const x = [p[3 * i], p[3 * i + 1], p[3 * i + 2]];
      const y = [0, 1, 2].map((r) => m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2] + m[r][3]);
      out.push({ recon: x, gt: y });
    }
    st.pairs = out;
    return out;
  }, rep.alignment.gt_from_recon);
  writeFileSync(join(out, 'pairs.json'), JSON.stringify({ pairs }));
  await page.check('input[name=align][value="points+icp"]');
  await evaluateAndWait();
  const expectedPoints = cliReport(['--recon', demo('sparse.ply'), '--align', 'points+icp', '--pairs', join(out, 'pairs.json')], 'cli-points.json');
  const pagePoints = await downloadText('#dl-report');
  check('report-point-pairs-equals-cli', noteSame('report-point-pairs-equals-cli', pagePoints.text, expectedPoints), `page ${pagePoints.path} vs cli-points.json: ${firstDiff(pagePoints.text, expectedPoints)}`);

  // 2. crop (box through the gizmo's object, plus "discard farther than D") and align auto
  await page.check('input[name=align][value=auto]');
  await page.selectOption('#crop-kind', 'box');
  const keptFull = await page.textContent('#kept');
  await page.evaluate(() => {
    const v = window.sfmevalViewer;
    const o = v.cropObject;
    o.scale.multiplyScalar(0.6);
    o.rotation.set(0.2, 0.3, 0.1);
    o.position.x += v.diag * 0.05;
    v.onCropChange();
  });
  const dmax = (rep.accuracy.percentiles.p95).toPrecision(6);
  await page.fill('#max-distance', dmax);
  // the live count follows the crop: wait for it to change (a fixed 200 ms wait failed once on
  // a busy machine), and report what it shows if it never does
  await page.waitForFunction((before) => document.getElementById('kept').textContent !== before, keptFull, { timeout: 15000 })
    .catch(() => {});
  const keptLive = await page.textContent('#kept');
  check('crop-live-count-changes', keptLive !== keptFull, `${keptFull} → ${keptLive}`);
  const msAuto = await evaluateAndWait();
  const cropFile = await downloadText('#crop-export');
  check('crop-file-schema', JSON.parse(cropFile.text).schema === 'sfmeval.crop/1' && JSON.parse(cropFile.text).volume.kind === 'oriented_box', cropFile.text);
  const expectedAuto = cliReport(['--recon', demo('sparse.ply'), '--align', 'auto', '--crop', cropFile.path], 'cli-auto-crop.json');
  const pageAuto = await downloadText('#dl-report');
  check('report-auto-crop-equals-cli', noteSame('report-auto-crop-equals-cli', pageAuto.text, expectedAuto), `page ${pageAuto.path} vs cli-auto-crop.json: ${firstDiff(pageAuto.text, expectedAuto)}`);
  const repAuto = JSON.parse(expectedAuto);
  check('dom-kept-equals-cli', (await page.textContent('#r-kept')) === String(repAuto.crop.kept));
  check('live-kept-equals-report', (await page.textContent('#kept')) === `${repAuto.crop.kept} / ${repAuto.inputs.reconstruction.points}`, await page.textContent('#kept'));
  check('dom-align-method', (await page.textContent('#r-align')) === repAuto.alignment.method);
  // the page shows the CLI report's notes, by code and level, in the core's words
  const notes = await page.$$eval('#summary [data-code]', (els) => els.map((e) => [e.dataset.code, e.className, e.textContent]));
  const cliNotes = repAuto.notes.map((n) => [n.code, n.level === 'warning' ? 'warn' : 'info', `${n.level === 'warning' ? 'warning' : 'note'}: ${n.message}`]);
  check('notes-equal-the-cli-report', notes.length > 0 && JSON.stringify(notes) === JSON.stringify(cliNotes), `${JSON.stringify(notes)} vs ${JSON.stringify(cliNotes)}`);
  // import the crop file back
  await page.selectOption('#crop-kind', 'none');
  await page.setInputFiles('#crop-import', cropFile.path);
  await page.waitForFunction(() => document.getElementById('crop-kind').value === 'box');
  const reexport = JSON.parse((await page.evaluate(() => window.sfmeval.cropText())));
  const orig = JSON.parse(cropFile.text);
  const close = (a, b) => JSON.stringify(a, (k, v) => (typeof v === 'number' ? Number(v.toPrecision(9)) : v)) === JSON.stringify(b, (k, v) => (typeof v === 'number' ? Number(v.toPrecision(9)) : v));
  check('crop-import-roundtrip', close(reexport, orig), `${JSON.stringify(reexport)} vs ${cropFile.text}`);

  // an Open3D SelectionPolygonVolume (a Tanks and Temples crop) imported: drawn as a prism, the
  // live count and the report as the CLI's with the same file
  const b = await page.evaluate(() => window.sfmeval.state.gt.bounds);
  const lerp = (k, t) => b[k] + t * (b[k + 3] - b[k]);
  const prism = {
    class_name: 'SelectionPolygonVolume', version_major: 1, version_minor: 0, orthogonal_axis: 'Y',
    axis_min: lerp(1, 0.2), axis_max: lerp(1, 1.1),
    bounding_polygon: [[lerp(0, -0.1), 0, lerp(2, -0.1)], [lerp(0, 0.7), 0, lerp(2, -0.1)], [lerp(0, 0.7), 0, lerp(2, 0.5)],
      [lerp(0, 0.4), 0, lerp(2, 1.1)], [lerp(0, -0.1), 0, lerp(2, 1.1)]],
  };
  const prismPath = join(out, 'Synth.json');
  writeFileSync(prismPath, JSON.stringify(prism, null, 1));
  await page.setInputFiles('#crop-import', prismPath);
  await page.waitForFunction(() => document.getElementById('crop-kind').value === 'polygon_prism');
  await evaluateAndWait();
  const pagePrism = await downloadText('#dl-report');
  const expectedPrism = cliReport(['--recon', demo('sparse.ply'), '--align', 'auto', '--crop', prismPath], 'cli-auto-prism.json');
  check('report-polygon-prism-crop-equals-cli', noteSame('report-polygon-prism-crop-equals-cli', pagePrism.text, expectedPrism),
    `page ${pagePrism.path} vs cli-auto-prism.json: ${firstDiff(pagePrism.text, expectedPrism)}`);
  const repPrism = JSON.parse(expectedPrism);
  check('polygon-prism-crops-something', repPrism.crop.kind === 'polygon_prism' && repPrism.crop.kept > 0
    && repPrism.crop.kept < repPrism.inputs.reconstruction.points, JSON.stringify(repPrism.crop));
  check('polygon-prism-live-kept-equals-report', (await page.textContent('#kept')) === `${repPrism.crop.kept} / ${repPrism.inputs.reconstruction.points}`,
    await page.textContent('#kept'));

  // 3. the viewer draws something: screenshot, and count non-background pixels of the canvas
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, 'page.png') });
  const lit = await page.evaluate(() => {
    const c = document.getElementById('view3d');
    const t = document.createElement('canvas');
    t.width = c.width; t.height = c.height;
    const ctx = t.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, t.width, t.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 0x1d) + Math.abs(d[i + 1] - 0x21) + Math.abs(d[i + 2] - 0x28) > 30) n++;
    return { n, total: d.length / 4 };
  });
  check('viewer-not-blank', lit.n > lit.total * 0.01, `${lit.n} of ${lit.total} pixels differ from the background`);
  const plots = await page.$$eval('.uplot canvas', (cs) => cs.length);
  check('plots-drawn', plots >= 2, `${plots} plot canvases`);

  // 4. "Try the demo" loads the shipped demo and gives the CLI's numbers
  await page.selectOption('#crop-kind', 'none');
  await page.fill('#max-distance', '');
  await page.click('#demo');
  await page.waitForFunction(() => /^sparse \(/.test(document.getElementById('info-recon').textContent));
  await page.waitForTimeout(300);
  await evaluateAndWait();
  const demoReport = await downloadText('#dl-report');
  check('demo-button-report-equals-cli', noteSame('demo-button-report-equals-cli', demoReport.text, expectedModel), `vs CLI report of data/demo/sparse with cameras.json: ${firstDiff(demoReport.text, expectedModel)}`);

  // 4b. the demo's depth maps (tests/browser/make_demo_depth.py wrote them into OUT/demo-depth):
  // visible-surface completeness as the CLI computes it, and the GT coloured by coverage
  const depthDir = join(out, 'demo-depth');
  const depthFiles = readdirSync(depthDir).filter((f) => f.endsWith('.npy')).map((f) => join(depthDir, f));
  await page.setInputFiles('#file-depth', depthFiles);
  await page.waitForFunction(() => /depth maps/.test(document.getElementById('info-depth').textContent));
  check('depth-maps-loaded', (await page.textContent('#info-depth')).startsWith(`${depthFiles.length} depth maps`), await page.textContent('#info-depth'));
  await evaluateAndWait();
  const depthReport = await downloadText('#dl-report');
  const expectedDepth = cliReport(['--recon', demo('sparse'), '--gt-cameras', demo('cameras.json'), '--depth', depthDir], 'cli-depth.json');
  check('depth-report-equals-cli', noteSame('depth-report-equals-cli', depthReport.text, expectedDepth), `page ${depthReport.path} vs cli-depth.json: ${firstDiff(depthReport.text, expectedDepth)}`);
  const cvCli = JSON.parse(expectedDepth).completeness_visible;
  const shown = await page.textContent('#r-visible-fraction');
  check('dom-visible-fraction-equals-cli', shown === `${(100 * cvCli.visible_fraction).toFixed(2)} %`, `${shown} vs ${cvCli.visible_fraction}`);
  check('coverage-layer-shown', await page.evaluate(() => {
    const v = window.sfmevalViewer;
    return document.getElementById('show-coverage').checked && !!v.coverage && v.coverage.visible && v.coverage.geometry.attributes.position.count > 1000;
  }));
  // words for people: no snake_case report key in the results or the stage table (file names
  // and the core's own note messages aside); here with the visible-surface row
  const keys = await page.evaluate(() => {
    const text = (el) => { const c = el.cloneNode(true); c.querySelectorAll('[data-code]').forEach((n) => n.remove()); return c.innerText; };
    return [...`${text(document.getElementById('summary'))}\n${text(document.getElementById('stages'))}`
      .matchAll(/(?:^|[\s(,])([a-z0-9]+_[a-z0-9_]+)(?=[\s),:]|$)/gm)].map((m) => m[1]);
  });
  check('results-without-snake-case-keys', keys.length === 0 && /completeness \(visible\)/.test(await page.textContent('#stats')), keys.join(', '));
  await page.uncheck('#show-recon');
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, 'page-coverage.png') });
  await page.check('#show-recon');
  await page.click('#clear-depth');

  // 4c. the demo-cameras trap: after the demo, the user's own ground truth and a COLMAP model whose
  // images are named like the demo's (0000.jpg…, here the demo's model with its names shifted, as
  // another scene shot by our generator) must not be aligned with the demo's cameras: loading them
  // resets the demo's cameras.json (said in one line) and the report equals the CLI's without
  // cameras, byte for byte.
  await page.click('#clear-cams');
  await page.waitForFunction(() => document.getElementById('info-cams').textContent === '—');
  await page.click('#demo');
  await page.waitForFunction(() => /^cameras\.json: 36 images/.test(document.getElementById('info-cams').textContent) && window.sfmeval.state.demoLoaded);
  const own = join(out, 'own');
  mkdirSync(join(own, 'mine'), { recursive: true });
  writeFileSync(join(own, 'my_ground_truth.glb'), readFileSync(demo('ground_truth.glb')));
  for (const f of ['cameras.txt', 'points3D.txt']) writeFileSync(join(own, 'mine', f), readFileSync(demo(`sparse/${f}`)));
  writeFileSync(join(own, 'mine', 'images.txt'), readFileSync(demo('sparse/images.txt'), 'utf8')
    .replace(/ (\d{4})\.jpg$/gm, (_, n) => ` ${String((Number(n) + 7) % 36).padStart(4, '0')}.jpg`));
  await page.setInputFiles('#file-gt', join(own, 'my_ground_truth.glb'));
  await page.waitForFunction(() => /my_ground_truth/.test(document.getElementById('info-gt').textContent));
  await page.setInputFiles('#dir-recon', join(own, 'mine'));
  await page.waitForFunction(() => /^mine \(/.test(document.getElementById('info-recon').textContent));
  const resetNote = await page.evaluate(() => {
    const el = document.querySelector('#notes-gt [data-reset], #notes-recon [data-reset]');
    return el ? { codes: el.dataset.reset, text: el.textContent, lines: el.getClientRects().length } : null;
  });
  check('own-files-after-demo-reset-cameras', resetNote && resetNote.codes.split(',').includes('cams') && /cameras\.json/.test(resetNote.text)
    && (await page.textContent('#info-cams')) === '—', JSON.stringify({ resetNote, cams: await page.textContent('#info-cams') }));
  await evaluateAndWait();
  const ownPage = await downloadText('#dl-report');
  execFileSync(cli, ['eval', '--gt', join(own, 'my_ground_truth.glb'), '--recon', join(own, 'mine'), '--quiet', '--report', join(out, 'cli-own.json')]);
  const ownCli = readFileSync(join(out, 'cli-own.json'), 'utf8');
  check('own-files-after-demo-equal-cli-without-cameras', noteSame('own-files-after-demo-equal-cli-without-cameras', ownPage.text, ownCli) && !JSON.parse(ownPage.text).cameras,
    `page ${ownPage.path} vs cli-own.json: ${firstDiff(ownPage.text, ownCli)}`);
  // the trap is real: the demo's cameras give other numbers on these files
  execFileSync(cli, ['eval', '--gt', join(own, 'my_ground_truth.glb'), '--recon', join(own, 'mine'), '--gt-cameras', demo('cameras.json'), '--quiet', '--report', join(out, 'cli-own-demo-cams.json')]);
  const trap = JSON.parse(readFileSync(join(out, 'cli-own-demo-cams.json'), 'utf8'));
  const fOf = (r) => r.thresholds.map((t) => t.f_score.toFixed(4)).join(' ');
  check('demo-cameras-would-give-other-numbers', fOf(trap) !== fOf(JSON.parse(ownCli)), `F with the demo's cameras ${fOf(trap)}, without ${fOf(JSON.parse(ownCli))}`);
  console.log(`note: own files after the demo: F ${fOf(JSON.parse(ownCli))} (the demo's cameras would give ${fOf(trap)})`);

  // 4d. a cameras.json of another schema (another tool's cameras, no "schema"): the page and the
  //     CLI say which schema is expected and where it is documented, in the core's same words
  const foreign = '{"camera_angle_x": 0.69,\n "frames": [{"file_path": "0000.jpg", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]}\n';
  mkdirSync(join(out, 'foreign'), { recursive: true });
  writeFileSync(join(out, 'foreign', 'cameras.json'), foreign);
  await page.setInputFiles('#file-cams', { name: 'cameras.json', mimeType: 'application/json', buffer: Buffer.from(foreign) });
  await page.waitForFunction(() => /not loaded/.test(document.getElementById('info-cams').textContent));
  const camsErr = await page.textContent('#error');
  let cliErr = '';
  try { execFileSync(cli, ['eval', '--gt', demo('ground_truth.glb'), '--recon', demo('sparse'), '--gt-cameras', join(out, 'foreign', 'cameras.json'), '--quiet'], { stdio: 'pipe' }); } catch (e) { cliErr = String(e.stderr); }
  const coreWords = (camsErr.match(/cameras\.json: .*$/) || [''])[0];
  check('foreign-cameras-json-names-the-schema-and-its-docs', /sfmeval\.cameras\/1/.test(camsErr) && /docs\/cameras-json\.md/.test(camsErr) && !/missing field/.test(camsErr)
    && coreWords.length > 0 && cliErr.includes(coreWords), JSON.stringify({ page: camsErr, cli: cliErr }));
  await page.click('#banner-close');

  // 5. a broken file gives a readable error
  await page.setInputFiles('#file-gt', { name: 'broken.glb', mimeType: 'model/gltf-binary', buffer: Buffer.from('glTF\x02\0\0\0\x40\0\0\0garbage') });
  await page.waitForFunction(() => document.getElementById('error').textContent.length > 0);
  const err = await page.textContent('#error');
  check('broken-file-error', /ground truth 'broken\.glb'/.test(err) && /GLB|glTF/i.test(err), err);
  await page.screenshot({ path: join(out, 'page-error.png') });

  writeFileSync(join(out, 'timings.json'), JSON.stringify({ msModel, msAuto }));
  console.log(`page: demo evaluation ${msModel} ms (COLMAP model, auto), ${msAuto} ms (PLY, auto + crop), wall time incl. UI`);
} catch (e) {
  check('e2e-run', false, e.stack || String(e));
} finally {
  const foreign = requests.filter((u) => !u.startsWith(origin) && !u.startsWith('data:') && !u.startsWith('blob:'));
  check('no-request-left-127.0.0.1', foreign.length === 0 && requests.length > 0, foreign.join(', '));
  const bad = consoleErrors.filter((t) => !/broken\.glb|Failed to load resource/.test(t));
  check('no-console-errors', bad.length === 0, bad.join(' | '));
  await browser.close();
}
process.exit(failed ? 1 : 0);
