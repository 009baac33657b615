// Session review: pick a boat and a session; heel and pitch charts (drag to zoom, double-click
// to reset) with a time scrubber, alarm events on the timeline, the heel distribution and the
// time in each heel band, a second session (another boat or another day) overlaid, and export.
// With GNSS: the session's track coloured by heel with a marker that follows the scrubber, a
// speed chart, distance and speeds, GPX download, and heel against speed (heel_speed.js).
// Manoeuvres (manoeuvres.js): listed, marked on the timeline and the track, overlaid at t0, ranked.
import { api, has, q } from './api.js';
import { COLORS, autoResize, loadUPlot, markersPlugin, widthOf } from './charts.js';
import { KNOTS_PER_M_S } from './geo.js';
import { heelSpeedPanel } from './heel_speed.js';
import { manoeuvreMarkersPlugin, manoeuvrePanels } from './manoeuvres.js';
import { moveTrackMarker, trackPanel } from './track.js';
import { clock, deg, duration, el, isoToSeconds, svg } from './util.js';

const CHART_H = 220;
const MAX_POINTS = 4000;
const BANDS = [-90, -20, -10, -5, 0, 5, 10, 20, 90]; // used when the server sends no bands

export function mountReview(container, { query, navigate }) {
  if (!has('/sessions')) {
    container.append(el('p', { class: 'message', text: 'This shore server does not offer recorded sessions yet.' }));
    return () => {};
  }
  const state = { boat: query.get('boat') || '', session: query.get('session') || '', vs: query.get('vs') || '' };
  const go = (patch) => {
    const s = { ...state, ...patch };
    navigate(`#/review${q({ boat: s.boat || null, session: s.session || null, vs: s.vs || null })}`);
  };
  const boatSel = el('select', { id: 'review-boat', 'aria-label': 'boat', onchange: () => go({ boat: boatSel.value, session: '', vs: '' }) });
  const sessSel = el('select', { id: 'review-session', 'aria-label': 'session', onchange: () => go({ session: sessSel.value }) });
  const vsSel = el('select', { id: 'review-vs', 'aria-label': 'compare with', onchange: () => go({ vs: vsSel.value }) });
  const body = el('div', { class: 'review-body' });
  container.append(el('div', { class: 'toolbar' },
    el('label', {}, 'Boat ', boatSel), el('label', {}, 'Session ', sessSel), el('label', {}, 'Compare ', vsSel)), body);

  const cleanups = [];
  let stopped = false;
  (async () => {
    const [boats, sessions] = await Promise.all([api('/boats'), api('/sessions')]);
    if (stopped) return;
    const boatIds = [...new Set([...boats.map((b) => b.id), ...sessions.map((s) => s.boat_id)])].sort();
    if (!state.boat && boatIds.length) state.boat = boatIds[0];
    boatSel.replaceChildren(...boatIds.map((b) => el('option', { value: b, text: b })));
    boatSel.value = state.boat;
    const mine = sessions.filter((s) => s.boat_id === state.boat).sort((a, b) => b.start_t_s - a.start_t_s);
    if (!state.session && mine.length) state.session = String(mine[0].id);
    const label = (s) => `${s.boat_id} · ${s.start.slice(0, 10)} ${s.start.slice(11, 16)} · ${duration(s.duration_s)}`;
    sessSel.replaceChildren(...mine.map((s) => el('option', { value: String(s.id), text: label(s) })));
    sessSel.value = state.session;
    const others = sessions.filter((s) => String(s.id) !== state.session).sort((a, b) => b.start_t_s - a.start_t_s);
    vsSel.replaceChildren(el('option', { value: '', text: '— none —' }),
      ...others.map((s) => el('option', { value: String(s.id), text: label(s) })));
    vsSel.value = state.vs;
    if (!state.session) {
      body.append(el('p', { class: 'empty', text: state.boat ? `No recorded session for ${state.boat}.` : 'No recorded sessions.' }));
      return;
    }
    const uPlot = await loadUPlot();
    const load = async (sid) => {
      const [detail, data] = await Promise.all([
        api(`/sessions/${sid}`),
        api(`/sessions/${sid}/attitude${q({ max_points: MAX_POINTS })}`),
      ]);
      // The GNSS track over the session (none from an older server or a boat without a fix).
      const track = await api(`/boats/${encodeURIComponent(detail.boat_id)}/track` +
        q({ from: detail.start_t_s, to: detail.end_t_s, max_points: MAX_POINTS })).catch(() => null);
      // The session detail lists its alarm events; older servers only count them.
      let events = Array.isArray(detail.alarm_events) ? detail.alarm_events : [];
      if (!Array.isArray(detail.alarm_events) && has('/alarms/events')) {
        events = await api(`/alarms/events${q({ boat: detail.boat_id, from: detail.start_t_s, to: detail.end_t_s + 1 })}`);
      }
      return { detail, data, events, track };
    };
    const main = await load(state.session);
    const vs = state.vs ? await load(state.vs) : null;
    if (stopped) return;
    cleanups.push(render(body, uPlot, main, vs, sessions));
  })().catch((err) => body.append(el('p', { class: 'message', text: `Cannot load the session: ${err.message}` })));

  return () => {
    stopped = true;
    cleanups.forEach((f) => f());
  };
}

function render(body, uPlot, main, vs, sessions) {
  const m = main.detail;
  const t0 = m.start_t_s;
  // Two sessions that overlap in time (two boats in the same race) are aligned on the clock;
  // otherwise both start at 0.
  const overlap = vs && vs.detail.start_t_s < m.end_t_s && vs.detail.end_t_s > m.start_t_s;
  const vsT0 = vs ? (overlap ? t0 : vs.detail.start_t_s) : 0;
  const rel = (d, base) => d.t_s.map((t) => t - base);
  const mainX = rel(main.data, t0);
  let data;
  if (vs) {
    data = uPlot.join([
      [mainX, main.data.heel_deg, main.data.pitch_deg],
      [rel(vs.data, vsT0), vs.data.heel_deg, vs.data.pitch_deg],
    ]);
  } else {
    data = [mainX, main.data.heel_deg, main.data.pitch_deg];
  }
  const name = (d) => `${d.detail.boat_id} #${d.detail.id}`;
  const markers = main.events.map((ev) => ({
    x: isoToSeconds(ev.raised_at) - t0,
    color: ev.level === 'alarm' ? '#c00018' : '#b35c00',
  }));
  const manoeuvreMarks = []; // filled once the session's manoeuvres are in
  const fmtRel = (v) => {
    const s = Math.round(v);
    return `${s < 0 ? '-' : ''}${Math.floor(Math.abs(s) / 60)}:${String(Math.abs(s) % 60).padStart(2, '0')}`;
  };

  const exportLinks = (d) => ['csv', 'json', ...(d.detail.gnss ? ['gpx'] : [])].map((f) => el('a', {
    class: 'button export', href: f === 'gpx' ? `/api/v1/sessions/${d.detail.id}/gpx` : `/api/v1/sessions/${d.detail.id}/export?format=${f}`,
    download: `${d.detail.boat_id}-session-${d.detail.id}.${f}`, dataset: { format: f, session: String(d.detail.id) },
    text: `Export ${f.toUpperCase()}`,
  }));
  const summary = (d, color) => el('p', { class: 'summary' },
    el('span', { class: 'swatch', style: `background:${color}` }),
    `${name(d)} · ${d.detail.start.slice(0, 19).replace('T', ' ')} UTC · ${duration(d.detail.duration_s)} · ` +
    `${d.detail.samples} samples${d.data.downsampled ? ` (drawn: ${d.data.t_s.length} points, peaks kept)` : ''}` +
    ` · ${d.events.length} alarm events `, gnssSummary(d.detail.gnss), ...exportLinks(d));

  const chartsBox = el('section', { class: 'charts', 'aria-label': 'session charts' });
  const track = main.track?.points ? trackPanel(main) : null;
  const scrub = el('input', { type: 'range', id: 'scrubber', min: 0, max: Math.ceil(m.duration_s), step: 0.1, value: 0,
    'aria-label': 'time scrubber' });
  const readout = el('output', { class: 'scrub-readout', for: 'scrubber' });
  body.append(...[
    summary(main, COLORS[0]), vs ? summary(vs, COLORS[1]) : null,
    vs ? el('p', { class: 'hint', text: overlap ? 'Overlay aligned on clock time.' : 'Overlay aligned on session start.' }) : null,
    el('div', { class: `review-grid${track ? ' with-track' : ''}` },
      el('div', { class: 'review-main' }, chartsBox,
        el('div', { class: 'scrub' }, el('label', { for: 'scrubber', text: 'Time' }), scrub, readout,
          el('button', { type: 'button', id: 'reset-zoom', text: 'Reset zoom', onclick: () => charts.forEach((u) => u.setScale('x', { min: data[0][0], max: data[0][data[0].length - 1] })) }))),
      track)]
    .filter(Boolean));

  const charts = [];
  const sync = uPlot.sync('review');
  const seriesFor = (idx, labelBase) => {
    const s = [{ label: `${labelBase} ${name(main)}`, stroke: COLORS[0], width: 2, spanGaps: true }];
    if (vs) s.push({ label: `${labelBase} ${name(vs)}`, stroke: COLORS[1], width: 2, spanGaps: true });
    return s;
  };
  for (const [idx, label] of [[1, 'Heel'], [2, 'Pitch']]) {
    const box = el('div', { class: 'chart', dataset: { series: label.toLowerCase() } });
    chartsBox.append(box);
    const cols = vs ? [data[0], data[idx], data[idx + 2]] : [data[0], data[idx]];
    const u = new uPlot({
      width: widthOf(chartsBox),
      height: CHART_H,
      scales: { x: { time: false } },
      cursor: { sync: { key: sync.key, setSeries: false }, drag: { x: true, y: false } },
      series: [{ label: 'Time', value: (u, v) => (v === null ? '–' : `${fmtRel(v)} (${clock(t0 + v)} UTC)`) },
        ...seriesFor(idx, `${label} °`)],
      axes: [{ space: 70, values: (u, vals) => {
        const step = vals.length > 1 ? vals[1] - vals[0] : 1;
        return vals.map((v) => (step < 1 ? `${v.toFixed(1)} s` : fmtRel(v)));
      } }, { size: 50 }],
      plugins: [markersPlugin(() => markers), manoeuvreMarkersPlugin(() => manoeuvreMarks)],
      hooks: {
        setCursor: [(u) => {
          const i = u.cursor.idx;
          if (i !== null && i !== undefined && document.activeElement !== scrub) {
            scrub.value = String(u.data[0][i]);
            showReadout(u.data[0][i]);
          }
        }],
      },
    }, cols, box);
    box.uplot = u; // the browser tests read the zoom from here
    charts.push(u);
  }
  // Speed over ground (knots) from the track, on the same time axis.
  if (main.track?.points) {
    const tr = main.track;
    const box = el('div', { class: 'chart', dataset: { series: 'sog' } });
    chartsBox.append(box);
    const u = new uPlot({
      width: widthOf(chartsBox),
      height: Math.round(CHART_H * 0.8),
      scales: { x: { time: false } },
      cursor: { sync: { key: sync.key, setSeries: false }, drag: { x: true, y: false } },
      series: [{ label: 'Time', value: (u, v) => (v === null ? '–' : `${fmtRel(v)} (${clock(t0 + v)} UTC)`) },
        { label: `Speed kn ${name(main)}`, stroke: COLORS[2], width: 2, spanGaps: false,
          value: (u, v) => (v === null ? '–' : `${v.toFixed(1)} kn`) }],
      axes: [{ space: 70, values: (u, vals) => vals.map((v) => fmtRel(v)) }, { size: 50 }],
      plugins: [markersPlugin(() => markers), manoeuvreMarkersPlugin(() => manoeuvreMarks)],
      hooks: {
        setCursor: [(u) => {
          const i = u.cursor.idx;
          if (i !== null && i !== undefined && document.activeElement !== scrub) {
            scrub.value = String(u.data[0][i]);
            showReadout(u.data[0][i]);
          }
        }],
      },
    }, [tr.t_s.map((t) => t - t0), tr.sog_m_s.map((v) => (Number.isFinite(v) ? v * KNOTS_PER_M_S : null))], box);
    box.uplot = u;
    u.setScale('x', { min: data[0][0], max: data[0][data[0].length - 1] });
    charts.push(u);
  }
  const valueAt = (d, base, t) => {
    const xs = d.data.t_s;
    let lo = 0;
    let hi = xs.length - 1;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (xs[mid] - base < t) lo = mid + 1;
      else hi = mid;
    }
    return lo < xs.length ? { heel: d.data.heel_deg[lo], pitch: d.data.pitch_deg[lo] } : null;
  };
  function showReadout(t) {
    if (track) moveTrackMarker(track, t0 + t);
    const a = valueAt(main, t0, t);
    const b = vs ? valueAt(vs, vsT0, t) : null;
    readout.textContent = `${fmtRel(t)} · ${clock(t0 + t)} UTC · ${name(main)} heel ${deg(a?.heel)} pitch ${deg(a?.pitch)}` +
      (b ? ` · ${name(vs)} heel ${deg(b.heel)} pitch ${deg(b.pitch)}` : '');
  }
  scrub.addEventListener('input', () => {
    const t = Number(scrub.value);
    showReadout(t);
    const u = charts[0];
    // Keep the scrubbed time in view, then put the cursor there.
    const { min, max } = u.scales.x;
    if (t < min || t > max) {
      const span = max - min;
      charts.forEach((c) => c.setScale('x', { min: t - span / 2, max: t + span / 2 }));
    }
    charts.forEach((c) => c.setCursor({ left: c.valToPos(t, 'x'), top: c.bbox.height / devicePixelRatio / 2 }));
  });
  showReadout(0);

  // Manoeuvres: listed (a row's time jumps the scrubber to its t0), on the timeline and the
  // track, overlaid, ranked against the other boats of the race.
  const jump = (rel) => {
    scrub.value = String(rel);
    scrub.dispatchEvent(new Event('input'));
    // The charts' cursors snap the scrubber to their nearest drawn point: back to t0 itself.
    scrub.value = String(rel);
    showReadout(rel);
  };
  const manoeuvres = has('/sessions/{id}/manoeuvres')
    ? manoeuvrePanels({ uPlot, detail: m, sessions, jump, marks: manoeuvreMarks, trackSection: track,
      redraw: () => charts.forEach((u) => u.redraw(false)) })
    : null;
  if (manoeuvres) body.append(manoeuvres.nodes[0]);

  // Alarm events on the timeline, listed too.
  body.append(el('section', { class: 'panel', 'aria-label': 'alarm events' },
    el('h2', { text: `Alarm events (${main.events.length})` }),
    main.events.length ? el('ul', { class: 'events' }, main.events.map((ev) => el('li', { class: `event ${ev.level}` },
      el('button', { type: 'button', class: 'link', text: fmtRel(isoToSeconds(ev.raised_at) - t0), onclick: () => {
        scrub.value = String(isoToSeconds(ev.raised_at) - t0);
        scrub.dispatchEvent(new Event('input'));
      } }), ` ${ev.level.toUpperCase()} · ${ev.message ?? ''} · ${ev.phase}`)))
      : el('p', { class: 'empty', text: 'No alarm in this session.' })));

  // Heel distribution and time in each band.
  body.append(el('section', { class: 'panel distribution', 'aria-label': 'heel distribution' },
    el('h2', { text: 'Heel distribution' }),
    histogram([main, vs].filter(Boolean)),
    el('h2', { text: 'Time in each heel band' }),
    bandsTable([main, vs].filter(Boolean), name)));
  if (m.gnss) body.append(heelSpeedPanel(m));
  if (manoeuvres) body.append(manoeuvres.nodes[1]);

  const stopResize = autoResize(() => charts, chartsBox, CHART_H);
  return () => {
    stopResize();
    manoeuvres?.destroy();
    charts.forEach((u) => u.destroy());
  };
}

function gnssSummary(g) {
  if (!g) return null;
  const kn = (v) => (Number.isFinite(v) ? `${(v * KNOTS_PER_M_S).toFixed(1)} kn` : '–');
  const dist = g.distance_m >= 1000 ? `${(g.distance_m / 1000).toFixed(2)} km` : `${Math.round(g.distance_m)} m`;
  return el('span', { class: 'gnss-summary', dataset: { distanceM: String(g.distance_m) } },
    g.fixes ? `${dist} sailed · SOG mean ${kn(g.sog_mean_m_s)}, max ${kn(g.sog_max_m_s)} · ` : 'no GNSS fix · ');
}

// Time-weighted heel histogram, 2 degree bins, each session as its own colour.
function histogram(list) {
  const lo = -40;
  const hi = 40;
  const bin = 2;
  const nb = (hi - lo) / bin;
  const hists = list.map((d) => {
    const h = new Array(nb).fill(0);
    const t = d.data.t_s;
    const v = d.data.heel_deg;
    for (let i = 0; i + 1 < t.length; i++) {
      if (v[i] === null) continue;
      const dt = Math.min(t[i + 1] - t[i], 1); // a gap counts at most 1 s
      const k = Math.max(0, Math.min(nb - 1, Math.floor((v[i] - lo) / bin)));
      h[k] += dt;
    }
    const total = h.reduce((a, b) => a + b, 0) || 1;
    return h.map((x) => x / total);
  });
  const peak = Math.max(0.01, ...hists.flat());
  const W = 400;
  const H = 120;
  const bw = W / nb / list.length;
  const bars = [];
  hists.forEach((h, s) => h.forEach((f, k) => {
    if (!f) return;
    const bh = (f / peak) * (H - 4);
    bars.push(svg('rect', { class: `bar s${s}`, x: (k * list.length + s) * bw, y: H - bh, width: Math.max(bw - 0.5, 0.5), height: bh, fill: COLORS[s] },
      svg('title', {}, document.createTextNode(`${lo + k * bin}…${lo + (k + 1) * bin}°: ${(f * 100).toFixed(1)} %`))));
  }));
  const ticks = [-40, -20, -10, 0, 10, 20, 40].map((d) => {
    const x = ((d - lo) / (hi - lo)) * W;
    return [svg('line', { class: 'tick', x1: x, y1: H, x2: x, y2: H + 4 }),
      svg('text', { x, y: H + 16, 'text-anchor': 'middle' }, document.createTextNode(`${d}°`))];
  }).flat();
  return svg('svg', { class: 'histogram', viewBox: `-16 0 ${W + 32} ${H + 20}`, role: 'img',
    'aria-label': 'heel distribution, port to starboard' }, svg('line', { class: 'axis', x1: 0, y1: H, x2: W, y2: H }), ...bars, ...ticks);
}

function bandsOf(d) {
  if (Array.isArray(d.detail.heel_bands)) return d.detail.heel_bands;
  // Computed from the drawn points when the server sends none.
  const bands = BANDS.slice(0, -1).map((from, i) => ({ from_deg: from, to_deg: BANDS[i + 1], seconds: 0 }));
  const { t_s: t, heel_deg: v } = d.data;
  for (let i = 0; i + 1 < t.length; i++) {
    const b = bands.find((x) => v[i] >= x.from_deg && v[i] < x.to_deg);
    if (b) b.seconds += Math.min(t[i + 1] - t[i], 1);
  }
  return bands;
}

function bandsTable(list, name) {
  const all = list.map(bandsOf);
  const rows = all[0].map((b, i) => el('tr', {},
    el('th', { scope: 'row', text: `${b.from_deg}° … ${b.to_deg}°` }),
    all.map((bands) => {
      const total = bands.reduce((a, x) => a + x.seconds, 0) || 1;
      const x = bands[i] ?? { seconds: 0 };
      const time = x.seconds < 60 ? `${x.seconds.toFixed(1)} s` : duration(x.seconds);
      return el('td', { text: `${time} (${((x.seconds / total) * 100).toFixed(0)} %)` });
    })));
  return el('div', { class: 'table-wrap' }, el('table', { class: 'bands' },
    el('thead', {}, el('tr', {}, el('th', { text: 'Heel band' }), list.map((d) => el('th', { text: name(d) })))),
    el('tbody', {}, rows)));
}
