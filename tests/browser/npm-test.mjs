// Installs the packed npm tarball into a fresh project, evaluates the demo with it in Node and
// checks the report is byte for byte the CLI's. Usage: node npm-test.mjs TARBALL CLI_REPORT.json
// Prints one "ok NAME" / "FAILED NAME: why" line per check.
import { sameReport } from './same-report.mjs';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { format } from 'node:util';

const [tarball, cliReport] = process.argv.slice(2).map((p) => resolve(p));
const root = resolve(new URL('../..', import.meta.url).pathname);
const demo = (f) => readFileSync(join(root, 'data/demo', f));
let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};

const dir = mkdtempSync(join(tmpdir(), 'sfmeval-npm-'));
writeFileSync(join(dir, 'package.json'), JSON.stringify({ name: 'consumer', private: true, type: 'module' }));
execFileSync('npm', ['install', '--offline', '--no-audit', '--no-fund', '--silent', tarball], { cwd: dir, stdio: 'inherit' });
const pkgJson = JSON.parse(readFileSync(join(dir, 'node_modules/sfmeval/package.json'), 'utf8'));
check('npm-package-metadata', pkgJson.name === 'sfmeval' && pkgJson.version && pkgJson.license && pkgJson.types, JSON.stringify(pkgJson));

// import by package name from inside the consumer project
writeFileSync(join(dir, 'run.mjs'), `
import { readFileSync } from 'node:fs';
export const sfmeval = await import('sfmeval');
`);
const { sfmeval } = await import(pathToFileURL(join(dir, 'run.mjs')).href);
await sfmeval.init();
check('npm-version', typeof sfmeval.version() === 'string' && sfmeval.version().length > 0);

let progressCalls = 0;
const t0 = performance.now();
// the demo as the CLI reads `--recon data/demo/sparse --gt-cameras data/demo/cameras.json`
const model = {};
for (const f of readdirSync(join(root, 'data/demo/sparse'))) model[f] = demo(`sparse/${f}`);
const r = sfmeval.evaluate({
  gt: { 'ground_truth.glb': demo('ground_truth.glb') },
  recon: sfmeval.loadReconstruction(model, 'sparse'),
  gtCameras: { 'cameras.json': demo('cameras.json') },
  onProgress: () => { progressCalls++; },
});
const ms = performance.now() - t0;
const expected = readFileSync(cliReport, 'utf8');
const same = sameReport(r.reportJson, expected);
console.log(`note: npm-report-equals-cli: ${same.detail}`);
check('npm-report-equals-cli', same.ok,
  `report differs from the CLI's (${r.reportJson.length} vs ${expected.length} bytes; ${r.reportJson.split('\n').filter((l, i) => l !== expected.split('\n')[i]).length} lines differ, first: ${r.reportJson.split('\n').find((l, i) => l !== expected.split('\n')[i])?.trim()})`);
check('npm-progress', progressCalls > 0);
const n = r.report.inputs.reconstruction.points;
check('npm-arrays', r.distances().length === n && r.status().length === n && r.colors().length === 3 * n && r.pointsInGt().length === 3 * n);
check('npm-colored-ply', Buffer.from(r.coloredPly().slice(0, 4)).toString() === 'ply\n');
// the sorted distances (sorted in the core) are a plain sort of the kept and the completeness
// distances, and count the report's precision and recall at every τ
{
  const st = r.status(), d = r.distances();
  const kept = Float64Array.from(d.filter((_, i) => st[i] === 0)).sort();
  const comp = Float64Array.from(r.completenessDistances()).sort();
  const sk = r.sortedKeptDistances(), sc = r.sortedCompletenessDistances();
  const below = (xs, t) => xs.filter((x) => x < t).length;
  const atTau = r.report.thresholds.every((t) => below(sk, t.tau) / sk.length === t.precision && below(sc, t.tau) / sc.length === t.recall);
  check('npm-sorted-distances', sk.length === kept.length && sk.every((x, i) => Object.is(x, kept[i]))
    && sc.length === comp.length && sc.every((x, i) => Object.is(x, comp[i])) && atTau, JSON.stringify({ kept: sk.length, comp: sc.length, atTau }));
}
check('npm-csv', r.csv().startsWith('index,x,y,z,distance,signed_distance,status\n'));
// the runner's table through the package: a run's row from run.json + this evaluation, a failed
// run's row, and the tables' text
const runJson = JSON.stringify({ dataset: 'demo', pipeline: 'colmap', tool: 'colmap', version: '3.9', status: 'ok', reason: null,
  wall_seconds: 1, cpu_seconds: 1, peak_memory_bytes: 1e6, images_total: 36, images_registered: 36, points: n });
const row = r.runRow(runJson);
const failedRow = sfmeval.runRow(runJson.replace('"ok"', '"failed"').replace('"pipeline":"colmap"', '"pipeline":"theia"'));
const tables = sfmeval.comparisonTables([row, failedRow]);
check('npm-run-row', row.mean === r.report.accuracy.mean && row.cdf.length === 201 && row.report === 'reports/demo/colmap.json'
  && failedRow.status === 'failed' && failedRow.mean === null, JSON.stringify({ mean: row.mean, report: row.report, failed: failedRow.status }));
check('npm-comparison-tables', tables.table1_md.includes('| dataset | colmap | theia |\n') && tables.table_md.startsWith(tables.table1_md)
  && tables.table1_csv.startsWith('dataset,colmap.mean_m,') && tables.runs_csv.split('\n').length === 4 && JSON.parse(tables.summary_json).rows.length === 2,
  tables.table1_md);
const gtObj = sfmeval.loadGroundTruth({ 'ground_truth.glb': demo('ground_truth.glb') });
gtObj.setCameras(sfmeval.loadCameras({ 'cameras.json': demo('cameras.json') }));
const rec = sfmeval.loadReconstruction(model, 'sparse');
check('npm-camera-poses', gtObj.cameraPoses().length === 36 * sfmeval.POSE_STRIDE && rec.cameraPoses().length === 36 * sfmeval.POSE_STRIDE
  && rec.cameraNames().length === 36 && sfmeval.errorColors([0, 1], 1).length === 6);
gtObj.free(); rec.free();
// the camera alignment's transform as a transform file (16 numbers, row-major)
const gtFromRecon = [...r.gtFromRecon()];
const transformText = [0, 4, 8, 12].map((i) => gtFromRecon.slice(i, i + 4).join(' ')).join('\n') + '\n';
r.free();

try {
  sfmeval.evaluate({ gt: { 'broken.glb': new Uint8Array([103, 108, 84, 70, 2, 0, 0, 0, 1, 2]) }, recon: { 'sparse.ply': demo('sparse.ply') } });
  check('npm-error', false, 'no error thrown');
} catch (e) {
  check('npm-error', e instanceof Error && /ground truth 'broken.glb'/.test(e.message), String(e && e.message));
}
// The alignment modes: the core's single list, the package's type declarations, and a mode
// that needs pairs refusing to run without them.
const modes = sfmeval.alignModes();
const dts = readFileSync(join(dir, 'node_modules/sfmeval', pkgJson.types), 'utf8');
const declared = [...(dts.match(/type AlignModeName =([^;]+);/)?.[1] ?? '').matchAll(/'([^']+)'/g)].map((m) => m[1]);
check('npm-align-modes-match-types', modes.length === 10 && JSON.stringify(modes.map((m) => m.name)) === JSON.stringify(declared),
  `${JSON.stringify(modes.map((m) => m.name))} vs .d.ts ${JSON.stringify(declared)}`);
check('npm-align-modes-needs', modes.filter((m) => m.needsPairs).map((m) => m.name).join() === 'points,points+icp'
  && modes.filter((m) => m.needsCameras).map((m) => m.name).join() === 'cameras,cameras+icp'
  && modes.filter((m) => m.needsTransform).map((m) => m.name).join() === 'given', JSON.stringify(modes));
try {
  sfmeval.evaluate({ gt: { 'ground_truth.glb': demo('ground_truth.glb') }, recon: { 'sparse.ply': demo('sparse.ply') }, options: { align: 'points+icp' } });
  check('npm-align-needs-pairs', false, 'no error thrown');
} catch (e) {
  check('npm-align-needs-pairs', /'points\+icp' needs point pairs/.test(e.message), String(e && e.message));
}

// The README's Node example, as the package ships it, run as written in the consumer project
// beside the demo's files (its gt_from_recon.txt: the transform of the camera alignment above):
// what it prints is the report's numbers, and the report.json it writes is the package's report
// for the same inputs and options.
const readme = readFileSync(join(dir, 'node_modules/sfmeval/README.md'), 'utf8');
const fenced = (heading, lang) => { // the first ```lang block of a README section
  const at = readme.indexOf(`\n## ${heading}\n`);
  const start = at < 0 ? -1 : readme.indexOf('```' + lang + '\n', at);
  const end = start < 0 ? -1 : readme.indexOf('\n```\n', start);
  return end < 0 || readme.slice(at + 1, start).includes('\n## ') ? null : readme.slice(start + lang.length + 4, end + 1);
};
const nodeExample = fenced('Example (Node)', 'js');
let readmeReport = null; // the report.json it writes
check('npm-readme-node-example-found', nodeExample?.includes("from 'sfmeval'"), String(nodeExample));
if (nodeExample) {
  writeFileSync(join(dir, 'readme-example.mjs'), nodeExample);
  writeFileSync(join(dir, 'ground_truth.glb'), demo('ground_truth.glb'));
  writeFileSync(join(dir, 'sparse.ply'), demo('sparse.ply'));
  writeFileSync(join(dir, 'gt_from_recon.txt'), transformText);
  let stdout = '', why = '';
  try {
    stdout = execFileSync(process.execPath, ['readme-example.mjs'], { cwd: dir, encoding: 'utf8', maxBuffer: 1 << 28 });
  } catch (e) { why = `${e.message}\n${e.stderr ?? ''}`; }
  const written = why ? '' : readFileSync(join(dir, 'report.json'), 'utf8');
  if (written) readmeReport = written;
  const same = sfmeval.evaluate({
    gt: { 'ground_truth.glb': demo('ground_truth.glb') },
    recon: { 'sparse.ply': demo('sparse.ply') },
    options: { transform: transformText, tau_percent_of_diagonal: [0.5, 1, 2] },
  });
  const report = same.report;
  check('npm-readme-node-example-runs', !why && written === same.reportJson,
    why || `report.json differs from the package's report (${written.length} vs ${same.reportJson.length} bytes)`);
  // progress lines, then `console.log(mean, thresholds)`
  const printed = format(report.accuracy.mean, report.thresholds) + '\n';
  check('npm-readme-node-example-prints-the-report', !why && stdout.endsWith(printed) && stdout.length > printed.length
    && report.options.align === 'given' && report.thresholds.length === 3 && report.accuracy.count > 0,
    `printed ${JSON.stringify(stdout.slice(-300))}, expected the end ${JSON.stringify(printed)}`);
  same.free();
}

// The package's declarations from TypeScript: npm-example.ts (the README's uses, with
// @ts-expect-error lines that only type-check while the report is typed) and the README's Node
// example as TypeScript, `tsc --noEmit --strict` in the consumer project; then the same with
// `report: any` in the installed index.d.ts must fail (so the check can fail). And real reports
// (the CLI's of the demo with cameras and notes, the README example's without cameras) as object
// literals of type `Report`: tsc rejects a missing field, a field the types do not declare and a
// value of another type, so the generated types say what reports hold. A third report has what
// those two lack: notes with values (`auto`'s global search and ICP), signed statistics, a crop
// volume.
{
  const third = sfmeval.evaluate({
    gt: { 'ground_truth.glb': demo('ground_truth.glb') },
    recon: { 'sparse.ply': demo('sparse.ply') },
    options: { align: 'auto', samples: 20000, signed: true,
      crop: { volume: { kind: 'sphere', center: [0, 0.1, 0], radius: 0.2 }, max_distance: 0.001 } },
  });
  const thirdJson = third.reportJson, thirdReport = third.report;
  third.free();
  const tsc = join(root, 'tests/browser/node_modules/typescript/bin/tsc');
  writeFileSync(join(dir, 'example.ts'), readFileSync(join(root, 'tests/browser/npm-example.ts')));
  writeFileSync(join(dir, 'readme-example.ts'), nodeExample ?? '');
  writeFileSync(join(dir, 'tsconfig.json'), JSON.stringify({
    compilerOptions: {
      strict: true, noEmit: true, target: 'es2022', module: 'nodenext', moduleResolution: 'nodenext',
      lib: ['esnext', 'dom'], types: ['node'], typeRoots: [join(root, 'tests/browser/node_modules/@types')],
    },
    files: ['example.ts', 'readme-example.ts'],
  }));
  writeFileSync(join(dir, 'reports.ts'), `import type { Report } from 'sfmeval';\nexport const reports: Report[] = [\n${
    [expected, readmeReport ?? '{}', thirdJson].join(',\n')}];\n`);
  writeFileSync(join(dir, 'tsconfig.reports.json'), JSON.stringify({ extends: './tsconfig.json', files: ['reports.ts'] }));
  const run = (config = 'tsconfig.json') => {
    try { execFileSync(process.execPath, [tsc, '-p', config], { cwd: dir, encoding: 'utf8' }); return { ok: true, out: '' }; }
    catch (e) { return { ok: false, out: `${e.stdout ?? ''}${e.stderr ?? ''}${e.stdout || e.stderr ? '' : e.message}` }; }
  };
  const typed = run();
  check('npm-types-tsc-example', typed.ok && nodeExample, typed.out.slice(0, 2000));
  const literal = run('tsconfig.reports.json');
  check('npm-types-accept-reports', literal.ok && readmeReport && thirdReport.notes.some((n) => n.values)
    && thirdReport.accuracy.signed && thirdReport.crop.volume, literal.out.slice(0, 2000) || JSON.stringify(thirdReport.notes));
  const indexDts = join(dir, 'node_modules/sfmeval/index.d.ts');
  const original = readFileSync(indexDts, 'utf8');
  const loose = original.replace('readonly report: Report;', 'readonly report: any;');
  writeFileSync(indexDts, loose);
  const untyped = run();
  writeFileSync(indexDts, original);
  check('npm-types-tsc-fails-when-report-is-any', loose !== original && !untyped.ok && /TS2578/.test(untyped.out),
    loose === original ? 'index.d.ts has no `readonly report: Report;`' : untyped.out.slice(0, 1000));
}

const crop = sfmeval.parseCrop('{"schema":"sfmeval.crop/1","volume":{"kind":"sphere","center":[0,0,0],"radius":1}}');
check('npm-crop-roundtrip', crop.volume.kind === 'sphere' && sfmeval.cropFile(crop).includes('"sfmeval.crop/1"'));

// The Compare table's cells come from the core's catalogue: its texts are the numbers as
// JavaScript writes them (String, toPrecision(4), toExponential(3): the page's former format),
// here against V8's own on numbers across every range and the rounding edges; the best marks
// follow each column's best end.
{
  const jsText = (v) => {
    if (v == null || Number.isNaN(v)) return '—';
    if (Number.isInteger(v)) return String(v);
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(3) : v.toPrecision(4);
  };
  let seed = 12345;
  const rand = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  const values = [0.00125, 0.125, 99999.99, 0.00099995, 1.0005, 2.5, 1e21, 123456.5, 0.0009999, -0.33335, 12345.65];
  for (let i = 0; i < 3000; i++) values.push((rand() - 0.3) * 10 ** Math.floor(rand() * 16 - 9));
  for (let i = 0; i < 300; i++) values.push(Math.round(rand() * 1e6) / 1e4); // 4 decimals: many ties
  const row = JSON.parse(JSON.stringify(sfmeval.runRow(JSON.stringify({
    dataset: 'd', pipeline: 'p', tool: 't', version: null, status: 'ok', reason: null, wall_seconds: 0,
    cpu_seconds: 0, peak_memory_bytes: 0, images_total: 36, images_registered: 30, points: 100,
  }))));
  const entries = values.map((v, i) => ({ row: { ...row, pipeline: `p${i}` }, report: { accuracy: { min: v }, thresholds: [] } }));
  const t = sfmeval.compareTable(entries);
  const minCol = t.columns.findIndex((c) => c.id === 'min');
  const bad = values.map((v, i) => [v, t.rows[i][minCol].text, jsText(v)]).filter(([, a, b]) => a !== b);
  check('npm-compare-table-numbers-as-javascript-writes-them', minCol >= 0 && bad.length === 0, JSON.stringify(bad.slice(0, 5)));
  const lowest = Math.min(...values);
  check('npm-compare-table-best-is-the-catalogue-end', t.columns[minCol].best === 'lower'
    && t.rows.every((r, i) => r[minCol].best === (values[i] === lowest)), JSON.stringify(t.columns[minCol]));
  const cat = sfmeval.metricCatalogue();
  const byKey = Object.fromEntries(cat.map((m) => [m.key, m]));
  check('npm-catalogue-drives-the-compare-columns', t.columns.every((c) => {
    const m = byKey[c.key.replace(/\[\d+\]/, '[*]')];
    return m && m.best === c.best && c.header.startsWith(m.header) && (m.unit ?? null) === c.unit;
  }) && byKey['report.accuracy.mean'].best === 'lower' && byKey['report.thresholds[*].f_score'].best === 'higher',
  JSON.stringify(t.columns));
}
// a run folder's reconstruction as the runner reads it: model/'s model files, else sparse.ply
check('npm-run-folder-layout', JSON.stringify(sfmeval.runReconstructionFiles(['run.json', 'log.txt', 'sparse.ply', 'model/sparse/0/points3D.bin', 'model/x.jpg']))
  === JSON.stringify([['model/sparse/0/points3D.bin', 'sparse/0/points3D.bin']])
  && JSON.stringify(sfmeval.runReconstructionFiles(['run.json', 'sparse.ply', 'model/notes.md'])) === JSON.stringify([['sparse.ply', 'sparse.ply']]));
console.log(`npm: demo evaluated in ${ms.toFixed(0)} ms in Node`);
process.exit(failed ? 1 : 0);
