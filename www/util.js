// Small helpers shared by the page's modules: element lookup, HTML escaping, the CLI's number
// format, downloads, and the 4×4 transform's text forms.

/** The element with this id. */
export const $ = (id) => document.getElementById(id);

/** Text made safe for HTML (element content and double-quoted attributes): the one `esc`. */
export const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));

/** The CLI summary's number format (Rust `{:.6}` or `{:.4e}`). */
export function g(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e-3 && a < 1e5) return v.toFixed(6);
  return v.toExponential(4).replace('e+', 'e');
}

/** 2 → "2nd", 3 → "3rd", 11 → "11th", 21 → "21st". */
export function ordinal(k) {
  const teen = k % 100 >= 11 && k % 100 <= 13;
  return `${k}${teen ? 'th' : ({ 1: 'st', 2: 'nd', 3: 'rd' }[k % 10] ?? 'th')}`;
}

/** A comma-separated list of numbers ("0.5, 1,2" → [0.5, 1, 2]). */
export const numList = (s) => s.split(',').map((w) => w.trim()).filter(Boolean).map(Number);

/** Saves `data` (text, bytes or a Blob) as a file named `name`. */
export function download(name, data, type) {
  const blob = data instanceof Blob ? data : new Blob([data], { type });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

/** 16 numbers in any layout (rows, commas, JSON brackets, # comments), else null. */
export function parseMatrixLoose(text) {
  const nums = text.replace(/#[^\n]*/g, '').split(/[\s,\[\]]+/).filter(Boolean).map(Number);
  return nums.length === 16 && nums.every(Number.isFinite) ? nums : null;
}

/**
 * A loaded transform's text as 4 rows of 4 right-aligned numbers, each printed exactly
 * (JavaScript's shortest round-trip form: the same doubles as the file); text that is not
 * 16 numbers stays as it is.
 */
export function alignedTransform(text) {
  const m = parseMatrixLoose(text);
  if (!m) return text;
  const cells = m.map((v) => (Object.is(v, -0) ? '-0' : String(v)));
  const w = Math.max(...cells.map((c) => c.length));
  return [0, 1, 2, 3].map((r) => cells.slice(4 * r, 4 * r + 4).map((c) => c.padStart(w)).join('  ')).join('\n');
}

/**
 * A 4×4 matrix as an aligned monospace grid: 4 right-aligned columns, the same number of
 * decimals everywhere (6, fewer when the largest entry needs more integer digits).
 */
export function matrixText(m) {
  const flat = m.flat();
  const big = Math.max(...flat.map((v) => Math.abs(v)).filter(Number.isFinite), 0);
  const intDigits = big >= 1 ? Math.floor(Math.log10(big)) + 1 : 1;
  const decimals = Math.max(2, Math.min(6, 9 - intDigits));
  const cells = flat.map((v) => (v === 0 ? 0 : v).toFixed(decimals));
  const w = Math.max(...cells.map((c) => c.length));
  const rows = [];
  for (let r = 0; r < 4; r++) rows.push(cells.slice(4 * r, 4 * r + 4).map((c) => c.padStart(w)).join('  '));
  return rows.join('\n');
}
