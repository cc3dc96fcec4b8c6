// The camera-pose protocols in the npm package (Node) and in the page (Chromium), against
// `sfmeval poses` on the same files: the `sfmeval.poses/1` report byte for byte, the summary's
// text and the pairs CSV; a wrong file refused with the core's message naming it.
// The inputs are real SfM outputs (tests/python/test_pose_protocols.py's cases): pycolmap's and
// openmvg-rs' models of a rendered 6-view scene (tests/fixtures/models), and pycolmap's cameras
// of the 36-view demo (tests/fixtures/global) against the demo's cameras.json.
// Usage: node poses.mjs --npm NPM_PACKAGE_DIR --cli CLI_BINARY --out OUT_DIR [--url PAGE_URL]
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { execFileSync } from 'node:child_process';
import { readdirSync, readFileSync } from 'node:fs';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { args, argPaths, check, download, ensureDir, finish, firstDiff, loadNpm, withPage } from './driver.mjs';

const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), '../..');
const [npmDir, cli, out] = argPaths('npm', 'cli', 'out');
ensureDir(out);
const sfmeval = await loadNpm(npmDir);

/** A model path (file or folder) as named bytes, as the page and npm get them. */
const filesOf = (p) => {
  try {
    return Object.fromEntries(readdirSync(p).map((f) => [f, readFileSync(join(p, f))]));
  } catch { return { [basename(p)]: readFileSync(p) }; }
};
const models = join(ROOT, 'tests/fixtures/models');
const demoCams = join(ROOT, 'data/demo/cameras.json');
const cases = [
  ['pycolmap', join(models, 'gt_cameras.json'), join(models, 'colmap_text')],
  ['openmvg', join(models, 'gt_cameras.json'), join(models, 'openmvg_colmap')],
  ['demo', demoCams, join(ROOT, 'tests/fixtures/global/pycolmap_cameras.json')],
];

/** `sfmeval poses`: the JSON it prints, the summary and the pairs CSV. */
function cliPoses(gt, est, protocol, extra = []) {
  const run = (flags) => execFileSync(cli, ['poses', '--gt-cameras', gt, '--recon', est, '--protocol', protocol, ...extra, ...flags],
    { maxBuffer: 1 << 26 }).toString();
  const pairs = join(out, `poses-cli-pairs-${protocol}.csv`);
  const json = run(['--json', '--pairs', pairs]);
  return { json, summary: run([]), pairs: readFileSync(pairs, 'utf8') };
}

// 1. npm: every case and protocol, byte for byte the CLI's
const cliOut = {};
for (const [name, gt, est] of cases) {
  for (const protocol of ['colmap', 'imc', 'co3d']) {
    const extra = protocol === 'colmap' && name === 'demo' ? ['--position-accuracy', '0.01'] : [];
    const id = `poses-npm-${name}-${protocol}`;
    let want;
    try { want = cliPoses(gt, est, protocol, extra); } catch (e) { check(id, false, `CLI failed: ${e.stderr || e.message}`); continue; }
    cliOut[`${name}-${protocol}`] = want;
    let got;
    try {
      got = sfmeval.evaluatePoses({ gtCameras: filesOf(gt), recon: filesOf(est) },
        { protocol, ...(extra.length ? { position_accuracy: 0.01 } : {}) });
    } catch (e) { check(id, false, `npm failed: ${e.message}`); continue; }
    check(`${id}-report-equals-cli`, got.reportJson === want.json, firstDiff(got.reportJson, want.json));
    check(`${id}-summary-equals-cli`, got.summary === want.summary, firstDiff(got.summary, want.summary));
    check(`${id}-pairs-equal-cli`, got.pairsCsv === want.pairs, firstDiff(got.pairsCsv, want.pairs));
    const rep = got.report;
    const rows = got.summaryRows;
    check(`${id}-rows-are-the-summary`, rows.length === want.summary.trimEnd().split('\n').length
      && rows.every((r) => want.summary.includes(r.text)) && rep.schema === 'sfmeval.poses/1' && rep.result.protocol === protocol
      && rep.matched > 0, JSON.stringify(rows));
  }
}

// 2. wrong files: the core's message naming the file
const hostile = [
  ['poses-npm-bad-gt-names-the-file', { gtCameras: { 'cameras.json': Buffer.from('{"images": [oops') }, recon: filesOf(cases[0][2]) }, /cameras\.json/],
  ['poses-npm-bare-cloud-refused', { gtCameras: filesOf(cases[2][1]), recon: { 'pycolmap_points3D.ply': readFileSync(join(ROOT, 'tests/fixtures/global/pycolmap_points3D.ply')) } }, /pycolmap_points3D\.ply.*no cameras/],
];
for (const [id, files, re] of hostile) {
  try {
    sfmeval.evaluatePoses(files, { protocol: 'colmap' });
    check(id, false, 'no error');
  } catch (e) { check(id, re.test(e.message) && !/panic|unreachable/i.test(e.message), e.message); }
}
try {
  sfmeval.evaluatePoses({ gtCameras: filesOf(cases[0][1]), recon: filesOf(cases[0][2]) }, { protocol: 'eth3d' });
  check('poses-npm-unknown-protocol', false, 'no error');
} catch (e) { check('poses-npm-unknown-protocol', /colmap, imc, co3d/.test(e.message), e.message); }

// 3. the page: the demo's cameras and pycolmap's model dropped on section 7, CO3D, then the
//    core's summary rows shown, the report downloaded byte for byte the CLI's; a bare cloud as
//    the estimate refused with the core's message naming the file
if (args.url && cliOut['demo-co3d']) {
  await withPage(args.url, 'poses', async (page) => {
    const before = await page.evaluate(() => document.getElementById('poses-run').disabled);
    await page.setInputFiles('#file-poses-gt', [cases[2][1]]);
    await page.setInputFiles('#file-poses-est', [cases[2][2]]);
    await page.selectOption('#poses-protocol', 'co3d');
    await page.locator('#drop-poses-gt').scrollIntoViewIfNeeded();
    check('poses-page-run-needs-both', before && !(await page.evaluate(() => document.getElementById('poses-run').disabled)));
    await page.click('#poses-run');
    await page.waitForFunction(() => document.body.dataset.poses || document.getElementById('error').textContent, null, { timeout: 60000 });
    const shown = await page.evaluate(() => ({
      rows: [...document.querySelectorAll('#poses-table tbody tr')].map((tr) => [tr.cells[0]?.textContent ?? tr.querySelector('th').textContent, tr.querySelector('td').textContent]),
      error: document.getElementById('error').textContent,
    }));
    const want = cliOut['demo-co3d'].summary.trimEnd().split('\n');
    // the CLI pads the label to 15 columns; a note is `level: message`
    const asLines = shown.rows.map(([l, t]) => (/^(info|warning|error)$/.test(l) ? `${l}: ${t}` : `${l.padEnd(15)} ${t}`));
    check('poses-page-shows-the-cores-summary', !shown.error && asLines.length === want.length && asLines.every((l, i) => l === want[i])
      && shown.rows.some(([l]) => l === 'RRA') && shown.rows.some(([l]) => l === 'convention'), JSON.stringify({ shown, want }));
    const [, rep] = await download(page, '#poses-dl-report', out, 'poses');
    check('poses-page-report-equals-cli', rep.toString() === cliOut['demo-co3d'].json, firstDiff(rep.toString(), cliOut['demo-co3d'].json));
    await page.locator('#poses-result').screenshot({ path: join(out, 'poses-section.png') });
    await page.screenshot({ path: join(out, 'poses-1366x768.png') });
    // a point cloud dropped as the estimated model: the core's message, naming the file
    const ply = join(ROOT, 'tests/fixtures/global/pycolmap_points3D.ply');
    await page.setInputFiles('#file-poses-est', [ply]);
    await page.click('#poses-run');
    await page.waitForFunction(() => /no cameras/.test(document.getElementById('error').textContent), null, { timeout: 30000 }).catch(() => {});
    const err = await page.evaluate(() => [document.getElementById('error').textContent, document.getElementById('poses-result').hidden]);
    check('poses-page-wrong-file-named', err[0].includes('pycolmap_points3D.ply') && /no cameras/.test(err[0]) && err[1], JSON.stringify(err));
  }, { consoleErrors: true });
}
finish(out, 'poses');
