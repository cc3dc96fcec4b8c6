// The Tanks and Temples protocol in the npm package (Node) and in the page (Chromium), against
// `sfmeval tnt` on the same files (given the scene folder by its name, as the page names it): the
// `sfmeval.tanksandtemples/2` report byte for byte, the summary's text, every file the CLI writes
// beside the report (coloured clouds, curves, the plot's SVG) byte for byte; the scene's files
// recognised and what is missing said; a wrong file refused with the core's message naming it.
// The scene: tests/python/tnt_scene.py (the demo's statue in the benchmark's layout, a dense-like
// cloud in the pycolmap run's frame), the trajectory written by `sfmeval log` from the demo's
// COLMAP model, τ given (the scene is not in the benchmark's table).
// Usage: node tnt.mjs --npm NPM_PACKAGE_DIR --cli CLI_BINARY --scene OUT_OF_TNT_SCENE --tau T --out OUT_DIR [--url PAGE_URL]
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { args, bytesEqual, check, download, dropAndCheckSummary, ensureDir, finish, firstDiff, loadNpm, argPaths, withPage } from './driver.mjs';

const [npmDir, cli, root, out] = argPaths('npm', 'cli', 'scene', 'out');
const tau = Number(args.tau);
ensureDir(out);
const sfmeval = await loadNpm(npmDir);

const S = 'Synth';
const paths = {
  [`${S}.ply`]: join(root, S, `${S}.ply`), [`${S}.json`]: join(root, S, `${S}.json`),
  [`${S}_trans.txt`]: join(root, S, `${S}_trans.txt`), [`${S}_COLMAP_SfM.log`]: join(root, S, `${S}_COLMAP_SfM.log`),
  'traj.log': join(root, 'recon', 'traj.log'), 'dense.ply': join(root, 'recon', 'dense.ply'),
};
const files = Object.fromEntries(Object.entries(paths).map(([n, p]) => [n, readFileSync(p)]));

// 1. the npm package: report, summary and every output file equal the CLI's
const cliOut = join(out, 'tnt-cli');
let want = null;
try {
  const run = (extra) => execFileSync(cli, ['tnt', '--scene', S, '--recon', 'recon/dense.ply', '--trajectory', 'recon/traj.log',
    '--tau', String(tau), '--out', cliOut, ...extra], { cwd: root, maxBuffer: 1 << 26 }).toString();
  want = { json: run(['--json']), summary: run([]) };
} catch (e) { check('tnt-cli', false, `CLI failed: ${e.stderr || e.message}`); }
if (want) {
  let got = null;
  try { got = sfmeval.evaluateTnt(files, { tau }); } catch (e) { check('tnt-npm', false, `npm failed: ${e.message}`); }
  if (got) {
    check('tnt-npm-report-equals-cli', got.reportJson === want.json, firstDiff(got.reportJson, want.json));
    // the CLI's summary ends with where it wrote the files
    const wantSummary = want.summary.split('\n').filter((l) => l && !/^ {2}written to /.test(l)).join('\n') + '\n';
    check('tnt-npm-summary-equals-cli', got.summary === wantSummary, firstDiff(got.summary, wantSummary));
    let same = got.fileNames.length === 6, why = `${got.fileNames}`;
    for (const n of got.fileNames) {
      if (!bytesEqual(got.file(n), readFileSync(join(cliOut, n)))) { same = false; why += `; ${n} differs`; }
    }
    check('tnt-npm-files-equal-cli', same, why);
    const rep = got.report;
    check('tnt-npm-numbers', rep.protocol.scene === S && rep.f_score > 0.3 && rep.f_score < 1 && rep.registration.refinement.length === 3
      && /<svg/.test(got.plotSvg), JSON.stringify(rep).slice(0, 300));
    got.free();
  }
}

// 2. the files: what is missing is said; a wrong file names itself
const found = sfmeval.tntFiles([`${S}.ply`, `${S}_trans.txt`, `${S}_COLMAP_SfM.log`, 'traj.log', 'dense.ply', 'notes.md']);
check('tnt-npm-files-missing-named', found.scene === S && found.missing.length === 1 && found.missing[0].includes(`${S}.json`)
  && found.trajectory === 'traj.log' && found.reconstruction === 'dense.ply' && found.ignored.join() === 'notes.md', JSON.stringify(found));
try {
  sfmeval.evaluateTnt({ ...files, [`${S}_trans.txt`]: Buffer.from('1 0 0\n0 1 0\n') }, { tau });
  check('tnt-npm-bad-alignment-names-the-file', false, 'no error');
} catch (e) {
  check('tnt-npm-bad-alignment-names-the-file', e.message.includes(`${S}_trans.txt`) && !/panic|unreachable/i.test(e.message), e.message);
}

// 3. the page: all but the crop dropped (said missing, Evaluate off), then the crop; the core's
//    lines and plot shown, the report and a cloud downloaded byte for byte the CLI's; then a
//    trajectory that is not one: the core's message naming it
if (args.url && want) {
  await withPage(args.url, 'tnt', async (page) => {
    const dropped = Object.keys(paths).filter((n) => n !== `${S}.json`);
    const missing = await dropAndCheckSummary(page, 'tnt', dropped.map((n) => paths[n]), sfmeval.tntFiles(dropped), 'tnt-page-shows-the-cores-words-for-the-files');
    check('tnt-page-says-what-is-missing', missing.disabled && missing.line.includes(`${S}.json`) && missing.line.includes(`scene ${S}`), JSON.stringify(missing));
    await page.setInputFiles('#file-tnt', [paths[`${S}.json`]]);
    await page.waitForFunction(() => !document.getElementById('tnt-run').disabled, null, { timeout: 10000 });
    await page.locator('#drop-tnt').scrollIntoViewIfNeeded();
    await page.fill('#tnt-tau', String(tau));
    await page.click('#tnt-run');
    await page.waitForFunction(() => document.body.dataset.tnt || document.getElementById('error').textContent, null, { timeout: 120000 });
    const shown = await page.evaluate(() => ({
      lines: [...document.querySelectorAll('#tnt-lines li')].map((li) => li.textContent),
      plot: (() => { const img = document.querySelector('#tnt-plot img'); return img ? img.naturalWidth : 0; })(),
      error: document.getElementById('error').textContent,
    }));
    const wantLines = want.summary.split('\n').filter((l) => l && !/^ {2}written to /.test(l)).map((l) => l.trim());
    check('tnt-page-shows-the-cores-summary', !shown.error && shown.lines.length === wantLines.length && shown.lines.every((l, i) => l === wantLines[i])
      && shown.lines.some((l) => /^precision .* F-score/.test(l)), JSON.stringify({ shown, wantLines }));
    check('tnt-page-shows-the-plot', shown.plot > 0, `image width ${shown.plot}`);
    const [, rep] = await download(page, '#tnt-dl-report', out, 'tnt');
    check('tnt-page-report-equals-cli', rep.toString() === want.json, firstDiff(rep.toString(), want.json));
    await page.selectOption('#tnt-file', `${S}.precision.ply`);
    const [name, cloud] = await download(page, '#tnt-dl-file', out, 'tnt');
    check('tnt-page-cloud-equals-cli', name === `${S}.precision.ply` && bytesEqual(cloud, readFileSync(join(cliOut, name))), name);
    await page.locator('#tnt-result').screenshot({ path: join(out, 'tnt-section.png') });
    await page.screenshot({ path: join(out, 'tnt-1366x768.png') });
    // traj.log replaced by a file that is no trajectory: the core's message, naming it
    const bad = join(out, 'traj.log');
    writeFileSync(bad, '0 0 1\n1 0 0 0\n');
    await page.setInputFiles('#file-tnt', [bad]);
    await page.waitForFunction(() => !document.getElementById('tnt-run').disabled, null, { timeout: 10000 });
    await page.click('#tnt-run');
    await page.waitForFunction(() => /failed/.test(document.getElementById('error').textContent), null, { timeout: 30000 }).catch(() => {});
    const err = await page.evaluate(() => document.getElementById('error').textContent);
    check('tnt-page-wrong-file-named', err.includes('traj.log') && !/panic|unreachable/i.test(err), err);
  });
}
finish(out, 'tnt');
