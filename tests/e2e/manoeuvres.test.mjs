// Manoeuvres on the dashboard, against two simulated boats of one race whose seeds
// tack early (seed 10: ~28 s after the node starts, seed 328: ~25 s): the live fleet card shows
// the tack the shore pushes on the stream (no polling) within 30 s of its exit; in the review, a list row's time moves the scrubber to its
// t0, two tacks (one per boat) overlay aligned each at its own t0, and the boats are ranked by
// the shore's mean distance lost. The boats keep sailing: the review reads their live sessions.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { domainFor, eventually, login, screenshots, startBrowser, startFleet } from './harness.mjs';

const A = 'TACK-A';
const B = 'TACK-B';
const SEEDS = { [A]: '10', [B]: '328' };

let fleet;
let browser;
let page;

before(async () => {
  fleet = await startFleet({ domain: domainFor(6) });
  for (const id of [A, B]) await fleet.addBoat(id, ['--seed', SEEDS[id]]);
  browser = await startBrowser();
  page = await browser.page();
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

const sessionOf = async (boat) => (await fleet.json(`/sessions?boat=${boat}`))[0];
const secondsOf = (iso) => Date.parse(iso) / 1000;
// The session's first tack once its every metric is final (the data reaches t0 + 25 s).
async function finalTack(boat) {
  return eventually(async () => {
    const s = await sessionOf(boat);
    const r = await fleet.json(`/sessions/${s.id}/manoeuvres`);
    const m = r.manoeuvres.find((x) => x.kind === 'tack');
    return m && secondsOf(r.data_to_utc) >= secondsOf(m.t_utc) + 25 ? { s, m, r } : null;
  }, { timeoutMs: 90000, intervalMs: 1000, what: `a measured tack of ${boat}` });
}

test('review before any manoeuvre, and a failed fetch: one clear message each', async () => {
  await login(page, fleet);
  const s = await eventually(() => sessionOf(A), { what: 'a session' });
  await page.evaluate(([b, id]) => { location.hash = `#/review?boat=${b}&session=${id}`; }, [A, s.id]);
  await page.waitForSelector('.manoeuvres[data-state="ready"]', { timeout: 8000 });
  assert.match(await page.textContent('.manoeuvres p.empty'), /No manoeuvre found in this session/);
  assert.equal(await page.$$eval('tr.manoeuvre', (r) => r.length), 0);
  // The shore failing: a message in the panel, the rest of the review still there.
  await page.route('**/manoeuvres', (route) => route.fulfill({ status: 503, contentType: 'application/json',
    body: JSON.stringify({ error: 'shore busy' }) }));
  try {
    await page.evaluate(() => { location.hash = `${location.hash}&x=1`; });
    await page.waitForSelector('.manoeuvres[data-state="error"]', { timeout: 8000 });
    assert.match(await page.textContent('.manoeuvres .message'), /Cannot load the manoeuvres: shore busy/);
    assert.ok(await page.$('.chart[data-series="heel"] canvas'), 'charts still drawn');
  } finally {
    await page.unroute('**/manoeuvres');
  }
});

test('live: the fleet card shows the tack the stream pushes, its distance lost within 30 s of its exit, with no polling', async (t) => {
  // The shore's "manoeuvre" events, recorded on an EventSource of the page's own.
  await page.evaluate(() => {
    window.__manoeuvres = [];
    const es = new EventSource('/api/v1/stream');
    es.addEventListener('manoeuvre', (e) => window.__manoeuvres.push({ ...JSON.parse(e.data), at: Date.now() / 1000 }));
  });
  const asked = []; // the fleet view's REST calls for manoeuvres: one per boat when it opens
  const onRequest = (r) => { if (/\/manoeuvres(\?|$)/.test(new URL(r.url()).pathname + new URL(r.url()).search)) asked.push(Date.now() / 1000); };
  page.on('request', onRequest);
  await page.evaluate(() => { location.hash = '#/fleet'; });
  const openedAt = Date.now() / 1000;
  await page.waitForSelector(`.card[data-boat="${A}"]`, { timeout: 5000 });
  const row = `.card[data-boat="${A}"] .last-manoeuvre`;
  let shownAt = null;
  let measuring = false;
  const seen = await eventually(async () => {
    const d = await page.$eval(row, (r) => (r.hidden ? null : { ...r.dataset, text: r.textContent }));
    if (d && shownAt === null) shownAt = Date.now() / 1000;
    if (d?.final === 'false') measuring = true;
    return d?.final === 'true' ? { ...d, at: Date.now() / 1000 } : null;
  }, { timeoutMs: 80000, intervalMs: 250, what: `${A}'s card to show a measured manoeuvre` });
  page.off('request', onRequest);
  const { m } = await finalTack(A);
  const t0 = secondsOf(m.t_utc);
  assert.equal(seen.kind, 'tack');
  assert.ok(Math.abs(Number(seen.t0) - t0) < 0.01, `card t0 ${seen.t0} vs REST ${t0}`);
  // Driven by the stream: the card is the shore's final event of that tack, found first. This
  // page's second stream gets it on its own tick, which may come a little after the card's.
  let events = [];
  const fin = await eventually(async () => {
    events = (await page.evaluate(() => window.__manoeuvres)).filter((e) => e.boat_id === A);
    return events.find((e) => e.final && Math.abs(secondsOf(e.t_utc) - t0) < 12) ?? null;
  }, { timeoutMs: 5000, intervalMs: 100, what: `the final manoeuvre event for ${A} on the test's own stream` }).catch(() => null);
  assert.ok(fin, `a final manoeuvre event for ${A}: ${JSON.stringify(events)}`);
  assert.equal(fin.kind, seen.kind);
  assert.equal(secondsOf(fin.t_utc), Number(seen.t0), `card t0 ${seen.t0} vs event ${fin.t_utc}`);
  assert.equal(fin.distance_lost_m, Number(seen.lost));
  assert.ok(events.some((e) => !e.final && e.at <= fin.at), 'found (measuring) before final');
  assert.ok(measuring, 'the card said "measuring" before the distance lost was final');
  // No polling: at most the one call per boat when the view opened, none later.
  assert.ok(asked.length <= 2, `${asked.length} REST calls for manoeuvres`);
  assert.ok(asked.every((at) => at - openedAt < 5), `REST calls after the view opened: ${asked.map((a) => (a - openedAt).toFixed(1))}`);
  // Exit: the end of the turn (90 % of it done), half its 10-90 % duration after t0.
  const exit = t0 + m.turn_duration_s / 2;
  t.diagnostic(`tack shown ${(shownAt - exit).toFixed(1)} s, its distance lost ${(seen.at - exit).toFixed(1)} s after the exit`);
  assert.ok(shownAt - exit <= 30, `shown ${(shownAt - exit).toFixed(1)} s after the exit`);
  assert.ok(seen.at - exit <= 30, `distance lost shown ${(seen.at - exit).toFixed(1)} s after the exit`);
  assert.ok(Math.abs(Number(seen.lost) - m.distance_lost_m) < 0.05, `card ${seen.lost} m vs REST ${m.distance_lost_m} m`);
  assert.match(seen.text, /^LastTack\d+ s agolost -?\d+\.\d m$/i);
  await screenshots(page, 'manoeuvre-card');
});

test('review: the list is the shore\'s, and a row\'s time moves the scrubber to its t0', async () => {
  const { s, r } = await finalTack(A);
  await finalTack(B);
  const detail = await fleet.json(`/sessions/${s.id}`);
  await page.evaluate(([b, id]) => { location.hash = `#/review?boat=${b}&session=${id}`; }, [A, s.id]);
  await page.waitForSelector('.manoeuvres[data-state="ready"] tr.manoeuvre', { timeout: 8000 });
  const rows = await page.$$eval('tr.manoeuvre', (rs) => rs.map((x) => ({ ...x.dataset, lost: x.querySelector('.lost').textContent })));
  // The review loaded at least what the REST read above saw (the boat sails on).
  assert.ok(rows.length >= r.manoeuvres.length, `rows ${rows.length} vs REST ${r.manoeuvres.length}`);
  r.manoeuvres.forEach((m, i) => {
    assert.equal(rows[i].kind, m.kind);
    assert.ok(Math.abs(Number(rows[i].t0) - secondsOf(m.t_utc)) < 0.01, `row ${i} t0`);
  });
  assert.equal(await page.$$eval('#review-track .manoeuvre-mark', (g) => g.length), rows.length, 'one mark per manoeuvre on the track');
  const tack = rows.find((x) => x.kind === 'tack');
  const rel = Number(tack.t0) - detail.start_t_s;
  await page.fill('#scrubber', '3');
  await page.dispatchEvent('#scrubber', 'input');
  await page.click(`tr.manoeuvre[data-key="${tack.key}"] button.jump`);
  const scrub = Number(await page.inputValue('#scrubber'));
  assert.ok(Math.abs(scrub - rel) < 0.5, `scrubber at ${scrub} s, t0 at ${rel} s`);
  const marker = Number(await page.getAttribute('#review-track .track-marker', 'data-t'));
  assert.ok(Math.abs(marker - Number(tack.t0)) < 0.5, `track marker at ${marker}, t0 ${tack.t0}`);
});

test('review: two tacks of two boats overlaid, each aligned at its own t0', async () => {
  await page.selectOption('#manoeuvre-boats', 'all');
  // Both boats past t0 + 30 s (the overlay's end), so the page and this test read the same samples.
  const t0s = await page.$$eval('tr.manoeuvre[data-kind="tack"]', (rs) => rs.map((x) => Number(x.dataset.t0)));
  const wait = (Math.max(...t0s.slice(0, 2)) + 31.5) * 1000 - Date.now();
  if (wait > 0) await new Promise((r) => setTimeout(r, wait));
  const picks = [];
  for (const boat of [A, B]) {
    const key = await page.$eval(`tr.manoeuvre[data-boat="${boat}"][data-kind="tack"]`, (x) => x.dataset.key);
    await page.check(`tr.manoeuvre[data-key="${key}"] input.pick`);
    picks.push(key);
  }
  await page.waitForSelector('.manoeuvre-overlay[data-state="ready"][data-count="2"]', { timeout: 8000 });
  const charts = await page.$$eval('.manoeuvre-overlay .chart', (boxes) => boxes.map((b) => ({
    series: b.dataset.series, min: b.uplot.scales.x.min, max: b.uplot.scales.x.max,
    data: b.uplot.data.map((col) => Array.from(col)), manoeuvres: b.manoeuvres })));
  assert.deepEqual(charts.map((c) => c.series), ['overlay-heel', 'overlay-sog', 'overlay-rate']);
  const items = charts[0].manoeuvres;
  assert.deepEqual(items.map((x) => x.boat).sort(), [A, B], 'one tack of each boat (in time order)');
  assert.ok(Math.abs(items[0].t0 - items[1].t0) > 1, `two tacks at different times: ${items.map((x) => x.t0)}`);
  for (const c of charts) {
    assert.equal(c.min, -20, `${c.series} axis starts at -20 s`);
    assert.equal(c.max, 30, `${c.series} axis ends at +30 s`);
    assert.ok(c.data[0][0] >= -20 && c.data[0][0] < -19.8, `${c.series} first point at ${c.data[0][0]} s`);
  }
  // Each series is its boat's recorded samples with the time taken from its own t0.
  for (const [k, m] of items.entries()) {
    const range = `from=${(m.t0 - 21).toFixed(3)}&to=${(m.t0 + 31).toFixed(3)}&max_points=5000`;
    const att = await fleet.json(`/boats/${m.boat}/attitude?${range}`);
    const tr = await fleet.json(`/boats/${m.boat}/track?${range}`);
    for (const [c, src, col, scale] of [[charts[0], att, 'heel_deg', 1], [charts[1], tr, 'sog_m_s', 3600 / 1852]]) {
      const want = src.t_s.map((t, i) => [Math.round((t - m.t0) * 1000) / 1000, src[col][i] * scale])
        .filter(([x, y]) => x >= -20 && x <= 30 && Number.isFinite(y));
      const got = c.data[0].map((x, i) => [x, c.data[k + 1][i]]).filter(([, y]) => y !== null && y !== undefined);
      assert.equal(got.length, want.length, `${c.series} ${m.boat}: ${got.length} points vs ${want.length} recorded`);
      got.forEach(([x, y], i) => {
        assert.ok(Math.abs(x - want[i][0]) < 0.002, `${c.series} ${m.boat} point ${i}: x ${x} vs ${want[i][0]}`);
        assert.ok(Math.abs(y - want[i][1]) < 1e-6, `${c.series} ${m.boat} point ${i}: y ${y} vs ${want[i][1]}`);
      });
    }
    // Turn rate: the turn shows up around the series' own zero, in the turn's direction.
    const rate = charts[2].data[0].map((x, i) => [x, charts[2].data[k + 1][i]]).filter(([, y]) => Number.isFinite(y));
    const peak = rate.reduce((a, b) => (b[1] > a[1] ? b : a));
    assert.ok(peak[1] > 8 && Math.abs(peak[0]) < 5, `${m.boat} turn rate peak ${peak[1]} deg/s at ${peak[0]} s`);
  }
  await page.locator('.manoeuvre-overlay').scrollIntoViewIfNeeded();
  await screenshots(page, 'manoeuvres-overlay');
});

test('review: the race\'s boats ranked by the shore\'s mean distance lost per kind', async () => {
  const means = {};
  for (const boat of [A, B]) {
    const s = await sessionOf(boat);
    const r = await fleet.json(`/sessions/${s.id}/manoeuvres`);
    means[boat] = r.summary.find((k) => k.kind === 'tack').mean_distance_lost_m;
  }
  const shown = await page.$$eval('table.ranking[data-kind="tack"] tbody tr', (rs) => rs.map((x) => [x.dataset.boat, Number(x.dataset.mean)]));
  assert.equal(shown.length, 2);
  assert.deepEqual(shown.map(([b]) => b), [A, B].sort((x, y) => means[x] - means[y]), `order ${JSON.stringify(shown)} vs ${JSON.stringify(means)}`);
  // The page loaded its summaries a little earlier: the same tack (the boats' next is minutes away).
  for (const [boat, mean] of shown) assert.ok(Math.abs(mean - means[boat]) < 1e-9, `${boat}: ${mean} vs ${means[boat]}`);
});

test('no console errors on the manoeuvre pages (but the failure the first test made)', () => {
  assert.deepEqual(browser.problems.filter((p) => !/status of 503/.test(p)), []);
});
