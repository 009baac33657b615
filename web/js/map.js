// Live fleet map: every boat at its GNSS position with an arrow along its course over ground
// (heading when there is no course), its last two minutes as a trail, coloured by alarm state
// (silent boats greyed), north up, a scale bar. Drawn in local metres around the fleet on an
// SVG, so it works without internet; a tile layer only when the coach sets a tile URL (stored
// in this browser, off by default). Follows the fleet until the coach pans or zooms; "Fit
// fleet" follows again. Tap a boat to open it.
import { api, q } from './api.js';
import { hasFix, metresText, niceMetres, projection, speedText } from './geo.js';
import { el, svg } from './util.js';

const TRAIL_S = 120;
const TRAIL_STEP_S = 0.5; // one trail point per half second from the live frames
const FIT_PAD_PX = 56;
const MIN_SPAN_M = 80; // never zoom in closer than this across the fleet
const TILE_KEY = 'telltale.map.tiles';
const STATE_CLASS = { normal: 'normal', warn: 'warn', alarm: 'alarm' };

export function mountMap(container, { live, navigate }) {
  const fitBtn = el('button', { type: 'button', id: 'map-fit', 'aria-pressed': 'true', text: 'Fit fleet' });
  const zoomIn = el('button', { type: 'button', id: 'map-zoom-in', 'aria-label': 'zoom in', text: '+' });
  const zoomOut = el('button', { type: 'button', id: 'map-zoom-out', 'aria-label': 'zoom out', text: '−' });
  const count = el('span', { class: 'count' });
  const tileInput = el('input', { type: 'text', id: 'map-tiles', inputmode: 'url', spellcheck: 'false',
    placeholder: 'https://tiles.example/{z}/{x}/{y}.png', 'aria-label': 'tile URL template',
    value: localStorage.getItem(TILE_KEY) ?? '' });
  const tileSave = el('button', { type: 'button', id: 'map-tiles-save', text: 'Save' });
  const settings = el('details', { class: 'map-settings' },
    el('summary', { text: 'Map tiles (optional, needs internet)' }),
    el('p', { class: 'hint', text: 'Leave empty for the plain map. {z}/{x}/{y} are replaced by the tile numbers.' }),
    el('div', { class: 'row' }, tileInput, tileSave));

  const layers = { tiles: svg('g', { class: 'tiles' }), trails: svg('g', { class: 'trails' }),
    boats: svg('g', { class: 'boats' }), overlay: svg('g', { class: 'overlay' }) };
  const scaleLine = svg('path', { class: 'scale-line', d: '' });
  const scaleText = svg('text', { class: 'scale-text', x: 0, y: 0 });
  const scaleBar = svg('g', { class: 'scale-bar' }, scaleLine, scaleText);
  const north = svg('g', { class: 'north', 'aria-hidden': 'true' },
    svg('path', { d: 'M0 -16 L9 10 L0 4 L-9 10 Z' }),
    svg('text', { x: 0, y: 28, 'text-anchor': 'middle' }, document.createTextNode('N')));
  layers.overlay.append(scaleBar, north);
  const map = svg('svg', { id: 'fleet-map', class: 'fleet-map', role: 'application',
    'aria-label': 'fleet map, north up; drag to pan, wheel or pinch to zoom' },
  layers.tiles, layers.trails, layers.boats, layers.overlay);
  const empty = el('p', { class: 'empty map-empty', text: 'Waiting for boats with a GNSS fix…' });
  const list = el('ul', { class: 'map-list', 'aria-label': 'boats on the map' });
  container.append(
    el('div', { class: 'toolbar' }, fitBtn, zoomOut, zoomIn, count),
    el('div', { class: 'map-wrap' }, map, empty),
    list, settings);

  // View: the projection's origin, the point shown at the centre (metres) and pixels per metre.
  let proj = null;
  const view = { cx: 0, cy: 0, k: 1, w: 300, h: 300 };
  let follow = true;
  let lastFit = 0;
  const boats = new Map(); // id -> {trail: {t, lat, lon}, node, trailNode, item, fetched}
  let frame = 0;

  const toScreen = (lat, lon) => {
    const [x, y] = proj.toXY(lat, lon);
    return [view.w / 2 + (x - view.cx) * view.k, view.h / 2 - (y - view.cy) * view.k];
  };

  function setFollow(on) {
    follow = on;
    fitBtn.setAttribute('aria-pressed', String(on));
    if (on) {
      lastFit = 0;
      schedule();
    }
  }

  function boatState(id) {
    let s = boats.get(id);
    if (s) return s;
    const arrow = svg('path', { class: 'arrow', d: 'M0 -17 L10 11 L0 5 L-10 11 Z' });
    const label = svg('text', { class: 'tag', x: 20, y: 6 });
    const node = svg('g', { class: 'boat', role: 'link', tabindex: '0', 'data-boat': id },
      svg('circle', { class: 'hit', r: 26 }), svg('circle', { class: 'disc', r: 15 }), arrow, label);
    const trailNode = svg('polyline', { class: 'trail', 'data-boat': id, points: '' });
    const open = () => navigate(`#/boat/${encodeURIComponent(id)}`);
    node.addEventListener('click', open);
    node.addEventListener('keydown', (e) => {
      if (e.key === 'Enter' || e.key === ' ') {
        e.preventDefault();
        open();
      }
    });
    const item = el('li', {}, el('a', { href: `#/boat/${encodeURIComponent(id)}`, class: 'button', dataset: { boat: id } }));
    s = { trail: { t: [], lat: [], lon: [] }, node, trailNode, arrow, label, item, fetched: false };
    boats.set(id, s);
    layers.trails.append(trailNode);
    layers.boats.append(node);
    const items = [...boats.keys()].sort().map((b) => boats.get(b).item);
    list.replaceChildren(...items);
    return s;
  }

  // The last two minutes, once per boat, from the stored fixes; the live frames extend it.
  async function backfill(id, s, tEnd) {
    s.fetched = true;
    // Not gated on the OpenAPI list: the shore's document does not list the track yet.
    try {
      const d = await api(`/boats/${encodeURIComponent(id)}/track${q({ from: (tEnd - TRAIL_S).toFixed(3), to: tEnd.toFixed(3), max_points: 600 })}`);
      const tr = s.trail;
      const first = tr.t.length ? tr.t[0] : Infinity;
      const keep = d.t_s.findIndex((t) => t >= first);
      const n = keep < 0 ? d.t_s.length : keep;
      const ok = (i) => Number.isFinite(d.lat_deg[i]) && Number.isFinite(d.lon_deg[i]);
      const idx = [...Array(n).keys()].filter(ok);
      tr.t.unshift(...idx.map((i) => d.t_s[i]));
      tr.lat.unshift(...idx.map((i) => d.lat_deg[i]));
      tr.lon.unshift(...idx.map((i) => d.lon_deg[i]));
      schedule();
    } catch {
      // No stored track (older server, no fixes yet): the live trail grows from now.
    }
  }

  function addFix(b) {
    if (!hasFix(b)) return;
    const s = boatState(b.id);
    const t = b.t_utc_ns / 1e9;
    const tr = s.trail;
    if (!tr.t.length || t - tr.t[tr.t.length - 1] >= TRAIL_STEP_S) {
      tr.t.push(t);
      tr.lat.push(b.lat_deg);
      tr.lon.push(b.lon_deg);
      const cut = tr.t.findIndex((x) => x >= t - TRAIL_S);
      if (cut > 0) for (const k of ['t', 'lat', 'lon']) tr[k].splice(0, cut);
    }
    if (!s.fetched) backfill(b.id, s, t);
  }

  // Fits the fleet (positions and trails) into the map, north up.
  function fit() {
    const pts = [];
    for (const [id, s] of boats) {
      const b = live.boats.get(id)?.boat;
      if (hasFix(b)) pts.push([b.lat_deg, b.lon_deg]);
      for (let i = 0; i < s.trail.t.length; i += 4) pts.push([s.trail.lat[i], s.trail.lon[i]]);
    }
    if (!pts.length) return;
    const lat = pts.map((p) => p[0]);
    const lon = pts.map((p) => p[1]);
    const midLat = (Math.min(...lat) + Math.max(...lat)) / 2;
    const midLon = (Math.min(...lon) + Math.max(...lon)) / 2;
    if (!proj) proj = projection(midLat, midLon);
    const xy = pts.map((p) => proj.toXY(p[0], p[1]));
    const xs = xy.map((p) => p[0]);
    const ys = xy.map((p) => p[1]);
    const spanX = Math.max(MIN_SPAN_M, Math.max(...xs) - Math.min(...xs));
    const spanY = Math.max(MIN_SPAN_M, Math.max(...ys) - Math.min(...ys));
    view.cx = (Math.min(...xs) + Math.max(...xs)) / 2;
    view.cy = (Math.min(...ys) + Math.max(...ys)) / 2;
    // Room for the labels, which sit right of each boat.
    const k = Math.min((view.w - 3 * FIT_PAD_PX) / spanX, (view.h - 2 * FIT_PAD_PX) / spanY);
    // Zoom out at once when a boat leaves the view; zoom in only for a real change, so the map
    // does not breathe with every tack.
    if (k < view.k || k > view.k * 1.4 || lastFit === 0) view.k = Math.max(1e-4, k);
    lastFit = performance.now();
  }

  function draw() {
    frame = 0;
    const rect = map.getBoundingClientRect();
    if (rect.width && (rect.width !== view.w || rect.height !== view.h)) {
      view.w = rect.width;
      view.h = rect.height;
      map.setAttribute('viewBox', `0 0 ${view.w} ${view.h}`);
      if (follow) lastFit = 0;
    }
    if (follow && (lastFit === 0 || performance.now() - lastFit > 1000)) fit();
    const withFix = [...boats.keys()].filter((id) => hasFix(live.boats.get(id)?.boat));
    empty.hidden = withFix.length > 0;
    count.textContent = `${withFix.length} of ${live.boats.size} boat${live.boats.size === 1 ? '' : 's'} with a fix`;
    if (!proj) return;
    map.dataset.pxPerM = view.k.toFixed(6);
    for (const [id, s] of boats) {
      const entry = live.boats.get(id);
      const b = entry?.boat;
      const stale = entry ? live.isStale(entry) : true;
      const state = stale ? 'stale' : (STATE_CLASS[b?.alarm_state] ?? 'normal');
      const tr = s.trail;
      const pts = [];
      for (let i = 0; i < tr.t.length; i++) {
        const [x, y] = toScreen(tr.lat[i], tr.lon[i]);
        pts.push(`${x.toFixed(1)},${y.toFixed(1)}`);
      }
      if (hasFix(b)) {
        const [x, y] = toScreen(b.lat_deg, b.lon_deg);
        pts.push(`${x.toFixed(1)},${y.toFixed(1)}`);
        const dir = Number.isFinite(b.cog_deg) ? b.cog_deg : b.heading_deg;
        s.node.setAttribute('transform', `translate(${x.toFixed(1)} ${y.toFixed(1)})`);
        const left = x > view.w - 130; // near the right edge the label goes left of the boat
        if (left !== (s.label.getAttribute('text-anchor') === 'end')) {
          s.label.setAttribute('text-anchor', left ? 'end' : 'start');
          s.label.setAttribute('x', left ? '-20' : '20');
        }
        s.arrow.setAttribute('transform', `rotate(${(dir ?? 0).toFixed(0)})`);
        s.arrow.classList.toggle('no-course', !Number.isFinite(dir));
        s.node.dataset.x = x.toFixed(2);
        s.node.dataset.y = y.toFixed(2);
        s.node.dataset.lat = String(b.lat_deg);
        s.node.dataset.lon = String(b.lon_deg);
        s.node.dataset.course = Number.isFinite(dir) ? dir.toFixed(1) : '';
        s.node.style.display = '';
      } else {
        s.node.style.display = 'none';
      }
      const sp = speedText(b?.sog_m_s);
      const labelText = `${id} ${sp.kn} kn`;
      if (s.label.textContent !== labelText) s.label.textContent = labelText;
      s.node.dataset.state = state;
      s.trailNode.dataset.state = state;
      s.trailNode.setAttribute('points', pts.join(' '));
      const aria = `${id}: ${sp.kn} knots, ${stale ? 'silent' : b?.alarm_state ?? 'normal'}${hasFix(b) ? '' : ', no fix'}. Open the boat.`;
      if (s.node.getAttribute('aria-label') !== aria) s.node.setAttribute('aria-label', aria);
      const a = s.item.firstChild;
      const itemText = `${id} · ${sp.kn} kn${hasFix(b) ? '' : ' · no fix'}`;
      if (a.textContent !== itemText) a.textContent = itemText;
      a.dataset.state = state;
    }
    drawScale();
    drawTiles();
  }

  function drawScale() {
    const metres = niceMetres((view.w * 0.28) / view.k);
    const px = metres * view.k;
    const x0 = 16;
    const y0 = view.h - 18;
    scaleLine.setAttribute('d', `M${x0} ${y0 - 8} V${y0} H${(x0 + px).toFixed(1)} V${y0 - 8}`);
    scaleText.setAttribute('x', String(x0));
    scaleText.setAttribute('y', String(y0 - 12));
    scaleText.textContent = metresText(metres);
    scaleBar.dataset.metres = String(metres);
    scaleBar.dataset.px = px.toFixed(2);
    north.setAttribute('transform', `translate(${view.w - 30} 30)`);
  }

  // Optional slippy-map tiles (Web Mercator) under the boats; drawn only when configured.
  let tileKey = '';
  function drawTiles() {
    const url = localStorage.getItem(TILE_KEY) ?? '';
    if (!url || !proj) {
      if (tileKey) layers.tiles.replaceChildren();
      tileKey = '';
      return;
    }
    const mpp = 1 / view.k;
    const z = Math.max(0, Math.min(19, Math.round(Math.log2((156543.03 * Math.cos(proj.lat0 * Math.PI / 180)) / mpp))));
    const corner = (sx, sy) => proj.toLatLon(view.cx + (sx - view.w / 2) / view.k, view.cy - (sy - view.h / 2) / view.k);
    const [latN, lonW] = corner(0, 0);
    const [latS, lonE] = corner(view.w, view.h);
    const n = 2 ** z;
    const tx = (lon) => Math.floor(((lon + 180) / 360) * n);
    const ty = (lat) => {
      const r = (lat * Math.PI) / 180;
      return Math.floor(((1 - Math.log(Math.tan(r) + 1 / Math.cos(r)) / Math.PI) / 2) * n);
    };
    const lonOf = (x) => (x / n) * 360 - 180;
    const latOf = (y) => (Math.atan(Math.sinh(Math.PI * (1 - (2 * y) / n))) * 180) / Math.PI;
    const key = `${url}|${z}|${view.cx.toFixed(1)}|${view.cy.toFixed(1)}|${view.k.toFixed(5)}|${view.w}|${view.h}`;
    if (key === tileKey) return;
    tileKey = key;
    const imgs = [];
    for (let x = tx(lonW); x <= tx(lonE) && imgs.length < 64; x++) {
      for (let y = ty(latN); y <= ty(latS) && imgs.length < 64; y++) {
        const [x1, y1] = toScreen(latOf(y), lonOf(x));
        const [x2, y2] = toScreen(latOf(y + 1), lonOf(x + 1));
        imgs.push(svg('image', { href: url.replace('{z}', z).replace('{x}', x).replace('{y}', y),
          x: x1.toFixed(1), y: y1.toFixed(1), width: (x2 - x1).toFixed(1), height: (y2 - y1).toFixed(1),
          preserveAspectRatio: 'none' }));
      }
    }
    layers.tiles.replaceChildren(...imgs);
  }

  function schedule() {
    if (!frame) frame = requestAnimationFrame(draw);
  }

  // Pan (one pointer), pinch (two), wheel zoom; a tap that does not move opens the boat.
  const pointers = new Map();
  let pinch = null;
  function zoomAt(factor, sx, sy) {
    if (!proj) return;
    const mx = view.cx + (sx - view.w / 2) / view.k;
    const my = view.cy - (sy - view.h / 2) / view.k;
    view.k = Math.max(1e-4, Math.min(200, view.k * factor));
    view.cx = mx - (sx - view.w / 2) / view.k;
    view.cy = my + (sy - view.h / 2) / view.k;
    setFollow(false);
    schedule();
  }
  const local = (e) => {
    const r = map.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  };
  map.addEventListener('pointerdown', (e) => {
    pointers.set(e.pointerId, { start: local(e), last: local(e), moved: false });
    if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      pinch = { d: Math.hypot(a.last[0] - b.last[0], a.last[1] - b.last[1]) };
    }
  });
  map.addEventListener('pointermove', (e) => {
    const p = pointers.get(e.pointerId);
    if (!p || !proj) return;
    const cur = local(e);
    if (!p.moved && Math.hypot(cur[0] - p.start[0], cur[1] - p.start[1]) > 6) {
      p.moved = true;
      map.setPointerCapture(e.pointerId);
    }
    if (!p.moved) return;
    if (pointers.size === 2 && pinch) {
      p.last = cur;
      const [a, b] = [...pointers.values()];
      const d = Math.hypot(a.last[0] - b.last[0], a.last[1] - b.last[1]);
      if (pinch.d > 0 && d > 0) zoomAt(d / pinch.d, (a.last[0] + b.last[0]) / 2, (a.last[1] + b.last[1]) / 2);
      pinch.d = d;
      return;
    }
    view.cx -= (cur[0] - p.last[0]) / view.k;
    view.cy += (cur[1] - p.last[1]) / view.k;
    p.last = cur;
    setFollow(false);
    schedule();
  });
  const up = (e) => {
    pointers.delete(e.pointerId);
    if (pointers.size < 2) pinch = null;
  };
  map.addEventListener('pointerup', up);
  map.addEventListener('pointercancel', up);
  map.addEventListener('wheel', (e) => {
    e.preventDefault();
    const [sx, sy] = local(e);
    zoomAt(Math.exp(-e.deltaY * 0.0015), sx, sy);
  }, { passive: false });
  fitBtn.addEventListener('click', () => setFollow(true));
  zoomIn.addEventListener('click', () => zoomAt(1.5, view.w / 2, view.h / 2));
  zoomOut.addEventListener('click', () => zoomAt(1 / 1.5, view.w / 2, view.h / 2));
  tileSave.addEventListener('click', () => {
    const v = tileInput.value.trim();
    if (v) localStorage.setItem(TILE_KEY, v);
    else localStorage.removeItem(TILE_KEY);
    tileKey = '-';
    schedule();
  });

  function onBoat(e) {
    addFix(e.detail);
    schedule();
  }
  live.addEventListener('boat', onBoat);
  for (const entry of live.boats.values()) addFix(entry.boat);
  const ro = new ResizeObserver(schedule);
  ro.observe(map);
  const slow = setInterval(schedule, 1000); // silent boats send nothing: grey them anyway
  schedule();

  return () => {
    live.removeEventListener('boat', onBoat);
    ro.disconnect();
    clearInterval(slow);
    if (frame) cancelAnimationFrame(frame);
  };
}
