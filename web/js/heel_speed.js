// Heel against speed for one session: upwind and downwind, port and starboard tack apart, the
// mean SOG in each 5-degree heel band with the time spent there (bars plus a table), the time
// that fits no band (reaching, slow, no fix, no wind to split by) and the total. The wind
// direction is the shore's estimate from the track unless the coach enters one.
import { api, q } from './api.js';
import { KNOTS_PER_M_S } from './geo.js';
import { el, svg } from './util.js';

const GROUPS = [
  ['upwind', 'port', 'Upwind · port tack'],
  ['upwind', 'starboard', 'Upwind · starboard tack'],
  ['downwind', 'port', 'Downwind · port gybe'],
  ['downwind', 'starboard', 'Downwind · starboard gybe'],
];
const OTHER = [
  ['reaching_s', 'Reaching (70–110° off the wind)'],
  ['slow_s', 'Slow or no course (< 0.5 m/s)'],
  ['no_fix_s', 'No GNSS fix'],
  ['unsplit_s', 'Sailing, no wind to split by'],
];

const secs = (s) => `${s.toFixed(1)} s`;
const band = (b) => `${b.from_deg}° … ${b.to_deg}°`;

export function heelSpeedPanel(detail) {
  const input = el('input', { type: 'number', id: 'wind-from', min: 0, max: 359, step: 1, inputmode: 'numeric',
    'aria-label': 'wind from, degrees true', placeholder: 'e.g. 255' });
  const apply = el('button', { type: 'submit', id: 'wind-apply', class: 'primary', text: 'Use this wind' });
  const estimate = el('button', { type: 'button', id: 'wind-estimate', text: 'Estimate from track' });
  const wind = el('p', { class: 'hs-wind', 'aria-live': 'polite' });
  const out = el('div', { class: 'hs-out' });
  const form = el('form', { class: 'hs-form' },
    el('label', { for: 'wind-from', text: 'Wind from (°)' }), input, apply, estimate);
  const section = el('section', { class: 'panel heel-speed', 'aria-label': 'heel against speed' },
    el('h2', { text: 'Heel against speed' }), form, wind, out);

  let seq = 0;
  async function load(windFrom) {
    const mine = ++seq;
    section.dataset.loading = 'true';
    try {
      const d = await api(`/sessions/${detail.id}/heel_speed${q({ wind_from_deg: windFrom })}`);
      if (mine !== seq) return;
      render(d);
    } catch (err) {
      if (mine === seq) out.replaceChildren(el('p', { class: 'message', text: `Heel against speed not available: ${err.message}` }));
    } finally {
      if (mine === seq) delete section.dataset.loading;
    }
  }

  function render(d) {
    const w = d.wind_from_deg;
    wind.dataset.estimated = String(!!d.wind_estimated);
    wind.textContent = w === null || w === undefined
      ? 'Wind: not known (no beat in this session to read it from). Enter it to split upwind and downwind.'
      : `Wind from ${Math.round(w)}° — ${d.wind_estimated ? 'estimated from the track' : 'entered'}`;
    if (Number.isFinite(w) && document.activeElement !== input) input.value = String(Math.round(w));
    const groups = GROUPS.map(([leg, tack, title]) => ({ leg, tack, title, bands: d[leg]?.[tack] ?? [] }));
    const maxKn = Math.max(1, ...groups.flatMap((g) => g.bands.map((b) => (b.mean_sog_m_s ?? 0) * KNOTS_PER_M_S)));
    const maxS = Math.max(1e-9, ...groups.flatMap((g) => g.bands.map((b) => b.seconds)));
    out.replaceChildren(
      el('div', { class: 'hs-grid' }, groups.map((g) => groupView(g, maxKn, maxS))),
      otherTable(d));
    section.dataset.total = String(d.total_s);
  }

  form.addEventListener('submit', (e) => {
    e.preventDefault();
    const v = Number(input.value);
    if (input.value === '' || !Number.isFinite(v)) return;
    load(((v % 360) + 360) % 360);
  });
  estimate.addEventListener('click', () => {
    input.value = '';
    load(null);
  });
  load(null);
  return section;
}

// Bars: height = mean SOG (knots), darker the more time in the band; a table below.
function groupView(g, maxKn, maxS) {
  const n = g.bands.length || 1;
  const Wc = 280;
  const Hc = 110;
  const bw = Wc / n;
  // The fastest band (of those with time) carries its speed as a label.
  const fastest = g.bands.reduce((best, b) => (b.seconds > 0 && Number.isFinite(b.mean_sog_m_s) &&
    (!best || b.mean_sog_m_s > best.mean_sog_m_s) ? b : best), null);
  const bars = g.bands.map((b, i) => {
    if (!b.seconds || !Number.isFinite(b.mean_sog_m_s)) return null;
    const kn = b.mean_sog_m_s * KNOTS_PER_M_S;
    const h = (kn / maxKn) * (Hc - 18);
    return svg('g', {},
      svg('rect', { class: 'hs-bar', x: (i * bw + 1).toFixed(1), y: (Hc - h).toFixed(1), width: (bw - 2).toFixed(1),
        height: h.toFixed(1), 'fill-opacity': (0.35 + 0.65 * (b.seconds / maxS)).toFixed(2) },
      svg('title', {}, document.createTextNode(`${band(b)}: ${kn.toFixed(1)} kn, ${secs(b.seconds)}`))),
      b === fastest ? svg('text', { x: (i * bw + bw / 2).toFixed(1), y: (Hc - h - 3).toFixed(1), 'text-anchor': 'middle' },
        document.createTextNode(`${kn.toFixed(1)} kn`)) : null);
  });
  // Ticks at the band edges -30, 0 and +30 degrees.
  const ticks = g.bands.flatMap((b, i) => ([-30, 0, 30].includes(b.from_deg)
    ? [svg('text', { class: 'tick', x: (i * bw).toFixed(1), y: Hc + 14, 'text-anchor': 'middle' },
      document.createTextNode(`${b.from_deg}°`))] : []));
  const rows = g.bands.filter((b) => b.seconds > 0).map((b) => el('tr', {},
    el('th', { scope: 'row', text: band(b) }),
    el('td', { text: Number.isFinite(b.mean_sog_m_s) ? `${(b.mean_sog_m_s * KNOTS_PER_M_S).toFixed(1)} kn` : '–' }),
    el('td', { class: 'hs-seconds', dataset: { seconds: String(b.seconds) }, text: secs(b.seconds) })));
  const total = g.bands.reduce((a, b) => a + b.seconds, 0);
  return el('figure', { class: 'hs-group', dataset: { group: `${g.leg}-${g.tack}` } },
    el('figcaption', { text: `${g.title} · ${secs(total)}` }),
    svg('svg', { class: 'hs-chart', viewBox: `0 -4 ${Wc} ${Hc + 20}`, role: 'img',
      'aria-label': `${g.title}: mean speed in knots per heel band, port heel left` },
    svg('line', { class: 'axis', x1: 0, y1: Hc, x2: Wc, y2: Hc }), ...bars.filter(Boolean), ...ticks),
    rows.length
      ? el('table', { class: 'hs-table' },
        el('thead', {}, el('tr', {}, el('th', { text: 'Heel' }), el('th', { text: 'Mean SOG' }), el('th', { text: 'Time' }))),
        el('tbody', {}, rows))
      : el('p', { class: 'empty', text: 'No time on this leg and tack.' }));
}

function otherTable(d) {
  return el('div', { class: 'table-wrap' }, el('table', { class: 'hs-other' },
    el('caption', { text: 'Time in no heel band above, and the session total' }),
    el('tbody', {}, OTHER.map(([k, label]) => el('tr', {},
      el('th', { scope: 'row', text: label }),
      el('td', { dataset: { bucket: k, seconds: String(d[k] ?? 0) }, text: secs(d[k] ?? 0) })))),
    el('tfoot', {}, el('tr', {}, el('th', { scope: 'row', text: 'Total' }),
      el('td', { id: 'hs-total', dataset: { seconds: String(d.total_s) }, text: secs(d.total_s) })))));
}
