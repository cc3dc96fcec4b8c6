// The npm package used from TypeScript as its README shows: type-checked (never run) by
// npm-test.mjs with `tsc --noEmit --strict` against the packed package's declarations, so the
// report's types (report.d.ts, generated from the Rust types) are what a user compiles against.
// The @ts-expect-error lines must stay errors: if the types loosened (`report: any`) or lost a
// field's type, tsc would fail on the unused directive.
import { readFile, writeFile } from 'node:fs/promises';
import { init, evaluate, loadReconstruction, evaluateDtu, dtuFiles, type Code, type DtuReport, type Note, type Report, type Statistics } from 'sfmeval';

await init();
const result = evaluate({
  gt: { 'ground_truth.glb': await readFile('ground_truth.glb') },
  recon: loadReconstruction({ 'sparse.ply': await readFile('sparse.ply') }),
  gtCameras: { 'cameras.json': await readFile('cameras.json') },
  options: { align: 'auto', tau_percent_of_diagonal: [0.5, 1, 2] },
  onProgress: (stage, done, total) => console.log(stage, done, total),
});
// inferred, not annotated: the check below must see what `result.report` is
const report = result.report;
const same: Report = report;

// statistics are flattened into their section
const mean: number = report.accuracy.mean;
const p95: number = report.accuracy.percentiles.p95;
const bins: number[] = report.completeness.histogram.counts;
const stats: Statistics = report.completeness;
// @ts-expect-error: there is no `stats` object (the README's old example read it and threw)
console.log(report.accuracy.stats.mean);

// thresholds, a fixed 4×4, the schema literal
const f: number = report.thresholds[0].f_score;
const row: [number, number, number, number] = report.alignment.gt_from_recon[0];
const schema: 'sfmeval.report/3' = report.schema;
// @ts-expect-error: the schema is a literal, not any string
const other: 'sfmeval.report/2' = report.schema;

// cameras: null without ground-truth cameras
const ate: number | undefined = report.cameras?.ate_rmse;
// @ts-expect-error: possibly null
console.log(report.cameras.ate_rmse);
// sections only present with depth maps: optional, never null
const visible: number | undefined = report.completeness_visible?.visible_fraction;
// @ts-expect-error: absent, not null
const nullVisible: typeof report.completeness_visible = null;

// notes: a code from the catalogue, a level, values by name
const note: Note | undefined = report.notes[0];
const code: Code | undefined = note?.code;
const warnings = report.notes.filter((n) => n.level === 'warning').map((n) => n.message);
const icpRejected = report.notes.some((n) => n.code === 'alignment.icp_rejected');
// @ts-expect-error: not a code of the catalogue
const noSuchCode = report.notes.some((n) => n.code === 'alignment.no_such_code');
// @ts-expect-error: levels are 'info' | 'warning'
const badLevel = report.notes.some((n) => n.level === 'error');
const stage = note?.values?.stage;

// the crop volume of the report, a tagged union
const volume = report.crop.volume;
const radius = volume?.kind === 'sphere' ? volume.radius : undefined;

console.log(same === report, mean, p95, bins.length, stats.count, f, row, schema, other, ate, visible, nullVisible,
  code, warnings, icpRejected, noSuchCode, badLevel, stage, radius);
await writeFile('report.json', result.reportJson);
result.free();

// the DTU evaluation: the report's types generated from sfmeval-dtu's Rust types
const scanFiles = {
  'stl001_total.ply': await readFile('stl001_total.ply'),
  'ObsMask1_10.mat': await readFile('ObsMask1_10.mat'),
  'Plane1.mat': await readFile('Plane1.mat'),
  'recon.ply': await readFile('recon.ply'),
};
const found = dtuFiles(Object.keys(scanFiles));
if (found.missing.length) console.log(`missing: ${found.missing.join('; ')}`);
const dtu = evaluateDtu(scanFiles, { mode: 'pcd' });
const dtuReport: DtuReport = dtu.report;
const overall: number | null = dtuReport.overall;
const observed: number = dtuReport.counts.observed;
const dtuSchema: 'sfmeval.dtu/1' = dtuReport.schema;
// @ts-expect-error: the DTU report has no `accuracy` section (its means are top-level)
console.log(dtuReport.accuracy.mean);
console.log(overall, observed, dtuSchema, dtu.resultLines.join('\n'));
dtu.free();
