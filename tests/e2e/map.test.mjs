// Live fleet map against a sailing fleet (boat_node's simulated race course near Kiel): boats
// drawn where they are relative to each other (bearing and distance between every pair, from
// the REST positions, against the drawn pixels and the map's scale), course arrows, two-minute
// trails, a silent boat greyed, zoom/fit, a tap opens the boat; SOG on the fleet cards.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { domainFor, eventually, login, screenshots, startBrowser, startFleet, stop } from './harness.mjs';

// Ids whose simulated start positions are spread along the line (35-105 m apart): the start
// position is seeded by the id, and some ids start only metres apart.
const IDS = ['ILCA-5', 'ILCA-6', 'ILCA-7'];
let fleet;
let browser;
let page;

before(async () => {
  fleet = await startFleet({ domain: domainFor(4), boats: IDS });
  browser = await startBrowser();
  page = await browser.page();
  await eventually(async () => (await fleet.json('/boats')).filter((b) => Number.isFinite(b.lat_deg)).length === IDS.length,
    { timeoutMs: 15000, intervalMs: 250, what: 'every boat with a fix' });
  await new Promise((r) => setTimeout(r, 4000)); // a few seconds of track for the trails
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

// Great-circle initial bearing (deg) and haversine distance (m): independent of the page's
// equirectangular projection.
function bearingDistance(a, b) {
  const r = Math.PI / 180;
  const [p1, p2, dl] = [a.lat_deg * r, b.lat_deg * r, (b.lon_deg - a.lon_deg) * r];
  const y = Math.sin(dl) * Math.cos(p2);
  const x = Math.cos(p1) * Math.sin(p2) - Math.sin(p1) * Math.cos(p2) * Math.cos(dl);
  const brg = (Math.atan2(y, x) / r + 360) % 360;
  const h = Math.sin((p2 - p1) / 2) ** 2 + Math.cos(p1) * Math.cos(p2) * Math.sin(dl / 2) ** 2;
  return { brg, dist: 2 * 6371008.8 * Math.asin(Math.sqrt(h)) };
}
const angleDiff = (a, b) => Math.abs(((a - b + 540) % 360) - 180);

// The REST positions and the drawn ones, read in one tick of the page.
const snapshot = () => page.evaluate(async () => {
  const boats = await (await fetch('/api/v1/boats')).json();
  const map = document.getElementById('fleet-map');
  const drawn = Object.fromEntries([...map.querySelectorAll('.boat')].map((n) =>
    [n.dataset.boat, { x: Number(n.dataset.x), y: Number(n.dataset.y), course: Number(n.dataset.course), state: n.dataset.state }]));
  const bar = map.querySelector('.scale-bar').dataset;
  return { boats, drawn, pxPerM: Number(map.dataset.pxPerM), bar: { metres: Number(bar.metres), px: Number(bar.px) } };
});

test('map: every boat is drawn where it is relative to the others, north up, at the scale shown', async () => {
  await login(page, fleet, '#/map');
  await page.waitForSelector(`#fleet-map .boat[data-boat="${IDS[2]}"][data-x]`, { timeout: 8000 });
  await page.waitForTimeout(1500); // let the map settle on its fit
  const s = await snapshot();
  assert.ok(s.pxPerM > 0, `px per metre ${s.pxPerM}`);
  // The scale bar says what a metre is on screen.
  assert.ok(Math.abs(s.bar.px / s.bar.metres - s.pxPerM) < 1e-3 * s.pxPerM, `scale bar ${JSON.stringify(s.bar)} vs ${s.pxPerM}`);
  const rest = Object.fromEntries(s.boats.map((b) => [b.id, b]));
  let pairs = 0;
  for (let i = 0; i < IDS.length; i++) {
    for (let j = i + 1; j < IDS.length; j++) {
      const [a, b] = [IDS[i], IDS[j]];
      const want = bearingDistance(rest[a], rest[b]);
      const dx = s.drawn[b].x - s.drawn[a].x;
      const dy = -(s.drawn[b].y - s.drawn[a].y); // screen y grows south
      const gotBrg = (Math.atan2(dx, dy) * 180 / Math.PI + 360) % 360;
      const gotDist = Math.hypot(dx, dy) / s.pxPerM;
      const msg = `${a}->${b}: REST bearing ${want.brg.toFixed(1)} deg ${want.dist.toFixed(1)} m, drawn ${gotBrg.toFixed(1)} deg ${gotDist.toFixed(1)} m`;
      // The boats sail at ~3 m/s; REST and the drawn frame may be one 40 ms frame apart.
      assert.ok(Math.abs(gotDist - want.dist) < 0.03 * want.dist + 1.5, msg);
      if (want.dist > 15) {
        assert.ok(angleDiff(gotBrg, want.brg) < 3, msg);
        pairs++;
      }
    }
  }
  assert.ok(pairs >= 2, 'at least two pairs of boats far enough apart for a bearing');
  // Every boat on screen, each arrow along its course over ground.
  const box = await page.$eval('#fleet-map', (m) => [m.clientWidth, m.clientHeight]);
  for (const id of IDS) {
    const d = s.drawn[id];
    assert.ok(d.x >= 0 && d.x <= box[0] && d.y >= 0 && d.y <= box[1], `${id} on the map: ${JSON.stringify(d)} in ${box}`);
    assert.ok(angleDiff(d.course, rest[id].cog_deg) < 20, `${id} arrow ${d.course} vs COG ${rest[id].cog_deg}`);
    assert.equal(d.state, 'normal');
  }
});

test('map: trails reach back before the page opened (from /track), and grow', async () => {
  const trail = (id) => page.$eval(`#fleet-map .trail[data-boat="${id}"]`, (p) =>
    p.getAttribute('points').split(' ').filter(Boolean).map((xy) => xy.split(',').map(Number)));
  const pxPerM = Number(await page.getAttribute('#fleet-map', 'data-px-per-m'));
  for (const id of IDS) {
    const pts = await trail(id);
    assert.ok(pts.length > 10, `${id} trail has ${pts.length} points`);
    const len = pts.slice(1).reduce((a, p, i) => a + Math.hypot(p[0] - pts[i][0], p[1] - pts[i][1]), 0) / pxPerM;
    // >= 4 s of sailing before the page opened at >= 1.5 m/s.
    assert.ok(len > 6, `${id} trail ${len.toFixed(1)} m long`);
  }
  const n = (await trail('ILCA-5')).length;
  await eventually(async () => (await trail('ILCA-5')).length > n, { timeoutMs: 3000, what: 'trail to grow' });
});

test('map: zoom, fit and a silent boat greyed; screenshots', async () => {
  const k = async () => Number(await page.getAttribute('#fleet-map', 'data-px-per-m'));
  const before1 = await k();
  await page.click('#map-zoom-in');
  await eventually(async () => Math.abs((await k()) / before1 - 1.5) < 0.01, { what: 'zoomed in 1.5x' });
  assert.equal(await page.getAttribute('#map-fit', 'aria-pressed'), 'false', 'zooming stops following');
  await page.click('#map-fit');
  assert.equal(await page.getAttribute('#map-fit', 'aria-pressed'), 'true');
  await eventually(async () => Math.abs((await k()) / before1 - 1) < 0.3, { what: 'fit again' });
  await stop(fleet.boats.get('ILCA-7'));
  await page.waitForSelector('#fleet-map .boat[data-boat="ILCA-7"][data-state="stale"]', { timeout: 5000 });
  assert.equal(await page.getAttribute('#fleet-map .trail[data-boat="ILCA-7"]', 'data-state'), 'stale');
  assert.equal(await page.getAttribute('#fleet-map .boat[data-boat="ILCA-5"]', 'data-state'), 'normal');
  await screenshots(page, 'map', 1200);
});

test('map: clicking a boat opens it', async () => {
  await page.click('#fleet-map .boat[data-boat="ILCA-6"] .disc', { timeout: 5000 });
  await eventually(async () => (await page.evaluate(() => location.hash)) === '#/boat/ILCA-6', { what: 'boat view' });
  await page.waitForSelector('[data-view="boat"] .card[data-boat="ILCA-6"]');
});

test('fleet cards show SOG in knots and m/s', async () => {
  await page.evaluate(() => { location.hash = '#/fleet'; });
  await page.waitForSelector('.card[data-boat="ILCA-5"] .speed');
  await eventually(async () => /^\d+\.\d$/.test(await page.textContent('.card[data-boat="ILCA-5"] .speed')), { what: 'SOG on the card' });
  // Both read in one evaluation: the card writes them together on each live update, and two
  // separate reads can straddle one (failed so once in the sanitized suite: 5.8 kn vs 2.8 m/s,
  // the boat speeding up between the reads).
  const [knText, msText] = await page.evaluate(() => {
    const card = document.querySelector('.card[data-boat="ILCA-5"]');
    return [card.querySelector('.speed').textContent, card.querySelector('.speed-ms').textContent];
  });
  const kn = Number(knText);
  const ms = Number(msText.replace(' m/s', ''));
  const rest = (await fleet.json('/boats')).find((b) => b.id === 'ILCA-5');
  assert.ok(Math.abs(kn / 1.943844 - ms) < 0.1, `${kn} kn vs ${ms} m/s`);
  assert.ok(Math.abs(ms - rest.sog_m_s) < 1.0, `card ${ms} m/s vs REST ${rest.sog_m_s}`);
  assert.match(await page.textContent('.card[data-boat="ILCA-5"] .cog'), /^COG \d{3}°$/);
});

test('no console errors, failed or external requests on the map pages', () => {
  assert.deepEqual(browser.problems, []);
});
