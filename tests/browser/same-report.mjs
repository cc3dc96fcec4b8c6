// Compares a report written by the wasm build with the CLI's: they must be byte for byte the same
// (the core computes every transcendental function through the `libm` crate on all targets and
// parses numbers exactly, so nothing legitimately differs). On a difference, `detail` says where
// the first differing number is and how large the largest relative difference is.
export function sameReport(a, b) {
  if (a === b) return { ok: true, bytes: true, detail: 'byte-identical' };
  let ja, jb;
  try { ja = JSON.parse(a); jb = JSON.parse(b); } catch (e) { return { ok: false, bytes: false, detail: `not JSON: ${e}` }; }
  let differing = 0, maxRel = 0, first = null;
  const walk = (x, y, path) => {
    if (typeof x === 'number' && typeof y === 'number') {
      if (x !== y) {
        differing++;
        maxRel = Math.max(maxRel, Math.abs(x - y) / Math.max(Math.abs(x), Math.abs(y), 1e-300));
        first ??= `${path}: ${x} vs ${y}`;
      }
      return;
    }
    if (Array.isArray(x) && Array.isArray(y)) {
      if (x.length !== y.length) { first ??= `${path}: length ${x.length} vs ${y.length}`; return; }
      x.forEach((v, i) => walk(v, y[i], `${path}[${i}]`));
      return;
    }
    if (x && y && typeof x === 'object' && typeof y === 'object') {
      const kx = Object.keys(x), ky = Object.keys(y);
      if (kx.join() !== ky.join()) { first ??= `${path}: keys differ`; return; }
      kx.forEach((k) => walk(x[k], y[k], `${path}.${k}`));
      return;
    }
    if (x !== y) first ??= `${path}: ${JSON.stringify(x)} vs ${JSON.stringify(y)}`;
  };
  walk(ja, jb, '$');
  if (!first) return { ok: false, bytes: false, detail: 'same values, different bytes (formatting or key order)' };
  return { ok: false, bytes: false, detail: `not byte-identical: ${differing} number(s) differ, max rel ${maxRel.toExponential(1)}; first ${first}` };
}
