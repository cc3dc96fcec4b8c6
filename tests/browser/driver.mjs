// What the benchmark drivers (dtu.mjs, poses.mjs, eth3d.mjs, tnt.mjs) share: their `--name value`
// arguments, the npm package loaded, the "ok NAME" / "FAILED NAME: why" lines and the exit code,
// text and byte comparisons, the page opened in headless Chromium (the flags CI needs as root,
// SwiftShader for WebGL, downloads on, 1366×768), a download saved and read back, and the
// core's words for a set of dropped files checked as the page shows them.
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

/** `--name value` pairs of the command line. */
export const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));

/** The arguments `names` as absolute paths. */
export const argPaths = (...names) => names.map((k) => resolve(args[k]));

/** The npm package in `npmDir`, initialised. */
export async function loadNpm(npmDir) {
  const sfmeval = await import(pathToFileURL(join(npmDir, 'index.js')).href);
  await sfmeval.init();
  return sfmeval;
}

let failed = 0;
/** Prints `ok name`, or `FAILED name: why` and counts it. */
export const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};

/** Marks the driver done in `out` (`KEY-done`) and exits 1 when a check failed. */
export function finish(out, key) {
  writeFileSync(join(out, `${key}-done`), '');
  process.exit(failed ? 1 : 0);
}

/** Where two texts first differ, for a failure's message. */
export const firstDiff = (a, b) => {
  const x = a.split('\n'), y = b.split('\n');
  const i = x.findIndex((l, k) => l !== y[k]);
  return i < 0 ? (x.length === y.length ? 'equal' : 'lengths differ') : `line ${i + 1}: ${x[i]} vs ${y[i]}`;
};

/** Whether two byte arrays are equal. */
export const bytesEqual = (a, b) => a.length === b.length && Buffer.compare(Buffer.from(a), Buffer.from(b)) === 0;

/**
 * Opens the page at `url` in headless Chromium and waits until it is ready, then awaits
 * `run(page, errors)`; `errors` collects the page's uncaught errors (and, with `consoleErrors`,
 * its console errors). A throw is the check `key-page` failing. The browser is closed after.
 */
export async function withPage(url, key, run, { consoleErrors = false } = {}) {
  const { chromium } = await import('playwright-core');
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  try {
    const page = await (await browser.newContext({ acceptDownloads: true, viewport: { width: 1366, height: 768 } })).newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(String(e)));
    if (consoleErrors) page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    await page.goto(url);
    await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
    await run(page, errors);
    check(`${key}-page-no-errors`, errors.length === 0, errors.join(' | '));
  } catch (e) {
    check(`${key}-page`, false, e.stack || String(e));
  } finally {
    await browser.close();
  }
}

/** Clicks `selector` and saves the download into `out` as `PREFIX-page-NAME`: `[name, bytes]`. */
export async function download(page, selector, out, prefix) {
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click(selector)]);
  const p = join(out, `${prefix}-page-${dl.suggestedFilename()}`);
  await dl.saveAs(p);
  return [dl.suggestedFilename(), readFileSync(p)];
}

/**
 * Picks `files` in section `key`'s file input and checks that the page shows the core's words
 * for them as they are (`want`, the npm package's answer for the same names: its `summary` line
 * and status) with Evaluate off or on as the core says; returns what the page showed.
 */
export async function dropAndCheckSummary(page, key, files, want, name) {
  await page.setInputFiles(`#file-${key}`, files);
  await page.waitForFunction(([k, line]) => document.getElementById(`info-${k}`).textContent === line, [key, want.summary.line], { timeout: 10000 }).catch(() => {});
  const shown = await page.evaluate((k) => ({
    line: document.getElementById(`info-${k}`).textContent,
    status: document.getElementById(`${k}-status`).textContent,
    disabled: document.getElementById(`${k}-run`).disabled,
    error: document.getElementById(`info-${k}`).classList.contains('error'),
  }), key);
  check(name, shown.line === want.summary.line && shown.status === want.summary.status
    && shown.disabled === !want.summary.complete && shown.error === want.summary.problem, JSON.stringify({ shown, want: want.summary }));
  return shown;
}

/** `mkdir -p out`. */
export const ensureDir = (out) => { mkdirSync(out, { recursive: true }); return out; };
