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
import { copyFileSync, readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { args, argPaths, bytesEqual, check, download, dropAndCheckSummary, ensureDir, finish, firstDiff, loadNpm, withPage } from './driver.mjs';

const [npmDir, cli, sceneDir, out] = argPaths('npm', 'cli', 'scene', 'out');
ensureDir(out);
const sfmeval = await loadNpm(npmDir);

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
  await withPage(args.url, 'eth3d', async (page) => {
    const dropped = ['scan_alignment.mlp', 'scan1.ply', 'dense.ply'];
    const wantFound = sfmeval.eth3dFiles(dropped, files['scan_alignment.mlp']);
    const missing = await dropAndCheckSummary(page, 'eth3d', dropped.map((n) => join(gtDir, n)), wantFound, 'eth3d-page-shows-the-cores-words-for-the-files');
    check('eth3d-page-says-what-is-missing', missing.disabled && missing.line.includes('scan2.ply') && missing.line.includes('reconstruction: dense.ply'), JSON.stringify(missing));
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
    const [, rep] = await download(page, '#eth3d-dl-report', out, 'eth3d');
    check('eth3d-page-report-equals-cli', rep.toString() === want.json, firstDiff(rep.toString(), want.json));
    await page.selectOption('#eth3d-tolerance', '2');
    const [name, cloud] = await download(page, '#eth3d-dl-acc', out, 'eth3d');
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
  });
}
finish(out, 'eth3d');
