// The page's Compare section in Chromium: a runner runs folder and its dataset's ground truth go
// in; the table, its exports and every report must be what `sfmeval-runner report` wrote for the
// same folder, byte for byte; sorting, best marks, overlaid curves, the side-by-side viewer and
// the camera frusta are checked too.
// Usage: node compare.mjs --url URL --runs RUNS --dataset DATASET --table RUNNER_TABLE
//          --cli target/release/sfmeval --out DIR --crop crop.json --table-crop TABLE_WITH_CROP
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { chromium } from 'playwright-core';
import { axeViolations } from './axe.mjs';
import { execFileSync } from 'node:child_process';
import { copyFileSync, readFileSync, mkdirSync, readdirSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const [runs, dataset, table, cli, out, cropFile, tableCrop] = ['runs', 'dataset', 'table', 'cli', 'out', 'crop', 'table-crop'].map((k) => resolve(args[k]));
mkdirSync(out, { recursive: true });
const origin = new URL(args.url).origin;

// the npm package of the same build (scripts/build-web.sh), in Node: the core's catalogue and
// colour map as the page must show them
const npm = await import(pathToFileURL(resolve(new URL('../..', import.meta.url).pathname, 'target/web/npm/index.js')).href);
await npm.init();

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};
function firstDiff(a, b) {
  const x = a.split('\n'), y = b.split('\n');
  const i = x.findIndex((l, k) => l !== y[k]);
  return i < 0 ? (x.length === y.length ? 'equal' : 'lengths differ') : `line ${i + 1}: ${x[i]} vs ${y[i]}`;
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
});
const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1400, height: 900 } });
const page = await context.newPage();
const requests = [];
context.on('request', (r) => requests.push(r.url()));
const consoleErrors = [];
page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
page.on('pageerror', (e) => consoleErrors.push(String(e)));

async function downloadText(sel) {
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click(sel)]);
  const p = join(out, `compare-${dl.suggestedFilename()}`);
  await dl.saveAs(p);
  return readFileSync(p, 'utf8');
}
const tableRows = () => page.$$eval('#cmp-table tbody tr', (trs) => trs.map((tr) => ({
  pipeline: tr.dataset.pipeline,
  cells: Object.fromEntries([...tr.querySelectorAll('td')].map((td) => [td.dataset.k, { v: td.dataset.v === undefined ? null : Number(td.dataset.v), best: td.dataset.best === '1', text: td.textContent }])),
})));

try {
  await page.goto(args.url);
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
  await page.setInputFiles('#file-gt', join(dataset, 'ground_truth.glb'));
  await page.waitForFunction(() => /triangles/.test(document.getElementById('info-gt').textContent));
  await page.setInputFiles('#file-cams', join(dataset, 'cameras.json'));
  await page.waitForFunction(() => /images/.test(document.getElementById('info-cams').textContent));

  // 1. the runs folder through the folder input: one row per run.json
  await page.setInputFiles('#dir-runs', runs);
  // (which files form each run comes from the core, through the worker)
  await page.waitForFunction(() => /runner run/.test(document.getElementById('info-runs').textContent), null, { timeout: 20000 }).catch(() => {});
  const info = await page.textContent('#info-runs');
  const pipelines = readdirSync(join(runs, 'statue')).sort();
  check('compare-recognises-runs', info.includes(`${pipelines.length} reconstructions (${pipelines.length} runner runs)`), info);
  check('compare-ready', await page.isEnabled('#compare'), 'Compare button disabled');
  const t0 = Date.now();
  await page.click('#compare');
  await page.waitForFunction(() => document.body.dataset.compared || document.getElementById('error').textContent, null, { timeout: 300000 });
  const err = await page.textContent('#error');
  if (err) throw new Error(`page error: ${err}`);
  console.log(`note: compared ${pipelines.length} runs in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  let rows = await tableRows();
  check('compare-table-rows', rows.length === pipelines.length && rows.map((r) => r.pipeline).join() === pipelines.join(), JSON.stringify(rows.map((r) => r.pipeline)));

  // 2. exports: the runner's files, byte for byte
  for (const [sel, file] of [['#cmp-dl-table-md', 'table.md'], ['#cmp-dl-table1-md', 'table1.md'], ['#cmp-dl-table1-csv', 'table1.csv'], ['#cmp-dl-runs-csv', 'runs.csv']]) {
    const got = await downloadText(sel);
    const want = readFileSync(join(table, file), 'utf8');
    check(`compare-export-${file}-equals-runner`, got === want, firstDiff(got, want));
  }
  const summary = await page.evaluate(() => window.sfmeval.compare.tables.summary_json);
  check('compare-summary-json-equals-runner', summary === readFileSync(join(table, 'summary.json'), 'utf8'), firstDiff(summary, readFileSync(join(table, 'summary.json'), 'utf8')));

  // 3. every report: the runner's reports/<dataset>/<pipeline>.json, and `sfmeval eval` on the
  //    same model folder with the same flags, named as the runner and the page name a run
  //    (`--name <dataset>/<pipeline>`): byte for byte
  const reports = await page.evaluate(() => window.sfmeval.compare.entries.map((e) => [e.row.pipeline, e.reportJson]));
  for (const [p, json] of reports.filter(([, j]) => j)) {
    const runner = readFileSync(join(table, 'reports', 'statue', `${p}.json`), 'utf8');
    check(`compare-report-${p}-equals-runner`, json === runner, firstDiff(json, runner));
    const file = join(out, `compare-cli-${p}.json`);
    execFileSync(cli, ['eval', '--dataset', dataset, '--recon', join(runs, 'statue', p, 'model'), '--name', `statue/${p}`, '--quiet', '--report', file]);
    const cliText = readFileSync(file, 'utf8');
    check(`compare-report-${p}-equals-cli`, json === cliText, firstDiff(json, cliText));
  }

  // 4. best marks: lowest mean, highest F, most registered images
  rows = await tableRows();
  const bestOf = (k, pick) => {
    const vals = rows.map((r) => r.cells[k].v).filter((v) => v != null);
    const b = pick(...vals);
    return rows.every((r) => r.cells[k].best === (r.cells[k].v === b)) && rows.some((r) => r.cells[k].best);
  };
  check('compare-best-mean-is-lowest', bestOf('mean', Math.min), JSON.stringify(rows.map((r) => r.cells.mean)));
  check('compare-best-f-is-highest', bestOf('f0', Math.max) && bestOf('f2', Math.max), JSON.stringify(rows.map((r) => r.cells.f0)));
  check('compare-best-registered', bestOf('registered', Math.max), JSON.stringify(rows.map((r) => r.cells.registered)));
  const headers = await page.$$eval('#cmp-table thead th', (ths) => ths.map((t) => t.dataset.k));
  // the pose protocols' columns (the catalogue's WIDE_POSES) join before the status: the dataset
  // has ground-truth cameras and the runs' models have cameras
  const poseIds = ['colmap_auc0', 'colmap_auc1', 'colmap_auc2', 'colmap_auc3', 'imc_maa', 'co3d_rra0', 'co3d_rra1', 'co3d_rra2', 'co3d_rta0', 'co3d_rta1', 'co3d_rta2', 'co3d_auc'];
  const want = ['pipeline', 'registered', 'points', 'min', 'max', 'mean', 'median', 'std', 'completeness', 'f0', 'f1', 'f2', 'ate', ...poseIds, 'status'];
  check('compare-columns', headers.join() === want.join(), headers.join());

  // 4b. the table is the core's: headers, sort titles (best end), cell texts and best marks equal
  //     the npm package's compareTable of the same rows and reports (the catalogue in Rust), and
  //     the columns are the catalogue's COMPARE list with its best ends
  const page4b = await page.evaluate(() => ({
    entries: window.sfmeval.compare.entries.map((e) => ({ row: e.row, report: e.report })),
    head: [...document.querySelectorAll('#cmp-table thead th')].map((th) => [th.dataset.k, th.querySelector('button').textContent, th.querySelector('button').title]),
    cells: [...document.querySelectorAll('#cmp-table tbody tr')].map((tr) => [Number(tr.dataset.i), [...tr.querySelectorAll('td')].map((td) => td.textContent)]),
  }));
  const core = npm.compareTable(page4b.entries);
  const wantHead = core.columns.map((c) => [c.id, c.header, `sort by ${c.header}${c.best ? ` (best: ${c.best === 'lower' ? 'lowest' : 'highest'})` : ''}`]);
  check('compare-headers-from-the-catalogue', JSON.stringify(page4b.head) === JSON.stringify(wantHead), `${JSON.stringify(page4b.head)} vs ${JSON.stringify(wantHead)}`);
  const wantCells = page4b.cells.map(([i]) => [i, core.rows[i].map((c) => `${c.text}${c.best ? ' ★' : ''}`)]);
  check('compare-cells-from-the-core', JSON.stringify(page4b.cells) === JSON.stringify(wantCells), `${JSON.stringify(page4b.cells[0])} vs ${JSON.stringify(wantCells[0])}`);
  const catalogue = Object.fromEntries(npm.metricCatalogue().map((m) => [m.key, m]));
  check('compare-best-ends-are-the-catalogue-ones', core.columns.every((c) => (catalogue[c.key] || catalogue[c.key.replace(/\[\d+\]/, '[*]')] || {}).best === c.best)
    && core.columns.find((c) => c.id === 'mean').best === 'lower' && core.columns.find((c) => c.id === 'f0').best === 'higher', JSON.stringify(core.columns));

  // 5. sorting: mean ascending, then descending
  await page.click('#cmp-table button.sort[data-k="mean"]');
  // (a run that failed has no mean: last either way)
  let means = (await tableRows()).map((r) => r.cells.mean.v).filter((v) => v != null);
  check('compare-sort-ascending', means.every((v, i) => i === 0 || means[i - 1] <= v), means.join());
  await page.click('#cmp-table button.sort[data-k="mean"]');
  means = (await tableRows()).map((r) => r.cells.mean.v).filter((v) => v != null);
  check('compare-sort-descending', means.every((v, i) => i === 0 || means[i - 1] >= v) && means[0] > means[means.length - 1], means.join());

  // 6. the curves: precision, recall and F of every reconstruction on one plot
  const okRuns = pipelines.filter((p) => JSON.parse(readFileSync(join(runs, 'statue', p, 'run.json'), 'utf8')).status === 'ok');
  check('compare-has-a-failed-run', okRuns.length >= 2 && okRuns.length < pipelines.length, okRuns.join());
  const failedRow = rows.find((r) => !okRuns.includes(r.pipeline));
  check('compare-failed-run-row', failedRow && failedRow.cells.status.text === 'failed' && failedRow.cells.mean.v == null, JSON.stringify(failedRow));
  const series = Number(await page.getAttribute('#cmp-curves', 'data-series'));
  check('compare-curves-overlaid', series === 3 * okRuns.length, `${series} series for ${okRuns.length} evaluated runs`);

  // 7. the viewer: the model with cameras in view A: one frustum per registered image, GT ones
  //    too, coloured by centre error (the largest error at the yellow end, the smallest darker)
  const withCams = rows.find((r) => r.cells.ate.v != null);
  const idx = await page.evaluate((p) => window.sfmeval.compare.entries.findIndex((e) => e.row.pipeline === p), withCams.pipeline);
  await page.selectOption('#cmp-view-a', String(idx));
  const cams = await page.evaluate(() => window.sfmevalViewer.cameraCounts());
  const entry = await page.evaluate((i) => { const e = window.sfmeval.compare.entries[i]; return { registered: e.row.images_registered, gt: e.report.cameras.ground_truth, errors: e.report.cameras.images.map((m) => [m.estimated_name, m.center_error]), p95: e.report.cameras.center_error.percentiles.p95, names: e.cameras.estErrors ? Array.from(e.cameras.estErrors) : [] }; }, idx);
  check('frusta-estimated-count', cams.estCams && cams.estCams.count === entry.registered && entry.registered > 0, JSON.stringify({ cams: cams.estCams && cams.estCams.count, entry: entry.registered }));
  check('frusta-gt-count', cams.gtCams && cams.gtCams.count === entry.gt, JSON.stringify(cams.gtCams && cams.gtCams.count));
  if (cams.estCams && cams.estCams.colors) {
    const col = cams.estCams.colors;
    const errs = entry.names; // per drawn camera, its centre error
    const lum = (i) => 0.3 * col[3 * i] + 0.59 * col[3 * i + 1] + 0.11 * col[3 * i + 2];
    const order = errs.map((e, i) => [e, i]).sort((a, b) => a[0] - b[0]);
    const lo = order[0][1], hi = order[order.length - 1][1];
    // viridis brightens with the value: the colours sort as the errors do
    const monotone = order.every(([, i], k) => k === 0 || lum(order[k - 1][1]) <= lum(i) + 1e-9);
    check('frusta-colour-follows-centre-error', monotone && lum(hi) > lum(lo) + 50 && errs.every(Number.isFinite),
      JSON.stringify({ lo: [errs[lo], col.slice(3 * lo, 3 * lo + 3)], hi: [errs[hi], col.slice(3 * hi, 3 * hi + 3)] }));
  } else check('frusta-colour-follows-centre-error', false, 'no colours');
  // the frusta's colours and clip are the core's (Evaluation.cameraColors / cameraClip): the
  // core's colour map at the core's clip, and the page keeps no clip rule or colour map of its own
  const frusta = await page.evaluate((i) => { const c = window.sfmeval.compare.entries[i].cameras; return { errors: Array.from(c.estErrors), colors: Array.from(c.estColors), clip: c.camClip }; }, idx);
  const wantFrusta = Array.from(npm.errorColors(frusta.errors, frusta.clip));
  const pageSources = readdirSync(join(resolve(new URL('../..', import.meta.url).pathname), 'www')).filter((f) => f.endsWith('.js'))
    .map((f) => [f, readFileSync(join(resolve(new URL('../..', import.meta.url).pathname), 'www', f), 'utf8')]);
  const clipRule = pageSources.filter(([, t]) => /center_error\.percentiles/.test(t)).map(([f]) => f);
  check('frusta-colours-and-clip-from-the-core', frusta.colors.length === 3 * frusta.errors.length && frusta.colors.every((v, i) => v === wantFrusta[i])
    && frusta.clip === entry.p95 && clipRule.length === 0, JSON.stringify({ clipRule, clip: frusta.clip, p95: entry.p95, first: frusta.colors.slice(0, 6), want: wantFrusta.slice(0, 6) }));
  // which files are model files is the core's rule (isModelFile), not a list in the page
  const extLists = pageSources.filter(([, t]) => /\bnvm\b[^\n]*\bout\b|MODEL_EXT/.test(t)).map(([f]) => f);
  const modelNames = ['a/cameras.txt', 'b/x.PLY', 'c/sfm_data.json', 'd/img.jpg', 'e/m.nvm', 'f/b.out', 'g/r.bmp', 'h/log.txt'];
  const pickedModels = await page.evaluate((ns) => window.sfmeval.call('modelFiles', { paths: ns }).then((r) => r.paths, (e) => String(e)), modelNames);
  check('compare-model-files-are-the-cores', extLists.length === 0 && JSON.stringify(pickedModels) === JSON.stringify(modelNames.filter((n) => npm.isModelFile(n))),
    JSON.stringify({ extLists, pickedModels }));
  await page.uncheck('#show-est-cams');
  const hidden = await page.evaluate(() => window.sfmevalViewer.cameraCounts());
  check('frusta-toggle', hidden.estCams.visible === false && hidden.gtCams.visible === true, JSON.stringify(hidden));
  await page.check('#show-est-cams');
  await page.waitForTimeout(300);
  await page.locator('#viewer').screenshot({ path: join(out, 'compare-frusta.png') });

  // 8. side by side: a second viewer with another reconstruction, same viewpoint
  const other = await page.evaluate((i) => window.sfmeval.compare.entries.findIndex((e, k) => k !== i && e.pointsInGt), idx);
  await page.selectOption('#cmp-view-b', String(other));
  await page.waitForTimeout(500);
  const side = await page.evaluate(() => {
    const a = document.getElementById('view3d').getBoundingClientRect();
    const bEl = document.getElementById('view3d-b');
    if (!bEl) return null;
    const b = bEl.getBoundingClientRect();
    const v2 = window.sfmevalViewer2;
    return { a: [a.left, a.width, a.height], b: [b.left, b.width, b.height], points: v2.points ? v2.points.geometry.attributes.position.count : 0,
      same: v2.camera.position.distanceTo(window.sfmevalViewer.camera.position) < 1e-9 };
  });
  const otherPoints = await page.evaluate((i) => window.sfmeval.compare.entries[i].pointsInGt.length / 3, other);
  check('side-by-side-viewers', side && side.b[0] >= side.a[0] + side.a[1] - 2 && side.b[1] > 200 && side.points === otherPoints && side.same, JSON.stringify({ side, otherPoints }));
  // each half names what it shows; the tools stay inside the left half, none cut off
  const layout = await page.evaluate(() => {
    const box = (el) => el.getBoundingClientRect();
    const a = box(document.getElementById('view3d'));
    const tools = document.getElementById('viewer-tools');
    const inside = [...tools.querySelectorAll('label, button')].every((el) => { const r = box(el); return r.left >= a.left && r.right <= a.left + a.width; });
    return {
      labelA: document.querySelector('#viewer > .view-label').textContent,
      labelB: document.querySelector('#viewer2 > .view-label').textContent,
      labelAInLeft: box(document.querySelector('#viewer > .view-label')).right <= a.left + a.width,
      toolsInLeft: box(tools).right <= a.left + a.width && inside,
    };
  });
  const names = await page.evaluate(([i, j]) => [i, j].map((k) => window.sfmeval.compare.entries[k].row.pipeline), [idx, other]);
  check('side-by-side-labels', layout.labelA === names[0] && layout.labelB === names[1] && layout.labelAInLeft, JSON.stringify({ layout, names }));
  check('side-by-side-tools-in-left-half', layout.toolsInLeft, JSON.stringify(layout));
  // the second canvas draws something
  const shot = await page.locator('#view3d-b').screenshot({ path: join(out, 'compare-side-b.png') });
  check('side-by-side-draws', shot.length > 5000, `${shot.length} bytes`);
  await page.screenshot({ path: join(out, 'compare.png') });
  // the comparison (table, sort buttons, curves, both viewers) passes axe-core: no serious or
  // critical violation
  const axe = await axeViolations(page);
  if (axe.minor.length) console.log(`note: compare: minor axe findings: ${axe.minor.join(', ')}`);
  check('compare-axe-no-serious-violations', axe.bad.length === 0, JSON.stringify(axe.bad));
  await page.selectOption('#cmp-view-b', '');
  const single = await page.evaluate(() => document.getElementById('viewer2').hidden);
  check('side-by-side-off', single === true, String(single));

  // 9. loose files: one row each, named by the file; reports equal `sfmeval eval` on that file
  const root = resolve(new URL('../..', import.meta.url).pathname);
  const loose = [join(root, 'tests/fixtures/global/pycolmap_points3D.ply'), join(root, 'data/demo/sparse.ply')];
  const broken = join(out, 'broken.ply');
  writeFileSync(broken, 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n');
  await page.setInputFiles('#file-runs', [...loose, broken]);
  const before = Number(await page.evaluate(() => document.body.dataset.compared));
  await page.click('#compare');
  await page.waitForFunction((n) => Number(document.body.dataset.compared) > n, before, { timeout: 300000 });
  const looseRows = (await tableRows()).map((r) => r.pipeline).sort();
  check('compare-loose-files-rows', looseRows.join() === 'broken.ply,pycolmap_points3D.ply,sparse.ply', looseRows.join());
  // a file that cannot be read: its row says so, the others are evaluated, the banner names it
  const brokenRow = (await tableRows()).find((r) => r.pipeline === 'broken.ply');
  const banner = await page.textContent('#error');
  check('compare-unreadable-file-row', brokenRow && brokenRow.cells.status.text === 'evaluation failed' && /broken\.ply/.test(banner) && /1 of 3 could not be evaluated/.test(banner),
    JSON.stringify({ status: brokenRow && brokenRow.cells.status.text, banner }));
  await page.click('#banner-close');
  const looseReports = await page.evaluate(() => window.sfmeval.compare.entries.map((e) => [e.row.pipeline, e.reportJson]));
  for (const [name, json] of looseReports.filter(([, j]) => j)) {
    const file = join(out, `compare-cli-${name}.json`);
    execFileSync(cli, ['eval', '--gt', join(dataset, 'ground_truth.glb'), '--gt-cameras', join(dataset, 'cameras.json'), '--recon', loose.find((f) => f.endsWith(`/${name}`)), '--quiet', '--report', file]);
    const want = readFileSync(file, 'utf8');
    check(`compare-loose-report-${name}-equals-cli`, json === want, firstDiff(json, want));
  }

  // a compare under way shows the progress bar and the action bar's Cancel, which stops it:
  // no table change, no error, and the page compares again afterwards (step 10). 8M samples
  // make each evaluation last seconds, so Cancel lands mid-run.
  await page.fill('#samples', '8000000');
  const comparedBefore = await page.evaluate(() => document.body.dataset.compared);
  const cancelledBefore = Number(await page.evaluate(() => document.body.dataset.cancelled || 0));
  await page.click('#compare');
  await page.waitForFunction(() => !document.getElementById('cancel').hidden
    && getComputedStyle(document.getElementById('progress')).display !== 'none', null, { timeout: 30000 });
  const during = await page.evaluate(() => ({
    run: document.getElementById('run').disabled,
    status: document.getElementById('compare-status').textContent,
    cancelInView: (() => { const r = document.getElementById('cancel').getBoundingClientRect(); return r.bottom <= innerHeight && r.top >= 0; })(),
  }));
  check('compare-progress-and-cancel-in-view', during.run && /^evaluating \d\/3/.test(during.status) && during.cancelInView, JSON.stringify(during));
  await page.click('#cancel');
  await page.waitForFunction((n) => Number(document.body.dataset.cancelled || 0) > n, cancelledBefore, { timeout: 60000 });
  const after = await page.evaluate(() => ({
    status: document.getElementById('compare-status').textContent,
    error: document.getElementById('error').textContent,
    compared: document.body.dataset.compared,
    cancelHidden: document.getElementById('cancel').hidden,
  }));
  check('compare-cancelled', /cancelled/.test(after.status) && !after.error && after.compared === comparedBefore && after.cancelHidden, JSON.stringify(after));
  await page.fill('#samples', '1000000');

  // 10. the runs folder dropped on the drop zone: the page walks the folder entries. Playwright
  //     cannot drop a real folder, so the drop event carries entries (the FileSystemEntry
  //     interface: isFile/isDirectory, file(), createReader().readEntries()) over the files the
  //     folder input picked; the page's own walk, grouping and evaluation do the rest.
  await page.setInputFiles('#dir-runs', runs);
  await page.setInputFiles('#file-runs', loose);
  await page.evaluate(() => {
    const picked = [...document.getElementById('dir-runs').files];
    const root = { name: picked[0].webkitRelativePath.split('/')[0], dirs: new Map(), files: [] };
    for (const f of picked) {
      let node = root;
      for (const p of f.webkitRelativePath.split('/').slice(1, -1)) {
        if (!node.dirs.has(p)) node.dirs.set(p, { name: p, dirs: new Map(), files: [] });
        node = node.dirs.get(p);
      }
      node.files.push(f);
    }
    const fileEntry = (f) => ({ isFile: true, isDirectory: false, name: f.name, file: (res) => res(f) });
    const dirEntry = (n) => ({
      isFile: false, isDirectory: true, name: n.name,
      createReader() {
        let given = false;
        return { readEntries(res) { res(given ? [] : [...[...n.dirs.values()].map(dirEntry), ...n.files.map(fileEntry)]); given = true; } };
      },
    });
    const ev = new Event('drop', { bubbles: true, cancelable: true });
    Object.defineProperty(ev, 'dataTransfer', { value: { items: [{ webkitGetAsEntry: () => dirEntry(root) }], files: [] } });
    document.getElementById('drop-runs').dispatchEvent(ev);
  });
  await page.waitForFunction((n) => document.getElementById('info-runs').textContent.startsWith(`${n} reconstructions (${n} runner runs)`), pipelines.length, { timeout: 10000 })
    .then(() => check('compare-drop-folder-recognised', true), async () => check('compare-drop-folder-recognised', false, await page.textContent('#info-runs')));
  const beforeDrop = Number(await page.evaluate(() => document.body.dataset.compared));
  await page.click('#compare');
  await page.waitForFunction((n) => Number(document.body.dataset.compared) > n || document.getElementById('error').textContent, beforeDrop, { timeout: 300000 });
  const droppedMd = await downloadText('#cmp-dl-table-md');
  check('compare-drop-folder-table-equals-runner', droppedMd === readFileSync(join(table, 'table.md'), 'utf8'), firstDiff(droppedMd, readFileSync(join(table, 'table.md'), 'utf8')));

  // 11. the section 3 crop applies to every reconstruction, as `sfmeval-runner report --crop`
  //     (the same crop file, imported through the page's crop import)
  await page.setInputFiles('#crop-import', cropFile);
  await page.waitForFunction(() => document.getElementById('max-distance').value !== '', null, { timeout: 10000 });
  const beforeCrop = Number(await page.evaluate(() => document.body.dataset.compared));
  await page.click('#compare');
  await page.waitForFunction((n) => Number(document.body.dataset.compared) > n || document.getElementById('error').textContent, beforeCrop, { timeout: 300000 });
  for (const [sel, file] of [['#cmp-dl-table-md', 'table.md'], ['#cmp-dl-runs-csv', 'runs.csv']]) {
    const got = await downloadText(sel);
    const want = readFileSync(join(tableCrop, file), 'utf8');
    check(`compare-cropped-${file}-equals-runner-crop`, got === want && got !== readFileSync(join(table, file), 'utf8'), firstDiff(got, want));
  }

  // 12. COLMAP files are one model: the demo's cameras.txt, images.txt, points3D.txt picked as
  //     loose files give one row (named 'model', as the Reconstruction input names them) whose
  //     report equals `sfmeval eval` on that model; in a picked folder, the COLMAP folder is named
  //     by itself and a loose file beside it by the file (not by the picked folder)
  await page.selectOption('#crop-kind', 'none');
  await page.fill('#max-distance', '');
  const compareAgain = async () => {
    const n = Number(await page.evaluate(() => document.body.dataset.compared || 0));
    await page.click('#compare');
    await page.waitForFunction((k) => Number(document.body.dataset.compared || 0) > k || document.getElementById('error').textContent, n, { timeout: 300000 });
  };
  const demoSparse = join(root, 'data/demo/sparse');
  await page.setInputFiles('#file-runs', ['cameras.txt', 'images.txt', 'points3D.txt'].map((f) => join(demoSparse, f)));
  // The line is written once the dropped files are read: wait for it (the check fails if it
  // never comes) rather than read the previous one.
  await page.waitForFunction(() => document.getElementById('info-runs').textContent.startsWith('1 reconstruction: model'), null, { timeout: 20000 }).catch(() => {});
  check('compare-colmap-files-one-item', (await page.textContent('#info-runs')).startsWith('1 reconstruction: model'), await page.textContent('#info-runs'));
  await compareAgain();
  const colmapRows = await tableRows();
  const colmapReport = await page.evaluate(() => window.sfmeval.compare.entries.map((e) => e.reportJson));
  execFileSync(cli, ['eval', '--gt', join(dataset, 'ground_truth.glb'), '--gt-cameras', join(dataset, 'cameras.json'), '--recon', demoSparse, '--quiet', '--report', join(out, 'compare-cli-colmap.json')]);
  const wantColmap = JSON.parse(readFileSync(join(out, 'compare-cli-colmap.json'), 'utf8'));
  wantColmap.inputs.reconstruction.name = 'model'; // the CLI names it by its folder, 'sparse'
  check('compare-colmap-files-one-row', colmapRows.length === 1 && colmapRows[0].pipeline === 'model' && colmapRows[0].cells.status.text === 'ok'
    && colmapReport.length === 1 && colmapReport[0] && JSON.stringify(JSON.parse(colmapReport[0])) === JSON.stringify(wantColmap),
  JSON.stringify({ rows: colmapRows.map((r) => [r.pipeline, r.cells.status.text]), diff: colmapReport[0] ? firstDiff(JSON.stringify(JSON.parse(colmapReport[0]), null, 1), JSON.stringify(wantColmap, null, 1)) : 'no report' }));
  const picked = join(out, 'picked');
  mkdirSync(join(picked, 'sparse'), { recursive: true });
  for (const f of ['cameras.txt', 'images.txt', 'points3D.txt']) writeFileSync(join(picked, 'sparse', f), readFileSync(join(demoSparse, f)));
  writeFileSync(join(picked, 'demo_points.ply'), readFileSync(join(root, 'data/demo/sparse.ply')));
  await page.setInputFiles('#dir-runs', picked);
  await compareAgain();
  const pickedRows = (await tableRows()).map((r) => r.pipeline).sort();
  check('compare-names-from-own-folder', pickedRows.join() === 'demo_points.ply,sparse', pickedRows.join());
  const pickedReports = await page.evaluate(() => window.sfmeval.compare.entries.map((e) => [e.row.pipeline, e.reportJson]));
  for (const [name, json] of pickedReports) {
    const file = join(out, `compare-cli-picked-${name}.json`);
    execFileSync(cli, ['eval', '--gt', join(dataset, 'ground_truth.glb'), '--gt-cameras', join(dataset, 'cameras.json'), '--recon', join(picked, name), '--quiet', '--report', file]);
    const want = readFileSync(file, 'utf8');
    check(`compare-picked-report-${name}-equals-cli`, json === want, json ? firstDiff(json, want) : 'no report');
  }

  // 13. after Compare the comparison is in view, at 1366×768 and at 1920×1080: the results pane
  //     shows it (not the previous evaluation, whose "Out of date" note is there to cover it), the
  //     table's header and first row inside the window and the pane, nothing drawn over them
  await page.setInputFiles('#file-recon', join(root, 'data/demo/sparse.ply'));
  await page.waitForFunction(() => /sparse\.ply/.test(document.getElementById('info-recon').textContent));
  const clouds = [join(root, 'data/demo/sparse.ply'), join(root, 'tests/fixtures/global/pycolmap_points3D.ply')];
  for (const [k, [w, h]] of [[1366, 768], [1920, 1080]].entries()) {
    await page.setViewportSize({ width: w, height: h });
    const evaluated = Number(await page.evaluate(() => document.body.dataset.evaluated || 0));
    await page.click('#run');
    await page.waitForFunction((n) => Number(document.body.dataset.evaluated || 0) > n, evaluated, { timeout: 300000 });
    // an input changes: the evaluation goes out of date under its sticky note, then Compare
    const next = clouds[(k + 1) % 2];
    await page.setInputFiles('#file-recon', next);
    await page.waitForFunction(() => !document.getElementById('stale-note').hidden);
    await page.evaluate(() => { document.getElementById('results').scrollTop = 1e6; });
    await page.setInputFiles('#file-runs', clouds);
    await compareAgain();
    await page.waitForTimeout(200);
    const seen = await page.evaluate(() => {
      // vertically inside, starting inside (a wide table scrolls sideways within the pane)
      const inside = (r, box) => r.top >= box.top && r.bottom <= box.bottom && r.left >= box.left && r.left < box.right;
      const win = { top: 0, left: 0, bottom: innerHeight, right: innerWidth };
      const pane = document.getElementById('results').getBoundingClientRect();
      const uncovered = (el) => {
        const r = el.getBoundingClientRect();
        const hit = document.elementFromPoint(r.left + Math.min(20, r.width / 2), r.top + r.height / 2);
        return !!hit && el.contains(hit);
      };
      const head = document.querySelector('#cmp-table thead tr') || document.querySelector('#cmp-table tr');
      const first = document.querySelector('#cmp-table tbody tr');
      const visible = (id) => { const el = document.getElementById(id); return !!el && el.getClientRects().length > 0; };
      return {
        firstRow: !!first && inside(first.getBoundingClientRect(), win) && inside(first.getBoundingClientRect(), pane),
        firstRowUncovered: !!first && uncovered(first.querySelector('td')),
        headerUncovered: !!head && inside(head.getBoundingClientRect(), pane) && uncovered(head.querySelector('th')),
        summaryShown: visible('summary'), staleShown: visible('stale-note'),
        tabs: visible('results-tabs'), top: first ? Math.round(first.getBoundingClientRect().top) : null,
      };
    });
    check(`compare-in-view-${w}x${h}`, seen.firstRow && seen.firstRowUncovered && seen.headerUncovered && !seen.summaryShown && !seen.staleShown && seen.tabs, JSON.stringify(seen));
    await page.screenshot({ path: join(out, `compare-in-view-${w}x${h}.png`) });
    // the tab brings the evaluation back, and the comparison again
    await page.click('#tab-evaluation');
    const back = await page.evaluate(() => [document.getElementById('summary').getClientRects().length > 0, document.getElementById('compare-results').getClientRects().length > 0]);
    await page.click('#tab-comparison');
    check(`results-tabs-switch-${w}x${h}`, back[0] && !back[1], JSON.stringify(back));
  }

  // 14. the colour bar is the core's colour map, column by column (no copy of it in the page)
  await page.click('#tab-evaluation');
  await page.waitForFunction(() => Number(document.getElementById('colorbar-canvas').dataset.drawn || 0) > 0, null, { timeout: 20000 });
  const bar = await page.evaluate(() => {
    const cv = document.getElementById('colorbar-canvas');
    const d = cv.getContext('2d').getImageData(0, 0, cv.width, 1).data;
    return { w: cv.width, rgb: Array.from(d).filter((_, i) => i % 4 !== 3) };
  });
  const wantBar = Array.from(npm.errorColors(Array.from({ length: bar.w }, (_, i) => i / (bar.w - 1)), 1));
  check('colorbar-is-the-core-colour-map', bar.rgb.length === wantBar.length && bar.rgb.every((v, i) => v === wantBar[i]),
    `${bar.rgb.slice(0, 9)} vs ${wantBar.slice(0, 9)}`);
  // 15. the comparison goes out of date when the ground truth changes (its note above the table,
  //     in the flow: the header stays uncovered), and a new Compare clears it
  await page.click('#tab-comparison');
  // (another file of the same mesh: the input's change event needs a new file)
  const gtCopy = join(out, 'compare-gt-copy.glb');
  copyFileSync(join(dataset, 'ground_truth.glb'), gtCopy);
  await page.setInputFiles('#file-gt', gtCopy);
  await page.waitForFunction(() => document.body.dataset.compareStale === '1', null, { timeout: 20000 }).catch(() => {});
  const stale = await page.evaluate(() => {
    const note = document.getElementById('cmp-stale-note');
    const th = document.querySelector('#cmp-table thead th');
    const r = th.getBoundingClientRect();
    const hit = document.elementFromPoint(r.left + Math.min(20, r.width / 2), r.top + r.height / 2);
    return { shown: note.getClientRects().length > 0, text: note.textContent, headerUncovered: !!hit && th.contains(hit), flag: document.body.dataset.compareStale };
  });
  check('compare-out-of-date-when-the-ground-truth-changes', stale.shown && /ground truth/.test(stale.text) && stale.flag === '1' && stale.headerUncovered, JSON.stringify(stale));
  await compareAgain();
  const fresh = await page.evaluate(() => [document.getElementById('cmp-stale-note').hidden, document.body.dataset.compareStale]);
  check('compare-again-is-current', fresh[0] === true && fresh[1] === undefined, JSON.stringify(fresh));
  // 16. it goes out of date too when what it was measured with changes: τ, then the samples, then
  //     the crop (each named in the note), as `sfmeval-runner report` would measure otherwise
  const staleNote = () => page.evaluate(() => [document.body.dataset.compareStale, document.getElementById('cmp-stale-note').textContent]);
  await page.fill('#tau-rel', '0.5,1,3');
  const afterTau = await staleNote();
  await page.fill('#samples', '900000');
  const afterSamples = await staleNote();
  await page.selectOption('#crop-kind', 'sphere');
  await page.waitForTimeout(100);
  const afterCrop = await staleNote();
  check('compare-out-of-date-when-tau-samples-or-crop-change', afterTau[0] === '1' && /τ/.test(afterTau[1]) && !/samples/.test(afterTau[1])
    && /samples/.test(afterSamples[1]) && /crop/.test(afterCrop[1]), JSON.stringify({ afterTau, afterSamples, afterCrop }));
  await page.selectOption('#crop-kind', 'none');
  await page.fill('#tau-rel', '');
  await page.fill('#samples', '1000000');

  check('compare-no-request-leaves-origin', requests.every((u) => u.startsWith(origin) || u.startsWith('blob:') || u.startsWith('data:')), requests.filter((u) => !u.startsWith(origin)).join(' '));
  check('compare-no-console-errors', consoleErrors.length === 0, consoleErrors.join(' | '));
} catch (e) {
  check('compare-run', false, e.stack || String(e));
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
