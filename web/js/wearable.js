// Wearable view: one card per athlete (steps, cadence, gait, pose, distance) with the
// dead-reckoned track drawn as SVG (recorded track from the shore, extended live).
import { api, has } from './api.js';
import { el, svg } from './util.js';

export function mountWearables(container, { live }) {
  if (!has('/athletes')) {
    container.append(el('p', { class: 'message', text: 'This shore server does not offer wearables yet.' }));
    return () => {};
  }
  const grid = el('section', { class: 'fleet athletes', 'aria-label': 'Athletes' });
  const empty = el('p', { class: 'empty', text: 'No athlete heard yet.' });
  container.append(empty, grid);
  const cards = new Map();
  const recorded = new Map(); // id -> {x, y} from the track endpoint

  function card(a) {
    let c = cards.get(a.id);
    if (c) return c;
    const path = svg('polyline', { class: 'track-line', points: '' });
    const dot = svg('circle', { class: 'track-now', r: 1.5, cx: 0, cy: 0 });
    const start = svg('circle', { class: 'track-start', r: 1.2, cx: 0, cy: 0 });
    const plot = svg('svg', { class: 'track', viewBox: '-10 -10 20 20', role: 'img', 'aria-label': 'dead-reckoned track, north up' },
      svg('g', { class: 'grid' }), path, start, dot);
    const v = (k, label, unit = '') => el('div', { class: 'readout' }, el('span', { class: 'label', text: label }),
      el('span', { class: `value small ${k}`, text: '–' }), unit ? el('span', { class: 'unit', text: unit }) : null);
    c = el('article', { class: 'card athlete', dataset: { athlete: a.id, stale: 'false', alarm: 'normal' } },
      el('header', {}, el('h2', { text: a.id }), el('span', { class: 'stale-marker', text: 'SILENT' })),
      el('div', { class: 'readouts wrap' }, v('steps', 'Steps'), v('cadence', 'Cadence', 'spm'),
        v('gait', 'Gait'), v('pose', 'Pose'), v('distance', 'Distance', 'm')),
      plot, el('footer', { class: 'meta' }));
    c._parts = { path, dot, start, plot };
    cards.set(a.id, c);
    grid.append(c);
    empty.hidden = true;
    const url = `/athletes/${encodeURIComponent(a.id)}/track`;
    if (has('/athletes/{id}/track')) {
      api(url).then((tr) => {
        recorded.set(a.id, tr);
        update(a.id);
      }).catch((err) => console.warn('track', err));
    }
    return c;
  }

  function update(id) {
    const entry = live.athletes.get(id);
    if (!entry) return;
    const a = entry.athlete;
    const c = card(a);
    const put = (k, text) => { c.querySelector(`.${k}`).textContent = text; };
    put('steps', String(a.steps ?? '–'));
    put('cadence', Number.isFinite(a.cadence_spm) ? a.cadence_spm.toFixed(0) : '–');
    put('gait', a.gait ?? '–');
    put('pose', a.pose ? a.pose.replace(/_/g, ' ') : '–');
    put('distance', Number.isFinite(a.distance_m) ? a.distance_m.toFixed(0) : '–');
    const stale = a.stale || Date.now() - entry.receivedAt > 3000;
    c.dataset.stale = String(stale);
    c.querySelector('.meta').textContent = `${(a.last_sample_time ?? '').slice(11, 19)} UTC` +
      (Number.isFinite(a.heading_deg) ? ` · HDG ${a.heading_deg.toFixed(0)}°` : '');
    // Track: recorded part, then what arrived live; x east, y north -> SVG y down.
    const rec = recorded.get(id) ?? { x_m: [], y_m: [] };
    const xs = [];
    const ys = [];
    const addPoints = (px, py) => px.forEach((x, i) => {
      if (Number.isFinite(x) && Number.isFinite(py[i])) {
        xs.push(x);
        ys.push(py[i]);
      }
    });
    addPoints(rec.x_m, rec.y_m);
    addPoints(entry.track.x, entry.track.y);
    if (!xs.length) return;
    const minX = Math.min(...xs);
    const maxX = Math.max(...xs);
    const minY = Math.min(...ys);
    const maxY = Math.max(...ys);
    const span = Math.max(maxX - minX, maxY - minY, 10) * 1.15;
    const cx = (minX + maxX) / 2;
    const cy = (minY + maxY) / 2;
    c.querySelector('.meta').textContent += ` · track ${span.toFixed(0)} m across, north up`;
    const p = c._parts;
    p.plot.setAttribute('viewBox', `${cx - span / 2} ${-cy - span / 2} ${span} ${span}`);
    p.path.setAttribute('points', xs.map((x, i) => `${x.toFixed(2)},${(-ys[i]).toFixed(2)}`).join(' '));
    p.path.setAttribute('stroke-width', (span / 120).toFixed(3));
    for (const [node, i] of [[p.start, 0], [p.dot, xs.length - 1]]) {
      node.setAttribute('cx', xs[i]);
      node.setAttribute('cy', -ys[i]);
      node.setAttribute('r', (span / 60).toFixed(3));
    }
  }

  const onWearable = (e) => update(e.detail.id);
  live.addEventListener('wearable', onWearable);
  api('/athletes').then((list) => list.forEach((a) => {
    if (!live.athletes.has(a.id)) live.addAthlete(a);
    else update(a.id);
  })).catch((err) => container.append(el('p', { class: 'message', text: err.message })));
  for (const id of live.athletes.keys()) update(id);
  const timer = setInterval(() => { for (const id of cards.keys()) update(id); }, 1000);
  return () => {
    live.removeEventListener('wearable', onWearable);
    clearInterval(timer);
  };
}
