// The DTU evaluation in the npm package (Node) and in the page (Chromium), against `sfmeval dtu`
// on the same files: the `sfmeval.dtu/1` report byte for byte, the summary's text, the error
// clouds byte for byte; the scan's files recognised by name and what is missing said.
// The scene: tests/python/dtu_scene.py (a scan in DTU's layout made from the demo, in mm).
// Usage: node dtu.mjs --npm NPM_PACKAGE_DIR --cli CLI_BINARY --scene SCENE_DIR --out OUT_DIR [--url PAGE_URL]
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { basename, dirname, join } from 'node:path';
import { args, argPaths, bytesEqual, check, download, dropAndCheckSummary, ensureDir, finish, firstDiff, loadNpm, withPage } from './driver.mjs';

const [npmDir, cli, sceneDir, out] = argPaths('npm', 'cli', 'scene', 'out');
ensureDir(out);
const sfmeval = await loadNpm(npmDir);

const scene = JSON.parse(readFileSync(join(sceneDir, 'scene.json'), 'utf8'));
const scan = Number(scene.scan);
const gtPaths = [join(sceneDir, `Points/stl/stl${String(scan).padStart(3, '0')}_total.ply`), join(sceneDir, `ObsMask/ObsMask${scan}_10.mat`), join(sceneDir, `ObsMask/Plane${scan}.mat`)];
const gtFiles = Object.fromEntries(gtPaths.map((p) => [basename(p), readFileSync(p)]));

/** `sfmeval dtu` on `recon` (named by its base name: run in its folder), its JSON, summary and clouds. */
function cli_(recon, flags) {
  const vis = join(out, `dtu-cli-${basename(recon, '.ply')}`);
  const run = (extra) => execFileSync(cli, ['dtu', '--dataset', sceneDir, '--scan', String(scan), '--recon', basename(recon), ...flags, ...extra],
    { cwd: dirname(recon), maxBuffer: 1 << 26 }).toString();
  const json = run(['--json', '--vis-out', vis]);
  const summary = run([]);
  const [d2s, s2d] = [`vis_${String(scan).padStart(3, '0')}_d2s.ply`, `vis_${String(scan).padStart(3, '0')}_s2d.ply`].map((f) => readFileSync(join(vis, f)));
  return { json, summary, d2s, s2d };
}

// 1. the npm package: report, summary and clouds equal the CLI's (a real sparse SfM cloud with the
//    default seeded shuffle; a mesh the evaluator samples, in the input's order)
const cases = [['sparse', scene.sparse, [], {}], ['mesh', scene.mesh, ['--mode', 'mesh', '--no-shuffle'], { mode: 'mesh', no_shuffle: true }]];
const cliOut = {};
for (const [name, recon, flags, options] of cases) {
  let want;
  try { want = cli_(recon, flags); } catch (e) { check(`dtu-npm-${name}`, false, `CLI failed: ${e.stderr || e.message}`); continue; }
  cliOut[name] = want;
  let got;
  try {
    got = sfmeval.evaluateDtu({ ...gtFiles, [basename(recon)]: readFileSync(recon) }, options);
  } catch (e) { check(`dtu-npm-${name}`, false, `npm failed: ${e.message}`); continue; }
  check(`dtu-npm-${name}-report-equals-cli`, got.reportJson === want.json, firstDiff(got.reportJson, want.json));
  check(`dtu-npm-${name}-summary-equals-cli`, got.summary === want.summary, firstDiff(got.summary, want.summary));
  check(`dtu-npm-${name}-result-lines-are-the-summarys`, got.resultLines.length === 3 && got.resultLines.every((l) => want.summary.split('\n').map((x) => x.trim()).includes(l))
    && /^mean accuracy/.test(got.resultLines[0]) && /^mean completeness/.test(got.resultLines[1]) && /^overall/.test(got.resultLines[2]), JSON.stringify(got.resultLines));
  check(`dtu-npm-${name}-error-clouds-equal-cli`, bytesEqual(got.d2sPly(), want.d2s) && bytesEqual(got.s2dPly(), want.s2d),
    `${got.d2sPly().length}/${want.d2s.length}, ${got.s2dPly().length}/${want.s2d.length} bytes`);
  const rep = got.report;
  check(`dtu-npm-${name}-numbers`, rep.schema === 'sfmeval.dtu/1' && rep.scan === scan && rep.mode === (name === 'mesh' ? 'mesh' : 'pcd')
    && Number.isFinite(rep.overall) && rep.counts.observed > 0, JSON.stringify(rep).slice(0, 400));
  got.free();
}

// 2. the files by name: what is missing is said, with the name the benchmark gives it
const found = sfmeval.dtuFiles([...Object.keys(gtFiles).filter((n) => !/^Plane/.test(n)), 'recon.ply', 'notes.txt']);
check('dtu-npm-files-missing-named', found.scan === scan && found.missing.length === 1 && found.missing[0].includes(`Plane${scan}.mat`)
  && found.reconstruction === 'recon.ply' && found.ignored.join() === 'notes.txt', JSON.stringify(found));
try {
  sfmeval.evaluateDtu({ [basename(gtPaths[0])]: gtFiles[basename(gtPaths[0])], 'recon.ply': readFileSync(scene.sparse) });
  check('dtu-npm-missing-files-refused', false, 'no error');
} catch (e) {
  check('dtu-npm-missing-files-refused', /ObsMask1_10\.mat/.test(e.message) && /Plane1\.mat/.test(e.message), e.message);
}
try {
  sfmeval.evaluateDtu({ ...gtFiles, [basename(gtPaths[1])]: Buffer.from('MATLAB 5.0 MAT-file, truncated'), 'recon.ply': readFileSync(scene.sparse) });
  check('dtu-npm-bad-mat-names-the-file', false, 'no error');
} catch (e) {
  check('dtu-npm-bad-mat-names-the-file', e.message.includes(basename(gtPaths[1])) && !/panic|unreachable/i.test(e.message), e.message);
}

// 3. the page: the four files dropped on section 6 (one missing first: said, Evaluate DTU off),
//    then the core's lines for mean accuracy, mean completeness and overall, and the report and
//    clouds downloaded byte for byte the CLI's
if (args.url && cliOut.sparse) {
  await withPage(args.url, 'dtu', async (page) => {
    const dropped = [gtPaths[0], gtPaths[1], scene.sparse];
    const missing = await dropAndCheckSummary(page, 'dtu', dropped, sfmeval.dtuFiles(dropped.map((p) => basename(p))), 'dtu-page-shows-the-cores-words-for-the-files');
    check('dtu-page-says-what-is-missing', missing.disabled && missing.line.includes(`Plane${scan}.mat`) && missing.line.includes('scan 1'), JSON.stringify(missing));
    await page.setInputFiles('#file-dtu', [gtPaths[2]]);
    await page.waitForFunction(() => !document.getElementById('dtu-run').disabled, null, { timeout: 10000 });
    await page.locator('#drop-dtu').scrollIntoViewIfNeeded();
    await page.click('#dtu-run');
    await page.waitForFunction(() => document.body.dataset.dtu || document.getElementById('error').textContent, null, { timeout: 300000 });
    const shown = await page.evaluate(() => ({
      lines: [...document.querySelectorAll('#dtu-lines li')].map((li) => li.textContent),
      counts: document.getElementById('dtu-counts').textContent,
      error: document.getElementById('error').textContent,
    }));
    const want = cliOut.sparse.summary.split('\n').filter(Boolean);
    check('dtu-page-shows-the-cores-summary', !shown.error && shown.lines.length === 3 && shown.lines.every((l, i) => l === want[i + 1].trim()) && shown.counts === want[0],
      JSON.stringify({ shown, want }));
    const [, rep] = await download(page, '#dtu-dl-report', out, 'dtu');
    // the page names the reconstruction by its file name, as the CLI run in its folder does
    check('dtu-page-report-equals-cli', rep.toString() === cliOut.sparse.json, firstDiff(rep.toString(), cliOut.sparse.json));
    const [, d2s] = await download(page, '#dtu-dl-d2s', out, 'dtu');
    const [, s2d] = await download(page, '#dtu-dl-s2d', out, 'dtu');
    check('dtu-page-clouds-equal-cli', bytesEqual(d2s, cliOut.sparse.d2s) && bytesEqual(s2d, cliOut.sparse.s2d));
    await page.locator('#drop-dtu').screenshot({ path: join(out, 'dtu-section.png') });
    await page.screenshot({ path: join(out, 'dtu-1366x768.png') });
  });
}
finish(out, 'dtu');
