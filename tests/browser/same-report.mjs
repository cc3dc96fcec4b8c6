// Compares a report written by the wasm build with the CLI's. Byte-identical is the goal; where
// the core still calls platform maths (acos, atan2, sin, cos, cbrt: glibc natively, Rust's libm
// in wasm), a few values differ in their last digits. `sameReport` accepts those only when
// every number agrees to 1e-9 relative and everything else is identical, and says which it was.
export function sameReport(a, b) {
  if (a === b) return { ok: true, bytes: true, detail: 'byte-identical' };
  let ja, jb;
  try { ja = JSON.parse(a); jb = JSON.parse(b); } catch (e) { return { ok: false, bytes: false, detail: `not JSON: ${e}` }; }
  let differing = 0, maxRel = 0, firstBad = null;
  const walk = (x, y, path) => {
    if (typeof x === 'number' && typeof y === 'number') {
      if (x !== y) {
        differing++;
        const rel = Math.abs(x - y) / Math.max(Math.abs(x), Math.abs(y), 1e-300);
        maxRel = Math.max(maxRel, Math.abs(x - y) <= 1e-12 ? 0 : rel);
        if (rel > 1e-9 && Math.abs(x - y) > 1e-12 && !firstBad) firstBad = `${path}: ${x} vs ${y}`;
      }
      return;
    }
    if (Array.isArray(x) && Array.isArray(y)) {
      if (x.length !== y.length) { firstBad ??= `${path}: length ${x.length} vs ${y.length}`; return; }
      x.forEach((v, i) => walk(v, y[i], `${path}[${i}]`));
      return;
    }
    if (x && y && typeof x === 'object' && typeof y === 'object') {
      const kx = Object.keys(x), ky = Object.keys(y);
      if (kx.join() !== ky.join()) { firstBad ??= `${path}: keys differ`; return; }
      kx.forEach((k) => walk(x[k], y[k], `${path}.${k}`));
      return;
    }
    if (x !== y) firstBad ??= `${path}: ${JSON.stringify(x)} vs ${JSON.stringify(y)}`;
  };
  walk(ja, jb, '$');
  if (firstBad) return { ok: false, bytes: false, detail: `differs: ${firstBad}` };
  return { ok: true, bytes: false, detail: `equal to 1e-9 relative, not byte-identical: ${differing} value(s) differ in the last digits (max rel ${maxRel.toExponential(1)})` };
}
