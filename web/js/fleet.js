// Fleet view: one card per boat, sortable (id, heel, alarm) and groupable (by the boat's group),
// each with the boat's last manoeuvre when the shore finds manoeuvres (manoeuvre_live.js).
import { has } from './api.js';
import { createCard, updateCard, updateManoeuvre, updateSparkline } from './card.js';
import { watchManoeuvres } from './manoeuvre_live.js';
import { el } from './util.js';

const ALARM_RANK = { alarm: 0, warn: 1, normal: 2 };

export function mountFleet(container, { live }) {
  const prefs = JSON.parse(localStorage.getItem('telltale.fleet') ?? '{}');
  const sort = el('select', { id: 'sort', 'aria-label': 'sort boats by' },
    el('option', { value: 'id', text: 'Sort: boat' }),
    el('option', { value: 'heel', text: 'Sort: heel' }),
    el('option', { value: 'alarm', text: 'Sort: alarm' }));
  sort.value = prefs.sort ?? 'id';
  const group = el('input', { type: 'checkbox', id: 'group' });
  group.checked = !!prefs.group;
  const count = el('span', { class: 'count' });
  const grid = el('section', { id: 'fleet', class: 'fleet', 'aria-label': 'Fleet' });
  const empty = el('p', { class: 'empty', text: 'Waiting for boats… (none heard yet)' });
  container.append(
    el('div', { class: 'toolbar' }, sort, el('label', {}, group, ' Group'), count),
    empty, grid);

  const cards = new Map();
  const pending = new Map(); // a boat's last manoeuvre found before its card exists
  const dirty = new Set();
  let frame = 0;

  function card(id) {
    let c = cards.get(id);
    if (!c) {
      c = createCard(id);
      cards.set(id, c);
      if (pending.has(id)) updateManoeuvre(c, pending.get(id));
      arrange();
    }
    return c;
  }

  function key(id) {
    const b = live.boats.get(id).boat;
    if (sort.value === 'heel') return [-Math.abs(b.heel_deg ?? 0), id];
    if (sort.value === 'alarm') return [ALARM_RANK[b.alarm_state] ?? 3, id];
    return [0, id];
  }
  function cmp(a, b) {
    const ka = key(a);
    const kb = key(b);
    return ka[0] - kb[0] || (ka[1] < kb[1] ? -1 : ka[1] > kb[1] ? 1 : 0);
  }

  // Rebuilds the order (and the group sections). Called on a new boat, a change of sort or
  // grouping, and every second when sorting by a live value, so cards do not jump at 25 Hz.
  function arrange() {
    const ids = [...cards.keys()].sort(cmp);
    for (const id of ids) cards.get(id).dataset.sortKey = String(Math.abs(key(id)[0]));
    empty.hidden = ids.length > 0;
    count.textContent = `${ids.length} boat${ids.length === 1 ? '' : 's'}`;
    if (!group.checked) {
      grid.classList.remove('grouped');
      grid.replaceChildren(...ids.map((id) => cards.get(id)));
      return;
    }
    grid.classList.add('grouped');
    const groups = new Map();
    for (const id of ids) {
      const g = live.boats.get(id).boat.group || 'no group';
      if (!groups.has(g)) groups.set(g, []);
      groups.get(g).push(cards.get(id));
    }
    const names = [...groups.keys()].sort();
    grid.replaceChildren(...names.map((g) =>
      el('section', { class: 'group', dataset: { group: g } },
        el('h2', { class: 'group-name', text: `${g} (${groups.get(g).length})` }),
        el('div', { class: 'group-cards' }, groups.get(g)))));
  }

  function savePrefs() {
    localStorage.setItem('telltale.fleet', JSON.stringify({ sort: sort.value, group: group.checked }));
    arrange();
  }
  sort.addEventListener('change', savePrefs);
  group.addEventListener('change', savePrefs);

  function draw() {
    frame = 0;
    for (const id of dirty) updateCard(card(id), live.boats.get(id), live.isStale(live.boats.get(id)));
    dirty.clear();
  }
  function onBoat(e) {
    dirty.add(e.detail.id);
    if (!frame) frame = requestAnimationFrame(draw);
  }
  live.addEventListener('boat', onBoat);
  for (const id of live.boats.keys()) dirty.add(id);
  draw();

  const sparkTimer = setInterval(() => {
    for (const [id, c] of cards) updateSparkline(c, live.boats.get(id));
  }, 250);
  const slowTimer = setInterval(() => {
    // Stale check: a silent boat sends nothing, so nothing else would redraw its card.
    for (const [id, c] of cards) {
      const entry = live.boats.get(id);
      const stale = live.isStale(entry);
      if (stale || c.dataset.stale === 'true') updateCard(c, entry, stale);
    }
    if (sort.value !== 'id') arrange();
    for (const c of cards.values()) updateManoeuvre(c); // its age
  }, 1000);
  const stopManoeuvres = watchManoeuvres(live, (id, m) => {
    if (cards.has(id)) updateManoeuvre(cards.get(id), m);
    else pending.set(id, m);
  }, { fill: has('/sessions/{id}/manoeuvres') });

  return () => {
    live.removeEventListener('boat', onBoat);
    clearInterval(sparkTimer);
    clearInterval(slowTimer);
    stopManoeuvres();
    if (frame) cancelAnimationFrame(frame);
  };
}
