// Import view: drop log files (Vakaros CSV/VKX, Velocitek VTK, NMEA 0183, GPX) or pick them; each
// is uploaded to POST /api/v1/imports for the boat typed above, with a progress bar for the upload
// (XMLHttpRequest: fetch reports no upload progress) and then for the shore's import, and ends in
// a line that opens the imported session in review.
import { api, has, q } from './api.js';
import { el } from './util.js';

const FORMATS = ['', 'vakaros_csv', 'vkx', 'vtk', 'nmea', 'gpx'];

function upload(path, file, onProgress) {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open('POST', `/api/v1${path}`);
    xhr.setRequestHeader('Content-Type', 'application/octet-stream');
    xhr.upload.onprogress = (e) => e.lengthComputable && onProgress(e.loaded, e.total);
    xhr.onload = () => {
      let data = null;
      try {
        data = JSON.parse(xhr.responseText);
      } catch {
        data = { error: xhr.responseText };
      }
      if (xhr.status === 202) resolve(data);
      else reject(new Error(data?.error ?? `HTTP ${xhr.status}`));
    };
    xhr.onerror = () => reject(new Error('the upload was cut'));
    xhr.send(file);
  });
}

export function mountImport(container, { role }) {
  if (!has('/imports')) {
    container.append(el('p', { class: 'message', text: 'This shore server does not import files yet.' }));
    return () => {};
  }
  let stopped = false;
  const boat = el('input', { id: 'import-boat', name: 'boat', required: true, pattern: '[A-Za-z0-9_-]{1,32}',
    placeholder: 'ILCA-7', autocomplete: 'off' });
  const format = el('select', { id: 'import-format', name: 'format' },
    FORMATS.map((f) => el('option', { value: f, text: f || 'read from the file' })));
  const tz = el('input', { id: 'import-tz', name: 'tz', placeholder: 'Europe/Madrid or +01:00', size: 12 });
  const pitch = el('input', { id: 'import-pitch', name: 'pitch_offset', type: 'number', step: '0.1', value: '0', size: 5 });
  const picker = el('input', { type: 'file', multiple: true, id: 'import-files', class: 'visually-hidden' });
  const drop = el('label', { class: 'drop-zone', for: 'import-files', tabindex: 0 },
    el('strong', { text: 'Drop log files here' }), el('span', { text: ' or click to choose them' }));
  const list = el('ol', { class: 'imports', 'aria-label': 'imports' });
  const note = el('p', { class: 'hint', text: role === 'athlete'
    ? 'Only a coach or an analyst may import files.'
    : 'Vakaros Atlas CSV and VKX, Velocitek VTK, NMEA 0183 logs, GPX. Importing the same file twice changes nothing.' });
  container.append(el('section', { class: 'import-view', 'aria-label': 'Import log files' },
    el('h2', { text: 'Import log files' }),
    el('div', { class: 'import-options' },
      el('label', { for: 'import-boat', text: 'Boat' }), boat,
      el('label', { for: 'import-format', text: 'Format' }), format,
      el('label', { for: 'import-tz', text: 'Time zone (files without an offset)' }), tz,
      el('label', { for: 'import-pitch', text: 'Pitch zero (°)' }), pitch),
    note, drop, picker, list));

  async function importOne(file) {
    const bar = el('progress', { max: 1, value: 0 });
    const status = el('span', { class: 'import-status', text: 'uploading' });
    const item = el('li', { class: 'import-item', dataset: { state: 'uploading' } },
      el('span', { class: 'import-name', text: file.name }), bar, status);
    list.prepend(item);
    const set = (state, text) => {
      item.dataset.state = state;
      status.textContent = text;
    };
    if (!/^[A-Za-z0-9_-]{1,32}$/.test(boat.value)) {
      set('failed', 'type the boat id first (letters, digits, - and _)');
      return;
    }
    const params = { boat: boat.value, name: file.name, format: format.value || undefined,
      tz: tz.value || undefined, pitch_offset: Number(pitch.value) ? pitch.value : undefined };
    try {
      const { id } = await upload(`/imports${q(params)}`, file, (done, total) => {
        bar.value = (0.5 * done) / total;
        status.textContent = `uploading ${Math.round((100 * done) / total)} %`;
      });
      set('running', 'importing');
      for (;;) {
        const r = await api(`/imports/${id}`);
        if (r.bytes) {
          bar.value = 0.5 + (0.5 * r.bytes_read) / r.bytes;
          if (r.state === 'running') status.textContent = `importing ${Math.round((100 * r.bytes_read) / r.bytes)} %`;
        }
        if (r.state === 'done') {
          bar.value = 1;
          set('done', `${r.format}, ${r.points} points${r.duplicate_of ? ' (already imported)' : ''}` +
            `${r.partial ? ` — partial: ${r.partial}` : ''}`);
          for (const s of r.sessions)
            item.append(el('a', { href: `#/review?boat=${encodeURIComponent(r.boat_id)}&session=${s}`,
              text: `review session ${s}` }));
          return;
        }
        if (r.state === 'failed') {
          set('failed', r.error);
          return;
        }
        if (stopped) return;
        await new Promise((ok) => setTimeout(ok, 300));
      }
    } catch (err) {
      set('failed', err.message);
    }
  }

  async function importAll(files) {
    for (const f of files) await importOne(f);
  }
  picker.addEventListener('change', () => importAll([...picker.files]));
  drop.addEventListener('keydown', (e) => (e.key === 'Enter' || e.key === ' ') && picker.click());
  for (const type of ['dragenter', 'dragover'])
    drop.addEventListener(type, (e) => {
      e.preventDefault();
      drop.classList.add('over');
    });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    importAll([...e.dataTransfer.files]);
  });
  return () => {
    stopped = true;
  };
}
