// The page used as a person would, in Debian's Chromium driven by playwright-core: at
// 1366×768 and 1920×1080 the Evaluate button and every error are inside the viewport
// (element geometry, and what is drawn at their centre); a broken file is reported beside its
// input and in the banner, and the previous results are marked out of date; the colour bar,
// P/R legend, transform grid and alignment notes read right; keyboard-only use reaches every
// control in order; axe-core finds no serious or critical violation; Cancel returns the UI to
// idle with the inputs kept; no request leaves the page's origin. Screenshots go to OUT.
// Usage: node ux.mjs --url http://127.0.0.1:PORT/ --out DIR
// Prints one "ok NAME" / "FAILED NAME: why" line per check; exits 1 when one failed.
import { chromium } from 'playwright-core';
import { axeViolations } from './axe.mjs';
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const url = args.url;
const out = resolve(args.out);
mkdirSync(out, { recursive: true });
const origin = new URL(url).origin;

let failed = 0;
const check = (name, ok, why = '') => {
  if (ok) console.log(`ok ${name}`);
  else { failed++; console.log(`FAILED ${name}: ${why}`); }
};

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-dev-shm-usage', '--disable-gpu'],
});
const requests = [];
const consoleErrors = [];
const t0 = Date.now();

/**
 * Where an element is: its rectangle, whether it lies wholly inside the viewport, and whether
 * it is what the page draws at its centre (not covered by anything else).
 */
function where(page, sel) {
  return page.evaluate((s) => {
    const el = document.querySelector(s);
    if (!el) return { missing: true };
    const r = el.getBoundingClientRect();
    const vw = window.innerWidth, vh = window.innerHeight;
    const inside = r.width > 0 && r.height > 0 && r.left >= 0 && r.top >= 0 && r.right <= vw && r.bottom <= vh;
    const hit = inside ? document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2) : null;
    return {
      inside, onTop: !!hit && (hit === el || el.contains(hit)), visible: el.checkVisibility(),
      rect: [r.left, r.top, r.right, r.bottom].map(Math.round), viewport: [vw, vh],
      // no page-level scrolling: the layout is the viewport's height, panels scroll inside it
      pageScroll: document.documentElement.scrollHeight - vh,
    };
  }, sel);
}
const inView = (w) => !w.missing && w.inside && w.onTop && w.visible && w.pageScroll <= 0;

async function evaluateAndWait(page) {
  const before = Number(await page.evaluate(() => document.body.dataset.evaluated || 0));
  await page.click('#run');
  await page.waitForFunction((n) => Number(document.body.dataset.evaluated || 0) > n || document.getElementById('error').textContent,
    before, { timeout: 600000 });
  const err = await page.textContent('#error');
  if (err) throw new Error(`page error: ${err}`);
}
async function loadDemo(page) {
  await page.click('#demo');
  await page.waitForFunction(() => /^sparse \(/.test(document.getElementById('info-recon').textContent)
    && !document.getElementById('run').disabled, null, { timeout: 60000 });
}
/** Drops a PLY whose vertex rows are short: the core's reader says it is malformed. */
async function dropBrokenPly(page) {
  await page.locator('#file-recon').scrollIntoViewIfNeeded(); // a person picks a file from the input in view
  await page.setInputFiles('#file-recon', {
    name: 'broken.ply', mimeType: 'application/octet-stream',
    buffer: Buffer.from('ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2\n'),
  });
  await page.waitForFunction(() => document.getElementById('info-recon').classList.contains('error'), null, { timeout: 30000 });
}
async function axeScan(page, name) {
  const { bad, minor } = await axeViolations(page);
  if (minor.length) console.log(`note: ${name}: minor axe findings: ${minor.join(', ')}`);
  check(name, bad.length === 0, JSON.stringify(bad));
}

async function newPage(w, h, before = null) {
  const context = await browser.newContext({ viewport: { width: w, height: h } });
  context.on('request', (r) => requests.push(r.url()));
  if (before) await before(context);
  const page = await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  await page.goto(url);
  await page.waitForFunction(() => document.body.dataset.ready === '1', null, { timeout: 60000 });
  return page;
}

/** The run button stays in view wherever the inputs panel is scrolled. */
async function runButtonChecks(page, tag) {
  const first = await where(page, '#run');
  check(`${tag} run-button-in-view-initially`, inView(first), JSON.stringify(first));
  const spots = ['#drop-recon', '#drop-depth', '#transform', '#crop-kind', '#bins'];
  const bad = [];
  for (const s of spots) {
    await page.locator(s).scrollIntoViewIfNeeded();
    await page.evaluate((q) => document.querySelector(q).scrollIntoView({ block: 'start' }), s);
    const w = await where(page, '#run');
    if (!inView(w)) bad.push(`${s}: ${JSON.stringify(w)}`);
  }
  // (the panel did scroll when its content is taller than it)
  const panel = await page.evaluate(() => {
    const p = document.getElementById('panel-scroll');
    return { top: p.scrollTop, overflows: p.scrollHeight > p.clientHeight };
  });
  check(`${tag} run-button-in-view-after-scrolling-inputs`, bad.length === 0 && (panel.top > 0) === panel.overflows,
    bad.join('; ') || JSON.stringify(panel));
  await page.evaluate(() => { document.getElementById('panel-scroll').scrollTop = 0; });
}

/** A broken reconstruction: banner and info line in view, the old results out of date. */
async function brokenFileChecks(page, tag) {
  await dropBrokenPly(page);
  const banner = await where(page, '#banner');
  const text = await page.textContent('#error');
  check(`${tag} error-banner-in-view`, inView(banner) && /broken\.ply/.test(text) && /malformed|PLY/i.test(text)
    && (await page.getAttribute('#error', 'role')) === 'alert', `${JSON.stringify(banner)} "${text}"`);
  const info = await where(page, '#info-recon');
  const infoText = await page.textContent('#info-recon');
  check(`${tag} error-beside-input-in-view`, inView(info) && /broken\.ply/.test(infoText)
    && (await page.getAttribute('#file-recon', 'aria-invalid')) === 'true', `${JSON.stringify(info)} "${infoText}"`);
  const stale = await page.evaluate(() => ({
    marked: document.getElementById('results').classList.contains('stale') && !document.getElementById('stale-note').hidden,
    note: document.getElementById('stale-note').textContent,
    downloads: ['dl-report', 'dl-ply', 'dl-csv'].map((id) => document.getElementById(id).disabled),
    points: !!window.sfmevalViewer.points,
    colorbar: getComputedStyle(document.getElementById('colorbar')).display,
    run: document.getElementById('run').disabled,
    status: document.getElementById('run-status').textContent,
  }));
  const note = await where(page, '#stale-note');
  check(`${tag} old-results-marked-stale`, stale.marked && /reconstruction failed to load/.test(stale.note) && inView(note)
    && stale.downloads.every(Boolean) && !stale.points && stale.colorbar === 'none' && stale.run && /load a reconstruction/.test(stale.status),
  JSON.stringify({ ...stale, note })); // eslint-disable-line
  await page.screenshot({ path: join(out, `ux-${tag}-error.png`) });
  // the banner's "show the input" focuses it; dismissing hides the banner, the info line stays
  await page.click('#banner-goto');
  const focused = await page.evaluate(() => document.activeElement && document.activeElement.id);
  await page.click('#banner-close');
  check(`${tag} error-banner-show-and-dismiss`, focused === 'file-recon' && await page.isHidden('#banner')
    && /broken\.ply/.test(await page.textContent('#info-recon')), `focused ${focused}`);
}

try {
  // ---- 1366×768: first look, demo, results, keyboard, axe, cancel, broken file ----------
  {
    const tag = '1366x768';
    const page = await newPage(1366, 768);
    check('page-loads', true);
    const hint = await page.textContent('#run-status');
    check(`${tag} run-button-says-what-is-missing`, await page.isDisabled('#run') && /load a reconstruction and a ground truth/.test(hint), hint);
    await axeScan(page, `${tag} axe-initial-no-serious-violations`);
    await runButtonChecks(page, tag);
    await loadDemo(page);
    await evaluateAndWait(page);
    // the 3D view draws on demand: idle, no frame at all (a redraw every frame kept a core busy
    // under a software renderer and slowed the evaluation's workers); a change draws once
    const frames = await page.evaluate(async () => {
      const v = window.sfmevalViewer;
      const draw = v.renderer.render.bind(v.renderer);
      let n = 0;
      v.renderer.render = (...a) => { n += 1; return draw(...a); };
      await new Promise((r) => setTimeout(r, 1500));
      const idle = n;
      v.setPointSize(4);
      await new Promise((r) => setTimeout(r, 500));
      const changed = n - idle;
      v.renderer.render = draw;
      return { idle, changed };
    });
    check(`${tag} viewer-idle-draws-nothing-a-change-draws-once`, frames.idle === 0 && frames.changed === 1, JSON.stringify(frames));
    // colour bar: 0 left of the gradient, "≥ clip" right of it, nothing else
    const cb = await page.evaluate(() => {
      const r = (id) => document.getElementById(id).getBoundingClientRect();
      return { lo: document.getElementById('cb-lo').textContent, hi: document.getElementById('cb-hi').textContent,
        loRight: r('cb-lo').right, canvasLeft: r('colorbar-canvas').left, canvasRight: r('colorbar-canvas').right, hiLeft: r('cb-hi').left,
        clip: window.sfmeval.state.result.clip };
    });
    check(`${tag} colour-bar-labels-at-their-ends`, cb.lo === '0' && cb.hi === `≥ ${Number(cb.clip.toPrecision(3))}` && cb.loRight <= cb.canvasLeft
      && cb.hiLeft >= cb.canvasRight, JSON.stringify(cb));
    // P/R legend: a key of the curves, no "--" placeholders
    const legend = await page.textContent('#pr .u-legend');
    check(`${tag} pr-legend-without-placeholders`, !/--/.test(legend) && /precision/.test(legend) && /recall/.test(legend) && !/τ/.test(legend), legend);
    // the transform: 4 lines of 4 right-aligned numbers with the same decimals, not wrapped
    const mx = await page.evaluate(() => {
      const el = document.getElementById('matrix');
      const lines = el.textContent.split('\n');
      const lh = parseFloat(getComputedStyle(el).lineHeight);
      return { lines, height: el.clientHeight, lh, fits: el.scrollWidth <= el.clientWidth };
    });
    const cells = mx.lines.map((l) => l.trim().split(/\s+/));
    const decimals = new Set(cells.flat().map((c) => (c.split('.')[1] || '').length));
    check(`${tag} transform-aligned-4x4`, mx.lines.length === 4 && cells.every((r) => r.length === 4) && new Set(mx.lines.map((l) => l.length)).size === 1
      && decimals.size === 1 && mx.height < 5 * mx.lh && mx.fits
      && mx.lines.every((l) => [...l.matchAll(/\S+/g)].map((m) => m.index + m[0].length).join() === [...mx.lines[0].matchAll(/\S+/g)].map((m) => m.index + m[0].length).join()),
    JSON.stringify(mx));
    // a transform file in the "given" box: one row per line, columns aligned, values exact
    const given = [[0.2439351234567891, -0.29985, 0.298601, 0.001844], [-0.000515, -0.34487, -0.345892, 1.1819175786081955], [0.423169, 0.172428, -0.172549, -1e-7], [0, 0, 0, 1]];
    await page.setInputFiles('#file-transform', { name: 'gt_from_recon.txt', mimeType: 'text/plain', buffer: Buffer.from(`${given.map((r) => r.join(' ')).join('\n')}\n`) });
    await page.waitForFunction(() => document.getElementById('transform').value.includes('1.1819175786081955'));
    const box = await page.evaluate(() => {
      const t = document.getElementById('transform');
      return { lines: t.value.split('\n'), wrap: t.wrap, lh: parseFloat(getComputedStyle(t).lineHeight), rows: t.rows };
    });
    check(`${tag} given-transform-box-aligned-exact-unwrapped`, box.lines.length === 4 && box.wrap === 'off' && new Set(box.lines.map((l) => l.length)).size === 1
      && JSON.stringify(box.lines.map((l) => l.trim().split(/\s+/).map(Number))) === JSON.stringify(given), JSON.stringify(box));
    await page.check('input[name=align][value=auto]');
    await page.fill('#transform', '');
    await page.screenshot({ path: join(out, `ux-${tag}-results.png`) });
    await axeScan(page, `${tag} axe-results-no-serious-violations`);

    // keyboard only: Tab from the top reaches every enabled, visible control once, in DOM order
    // start where a person would: click the page's title (Tab then starts from the top)
    await page.evaluate(() => { document.getElementById('panel-scroll').scrollTop = 0; });
    await page.click('h1');
    const expected = await page.evaluate(() => {
      const key = (el) => el.id || `${el.name}=${el.value}`;
      const seenGroups = new Set();
      const list = [];
      for (const el of document.querySelectorAll('a[href], button, input, select, textarea, [tabindex]')) {
        if (el.disabled || el.tabIndex < 0 || !el.checkVisibility()) continue;
        if (el.type === 'radio') { // one stop per group: its checked radio
          if (seenGroups.has(el.name)) continue;
          seenGroups.add(el.name);
          list.push(key(document.querySelector(`input[name="${el.name}"]:checked`) || el));
        } else list.push(key(el));
      }
      return list;
    });
    const reached = [];
    const offscreen = [];
    for (let i = 0; i < expected.length + 3; i++) {
      await page.keyboard.press('Tab');
      const f = await page.evaluate(() => {
        const el = document.activeElement;
        if (!el || el === document.body) return null;
        const r = (el.classList.contains('visually-hidden') ? el.parentElement : el).getBoundingClientRect();
        return { key: el.id || `${el.name}=${el.value}`, inside: r.bottom > 0 && r.top < window.innerHeight && r.right > 0 && r.left < window.innerWidth };
      });
      if (!f || (reached.length && f.key === reached[0])) break;
      reached.push(f.key);
      if (!f.inside) offscreen.push(f.key);
    }
    check(`${tag} keyboard-tab-reaches-every-control-in-order`, expected.length > 30 && JSON.stringify(reached) === JSON.stringify(expected),
      `expected ${expected.join(',')}\n  reached ${reached.join(',')}`);
    check(`${tag} keyboard-focus-scrolled-into-view`, offscreen.length === 0, offscreen.join(', '));

    // cancel a run: the UI returns to idle, says so, and the inputs still evaluate
    const mean = await page.textContent('#stats tr[data-row=accuracy] td[data-k=mean]');
    const evaluated = Number(await page.evaluate(() => document.body.dataset.evaluated));
    await page.fill('#samples', '5000000'); // a longer run, so that Cancel comes before its end
    await page.click('#run');
    await page.waitForSelector('#cancel', { state: 'visible' });
    check(`${tag} cancel-in-view-while-running`, inView(await where(page, '#cancel')) && inView(await where(page, '#progress')));
    await page.waitForTimeout(300);
    const tc = Date.now();
    await page.click('#cancel');
    await page.waitForFunction(() => Number(document.body.dataset.cancelled || 0) > 0, null, { timeout: 60000 });
    const idle = await page.evaluate(() => ({
      run: document.getElementById('run').disabled, cancel: document.getElementById('cancel').hidden,
      progress: getComputedStyle(document.getElementById('progress')).display, busy: document.body.classList.contains('busy'),
      status: document.getElementById('run-status').textContent, error: document.getElementById('error').textContent,
      evaluated: Number(document.body.dataset.evaluated), focus: document.activeElement.id,
      stale: !document.getElementById('stale-note').hidden, dl: document.getElementById('dl-ply').disabled,
    }));
    check(`${tag} cancel-returns-to-idle`, !idle.run && idle.cancel && idle.progress === 'none' && !idle.busy && /cancelled/i.test(idle.status)
      && !idle.error && idle.evaluated === evaluated && idle.focus === 'run' && idle.stale && idle.dl, JSON.stringify(idle));
    console.log(`note: cancel to idle (fresh worker, inputs reloaded) in ${Date.now() - tc} ms`);
    // keyboard only again: Cancel left the focus on Evaluate; Enter runs it in the fresh worker
    await page.fill('#samples', '1000000');
    await page.focus('#run');
    await page.keyboard.press('Enter');
    await page.waitForFunction((n) => Number(document.body.dataset.evaluated) > n || document.getElementById('error').textContent, evaluated, { timeout: 600000 });
    const mean2 = await page.textContent('#stats tr[data-row=accuracy] td[data-k=mean]');
    check(`${tag} keyboard-enter-evaluates-with-inputs-kept-after-cancel`, mean2 === mean && !(await page.textContent('#error'))
      && !(await page.evaluate(() => document.body.dataset.stale)), `${mean} vs ${mean2}`);

    await brokenFileChecks(page, tag);
    await dropBrokenPly(page); // leave the error up for the scan
    await axeScan(page, `${tag} axe-error-and-stale-no-serious-violations`);
    await page.context().close();
  }

  // ---- 1920×1080: the same geometry and error checks ------------------------------------
  {
    const tag = '1920x1080';
    const page = await newPage(1920, 1080);
    await runButtonChecks(page, tag);
    await loadDemo(page);
    await evaluateAndWait(page);
    await page.evaluate(() => document.getElementById('align-result').scrollIntoView({ block: 'center' }));
    await page.screenshot({ path: join(out, `ux-${tag}-results.png`) });
    await brokenFileChecks(page, tag);
    await page.context().close();
  }

  // ---- hostile ground truths: a glTF node DAG is refused at once and the page stays usable;
  // a mesh instanced past "max triangles" is refused naming the option ----
  {
    const tag = 'hostile';
    const page = await newPage(1366, 768);
    const glb = (nodes, roots) => {
      // one triangle, instanced by the nodes that carry `mesh: 0`
      const bin = Buffer.alloc(48);
      [0, 0, 0, 1, 0, 0, 0, 1, 0].forEach((v, i) => bin.writeFloatLE(v, 4 * i));
      [0, 1, 2].forEach((v, i) => bin.writeUInt32LE(v, 36 + 4 * i));
      const doc = {
        asset: { version: '2.0' }, scene: 0, scenes: [{ nodes: roots }], nodes,
        meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
        accessors: [
          { bufferView: 0, componentType: 5126, count: 3, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 0] },
          { bufferView: 1, componentType: 5125, count: 3, type: 'SCALAR' }],
        bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: 36 }, { buffer: 0, byteOffset: 36, byteLength: 12 }],
        buffers: [{ byteLength: 48 }],
      };
      let json = Buffer.from(JSON.stringify(doc));
      json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
      const header = Buffer.alloc(12);
      header.write('glTF', 0); header.writeUInt32LE(2, 4); header.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
      const chunk = (b, type) => { const h = Buffer.alloc(8); h.writeUInt32LE(b.length, 0); h.write(type, 4); return Buffer.concat([h, b]); };
      return Buffer.concat([header, chunk(json, 'JSON'), chunk(bin, 'BIN\0')]);
    };
    // 60 levels, each listing its child twice: 2^60 paths if expanded
    const dag = Array.from({ length: 61 }, (_, i) => (i < 60 ? { children: [i + 1, i + 1] } : { mesh: 0 }));
    const dropGt = async (name, buffer) => {
      await page.locator('#file-gt').scrollIntoViewIfNeeded();
      await page.setInputFiles('#file-gt', { name, mimeType: 'application/octet-stream', buffer });
      await page.waitForFunction(() => !/reading/.test(document.getElementById('info-gt').textContent), null, { timeout: 30000 });
    };
    const t = Date.now();
    await dropGt('dag.glb', glb(dag, [0]));
    const ms = Date.now() - t;
    const text = await page.textContent('#error');
    const responsive = await page.evaluate(() => new Promise((r) => { const s = performance.now(); setTimeout(() => r(performance.now() - s), 0); }));
    check(`${tag} gltf-dag-refused-quickly-naming-the-node`, /dag\.glb/.test(text) && /node/.test(text) && /parent/.test(text)
      && inView(await where(page, '#banner')) && ms < 20000 && responsive < 1000, `${ms} ms, "${text}"`);
    // 12 nodes instancing the triangle: 12 triangles expanded
    const instances = glb(Array.from({ length: 12 }, (_, i) => ({ mesh: 0, translation: [2 * i, 0, 0] })), [...Array(12).keys()]);
    await page.fill('#max-triangles', '10');
    await page.dispatchEvent('#max-triangles', 'change');
    await dropGt('instances.glb', instances);
    const limited = await page.textContent('#error');
    check(`${tag} triangle-limit-refuses-naming-the-option`, /instances\.glb/.test(limited) && /12/.test(limited)
      && /maxTriangles|max-triangles/.test(limited), `"${limited}"`);
    await page.context().close();
  }

  // ---- the core's typed notes: the page shows them by code and level, never by their words ----
  // The same evaluation twice (the demo's ground truth and its PLY cloud, auto: a global search
  // with its notes): once as the core wrote the report, once with every note's message reworded
  // by the page's own worker (its script served with a wrapper around `evaluate`). The page must
  // show the same notes (code, level), the same stage marks and verdicts, each with the new words.
  {
    const root = resolve(new URL('../..', import.meta.url).pathname);
    const evaluateDemoPly = async (page) => {
      await page.setInputFiles('#file-gt', join(root, 'data/demo/ground_truth.glb'));
      await page.waitForFunction(() => /triangles/.test(document.getElementById('info-gt').textContent));
      await page.setInputFiles('#file-recon', join(root, 'data/demo/sparse.ply'));
      await page.waitForFunction(() => /sparse\.ply/.test(document.getElementById('info-recon').textContent));
      await page.click('#run');
      await page.waitForFunction(() => Number(document.body.dataset.evaluated || 0) > 0 || document.getElementById('error').textContent, null, { timeout: 300000 });
      return page.evaluate(() => ({
        report: window.sfmeval.state.result.reportJson,
        notes: [...document.querySelectorAll('#summary [data-code]')].map((e) => [e.dataset.code, e.className, e.textContent]),
        stages: [...document.querySelectorAll('#stages tr[data-stage]')].map((tr) => [tr.dataset.stage,
          tr.querySelector('[data-stage-warnings]') ? tr.querySelector('[data-stage-warnings]').dataset.stageWarnings : '0', tr.lastElementChild.textContent]),
        error: document.getElementById('error').textContent,
      }));
    };
    const plain = await newPage(1366, 768);
    const asWritten = await evaluateDemoPly(plain);
    await plain.context().close();
    const reworded = await newPage(1366, 768, (context) => context.route('**/worker.js', async (route) => {
      const response = await route.fetch();
      const body = `${await response.text()}
;{ const evaluate = handlers.evaluate;
  handlers.evaluate = async (msg) => {
    const out = await evaluate(msg);
    const rep = JSON.parse(out.reply.reportJson);
    (rep.notes || []).forEach((n, i) => { n.message = \`REWORDED \${i} <i>\`; });
    out.reply.reportJson = JSON.stringify(rep, null, 2);
    return out;
  };
}`;
      await route.fulfill({ response, body });
    }));
    const got = await evaluateDemoPly(reworded);
    await reworded.context().close();
    const codes = JSON.parse(asWritten.report).notes.map((n) => n.code);
    const gotReport = JSON.parse(got.report);
    check('notes-reworded-report-reached-the-page', !got.error && gotReport.notes.length === codes.length && gotReport.notes.every((n, i) => n.message === `REWORDED ${i} <i>`),
      JSON.stringify({ error: got.error, notes: gotReport.notes }));
    const strip = (list) => list.map(([code, cls]) => [code, cls]);
    check('notes-shown-by-code-and-level-whatever-their-words', codes.length > 0 && JSON.stringify(strip(got.notes)) === JSON.stringify(strip(asWritten.notes))
      && JSON.stringify(asWritten.notes.map(([c]) => c)) === JSON.stringify(codes)
      && got.notes.every(([, , text], i) => text.endsWith(`REWORDED ${i} <i>`)),
    JSON.stringify({ codes, asWritten: asWritten.notes, reworded: got.notes }));
    check('stage-marks-by-code-whatever-the-words', asWritten.stages.length > 0 && JSON.stringify(got.stages) === JSON.stringify(asWritten.stages),
      JSON.stringify({ asWritten: asWritten.stages, reworded: got.stages }));
  }
} catch (e) {
  check('ux-run', false, e.stack || String(e));
} finally {
  const foreign = requests.filter((u) => !u.startsWith(origin) && !u.startsWith('data:') && !u.startsWith('blob:'));
  check('ux no-request-leaves-the-origin', foreign.length === 0 && requests.length > 0, foreign.join(', '));
  const bad = consoleErrors.filter((t) => !/broken\.ply|dag\.glb|instances\.glb|Failed to load resource/.test(t));
  check('ux no-console-errors', bad.length === 0, bad.join(' | '));
  console.log(`page: ux checks in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  await browser.close();
}
process.exit(failed ? 1 : 0);
