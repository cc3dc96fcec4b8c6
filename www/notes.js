// The report's notes as the core wrote them: chosen, styled and placed by their code and level,
// never by their wording.
import { esc } from './util.js';

/**
 * The report's notes (`rep.notes`: `{code, level, message, values}`, docs/notes.md): the level
 * picks the style, the code goes on the element (`data-code`) and places stage notes beside their
 * stage (`values.stage`); the message is shown as written. The page never reads the message
 * text. Returns [{code, level, stage, html}].
 */
export function reportNotes(rep) {
  return (rep.notes || []).map((n) => {
    const warning = n.level === 'warning';
    return {
      code: n.code,
      level: warning ? 'warn' : 'info',
      stage: (n.values && n.values.stage) || null,
      html: `${warning ? 'warning' : 'note'}: ${esc(n.message)}`,
    };
  });
}

/** The notes as HTML lines, each with its code in `data-code`. */
export function notesHtml(notes) {
  return notes.map((n) => `<div class="${n.level}" data-code="${esc(n.code)}">${n.html}</div>`).join('');
}
