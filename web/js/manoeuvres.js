// Manoeuvres in the session review: the session's tacks, gybes, bear-aways,
// round-ups and penalty turns as a list (a row's time jumps the scrubber to its t0), marked on
// the charts' timeline and on the track; several ticked (one boat, or several boats of the same
// race: their sessions overlap this one in time) overlaid as heel, SOG and turn rate from
// t0 - 20 s to t0 + 30 s, every one aligned at its own t0; and the boats of the race ranked by
// their mean distance lost, per kind. Every metric is the shore's (GET /sessions/{id}/manoeuvres);
// the overlay's curves are the recorded samples (GET /boats/{id}/attitude and /track).
import { api, q } from './api.js';
import { COLORS, autoResize, widthOf } from './charts.js';
import { KNOTS_PER_M_S, lowerBound } from './geo.js';
import { clock, deg, el, isoToSeconds, svg } from './util.js';

export const KIND_LABEL = { tack: 'Tack', gybe: 'Gybe', bear_away: 'Bear-away', round_up: 'Round-up',
  penalty: 'Penalty turn', other: 'Other turn' };
const KIND_LETTER = { tack: 'T', gybe: 'G', bear_away: 'B', round_up: 'R', penalty: 'P', other: '?' };
const KIND_ORDER = ['tack', 'gybe', 'bear_away', 'round_up', 'penalty', 'other'];
export const MARK_COLOR = '#7a3cb8';
export const BEFORE_S = 20;
export const AFTER_S = 30;
const OVERLAY_H = 190;

const kn = (v) => (Number.isFinite(v) ? (v * KNOTS_PER_M_S).toFixed(1) : '–');
export const metres = (v) => (Number.isFinite(v) ? `${v.toFixed(1)} m` : '–');
const fmtRel = (v) => {
  const s = Math.round(v);
  return `${s < 0 ? '-' : ''}${Math.floor(Math.abs(s) / 60)}:${String(Math.abs(s) % 60).padStart(2, '0')}`;
};

// The sessions of the same race: this one and every other boat's that overlaps it in time.
function raceSessions(detail, sessions) {
  const others = sessions.filter((s) => s.id !== detail.id && s.boat_id !== detail.boat_id &&
    s.start_t_s < detail.end_t_s && s.end_t_s > detail.start_t_s);
  return [detail, ...others];
}

// Vertical dashed lines with the kind's letter on a uPlot chart: [{x, kind}].
export function manoeuvreMarkersPlugin(getMarks) {
  return {
    hooks: {
      draw: [(u) => {
        const { ctx } = u;
        const { top, height, left, width } = u.bbox;
        ctx.save();
        ctx.strokeStyle = MARK_COLOR;
        ctx.fillStyle = MARK_COLOR;
        ctx.lineWidth = 2 * devicePixelRatio;
        ctx.setLineDash([6 * devicePixelRatio, 4 * devicePixelRatio]);
        ctx.font = `bold ${12 * devicePixelRatio}px system-ui, sans-serif`;
        ctx.textAlign = 'center';
        for (const m of getMarks()) {
          const x = Math.round(u.valToPos(m.x, 'x', true));
          if (x < left || x > left + width) continue;
          ctx.beginPath();
          ctx.moveTo(x, top + 14 * devicePixelRatio);
          ctx.lineTo(x, top + height);
          ctx.stroke();
          ctx.fillText(KIND_LETTER[m.kind] ?? '?', x, top + 11 * devicePixelRatio);
        }
        ctx.restore();
      }],
    },
  };
}

// The review's manoeuvre panels. `jump(rel)` moves the scrubber to `rel` seconds from the main
// session's start; `marks` (an array the charts draw from) is filled here; `redraw()` repaints
// the charts; `trackSection` is the track panel (or null).
export function manoeuvrePanels({ uPlot, detail, sessions, jump, marks, redraw, trackSection }) {
  const list = el('section', { class: 'panel manoeuvres', 'aria-label': 'manoeuvres', dataset: { state: 'loading' } },
    el('h2', { text: 'Manoeuvres' }), el('p', { class: 'hint', text: 'Finding the manoeuvres…' }));
  const ranking = el('section', { class: 'panel manoeuvre-ranking', 'aria-label': 'manoeuvre ranking' },
    el('h2', { text: 'Ranking by distance lost' }));
  const cleanups = [];
  const race = raceSessions(detail, sessions);
  let stopped = false;
  (async () => {
    const results = await Promise.all(race.map((s) => api(`/sessions/${s.id}/manoeuvres`)
      .then((r) => ({ s, r }), (err) => ({ s, err }))));
    if (stopped) return;
    const mainResult = results[0];
    if (mainResult.err) {
      list.dataset.state = 'error';
      list.replaceChildren(el('h2', { text: 'Manoeuvres' }),
        el('p', { class: 'message', text: `Cannot load the manoeuvres: ${mainResult.err.message}` }));
      ranking.remove();
      return;
    }
    const all = results.filter((x) => x.r).flatMap(({ s, r }) => r.manoeuvres.map((m, n) => ({
      ...m, n, boat: s.boat_id, session: s.id, t0: isoToSeconds(m.t_utc), key: `${s.id}:${n}` })));
    const mine = all.filter((m) => m.session === detail.id);
    marks.push(...mine.map((m) => ({ x: m.t0 - detail.start_t_s, kind: m.kind })));
    redraw();
    if (trackSection?.track) markTrack(trackSection, mine, (m) => jump(m.t0 - detail.start_t_s));
    const overlay = overlayPanel(uPlot);
    cleanups.push(overlay.destroy);
    fillList(list, { detail, results, all, jump, overlay });
    fillRanking(ranking, detail, results);
  })().catch((err) => {
    list.dataset.state = 'error';
    list.replaceChildren(el('h2', { text: 'Manoeuvres' }),
      el('p', { class: 'message', text: `Cannot show the manoeuvres: ${err.message}` }));
    ranking.remove();
  });
  return {
    nodes: [list, ranking],
    destroy() {
      stopped = true;
      cleanups.forEach((f) => f());
    },
  };
}

function fillList(section, { detail, results, all, jump, overlay }) {
  const main = results[0].r;
  const boats = results.length;
  const failed = results.filter((x) => x.err);
  const show = el('select', { id: 'manoeuvre-boats', 'aria-label': 'manoeuvres of' },
    el('option', { value: 'mine', text: `${detail.boat_id} only` }),
    el('option', { value: 'all', text: `All ${boats} boats of this race` }));
  const tbody = el('tbody');
  const empty = el('p', { class: 'empty' });
  const table = el('div', { class: 'table-wrap' }, el('table', { class: 'manoeuvre-list' },
    el('thead', {}, el('tr', {},
      el('th', { text: 'Overlay' }), el('th', { class: 'col-boat', text: 'Boat' }), el('th', { text: 'Kind' }),
      el('th', { text: 'Time (t0)' }), el('th', { text: 'Turn' }), el('th', { text: 'Lost' }),
      el('th', { text: 'Heel peak' }), el('th', { text: 'SOG entry / min / exit kn' }))),
    tbody));
  const picked = new Set();
  const pickHint = el('p', { class: 'hint pick-hint' });
  const updatePickHint = () => {
    pickHint.textContent = picked.size ? `${picked.size} ticked for the overlay below.`
      : 'Tick manoeuvres (of this boat or of others in the race) to overlay them below, aligned at t0.';
  };
  function rows() {
    const list = show.value === 'all' ? all : all.filter((m) => m.session === detail.id);
    list.sort((a, b) => a.t0 - b.t0 || (a.boat < b.boat ? -1 : 1));
    table.querySelector('table').classList.toggle('one-boat', show.value !== 'all');
    tbody.replaceChildren(...list.map((m) => {
      const rel = m.t0 - detail.start_t_s;
      const inSession = rel >= 0 && rel <= detail.duration_s;
      const label = `${KIND_LABEL[m.kind] ?? m.kind} ${m.boat} ${clock(m.t0)}`;
      const box = el('input', { type: 'checkbox', class: 'pick', 'aria-label': `overlay ${label}`, checked: picked.has(m.key),
        onchange: () => {
          if (box.checked) picked.add(m.key);
          else picked.delete(m.key);
          updatePickHint();
          overlay.show(all.filter((x) => picked.has(x.key)));
        } });
      const time = inSession
        ? el('button', { type: 'button', class: 'link jump', text: `${fmtRel(rel)} · ${clock(m.t0)}`,
          title: 'move the scrubber here', onclick: () => jump(rel) })
        : el('span', { text: clock(m.t0) });
      const turn = Number.isFinite(m.turn_deg) ? `${Math.round(m.turn_deg)}° ${m.turn_dir > 0 ? 'to stbd' : m.turn_dir < 0 ? 'to port' : ''}` : '–';
      return el('tr', { class: `manoeuvre${m.session === detail.id ? ' mine' : ''}`,
        dataset: { boat: m.boat, session: String(m.session), n: String(m.n), kind: m.kind, t0: String(m.t0), rel: String(rel), key: m.key } },
      el('td', {}, box), el('td', { class: 'col-boat', text: m.boat }),
      el('td', {}, el('span', { class: `kind-tag ${m.kind}`, text: KIND_LABEL[m.kind] ?? m.kind }),
        m.unsteady_entry ? el('span', { class: 'unsteady', title: 'unsteady before the turn: the loss may come from before it', text: ' ⚠' }) : null),
      el('td', {}, time), el('td', { text: turn }),
      el('td', { class: 'lost', dataset: { m: String(m.distance_lost_m) }, text: metres(m.distance_lost_m) }),
      el('td', { text: deg(m.heel_peak_deg) }),
      el('td', { text: `${kn(m.entry_sog_m_s)} / ${kn(m.min_sog_m_s)} / ${kn(m.exit_sog_m_s)}` }));
    }));
    empty.hidden = list.length > 0;
    empty.textContent = show.value === 'all' ? 'No manoeuvre in any session of this race.'
      : `No manoeuvre found in this session (a turn of 60° or more, sailing at 1 m/s or faster${detail.gnss && !detail.gnss.fixes ? '; and this session has no GNSS fix' : ''}).`;
    table.hidden = list.length === 0;
  }
  show.addEventListener('change', rows);
  const w = main.wind;
  // Where the wind came from: the coach's (typed in), the boat's wind instrument (an imported
  // log's), else the tacks; beside a given wind, what the tacks alone would have said.
  const estimate = Number.isFinite(w?.estimated_from_deg) && w.given
    ? `; the tacks say ${Math.round(w.estimated_from_deg)}°${Number.isFinite(w.estimate_error_deg) ? ` (${w.estimate_error_deg >= 0 ? '+' : '−'}${Math.abs(w.estimate_error_deg).toFixed(1)}°)` : ''}`
    : '';
  const source = w?.source === 'instrument'
    ? ` (the boat's wind instrument, spread ±${Math.round(w.instrument?.spread_deg ?? 0)}°${estimate})`
    : w?.source === 'coach' ? ` (given${estimate})`
      : ` (estimated from the tacks, ±${Math.max(1, Math.round(w?.uncertainty_deg ?? 0))}°)`;
  const wind = Number.isFinite(w?.from_deg)
    ? `Wind from ${Math.round(w.from_deg)}°${source}.`
    : 'Wind not known (no tack to read it from): every turn that is not clearly a tack or gybe is listed by its course.';
  const counts = KIND_ORDER.map((k) => [k, main.manoeuvres.filter((m) => m.kind === k).length]).filter(([, c]) => c)
    .map(([k, c]) => `${c} × ${KIND_LABEL[k].toLowerCase()}`).join(' · ');
  section.replaceChildren(
    el('h2', { text: `Manoeuvres (${main.manoeuvres.length})` }),
    el('p', { class: 'hint', text: `${counts ? `${counts}. ` : ''}${wind} Lost: metres behind the entry speed over t0 − 10 … t0 + 20 s.` }),
    boats > 1 ? el('div', { class: 'toolbar' }, el('label', {}, 'Show ', show)) : null,
    ...failed.map((x) => el('p', { class: 'message', text: `${x.s.boat_id}: cannot load its manoeuvres: ${x.err.message}` })),
    table, empty, pickHint, overlay.node);
  section.dataset.state = 'ready';
  updatePickHint();
  rows();
}

// Manoeuvre marks on the review track at each t0; a click jumps the scrubber there.
function markTrack(section, list, onJump) {
  const { t, xy, sx, sy, marker } = section.track;
  const svgNode = marker.ownerSVGElement;
  for (const m of list) {
    const i = lowerBound(t, m.t0);
    if (i <= 0 || i >= t.length) continue; // outside the track
    const f = (m.t0 - t[i - 1]) / (t[i] - t[i - 1]);
    const p = [xy[i - 1][0] + f * (xy[i][0] - xy[i - 1][0]), xy[i - 1][1] + f * (xy[i][1] - xy[i - 1][1])];
    const g = svg('g', { class: 'manoeuvre-mark', 'data-kind': m.kind, 'data-t0': String(m.t0), role: 'button',
      transform: `translate(${sx(p).toFixed(1)} ${sy(p).toFixed(1)})` },
    svg('circle', { r: 10 }),
    svg('text', { y: 5, 'text-anchor': 'middle' }, document.createTextNode(KIND_LETTER[m.kind] ?? '?')),
    svg('title', {}, document.createTextNode(`${KIND_LABEL[m.kind] ?? m.kind} ${clock(m.t0)}: lost ${metres(m.distance_lost_m)}`)));
    g.addEventListener('click', () => onJump(m));
    svgNode.insertBefore(g, marker);
  }
}

// Unwrapped difference b - a of two courses, degrees in (-180, 180].
function courseDiff(a, b) {
  let d = (b - a) % 360;
  if (d > 180) d -= 360;
  if (d <= -180) d += 360;
  return d;
}

// Turn rate from the COG (1 s central difference, as the shore's max_turn_rate), degrees per
// second, positive in the manoeuvre's own turning direction so every turn reads upwards.
export function turnRate(tr, dir) {
  const t = tr.t_s;
  const c = tr.cog_deg;
  return t.map((ti) => {
    const a = lowerBound(t, ti - 0.5);
    let b = lowerBound(t, ti + 0.5 + 1e-6) - 1;
    if (b >= t.length) b = t.length - 1;
    if (a < 0 || b <= a || !Number.isFinite(c[a]) || !Number.isFinite(c[b]) || t[b] - t[a] < 0.5) return null;
    return (courseDiff(c[a], c[b]) / (t[b] - t[a])) * (dir || 1);
  });
}

// Heel, SOG and turn rate of the ticked manoeuvres from t0 - 20 s to t0 + 30 s, each on its
// own t0. The chart boxes carry their uPlot (box.uplot) and the manoeuvres drawn
// (box.manoeuvres: boat, session, kind, t0 epoch seconds) for the browser tests.
function overlayPanel(uPlot) {
  const charts = el('div', { class: 'charts overlay-charts' });
  const status = el('div', { class: 'overlay-status', 'aria-live': 'polite' });
  const node = el('section', { class: 'manoeuvre-overlay', 'aria-label': 'manoeuvres overlaid at t0', dataset: { count: '0' } },
    el('h3', { text: `Overlay: −${BEFORE_S} s … +${AFTER_S} s around t0` }),
    el('p', { class: 'hint', text: 'Heel (+ starboard), SOG, and turn rate from the COG (1 s), positive in each manoeuvre\u2019s own turning direction.' }),
    status, charts);
  const cache = new Map();
  let drawn = [];
  let seq = 0;
  let stopResize = () => {};
  const clear = () => {
    stopResize();
    drawn.forEach((u) => u.destroy());
    drawn = [];
    charts.replaceChildren();
  };
  const load = (m) => {
    if (!cache.has(m.key)) {
      const range = { from: (m.t0 - BEFORE_S - 1).toFixed(3), to: (m.t0 + AFTER_S + 1).toFixed(3) };
      const id = encodeURIComponent(m.boat);
      cache.set(m.key, Promise.all([
        api(`/boats/${id}/attitude${q({ ...range, max_points: 5000 })}`),
        api(`/boats/${id}/track${q({ ...range, max_points: 5000 })}`).catch(() => null),
      ]).then(([att, tr]) => ({ att, tr })));
      cache.get(m.key).catch(() => cache.delete(m.key));
    }
    const got = cache.get(m.key);
    // A manoeuvre of a live session whose window is not over yet: read again next time.
    if (Date.now() / 1000 < m.t0 + AFTER_S + 5) cache.delete(m.key);
    return got;
  };
  async function show(list) {
    const mine = ++seq;
    node.dataset.count = String(list.length);
    if (!list.length) {
      clear();
      status.replaceChildren();
      node.dataset.state = 'empty';
      return;
    }
    node.dataset.state = 'loading';
    status.replaceChildren(el('p', { class: 'hint', text: `Loading ${list.length} manoeuvre${list.length > 1 ? 's' : ''}…` }));
    const got = await Promise.all(list.map((m) => load(m).then((d) => ({ m, d }), (err) => ({ m, err }))));
    if (mine !== seq) return;
    clear();
    const ok = got.filter((x) => x.d);
    const notes = got.filter((x) => x.err).map((x) => el('p', { class: 'message',
      text: `Cannot load ${KIND_LABEL[x.m.kind] ?? x.m.kind} ${x.m.boat} ${clock(x.m.t0)}: ${x.err.message}` }));
    if (ok.length && ok.every((x) => !x.d.tr?.t_s?.length)) {
      notes.push(el('p', { class: 'hint', text: 'No GNSS fix around these manoeuvres: speed and turn rate stay empty.' }));
    }
    status.replaceChildren(...notes);
    if (!ok.length) {
      node.dataset.state = 'error';
      return;
    }
    draw(ok);
    node.dataset.state = 'ready';
  }
  function draw(items) {
    const inWindow = (x) => x >= -BEFORE_S - 1e-9 && x <= AFTER_S + 1e-9;
    const rel = (ts, t0) => ts.map((t) => Math.round((t - t0) * 1000) / 1000);
    const tables = (pick) => items.map(({ m, d }) => {
      const [xs, ys] = pick(m, d);
      const keep = xs.map((x, i) => inWindow(x) && ys[i] !== null && ys[i] !== undefined && Number.isFinite(ys[i]));
      return [xs.filter((_, i) => keep[i]), ys.filter((_, i) => keep[i])];
    });
    const heel = tables((m, d) => [rel(d.att.t_s, m.t0), d.att.heel_deg]);
    const sog = tables((m, d) => (d.tr?.t_s ? [rel(d.tr.t_s, m.t0), d.tr.sog_m_s.map((v) => (Number.isFinite(v) ? v * KNOTS_PER_M_S : null))] : [[], []]));
    const rate = tables((m, d) => (d.tr?.t_s ? [rel(d.tr.t_s, m.t0), turnRate(d.tr, m.turn_dir)] : [[], []]));
    const label = ({ m }) => `${m.boat} ${KIND_LABEL[m.kind] ?? m.kind} ${clock(m.t0)}`;
    const sync = uPlot.sync('manoeuvre-overlay');
    for (const [name, title, unit, data] of [['heel', 'Heel', '°', heel], ['sog', 'SOG', 'kn', sog],
      ['rate', 'Turn', '°/s', rate]]) {
      const box = el('div', { class: 'chart', dataset: { series: `overlay-${name}` } });
      charts.append(box);
      const joined = joinTables(uPlot, data);
      const u = new uPlot({
        width: widthOf(charts),
        height: OVERLAY_H,
        scales: { x: { time: false, auto: false, range: [-BEFORE_S, AFTER_S] } },
        cursor: { sync: { key: sync.key, setSeries: false }, drag: { x: false, y: false } },
        series: [{ label: 's from t0', value: (uu, v) => (v === null ? '–' : `${v >= 0 ? '+' : ''}${v.toFixed(1)} s`) },
          ...items.map((it, i) => ({ label: `${title} ${unit} ${label(it)}`, stroke: COLORS[i % COLORS.length], width: 2,
            dash: i >= COLORS.length ? [8, 4] : undefined, spanGaps: true,
            value: (uu, v) => (v === null ? '–' : `${v.toFixed(1)} ${unit}`) }))],
        axes: [{ values: (uu, vals) => vals.map((v) => `${v > 0 ? '+' : ''}${v} s`) }, { size: 50 }],
        plugins: [zeroLinePlugin()],
      }, joined, box);
      box.uplot = u;
      box.manoeuvres = items.map(({ m }) => ({ boat: m.boat, session: m.session, n: m.n, kind: m.kind, t0: m.t0 }));
      drawn.push(u);
    }
    stopResize = autoResize(() => drawn, charts, OVERLAY_H);
  }
  return { node, show, destroy: clear };
}

// uPlot.join needs at least one table and x values in order; an empty table joins as nulls.
function joinTables(uPlot, tables) {
  const withData = tables.map((t) => (t[0].length ? t : [[0], [null]]));
  return uPlot.join(withData);
}

// A black line at t0.
function zeroLinePlugin() {
  return {
    hooks: {
      draw: [(u) => {
        const x = Math.round(u.valToPos(0, 'x', true));
        const { ctx } = u;
        ctx.save();
        ctx.strokeStyle = '#000';
        ctx.lineWidth = 2 * devicePixelRatio;
        ctx.beginPath();
        ctx.moveTo(x, u.bbox.top);
        ctx.lineTo(x, u.bbox.top + u.bbox.height);
        ctx.stroke();
        ctx.restore();
      }],
    },
  };
}

// The race's boats ranked by mean distance lost, per kind (least first); this boat marked.
function fillRanking(section, detail, results) {
  const perKind = new Map();
  for (const { s, r } of results) {
    if (!r) continue;
    for (const k of r.summary ?? []) {
      if (!perKind.has(k.kind)) perKind.set(k.kind, new Map());
      const boats = perKind.get(k.kind);
      const b = boats.get(s.boat_id) ?? { boat: s.boat_id, count: 0, sum: 0, n: 0, best: null, worst: null };
      b.count += k.count;
      // Each session's mean weighted by its count (a boat with two sessions in the race).
      if (Number.isFinite(k.mean_distance_lost_m)) {
        b.sum += k.mean_distance_lost_m * k.count;
        b.n += k.count;
      }
      if (Number.isFinite(k.best_distance_lost_m)) b.best = b.best === null ? k.best_distance_lost_m : Math.min(b.best, k.best_distance_lost_m);
      if (Number.isFinite(k.worst_distance_lost_m)) b.worst = b.worst === null ? k.worst_distance_lost_m : Math.max(b.worst, k.worst_distance_lost_m);
      boats.set(s.boat_id, b);
    }
  }
  const boatsInRace = new Set(results.map((x) => x.s.boat_id)).size;
  const head = [el('h2', { text: 'Ranking by distance lost' }),
    el('p', { class: 'hint', text: `${boatsInRace > 1 ? `The ${boatsInRace} boats of this race (sessions overlapping this one)` : 'Only this boat sailed in this session\u2019s time'}, per kind: mean metres lost, least first.` })];
  if (!perKind.size) {
    section.replaceChildren(...head, el('p', { class: 'empty', text: 'No manoeuvre to rank.' }));
    return;
  }
  const kinds = KIND_ORDER.filter((k) => perKind.has(k));
  section.replaceChildren(...head, el('div', { class: 'ranking-grid' }, kinds.map((kind) => {
    const list = [...perKind.get(kind).values()].map((b) => ({ ...b, mean: b.n ? b.sum / b.n : null }))
      .sort((a, b) => (a.mean === null) - (b.mean === null) || (a.mean ?? 0) - (b.mean ?? 0) || (a.boat < b.boat ? -1 : 1));
    return el('div', { class: 'table-wrap' }, el('table', { class: 'ranking', dataset: { kind } },
      el('caption', { text: `${KIND_LABEL[kind] ?? kind}s` }),
      el('thead', {}, el('tr', {}, el('th', { text: '#' }), el('th', { text: 'Boat' }), el('th', { text: 'Count' }),
        el('th', { text: 'Mean lost' }), el('th', { text: 'Best' }), el('th', { text: 'Worst' }))),
      el('tbody', {}, list.map((b, i) => el('tr', { class: b.boat === detail.boat_id ? 'mine' : null,
        dataset: { boat: b.boat, mean: String(b.mean) } },
      el('td', { text: String(i + 1) }), el('th', { scope: 'row', text: b.boat }), el('td', { text: String(b.count) }),
      el('td', { class: 'mean', text: metres(b.mean) }), el('td', { text: metres(b.best) }), el('td', { text: metres(b.worst) }))))));
  })));
}
