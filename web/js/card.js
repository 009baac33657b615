// One boat's card: big heel and pitch numbers, the boat seen from astern (heels) and from the
// side (pitches), the instrument's LED panel, alarm state, stale marker and a one-minute
// sparkline; on the fleet view also the boat's last manoeuvre (kind, age, distance lost). Used by
// the fleet view and at the top of the boat view.
import { speedText } from './geo.js';
import { KIND_LABEL, metres } from './manoeuvres.js';
import { deg, el, svg } from './util.js';

const SPARK_S = 60;
const SPARK_RANGE_DEG = 30; // sparkline y range: +-30 deg

export function createCard(id) {
  const root = el('article', { class: 'card', dataset: { boat: id, alarm: 'normal', stale: 'false' } });
  const leds = {};
  for (const side of ['left', 'right', 'up', 'down']) leds[side] = el('div', { class: `bar ${side}` });
  const astern = svg('g', { class: 'hull-heel' },
    svg('path', { class: 'hull', d: 'M-30 0 L30 0 L18 14 L-18 14 Z' }),
    svg('line', { class: 'mast', x1: 0, y1: 0, x2: 0, y2: -46 }),
    svg('path', { class: 'sail', d: 'M2 -44 L2 -4 L22 -4 Z' }));
  const side = svg('g', { class: 'hull-pitch' },
    svg('path', { class: 'hull', d: 'M-44 0 L40 0 L28 10 L-40 10 Z' }),
    svg('line', { class: 'mast', x1: 6, y1: 0, x2: 6, y2: -46 }),
    svg('path', { class: 'sail', d: 'M4 -44 L4 -3 L-30 -3 Z' }));
  const spark = {
    heel: svg('polyline', { class: 'spark-heel', points: '' }),
    pitch: svg('polyline', { class: 'spark-pitch', points: '' }),
  };
  root.append(
    el('header', {},
      el('h2', {}, el('a', { class: 'boat-id', href: `#/boat/${encodeURIComponent(id)}`, text: id })),
      el('span', { class: 'group-tag' }),
      el('span', { class: 'alarm-badge', text: 'OK' }),
      el('span', { class: 'stale-marker', text: 'SILENT' }),
      el('ul', { class: 'problems', 'aria-label': 'problems' })),
    el('div', { class: 'readouts' },
      el('div', { class: 'readout' }, el('span', { class: 'label', text: 'Heel' }),
        el('span', { class: 'value heel', text: '–' })),
      el('div', { class: 'readout' }, el('span', { class: 'label', text: 'Pitch' }),
        el('span', { class: 'value pitch', text: '–' }))),
    el('div', { class: 'speed-row', 'aria-label': 'speed over ground' },
      el('span', { class: 'label', text: 'SOG' }),
      el('span', { class: 'value speed', text: '–' }), el('span', { class: 'unit-big', text: 'kn' }),
      el('span', { class: 'speed-ms', text: '– m/s' }), el('span', { class: 'cog' })),
    el('div', { class: 'last-manoeuvre', hidden: true, 'aria-label': 'last manoeuvre' },
      el('span', { class: 'label', text: 'Last' }), el('span', { class: 'm-kind' }), el('span', { class: 'm-age' }),
      el('span', { class: 'm-lost' })),
    el('div', { class: 'figures' },
      svg('svg', { class: 'silhouette astern', viewBox: '-55 -52 110 70', role: 'img',
        'aria-label': 'boat from astern' },
        svg('line', { class: 'horizon', x1: -55, y1: 7, x2: 55, y2: 7 }), astern),
      svg('svg', { class: 'silhouette side', viewBox: '-55 -52 110 70', role: 'img',
        'aria-label': 'boat from the side, bow right' },
        svg('line', { class: 'horizon', x1: -55, y1: 5, x2: 55, y2: 5 }), side),
      el('div', { class: 'leds', 'aria-label': 'LED panel' },
        leds.up, el('div', { class: 'led-row' }, leds.left, el('span', { class: 'led-centre' }), leds.right),
        leds.down)),
    svg('svg', { class: 'sparkline', viewBox: `0 ${-SPARK_RANGE_DEG} ${SPARK_S} ${2 * SPARK_RANGE_DEG}`,
      preserveAspectRatio: 'none', role: 'img', 'aria-label': 'heel and pitch, last minute' },
      svg('line', { class: 'zero', x1: 0, y1: 0, x2: SPARK_S, y2: 0 }), spark.pitch, spark.heel),
    el('footer', { class: 'meta' }));
  root._parts = {
    heel: root.querySelector('.heel'),
    pitch: root.querySelector('.pitch'),
    speed: root.querySelector('.speed'),
    speedMs: root.querySelector('.speed-ms'),
    cog: root.querySelector('.cog'),
    astern,
    side,
    leds,
    spark,
    badge: root.querySelector('.alarm-badge'),
    group: root.querySelector('.group-tag'),
    problems: root.querySelector('.problems'),
    meta: root.querySelector('.meta'),
    manoeuvre: root.querySelector('.last-manoeuvre'),
  };
  return root;
}

function ledBar(bar, lit, count) {
  if (bar.childElementCount !== count) {
    bar.replaceChildren(...Array.from({ length: count }, () => el('span', { class: 'led' })));
  }
  [...bar.children].forEach((led, i) => led.classList.toggle('on', i < lit));
}

const BADGE = { normal: 'OK', warn: 'WARN', alarm: 'ALARM' };
// What the shore says is wrong with the boat (its `problems`), one badge each; the full text is
// the badge's tooltip. The log first: a failing session log loses for good what the link drops.
const PROBLEM_LABEL = { log_failing: 'LOG FAILING', duplicate_id: 'TWO NODES', clock_suspect: 'CLOCK',
  sensor: 'SENSOR' };

function updateProblems(list, problems) {
  const key = problems.map((p) => `${p.code}\u0000${p.text}`).join('\u0001');
  if (list.dataset.key === key) return;
  list.dataset.key = key;
  list.replaceChildren(...problems.map((p) => el('li', {
    class: `problem ${p.code}`, title: p.text, dataset: { code: p.code },
    text: PROBLEM_LABEL[p.code] ?? p.code.toUpperCase() })));
}

export function updateCard(root, entry, stale) {
  const b = entry.boat;
  const p = root._parts;
  root.dataset.alarm = b.alarm_state ?? 'normal';
  root.dataset.stale = String(stale);
  p.badge.textContent = BADGE[b.alarm_state] ?? b.alarm_state;
  p.group.textContent = b.group ?? '';
  updateProblems(p.problems, b.problems ?? []);
  p.heel.textContent = deg(b.heel_deg);
  p.pitch.textContent = deg(b.pitch_deg);
  const sp = speedText(b.sog_m_s);
  p.speed.textContent = sp.kn;
  p.speedMs.textContent = sp.ms;
  p.cog.textContent = Number.isFinite(b.cog_deg) ? `COG ${b.cog_deg.toFixed(0).padStart(3, '0')}°`
    : b.gnss_fix === undefined ? '' : 'no fix';
  // Seen from astern, starboard is on the right: heel > 0 (starboard down) turns the hull
  // clockwise on screen, which is a positive SVG rotation.
  p.astern.setAttribute('transform', `rotate(${(b.heel_deg ?? 0).toFixed(1)})`);
  // Seen from starboard with the bow to the right: pitch > 0 (bow up) is counter-clockwise.
  p.side.setAttribute('transform', `rotate(${(-(b.pitch_deg ?? 0)).toFixed(1)})`);
  const leds = b.leds ?? { left: 0, right: 0, up: 0, down: 0, count: 6 };
  for (const s of ['left', 'right', 'up', 'down']) ledBar(p.leds[s], leds[s] ?? 0, leds.count || 6);
  const age = Math.max(0, (Date.now() - b.t_utc_ns / 1e6) / 1000); // since the boat's last sample
  p.meta.textContent =
    `${b.last_sample_time.slice(11, 19)} UTC` +
    (b.heading_deg === null || b.heading_deg === undefined ? '' : ` · HDG ${b.heading_deg.toFixed(0)}°`) +
    (stale ? ` · silent ${age.toFixed(0)} s` : '');
}

export function updateSparkline(root, entry) {
  const { t, heel, pitch } = entry.hist;
  if (!t.length) return;
  const end = t[t.length - 1];
  let i = t.length - 1;
  while (i > 0 && t[i - 1] >= end - SPARK_S) i--;
  // At most ~300 points per line: the card is a few hundred pixels wide.
  const step = Math.max(1, Math.floor((t.length - i) / 300));
  const line = (v) => {
    const pts = [];
    for (let k = i; k < t.length; k += step) {
      if (v[k] === null || v[k] === undefined) continue;
      const y = Math.max(-SPARK_RANGE_DEG, Math.min(SPARK_RANGE_DEG, -v[k]));
      pts.push(`${(SPARK_S - (end - t[k])).toFixed(2)},${y.toFixed(2)}`);
    }
    return pts.join(' ');
  };
  root._parts.spark.heel.setAttribute('points', line(heel));
  root._parts.spark.pitch.setAttribute('points', line(pitch));
}

// The boat's last manoeuvre: {kind, t0 (epoch s), distance_lost_m, final}; without `m` the one
// shown (its age moves on).
export function updateManoeuvre(root, m = root._manoeuvre) {
  if (!m) return;
  root._manoeuvre = m;
  const row = root._parts.manoeuvre;
  row.hidden = false;
  Object.assign(row.dataset, { kind: m.kind, t0: String(m.t0), final: String(m.final), lost: String(m.distance_lost_m) });
  row.querySelector('.m-kind').textContent = KIND_LABEL[m.kind] ?? m.kind;
  const age = Math.max(0, Date.now() / 1000 - m.t0);
  row.querySelector('.m-age').textContent = age < 90 ? `${Math.round(age)} s ago` : age < 5400 ? `${Math.round(age / 60)} min ago`
    : `${(age / 3600).toFixed(1)} h ago`;
  row.querySelector('.m-lost').textContent = m.final ? `lost ${metres(m.distance_lost_m)}` : 'lost: measuring…';
}
