// What the page holds: the loaded inputs and the last result, the files behind each input, and
// the main viewer.
import { Viewer } from './viewer.js';
import { $ } from './util.js';

export const state = {
  gt: null, // {name, format, bounds, vertices, triangles, ...}
  recon: null, // {name, format, count, positions (Float64Array, recon frame), colors}
  camerasName: null,
  result: null, // {report, reportJson, pointsInGt, distances, status, completeness, colors, clip}
  pairs: [], // [{recon: [x,y,z], gt: [x,y,z]}]
  pendingRecon: null,
  picking: false,
  transformText: '',
  running: false, // an evaluation is under way
  restoring: false, // a fresh worker is reloading the inputs after a cancel
  loading: 0, // loads under way
  shownResult: false, // results are on screen (current or stale)
};
/** The files behind each loaded input, to reload them into a fresh worker after a cancel. */
export const sources = { gt: null, recon: null, cams: null, depth: null };

export const viewer = new Viewer($('viewer'));
window.sfmevalViewer = viewer;
