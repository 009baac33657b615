// A recorded session's GNSS track, north up in local metres, coloured by |heel| (the heel at
// each fix, from the session's attitude), with a marker the review's scrubber moves. The SVG
// carries its projection (data-lat0, -lon0, -k px per metre, -x0, -y0) for the browser tests.
import { HEEL_COLOURS, heelClass, lowerBound, metresText, niceMetres, projection } from './geo.js';
import { el, svg } from './util.js';

const W = 600;
const PAD = 28;
const MIN_SPAN_M = 20;

export function trackPanel(session) {
  const tr = session.track;
  const ok = tr.t_s.map((_, i) => Number.isFinite(tr.lat_deg[i]) && Number.isFinite(tr.lon_deg[i]));
  const t = tr.t_s.filter((_, i) => ok[i]);
  const lat = tr.lat_deg.filter((_, i) => ok[i]);
  const lon = tr.lon_deg.filter((_, i) => ok[i]);
  const section = el('section', { class: 'panel track-panel', 'aria-label': 'track coloured by heel' },
    el('h2', { text: 'Track, coloured by heel' }));
  if (t.length < 2) {
    section.append(el('p', { class: 'empty', text: 'No GNSS track in this session.' }));
    section.track = null;
    return section;
  }
  const midLat = (Math.min(...lat) + Math.max(...lat)) / 2;
  const midLon = (Math.min(...lon) + Math.max(...lon)) / 2;
  const proj = projection(midLat, midLon);
  const xy = t.map((_, i) => proj.toXY(lat[i], lon[i]));
  const xs = xy.map((p) => p[0]);
  const ys = xy.map((p) => p[1]);
  const spanX = Math.max(MIN_SPAN_M, Math.max(...xs) - Math.min(...xs));
  const spanY = Math.max(MIN_SPAN_M, Math.max(...ys) - Math.min(...ys));
  const H = Math.round(Math.max(260, Math.min(560, (W * spanY) / spanX)));
  const k = Math.min((W - 2 * PAD) / spanX, (H - 2 * PAD) / spanY);
  const x0 = W / 2 - ((Math.min(...xs) + Math.max(...xs)) / 2) * k;
  const y0 = H / 2 + ((Math.min(...ys) + Math.max(...ys)) / 2) * k;
  const sx = (p) => x0 + p[0] * k;
  const sy = (p) => y0 - p[1] * k;

  // Heel at each fix: the attitude sample at or after the fix's time.
  const at = session.data;
  const heelAt = (time) => {
    const i = Math.min(lowerBound(at.t_s, time), at.t_s.length - 1);
    return i >= 0 ? at.heel_deg[i] : null;
  };
  // Consecutive fixes of one heel colour make one polyline.
  const segments = [];
  let cur = null;
  for (let i = 0; i + 1 < t.length; i++) {
    const c = heelClass(heelAt(t[i]));
    if (!cur || cur.c !== c) {
      cur = { c, pts: [xy[i]] };
      segments.push(cur);
    }
    cur.pts.push(xy[i + 1]);
  }
  const lines = segments.map((s) => svg('polyline', { class: 'track-seg', 'data-heel-class': String(s.c),
    stroke: s.c >= 0 ? HEEL_COLOURS[s.c].color : '#888',
    points: s.pts.map((p) => `${sx(p).toFixed(1)},${sy(p).toFixed(1)}`).join(' ') }));
  const bar = niceMetres((W * 0.25) / k);
  const marker = svg('circle', { class: 'track-marker', r: 9, cx: sx(xy[0]).toFixed(2), cy: sy(xy[0]).toFixed(2) });
  const map = svg('svg', { id: 'review-track', class: 'review-track', viewBox: `0 0 ${W} ${H}`, role: 'img',
    'aria-label': 'the session track, north up, coloured by heel; the ring is the scrubber time',
    'data-lat0': String(midLat), 'data-lon0': String(midLon), 'data-k': String(k), 'data-x0': String(x0), 'data-y0': String(y0) },
  ...lines,
  svg('rect', { class: 'track-start', x: (sx(xy[0]) - 6).toFixed(1), y: (sy(xy[0]) - 6).toFixed(1), width: 12, height: 12 }),
  marker,
  svg('path', { class: 'scale-line', d: `M12 ${H - 20} V${H - 12} H${(12 + bar * k).toFixed(1)} V${H - 20}` }),
  svg('text', { class: 'scale-text', x: 12, y: H - 24 }, document.createTextNode(metresText(bar))),
  svg('g', { transform: `translate(${W - 22} 24)`, class: 'north' },
    svg('path', { d: 'M0 -14 L8 9 L0 4 L-8 9 Z' }),
    svg('text', { x: 0, y: 24, 'text-anchor': 'middle' }, document.createTextNode('N'))));
  const legend = el('ul', { class: 'heel-legend', 'aria-label': 'heel colours' },
    HEEL_COLOURS.map((c) => el('li', {}, el('span', { class: 'swatch', style: `background:${c.color}` }), ` ${c.label}`)),
    el('li', {}, el('span', { class: 'track-start-key' }), ' start'), el('li', {}, el('span', { class: 'marker-key' }), ' scrubber'));
  section.append(map, legend);
  section.track = { t, xy, sx, sy, marker };
  return section;
}

// Puts the marker where the boat was at `time` (epoch seconds): between the two fixes around
// it, in proportion; held at the first or last fix outside the track.
export function moveTrackMarker(section, time) {
  const tk = section.track;
  if (!tk) return;
  const { t, xy, sx, sy, marker } = tk;
  const i = lowerBound(t, time);
  let p;
  if (i <= 0) p = xy[0];
  else if (i >= t.length) p = xy[t.length - 1];
  else {
    const f = (time - t[i - 1]) / (t[i] - t[i - 1]);
    p = [xy[i - 1][0] + f * (xy[i][0] - xy[i - 1][0]), xy[i - 1][1] + f * (xy[i][1] - xy[i - 1][1])];
  }
  marker.setAttribute('cx', sx(p).toFixed(2));
  marker.setAttribute('cy', sy(p).toFixed(2));
  marker.dataset.t = String(time);
}
