// Every alignment path, evaluated by the CLI and by the npm package's wasm in Node: the two
// reports must be byte for byte the same (the core does all its transcendental maths through the
// `libm` crate and in a fixed order, so native and wasm round identically).
// Usage: node same-everywhere.mjs NPM_PACKAGE_DIR CLI_BINARY OUT_DIR [DEPTH_DIR]
// (DEPTH_DIR: depth maps of the demo, tests/browser/make_demo_depth.py, for the visibility case)
// Prints one "ok NAME" / "FAILED NAME: why" line per case.
import { execFileSync } from 'node:child_process';
import { readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [pkgDir, cli, out, depthDir] = process.argv.slice(2).map((p) => resolve(p));
const root = resolve(new URL('../..', import.meta.url).pathname);
const demo = (f) => join(root, 'data/demo', f);
const sfmeval = await import(pathToFileURL(join(pkgDir, 'index.js')).href);
await sfmeval.init();

const gtFiles = { 'ground_truth.glb': readFileSync(demo('ground_truth.glb')) };
const camFiles = { 'cameras.json': readFileSync(demo('cameras.json')) };
const model = {};
for (const f of readdirSync(demo('sparse'))) model[f] = readFileSync(demo(`sparse/${f}`));
const recons = {
  model: () => sfmeval.loadReconstruction(model, 'sparse'),
  ply: () => sfmeval.loadReconstruction({ 'sparse.ply': readFileSync(demo('sparse.ply')) }),
};

// Point pairs: a few model points and where a known similarity puts them (a rotation about a
// skew axis, scale 1.7, a shift), so the points stage has to solve a real rotation.
const recPts = sfmeval.evaluate({ gt: gtFiles, recon: recons.ply(), options: { align: 'none', samples: 1000 } });
const pts = recPts.pointsInGt();
recPts.free();
const [c, s] = [Math.cos(0.7), Math.sin(0.7)];
const pairs = [0, 37, 101, 202, 303, 404].map((i) => {
  const p = [pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]];
  const r = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
  return { recon: r.map((v, k) => 1.7 * v + [0.3, -0.2, 0.1][k]), gt: p };
});
writeFileSync(join(out, 'same-pairs.json'), JSON.stringify({ pairs }));
writeFileSync(join(out, 'same-crop.json'), JSON.stringify({
  schema: 'sfmeval.crop/1',
  volume: { kind: 'oriented_box', center: [0.01, 0.2, 0.0], half_extents: [0.3, 0.25, 0.35], rotation: [[c, -s, 0], [s, c, 0], [0, 0, 1]] },
  max_distance: 0.05,
}));

const cases = [
  ['auto-model', 'model', true, [], { }],
  ['cameras-model', 'model', true, ['--align', 'cameras'], { align: 'cameras' }],
  ['cameras+icp-model', 'model', true, ['--align', 'cameras+icp'], { align: 'cameras+icp' }],
  ['auto-ply-crop', 'ply', false, ['--align', 'auto', '--crop', join(out, 'same-crop.json')], { align: 'auto', crop: JSON.parse(readFileSync(join(out, 'same-crop.json'), 'utf8')) }],
  ['global-ply', 'ply', false, ['--align', 'global'], { align: 'global' }],
  ['points-ply', 'ply', false, ['--align', 'points', '--pairs', join(out, 'same-pairs.json')], { align: 'points', pairs }],
  ['points+icp-ply', 'ply', false, ['--align', 'points+icp', '--pairs', join(out, 'same-pairs.json')], { align: 'points+icp', pairs }],
  ['none-ply-signed', 'ply', false, ['--align', 'none', '--signed'], { align: 'none', signed: true }],
];
if (depthDir) {
  cases.push(['depth-model-min-views-3', 'model', true, ['--depth', depthDir, '--min-views', '3'], { min_views: 3 }]);
}
const depthFiles = {};
if (depthDir) for (const f of readdirSync(depthDir)) depthFiles[`depth/${f}`] = readFileSync(join(depthDir, f));
let failed = 0;
for (const [name, kind, withCams, flags, options] of cases) {
  const recon = kind === 'model' ? demo('sparse') : demo('sparse.ply');
  const common = ['--samples', '200000', '--seed', '3'];
  const args = ['eval', '--gt', demo('ground_truth.glb'), '--recon', recon, ...(withCams ? ['--gt-cameras', demo('cameras.json')] : []), ...flags, ...common, '--json', '--quiet'];
  let expected;
  try {
    expected = execFileSync(cli, args, { maxBuffer: 1 << 28 }).toString();
  } catch (e) {
    failed++; console.log(`FAILED same-${name}: CLI failed: ${e.stderr}`); continue;
  }
  let got;
  try {
    const args = { gt: gtFiles, recon: recons[kind](), options: { ...options, samples: 200000, seed: 3 } };
    if (withCams) args.gtCameras = camFiles;
    if (flags.includes('--depth')) args.depth = depthFiles;
    const r = sfmeval.evaluate(args);
    got = r.reportJson;
    if (flags.includes('--depth')) {
      const labels = r.sampleLabels();
      const rep = JSON.parse(got).completeness_visible;
      const unseen = labels ? labels.filter((l) => l === 2).length : -1;
      if (!labels || labels.length !== rep.samples || rep.samples - unseen !== rep.visible_samples) {
        failed++; console.log(`FAILED same-${name}-labels: ${labels?.length} labels, ${unseen} unseen vs ${JSON.stringify({ samples: rep.samples, visible: rep.visible_samples })}`);
      } else console.log(`ok same-${name}-labels`);
    }
    r.free();
  } catch (e) {
    failed++; console.log(`FAILED same-${name}: wasm failed: ${e.message}`); continue;
  }
  // the CLI prints the JSON with a trailing newline; --report writes the same bytes
  const a = got.trimEnd(), b = expected.trimEnd();
  if (a === b) { console.log(`ok same-${name}`); continue; }
  failed++;
  const la = a.split('\n'), lb = b.split('\n');
  const diff = la.map((l, i) => [l, lb[i]]).filter(([x, y]) => x !== y);
  writeFileSync(join(out, `same-${name}.wasm.json`), got);
  writeFileSync(join(out, `same-${name}.cli.json`), expected);
  console.log(`FAILED same-${name}: ${diff.length} lines differ, first: ${diff[0]?.[0]?.trim()} vs ${diff[0]?.[1]?.trim()}`);
}
process.exit(failed ? 1 : 0);
