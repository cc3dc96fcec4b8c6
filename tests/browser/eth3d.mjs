// ETH3D's multi-view evaluation in the npm package (Node) and in the page (Chromium), against
// `sfmeval eth3d` on the same files (run in the project's folder, so that both name the scans
// as the project writes them): the `sfmeval.eth3d/1` report byte for byte, the summary's text,
// the coloured clouds byte for byte; the scene's files recognised and what is missing said; a
// wrong file refused with the core's message naming it.
// The scene: tests/python/eth3d_scene.py (two scans of the demo's statue, a dense cloud with a
// hole and outliers), its reconstruction copied beside the project.
// Usage: node eth3d.mjs --npm NPM_PACKAGE_DIR --cli CLI_BINARY --scene SCENE_DIR --out OUT_DIR [--url PAGE_URL]
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const [npmDir, cli, sceneDir, out] = ['npm', 'cli', 'scene', 'out'].map((k) => resolve(args[k]));
mkdirSync(out, { recursive: true });
const sfmeval = await import(pathToFileURL(join(npmDir, 'index.js')).href);
await sfmeval.init();

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};
const firstDiff = (a, b) => {
  const x = a.split('\n'), y = b.split('\n');
  const i = x.findIndex((l, k) => l !== y[k]);
  return i < 0 ? (x.length === y.length ? 'equal' : 'lengths differ') : `line ${i + 1}: ${x[i]} vs ${y[i]}`;
};
const bytesEqual = (a, b) => a.length === b.length && Buffer.compare(Buffer.from(a), Buffer.from(b)) === 0;

const gtDir = join(sceneDir, 'dslr_scan_eval');
copyFileSync(join(sceneDir, 'dense.ply'), join(gtDir, 'dense.ply'));
const names = ['scan_alignment.mlp', 'scan1.ply', 'scan2.ply', 'dense.ply'];
const files = Object.fromEntries(names.map((n) => [n, readFileSync(join(gtDir, n))]));

// 1. the npm package: report, summary and every tolerance's clouds equal the CLI's
const vis = join(out, 'eth3d-cli');
let want = null;
try {
  const run = (extra) => execFileSync(cli, ['eth3d', '--gt', 'scan_alignment.mlp', '--recon', 'dense.ply', ...extra],
    { cwd: gtDir, maxBuffer: 1 << 26 }).toString();
  want = { json: run(['--json', '--out', vis]), summary: run([]) };
} catch (e) { check('eth3d-cli', false, `CLI failed: ${e.stderr || e.message}`); }
if (want) {
  let got = null;
  try { got = sfmeval.evaluateEth3d(files); } catch (e) { check('eth3d-npm', false, `npm failed: ${e.message}`); }
  if (got) {
    check('eth3d-npm-report-equals-cli', got.reportJson === want.json, firstDiff(got.reportJson, want.json));
    check('eth3d-npm-summary-equals-cli', got.summary === want.summary, firstDiff(got.summary, want.summary));
    const rep = got.report;
    const t = got.table;
    check('eth3d-npm-table-is-the-reports', t.rows.length === rep.tolerances.length && t.rows.length === 6
      && t.rows.every((r, k) => r[0] === `${rep.tolerances[k].tolerance} m` && Number(r[3]).toFixed(6) === rep.tolerances[k].f1.toFixed(6)
        && want.summary.includes(r[1]) && Number(r[4]) === rep.tolerances[k].accurate_points)
      && rep.tolerances.some((x) => x.f1 > 0.1 && x.f1 < 0.999) && rep.tolerances.some((x) => x.inaccurate_points > 0), JSON.stringify(t));
    let same = true, why = '';
    for (let k = 0; k < got.tolerances.length; k++) {
      const [a, c] = got.cloudNames(k);
      const okA = bytesEqual(got.accuracyPly(k), readFileSync(join(vis, a)));
      const okC = bytesEqual(got.completenessPly(k), readFileSync(join(vis, c)));
      if (!okA || !okC) { same = false; why += `${a}: ${okA}, ${c}: ${okC}; `; }
    }
    check('eth3d-npm-clouds-equal-cli', same, why);
    got.free();
  }
}

// 2. the files: what is missing is said; a wrong file names itself
const found = sfmeval.eth3dFiles(['scan_alignment.mlp', 'scan1.ply', 'dense.ply', 'notes.txt'], files['scan_alignment.mlp']);
check('eth3d-npm-files-missing-named', found.project === 'scan_alignment.mlp' && found.scans.length === 1 && found.missing.length === 1
  && found.missing[0].includes("'scan2.ply'") && found.reconstruction === 'dense.ply' && found.ignored.join() === 'notes.txt', JSON.stringify(found));
try {
  sfmeval.evaluateEth3d({ ...files, 'scan2.ply': Buffer.from('ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n') });
  check('eth3d-npm-bad-scan-names-the-file', false, 'no error');
} catch (e) {
  check('eth3d-npm-bad-scan-names-the-file', e.message.includes('scan2.ply') && !/panic|unreachable/i.test(e.message), e.message);
}

// 3. the page: the project and one scan dropped (the other scan said missing, Evaluate off), then
//    the rest; the core's table shown, the report and a cloud downloaded byte for byte the CLI's;
//    then a scan that is not a PLY: the core's message naming it
if (args.url && want) {
  const { chromium } = await import('playwright-core');
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  try {
    const page = await (await browser.newContext({ acceptDownloads: true, viewport: { width: 1366, height: 768 } })).newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(String(e)));
    await page.goto(args.url);
    await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
    await page.setInputFiles('#file-eth3d', [join(gtDir, 'scan_alignment.mlp'), join(gtDir, 'scan1.ply'), join(gtDir, 'dense.ply')]);
    await page.waitForFunction(() => /still needed/.test(document.getElementById('info-eth3d').textContent), null, { timeout: 10000 }).catch(() => {});
    const missing = await page.evaluate(() => [document.getElementById('info-eth3d').textContent, document.getElementById('eth3d-run').disabled]);
    check('eth3d-page-says-what-is-missing', missing[1] && missing[0].includes('scan2.ply') && missing[0].includes('reconstruction: dense.ply'), JSON.stringify(missing));
    await page.setInputFiles('#file-eth3d', [join(gtDir, 'scan2.ply')]);
    await page.waitForFunction(() => !document.getElementById('eth3d-run').disabled, null, { timeout: 10000 });
    await page.locator('#drop-eth3d').scrollIntoViewIfNeeded();
    await page.click('#eth3d-run');
    await page.waitForFunction(() => document.body.dataset.eth3d || document.getElementById('error').textContent, null, { timeout: 120000 });
    const shown = await page.evaluate(() => ({
      head: [...document.querySelectorAll('#eth3d-table thead th')].map((th) => th.textContent),
      rows: [...document.querySelectorAll('#eth3d-table tbody tr')].map((tr) => [...tr.cells].map((c) => c.textContent)),
      headline: document.getElementById('eth3d-headline').textContent,
      error: document.getElementById('error').textContent,
    }));
    const wantRep = JSON.parse(want.json);
    check('eth3d-page-shows-the-cores-table', !shown.error && shown.headline === want.summary.split('\n')[0] && shown.head.includes('F1')
      && shown.rows.length === wantRep.tolerances.length
      && shown.rows.every((r, k) => r[0] === `${wantRep.tolerances[k].tolerance} m` && want.summary.split('\n')[k + 2].includes(r[3])),
    JSON.stringify({ shown, summary: want.summary }));
    const download = async (sel) => {
      const [dl] = await Promise.all([page.waitForEvent('download'), page.click(sel)]);
      const p = join(out, `eth3d-page-${dl.suggestedFilename()}`);
      await dl.saveAs(p);
      return [dl.suggestedFilename(), readFileSync(p)];
    };
    const [, rep] = await download('#eth3d-dl-report');
    check('eth3d-page-report-equals-cli', rep.toString() === want.json, firstDiff(rep.toString(), want.json));
    await page.selectOption('#eth3d-tolerance', '2');
    const [name, cloud] = await download('#eth3d-dl-acc');
    check('eth3d-page-cloud-equals-cli', name === 'accuracy.tolerance_0.05.ply' && bytesEqual(cloud, readFileSync(join(vis, name))), name);
    await page.locator('#eth3d-result').screenshot({ path: join(out, 'eth3d-section.png') });
    await page.screenshot({ path: join(out, 'eth3d-1366x768.png') });
    // scan2.ply replaced by a file that is not a PLY: the core's message, naming it
    const bad = join(out, 'scan2.ply');
    writeFileSync(bad, 'not a ply at all\n');
    await page.setInputFiles('#file-eth3d', [bad]);
    await page.waitForFunction(() => !document.getElementById('eth3d-run').disabled, null, { timeout: 10000 });
    await page.click('#eth3d-run');
    await page.waitForFunction(() => /failed/.test(document.getElementById('error').textContent), null, { timeout: 30000 }).catch(() => {});
    const err = await page.evaluate(() => document.getElementById('error').textContent);
    check('eth3d-page-wrong-file-named', err.includes('scan2.ply') && !/panic|unreachable/i.test(err), err);
    check('eth3d-page-no-errors', errors.length === 0, errors.join(' | '));
  } catch (e) {
    check('eth3d-page', false, e.stack || String(e));
  } finally {
    await browser.close();
  }
}
writeFileSync(join(out, 'eth3d-done'), '');
process.exit(failed ? 1 : 0);
