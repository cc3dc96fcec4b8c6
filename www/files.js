// Dropped files and folders: the drop zones' drag handling and the walk of a dropped folder.

/**
 * Makes `zone` a drop target: highlighted while something is dragged over it, and on a drop
 * calls `onDrop(entries, files)` with the dropped items' FileSystem entries (folders included)
 * and the plain FileList.
 */
export function dropZone(zone, onDrop) {
  zone.addEventListener('dragover', (e) => { e.preventDefault(); zone.classList.add('over'); });
  zone.addEventListener('dragleave', () => zone.classList.remove('over'));
  zone.addEventListener('drop', (e) => {
    e.preventDefault();
    zone.classList.remove('over');
    const entries = Array.from(e.dataTransfer.items || []).map((i) => i.webkitGetAsEntry && i.webkitGetAsEntry()).filter(Boolean);
    onDrop(entries, e.dataTransfer.files);
  });
}

/** The files under a dropped entry (file or folder), named by their path from the drop. */
export async function entryFiles(entry, prefix = '') {
  if (entry.isFile) {
    const f = await new Promise((res, rej) => entry.file(res, rej));
    const out = new File([f], f.name);
    Object.defineProperty(out, 'webkitRelativePath', { value: `${prefix}${f.name}` });
    return [out];
  }
  const out = [];
  const reader = entry.createReader();
  for (;;) {
    const batch = await new Promise((res, rej) => reader.readEntries(res, rej));
    if (!batch.length) break;
    for (const c of batch) out.push(...(await entryFiles(c, `${prefix}${entry.name}/`)));
  }
  return out;
}
