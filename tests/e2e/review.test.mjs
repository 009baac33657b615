// Session review (needs the issue-7 endpoints: sessions, session attitude, export): charts
// for a recorded session, overlay of two boats, heel distribution, and the CSV / JSON export
// downloads that match the REST export row for row.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { after, before, test } from 'node:test';
import { join } from 'node:path';
import { artifacts, domainFor, eventually, login, screenshots, startBrowser, startFleet, stop } from './harness.mjs';

let fleet;
let browser;
let page;
let sessions;

before(async () => {
  fleet = await startFleet({ domain: domainFor(2), boats: ['ILCA-1', 'ILCA-2'] });
  browser = await startBrowser();
  page = await browser.page();
  // Record the launch and ~5 s of sailing, then stop the boats so the sessions are final (the
  // shore commits every 250 ms).
  await fleet.waitHeeled(['ILCA-1', 'ILCA-2']);
  await new Promise((r) => setTimeout(r, 5000));
  for (const c of fleet.boats.values()) await stop(c);
  await new Promise((r) => setTimeout(r, 1000));
  sessions = await fleet.json('/sessions');
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

const inkOf = (selector) => page.$eval(selector, (c) => {
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let ink = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i + 3] > 0 && (d[i] < 200 || d[i + 2] < 200)) ink++;
  return ink;
});

test('review: charts, heel distribution and bands for a recorded session', async () => {
  const s = sessions.find((x) => x.boat_id === 'ILCA-1');
  assert.ok(s && s.samples > 100, `a recorded session: ${JSON.stringify(sessions)}`);
  await login(page, fleet);
  await page.evaluate((id) => { location.hash = `#/review?boat=ILCA-1&session=${id}`; }, s.id);
  await page.waitForSelector('.chart[data-series="heel"] canvas', { timeout: 8000 });
  assert.ok((await inkOf('.chart[data-series="heel"] canvas')) > 500, 'heel chart drawn');
  assert.ok((await inkOf('.chart[data-series="pitch"] canvas')) > 500, 'pitch chart drawn');
  assert.ok((await page.$$('.histogram rect.bar')).length >= 2, 'heel histogram has bars');
  assert.ok((await page.$$('table.bands tbody tr')).length >= 3, 'time in heel bands');
  assert.equal(await page.inputValue('#review-session'), String(s.id));
  // The scrubber moves the readout through the session.
  await page.fill('#scrubber', String(Math.floor(s.duration_s / 2)));
  await page.dispatchEvent('#scrubber', 'input');
  assert.match(await page.textContent('.scrub-readout'), /heel [+−]\d+\.\d°/);
  // Drag across the middle of the heel chart: both charts zoom to that span; Reset zoom undoes it.
  const xScale = (series) => page.$eval(`.chart[data-series="${series}"]`, (b) => [b.uplot.scales.x.min, b.uplot.scales.x.max]);
  const full = await xScale('heel');
  const over = await page.$('.chart[data-series="heel"] .u-over');
  await over.scrollIntoViewIfNeeded(); // the scrubber sits below three charts now
  const box = await over.boundingBox();
  await page.mouse.move(box.x + box.width * 0.3, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width * 0.6, box.y + box.height / 2, { steps: 5 });
  await page.mouse.up();
  const zoomed = await xScale('heel');
  assert.ok(zoomed[1] - zoomed[0] < (full[1] - full[0]) * 0.5, `zoomed ${zoomed} from ${full}`);
  assert.deepEqual(await xScale('pitch'), zoomed, 'pitch chart follows');
  await page.click('#reset-zoom');
  assert.deepEqual(await xScale('heel'), full);
  // Nothing wider than the window (charts sized to their box, controls wrap on a phone).
  for (const width of [390, 1440]) {
    await page.setViewportSize({ width, height: 900 });
    await page.waitForTimeout(300);
    assert.ok((await page.evaluate(() => document.documentElement.scrollWidth)) <= width, `no horizontal scroll at ${width}`);
  }
  await screenshots(page, 'review');
});

test('review: two boats overlaid', async () => {
  const a = sessions.find((x) => x.boat_id === 'ILCA-1');
  const b = sessions.find((x) => x.boat_id === 'ILCA-2');
  await page.evaluate(([x, y]) => { location.hash = `#/review?boat=ILCA-1&session=${x}&vs=${y}`; }, [a.id, b.id]);
  await page.waitForSelector('.chart[data-series="heel"] canvas');
  const legend = await page.$$eval('.chart[data-series="heel"] .u-legend .u-series', (xs) => xs.map((x) => x.textContent));
  assert.equal(legend.length, 3, `time + two sessions: ${legend}`);
  assert.ok(legend.some((t) => t.includes('ILCA-2')));
  assert.match(await page.textContent('.review-body'), /aligned on clock time/);
  assert.ok((await page.$$('.histogram rect.s1')).length >= 1, 'second session in the histogram');
  await screenshots(page, 'review-overlay');
});

test('review: CSV and JSON export downloads match the REST export', async () => {
  const s = sessions.find((x) => x.boat_id === 'ILCA-1');
  await page.evaluate((id) => { location.hash = `#/review?boat=ILCA-1&session=${id}`; }, s.id);
  await page.waitForSelector('a.export[data-format="csv"]');
  const [csvDl] = await Promise.all([page.waitForEvent('download'), page.click('a.export[data-format="csv"]')]);
  const csv = readFileSync(await csvDl.path(), 'utf8');
  const rest = await fleet.rest(`/sessions/${s.id}/export?format=csv`);
  const lines = csv.trim().split('\n');
  assert.equal(lines[0], 'time_utc,t_s,seq,heel_deg,pitch_deg,heading_deg,heel_rate_deg_s,pitch_rate_deg_s,' +
    'yaw_rate_deg_s,accel_weight,quality,lat_deg,lon_deg,sog_m_s,cog_deg'); // the fix current at each sample
  assert.equal(lines.length - 1, s.samples, 'one row per stored sample');
  assert.equal(csv, rest, 'download equals the REST export');
  const [jsonDl] = await Promise.all([page.waitForEvent('download'), page.click('a.export[data-format="json"]')]);
  const json = JSON.parse(readFileSync(await jsonDl.path(), 'utf8'));
  assert.deepEqual(json, JSON.parse(await fleet.rest(`/sessions/${s.id}/export?format=json`)));
});

test('review: the track marker follows the scrubber; speed chart, distance, GPX', async () => {
  const s = sessions.find((x) => x.boat_id === 'ILCA-1');
  await page.evaluate((id) => { location.hash = `#/review?boat=ILCA-1&session=${id}`; }, s.id);
  await page.waitForSelector('#review-track .track-marker', { timeout: 8000 });
  assert.ok((await inkOf('.chart[data-series="sog"] canvas')) > 300, 'speed chart drawn');
  assert.ok((await page.$$('#review-track .track-seg')).length >= 1, 'track drawn');
  const detail = await fleet.json(`/sessions/${s.id}`);
  assert.equal(Number(await page.getAttribute('.gnss-summary', 'data-distance-m')), detail.gnss.distance_m);
  assert.match(await page.textContent('.gnss-summary'), /sailed · SOG mean \d+\.\d kn, max \d+\.\d kn/);
  // The track as the server gives it, projected with the drawing's own frame (origin and scale).
  const tr = await fleet.json(`/boats/ILCA-1/track?from=${detail.start_t_s}&to=${detail.end_t_s}&max_points=4000`);
  assert.ok(tr.points > 20, `track points: ${tr.points}`);
  const f = await page.$eval('#review-track', (m) => Object.fromEntries(['lat0', 'lon0', 'k', 'x0', 'y0'].map((k) => [k, Number(m.dataset[k])])));
  const R = 6371008.8 * Math.PI / 180;
  const expected = (t) => {
    let i = tr.t_s.findIndex((x) => x >= t);
    if (i < 0) i = tr.t_s.length - 1;
    const a = Math.max(0, i - 1);
    const w = i === a ? 0 : (t - tr.t_s[a]) / (tr.t_s[i] - tr.t_s[a]);
    const lat = tr.lat_deg[a] + w * (tr.lat_deg[i] - tr.lat_deg[a]);
    const lon = tr.lon_deg[a] + w * (tr.lon_deg[i] - tr.lon_deg[a]);
    return [f.x0 + (lon - f.lon0) * Math.cos(f.lat0 * Math.PI / 180) * R * f.k, f.y0 - (lat - f.lat0) * R * f.k];
  };
  const marker = () => page.$eval('#review-track .track-marker', (c) => [Number(c.getAttribute('cx')), Number(c.getAttribute('cy'))]);
  const seen = [];
  for (const frac of [0.2, 0.5, 0.85]) {
    const rel = Math.round(detail.duration_s * frac * 10) / 10;
    await page.fill('#scrubber', String(rel));
    await page.dispatchEvent('#scrubber', 'input');
    const got = await marker();
    const want = expected(detail.start_t_s + rel);
    assert.ok(Math.hypot(got[0] - want[0], got[1] - want[1]) < 0.5, `at ${rel} s marker ${got} vs track ${want}`);
    seen.push(got);
  }
  assert.ok(Math.hypot(seen[2][0] - seen[0][0], seen[2][1] - seen[0][1]) > 10, `marker moved: ${JSON.stringify(seen)}`);
  await page.setViewportSize({ width: 1440, height: 900 });
  await page.waitForTimeout(400);
  await page.screenshot({ path: join(artifacts, 'review-track-laptop.png'), fullPage: false });
  // GPX: the download is the server's GPX 1.1.
  const [dl] = await Promise.all([page.waitForEvent('download'), page.click('a.export[data-format="gpx"]')]);
  const gpx = readFileSync(await dl.path(), 'utf8');
  assert.match(gpx, /<gpx version="1.1"/);
  assert.equal(gpx, await fleet.rest(`/sessions/${s.id}/gpx`));
});

test('review: heel against speed, every band plus the other buckets adds up to the total', async () => {
  const s = sessions.find((x) => x.boat_id === 'ILCA-1');
  const rendered = () => page.evaluate(() => {
    const groups = Object.fromEntries([...document.querySelectorAll('.hs-group')].map((g) =>
      [g.dataset.group, [...g.querySelectorAll('td.hs-seconds')].map((td) => Number(td.dataset.seconds))]));
    const other = Object.fromEntries([...document.querySelectorAll('.hs-other td[data-bucket]')].map((td) =>
      [td.dataset.bucket, Number(td.dataset.seconds)]));
    const total = document.getElementById('hs-total');
    return { groups, other, total: Number(total.dataset.seconds), totalText: total.textContent,
      wind: document.querySelector('.hs-wind').textContent };
  });
  const check = async (rest) => {
    const r = await rendered();
    const bands = Object.values(r.groups).flat();
    const sum = bands.reduce((a, x) => a + x, 0) + Object.values(r.other).reduce((a, x) => a + x, 0);
    assert.ok(Math.abs(sum - r.total) < 1e-6, `bands ${sum} vs total ${r.total}: ${JSON.stringify(r)}`);
    assert.ok(Math.abs(r.total - rest.total_s) < 1e-6, `rendered total ${r.total} vs REST ${rest.total_s}`);
    assert.equal(r.totalText, `${rest.total_s.toFixed(1)} s`);
    // Each group's rows are the server's non-empty bands.
    for (const leg of ['upwind', 'downwind']) {
      for (const tack of ['port', 'starboard']) {
        assert.deepEqual(r.groups[`${leg}-${tack}`], rest[leg][tack].filter((b) => b.seconds > 0).map((b) => b.seconds), `${leg} ${tack}`);
      }
    }
    return { r, bands };
  };
  await page.waitForSelector('#hs-total', { timeout: 8000 });
  await check(await fleet.json(`/sessions/${s.id}/heel_speed`));
  // The coach enters the wind (the simulator's 255 deg): the boat's beat splits into upwind bands.
  await page.fill('#wind-from', '255');
  await page.click('#wind-apply');
  await eventually(async () => /entered/.test(await page.textContent('.hs-wind')), { what: 'entered wind shown' });
  await page.waitForSelector('.heel-speed:not([data-loading])');
  const { r } = await check(await fleet.json(`/sessions/${s.id}/heel_speed?wind_from_deg=255`));
  assert.match(r.wind, /Wind from 255° — entered/);
  const upwind = [...r.groups['upwind-port'], ...r.groups['upwind-starboard']].reduce((a, x) => a + x, 0);
  assert.ok(upwind > 3, `upwind time with the wind entered: ${upwind} s`);
  await page.locator('.heel-speed').screenshot({ path: join(artifacts, 'heel-speed-laptop.png') });
});

test('no console errors on the review pages', () => {
  assert.deepEqual(browser.problems, []);
});
