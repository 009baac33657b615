// Boat view: the boat's card, live heel / pitch / heading charts (uPlot) over the last minutes,
// its active alarms (ack and silence for the coach) and the alarm rules editor (coach only;
// others see the rules read-only).
import { api, has, q } from './api.js';
import { createCard, updateCard, updateSparkline } from './card.js';
import { COLORS, autoResize, loadUPlot, widthOf } from './charts.js';
import { clock, el } from './util.js';

const WINDOW_S = 120;
const CHART_H = 170;

export function mountBoat(container, { live, role, params, navigate }) {
  const cleanups = [];
  let id = params[0] ? decodeURIComponent(params[0]) : [...live.boats.keys()].sort()[0];
  const picker = el('select', { id: 'boat-picker', 'aria-label': 'boat' });
  const fillPicker = () => {
    const ids = [...new Set([...live.boats.keys(), ...(id ? [id] : [])])].sort();
    if (picker.options.length === ids.length) return;
    picker.replaceChildren(...ids.map((b) => el('option', { value: b, text: b })));
    if (id) picker.value = id;
  };
  fillPicker();
  picker.addEventListener('change', () => navigate(`#/boat/${encodeURIComponent(picker.value)}`));
  const review = el('a', { class: 'button', href: `#/review?boat=${encodeURIComponent(id ?? '')}`,
    text: 'Review sessions' });
  container.append(el('div', { class: 'toolbar' }, picker, review));
  if (!id) {
    container.append(el('p', { class: 'empty', text: 'No boat heard yet.' }));
    const onFirst = () => navigate(`#/boat/${encodeURIComponent([...live.boats.keys()][0])}`);
    live.addEventListener('boat', onFirst, { once: true });
    return () => live.removeEventListener('boat', onFirst);
  }

  const card = createCard(id);
  card.classList.add('wide');
  const chartsBox = el('section', { class: 'charts', 'aria-label': 'live charts' });
  const alarmsBox = el('section', { class: 'panel alarms', 'aria-label': 'alarms' });
  const rulesBox = el('section', { class: 'panel rules', 'aria-label': 'alarm rules' });
  container.append(el('div', { class: 'boat-layout' }, card, chartsBox), alarmsBox, rulesBox);

  // Live card.
  const onBoat = (e) => {
    fillPicker();
    if (e.detail.id === id) updateCard(card, live.boats.get(id), false);
  };
  live.addEventListener('boat', onBoat);
  cleanups.push(() => live.removeEventListener('boat', onBoat));
  const staleTimer = setInterval(() => {
    const entry = live.boats.get(id);
    if (entry) updateCard(card, entry, live.isStale(entry));
    if (entry) updateSparkline(card, entry);
  }, 1000);
  cleanups.push(() => clearInterval(staleTimer));
  if (live.boats.has(id)) updateCard(card, live.boats.get(id), live.isStale(live.boats.get(id)));

  // Charts.
  const charts = [];
  let stopped = false;
  (async () => {
    const uPlot = await loadUPlot();
    if (stopped) return;
    if (has('/boats/{id}/attitude') && live.boats.has(id)) {
      const now = Date.now() / 1000;
      try {
        const data = await api(`/boats/${encodeURIComponent(id)}/attitude` +
          q({ from: (now - WINDOW_S).toFixed(3), to: now.toFixed(3), max_points: 2000 }));
        live.backfill(id, data);
      } catch (err) {
        console.warn('backfill failed', err);
      }
    }
    if (stopped) return;
    const spec = [
      ['heel', 'Heel (°, + starboard down)', COLORS[0], [-40, 40]],
      ['pitch', 'Pitch (°, + bow up)', COLORS[2], [-20, 20]],
      ['heading', 'Heading (°)', COLORS[3], [0, 360]],
    ];
    const sync = uPlot.sync('boat-live');
    for (const [key, label, color, range] of spec) {
      const box = el('div', { class: 'chart', dataset: { series: key } });
      chartsBox.append(box);
      const u = new uPlot({
        width: widthOf(chartsBox),
        height: CHART_H,
        tzDate: (ts) => uPlot.tzDate(new Date(ts * 1e3), 'Etc/UTC'),
        cursor: { sync: { key: sync.key } },
        scales: {
          x: { time: true },
          y: { range: (u, min, max) => [Math.min(range[0], min ?? 0), Math.max(range[1], max ?? 0)] },
        },
        series: [{}, { label, stroke: color, width: 2, spanGaps: false }],
        axes: [{ space: 90, values: (u, vals) => vals.map(clock) }, { size: 50 }],
      }, [[], []], box);
      u._key = key;
      charts.push(u);
    }
    const redraw = () => {
      const entry = live.boats.get(id);
      if (!entry) return;
      const h = entry.hist;
      const end = h.t.length ? h.t[h.t.length - 1] : Date.now() / 1000;
      let i = h.t.length;
      while (i > 0 && h.t[i - 1] >= end - WINDOW_S) i--;
      const t = h.t.slice(i);
      for (const u of charts) u.setData([t, h[u._key].slice(i)]);
      const noHeading = !h.heading.slice(i).some((v) => v !== null && v !== undefined);
      chartsBox.querySelector('[data-series="heading"]').dataset.empty = String(noHeading);
    };
    redraw();
    const timer = setInterval(redraw, 250);
    cleanups.push(() => clearInterval(timer));
    cleanups.push(autoResize(() => charts, chartsBox, CHART_H));
  })().catch((err) => {
    chartsBox.append(el('p', { class: 'message', text: `Charts unavailable: ${err.message}. ` +
      'Run `npm ci` in web/ (it fills web/vendor/).' }));
  });
  cleanups.push(() => {
    stopped = true;
    charts.forEach((u) => u.destroy());
  });

  // Alarms of this boat.
  if (has('/alarms/events')) {
    // Renders overlap (an SSE alarm message and an ack's refresh): only the latest one started may
    // draw, or a slow answer from before an ack puts the stale 'raised' state back for good.
    let renders = 0;
    const renderAlarms = async () => {
      const mine = ++renders;
      const events = await api(`/alarms/events${q({ boat: id, active: 'true' })}`);
      if (mine !== renders) return;
      alarmsBox.replaceChildren(el('h2', { text: 'Active alarms' }),
        events.length ? el('ul', { class: 'events' }, events.map((ev) => eventItem(ev, role, renderAlarms)))
          : el('p', { class: 'empty', text: 'None.' }));
    };
    const show = () => renderAlarms().catch((err) => alarmsBox.replaceChildren(el('p', { class: 'message', text: err.message })));
    show();
    const onAlarm = (e) => { if (e.detail.boat_id === id) show(); };
    live.addEventListener('alarm', onAlarm);
    cleanups.push(() => live.removeEventListener('alarm', onAlarm));
  } else {
    alarmsBox.hidden = true;
  }

  // Rules.
  if (has('/alarms/rules')) {
    rulesEditor(rulesBox, id, role).catch((err) =>
      rulesBox.replaceChildren(el('p', { class: 'message', text: err.message })));
  } else {
    rulesBox.replaceChildren(el('h2', { text: 'Alarm rules' }),
      el('p', { class: 'empty', text: 'This shore server does not offer alarm rules.' }));
  }

  return () => cleanups.forEach((f) => f());
}

function eventItem(ev, role, refresh) {
  const note = el('span', { class: 'status', role: 'status' });
  const act = (what) => el('button', { type: 'button', class: `event-${what}`, text: what, onclick: async () => {
    try {
      await api(`/alarms/events/${ev.id}/${what}`, { method: 'POST' });
      await refresh();
    } catch (err) {
      // e.g. 409: the alarm cleared meanwhile.
      note.textContent = ` ${what} failed: ${err.message}`;
      note.dataset.state = 'error';
    }
  } });
  const open = ev.phase === 'raised' || ev.phase === 'acknowledged';
  return el('li', { class: `event ${ev.level}`, dataset: { level: ev.level, phase: ev.phase, event: String(ev.id) } },
    el('strong', { text: `${ev.level.toUpperCase()} ` }),
    `${ev.raised_at.slice(11, 19)} UTC · ${ev.message ?? ''} (${ev.phase})`,
    role === 'coach' && open ? [' ', ev.phase === 'raised' ? act('ack') : null, ' ', act('silence')] : null, note);
}

const FIELDS = [
  ['scope', 'Scope', 'text'],
  ['quantity', 'Quantity', ['heel', 'pitch']],
  ['min_deg', 'Min °', 'number'],
  ['max_deg', 'Max °', 'number'],
  ['hold_s', 'Hold s', 'number'],
  ['hysteresis_deg', 'Hyst. °', 'number'],
  ['level', 'Level', ['warn', 'alarm']],
  ['enabled', 'On', 'checkbox'],
];

// The alarm rules editor: a table of every rule (the PUT replaces the whole set). A rule keeps
// the boat "in band" while min_deg <= value <= max_deg; outside for hold_s raises its level.
async function rulesEditor(box, boatId, role) {
  const rules = await api('/alarms/rules');
  const editable = role === 'coach';
  const status = el('p', { class: 'status', role: 'status' });
  const tbody = el('tbody');
  const row = (r) => {
    const tr = el('tr', { class: 'rule', dataset: { id: String(r.id ?? '') } });
    tr._rule = r;
    for (const [k, , type] of FIELDS) {
      let input;
      if (Array.isArray(type)) {
        input = el('select', { name: k, disabled: !editable }, type.map((o) => el('option', { value: o, text: o })));
        input.value = r[k];
      } else if (type === 'checkbox') {
        input = el('input', { type: 'checkbox', name: k, disabled: !editable });
        input.checked = !!r[k];
      } else {
        input = el('input', { type, name: k, value: r[k] ?? '', step: 'any', disabled: !editable,
          size: type === 'text' ? 12 : 5 });
      }
      tr.append(el('td', { 'data-label': k }, input));
    }
    if (editable) tr.append(el('td', {}, el('button', { type: 'button', class: 'remove', text: 'Remove',
      onclick: () => tr.remove() })));
    return tr;
  };
  rules.forEach((r) => tbody.append(row(r)));
  // Rule ids are strings chosen by the editor: the scope and a free number.
  const nextId = (scope) => {
    const taken = new Set([...tbody.children].map((tr) => String(tr._rule.id)));
    const base = scope.replace(/[^A-Za-z0-9_-]+/g, '-');
    let n = 1;
    while (taken.has(`${base}-${n}`)) n++;
    return `${base}-${n}`;
  };
  const add = (scope) => tbody.append(row({ id: nextId(scope), scope, quantity: 'heel', min_deg: -25,
    max_deg: 25, hold_s: 2, hysteresis_deg: 1, level: 'alarm', enabled: true }));
  const collect = () => [...tbody.children].map((tr) => {
    const r = { ...tr._rule };
    for (const [k, label, type] of FIELDS) {
      const input = tr.querySelector(`[name="${k}"]`);
      if (type === 'checkbox') r[k] = input.checked;
      else if (type === 'number') {
        if (input.value.trim() === '' || !Number.isFinite(Number(input.value))) {
          throw new Error(`${label}: not a number in rule ${r.id}`);
        }
        r[k] = Number(input.value);
      } else r[k] = input.value;
    }
    if (r.min_deg > r.max_deg) throw new Error(`rule ${r.id}: min above max`);
    return r;
  });
  const save = async () => {
    try {
      const body = collect();
      await api('/alarms/rules', { method: 'PUT', body });
      status.textContent = `Saved ${body.length} rule${body.length === 1 ? '' : 's'}.`;
      status.dataset.state = 'ok';
    } catch (err) {
      status.textContent = `Not saved: ${err.message}`;
      status.dataset.state = 'error';
    }
  };
  box.replaceChildren(
    el('h2', { text: editable ? 'Alarm rules (coach)' : 'Alarm rules (read only)' }),
    el('p', { class: 'hint', text: 'In band while min ≤ value ≤ max; outside for “hold” seconds raises the level. ' +
      'Scope: fleet, group:NAME or boat:ID.' }),
    el('div', { class: 'table-wrap' }, el('table', { class: 'rules-table' },
      el('thead', {}, el('tr', {}, FIELDS.map(([, label]) => el('th', { text: label })), editable ? el('th') : null)),
      tbody)),
    editable ? el('div', { class: 'toolbar' },
      el('button', { type: 'button', id: 'add-boat-rule', text: `+ Rule for ${boatId}`, onclick: () => add(`boat:${boatId}`) }),
      el('button', { type: 'button', id: 'add-fleet-rule', text: '+ Fleet rule', onclick: () => add('fleet') }),
      el('button', { type: 'button', id: 'save-rules', class: 'primary', text: 'Save rules', onclick: save })) : null,
    status);
}
