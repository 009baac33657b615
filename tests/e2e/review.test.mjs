// Session review (needs the issue-7 endpoints: sessions, session attitude, export): charts
// for a recorded session, overlay of two boats, heel distribution, and the CSV / JSON export
// downloads that match the REST export row for row.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { after, before, test } from 'node:test';
import { domainFor, login, screenshots, startBrowser, startFleet, stop } from './harness.mjs';

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
    'yaw_rate_deg_s,accel_weight,quality');
  assert.equal(lines.length - 1, s.samples, 'one row per stored sample');
  assert.equal(csv, rest, 'download equals the REST export');
  const [jsonDl] = await Promise.all([page.waitForEvent('download'), page.click('a.export[data-format="json"]')]);
  const json = JSON.parse(readFileSync(await jsonDl.path(), 'utf8'));
  assert.deepEqual(json, JSON.parse(await fleet.rest(`/sessions/${s.id}/export?format=json`)));
});

test('no console errors on the review pages', () => {
  assert.deepEqual(browser.problems, []);
});
