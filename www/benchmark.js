// What the benchmark sections (DTU, the pose protocols, ETH3D, Tanks and Temples) share: a set of
// files dropped together, which the core recognises and words (`summary`: the line naming each
// file, what does not fit, what is still needed, what is not used, and the status), and the run
// of an evaluation in the worker with its status (evaluating, done, failed, cancelled). Each
// section's elements are named by its key: `file-KEY`, `drop-KEY`, `info-KEY`, `KEY-run`,
// `KEY-status`.
import { $ } from './util.js';
import { dropZone, entryFiles } from './files.js';

/** Calls `take(files)` with the files picked in `input` or dropped on `zone` (folders walked). */
export function onFiles(input, zone, take, fail) {
  input.addEventListener('change', (e) => { take(e.target.files); });
  dropZone(zone, async (entries, dropped) => {
    try {
      const files = [];
      for (const en of entries) files.push(...(await entryFiles(en)));
      await take(files.length ? files : dropped);
    } catch (err) { fail(err); }
  });
}

/**
 * The section's dropped files: each drop adds to those held (a name replaces the file of that
 * name, so a scene's files may come from several folders), `recognise(names, files)` returns the
 * core's answer for them (`{..., inputs, summary}`), and its summary is shown as the core words
 * it, the run button enabled only when it says the set is complete. Returns the state: `files`
 * by name and `found`, the core's latest answer.
 */
export function droppedFiles({ key, label, showError, recognise }) {
  const state = { files: {}, found: null };
  const info = $(`info-${key}`);
  let picks = 0;
  const take = async (list) => {
    const pick = ++picks;
    for (const f of Array.from(list)) state.files[f.name] = f;
    let found;
    try {
      found = await recognise(Object.keys(state.files), state.files);
    } catch (err) { showError(`${label}: ${err.message}`, `file-${key}`); return; }
    if (pick !== picks) return; // a later drop was answered first
    state.found = found;
    const { line, status, complete, problem } = found.summary;
    info.textContent = line;
    info.classList.toggle('error', problem);
    info.dataset.complete = complete ? '1' : '0';
    $(`${key}-run`).disabled = !complete;
    $(`${key}-status`).textContent = status;
  };
  onFiles($(`file-${key}`), $(`drop-${key}`), take, (err) => showError(`${label}: ${err.message}`, `file-${key}`));
  state.ready = () => Boolean(state.found && state.found.summary.complete);
  return state;
}

/** The bytes of the files named `names` of `files` (by name), and the buffers to transfer. */
export async function namedBytes(files, names) {
  const out = {};
  const transfer = [];
  for (const n of names) {
    const b = await files[n].arrayBuffer();
    out[n] = b;
    transfer.push(b);
  }
  return { files: out, transfer };
}

/**
 * Runs the section's evaluation when its button is clicked: claims the worker (`setRunning`),
 * says it is evaluating, awaits `evaluate()` (the worker's result, with its `ms`), shows it with
 * `show(r)`, and says how it ended; a failure goes to the banner and `clear()` hides the old
 * result. `ready()` says whether the button may be enabled again. The section's counter in
 * `document.body.dataset[key]` counts the results shown (the browser tests wait on it).
 */
export function runButton({ key, label, setRunning, showError, ready, evaluate, show, clear, errorTarget }) {
  const run = $(`${key}-run`);
  const status = $(`${key}-status`);
  run.onclick = async () => {
    if (!ready() || run.disabled) return;
    if (!setRunning(true)) { showError(`${label}: wait for the evaluation under way to end (or cancel it)`, `${key}-run`); return; }
    run.disabled = true;
    showError('');
    status.textContent = 'evaluating…';
    try {
      const r = await evaluate();
      show(r);
      status.textContent = `done in ${(r.ms / 1000).toFixed(1)} s`;
      document.body.dataset[key] = String(Number(document.body.dataset[key] || 0) + 1);
    } catch (err) {
      if (err.name !== 'Cancelled') {
        clear();
        showError(`${label} evaluation failed: ${err.message}`, errorTarget || `file-${key}`);
        status.textContent = '✗ failed: see the message at the top';
      } else status.textContent = 'cancelled';
    } finally {
      setRunning(false);
      run.disabled = !ready();
    }
  };
}
