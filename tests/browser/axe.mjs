// axe-core (npm, tests/browser/node_modules) run in a page: the serious or critical violations
// fail a check, the others are printed as notes.
import { createRequire } from 'node:module';

const axePath = createRequire(import.meta.url).resolve('axe-core/axe.min.js');

/**
 * Runs axe-core on `page` and returns `{ bad, minor }`: the serious or critical violations
 * (`{id, impact, n, where}`) and the other findings as `id (impact, count)` texts.
 */
export async function axeViolations(page) {
  if (!(await page.evaluate(() => typeof window.axe === 'object'))) await page.addScriptTag({ path: axePath });
  const res = await page.evaluate(async () => {
    const r = await window.axe.run(document, { resultTypes: ['violations'] });
    return r.violations.map((v) => ({ id: v.id, impact: v.impact, n: v.nodes.length, where: v.nodes.slice(0, 3).map((x) => x.target.join(' ')) }));
  });
  const bad = res.filter((v) => v.impact === 'serious' || v.impact === 'critical');
  const minor = res.filter((v) => !bad.includes(v)).map((v) => `${v.id} (${v.impact}, ${v.n})`);
  return { bad, minor };
}
