// Alarms (needs the issue-7 endpoints: PUT /api/v1/alarms/rules, alarm_state from rules):
// a boat crossing a threshold shows as an alarm in the browser within 2 s; the coach edits
// the rules in the boat view.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { domainFor, eventually, login, screenshots, startBrowser, startFleet } from './harness.mjs';

let fleet;
let browser;
let page;

before(async () => {
  fleet = await startFleet({ domain: domainFor(1), boats: ['ILCA-1', 'ILCA-2'] });
  browser = await startBrowser();
  page = await browser.page();
  await fleet.rest('/alarms/rules', { method: 'PUT', body: '[]', headers: { 'Content-Type': 'application/json' } });
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

test('an alarm shows in the fleet view within 2 s of the boat crossing the threshold', async () => {
  await login(page, fleet);
  await page.waitForSelector('.card[data-boat="ILCA-1"]');
  await fleet.waitHeeled(['ILCA-1', 'ILCA-2']);
  // Record every live sample of ILCA-1 (own EventSource) and the moment the card turns red.
  await page.evaluate(() => {
    window.__samples = [];
    const es = new EventSource('/api/v1/stream');
    es.addEventListener('sample', (e) => {
      const b = JSON.parse(e.data);
      if (b.id === 'ILCA-1') window.__samples.push({ t_ms: b.t_utc_ns / 1e6, heel: b.heel_deg, recv_ms: Date.now() });
    });
    const card = document.querySelector('.card[data-boat="ILCA-1"]');
    new MutationObserver(() => {
      if (card.dataset.alarm === 'alarm' && !window.__alarmSeenMs) {
        window.__alarmSeenMs = Date.now();
        // The badge as drawn with the red card: the boat may fall back under the threshold (and
        // the card clear) before the test reads the page again.
        window.__alarmBadge = card.querySelector('.alarm-badge')?.textContent;
      }
    }).observe(card, { attributes: true, attributeFilter: ['data-alarm'] });
  });
  // Six seconds of sailing (waves and gusts move the heel by several degrees): the threshold goes
  // in the middle of |heel|, and the band [-thr, thr] holds on either tack.
  await page.evaluate(() => { window.__samples = []; });
  await page.waitForTimeout(6000);
  const heels = (await page.evaluate(() => window.__samples)).map((s) => Math.abs(s.heel));
  const lo = Math.min(...heels);
  const hi = Math.max(...heels);
  assert.ok(hi - lo > 1.5, `boat moves enough to cross a threshold: ${lo}..${hi}`);
  const threshold = (lo + hi) / 2;
  // Arm the rule while the boat is in band, so the alarm comes from a crossing.
  await eventually(async () => {
    const s = await page.evaluate(() => window.__samples.at(-1));
    return Math.abs(s.heel) < threshold - 0.3;
  }, { timeoutMs: 10000, intervalMs: 20, what: '|heel| below the threshold' });
  const rule = { id: 'ilca1-heel', scope: 'boat:ILCA-1', quantity: 'heel', min_deg: -threshold, max_deg: threshold,
    hold_s: 0, hysteresis_deg: 0.2, level: 'alarm', enabled: true };
  const armedMs = Date.now();
  await fleet.rest('/alarms/rules', { method: 'PUT', body: JSON.stringify([rule]), headers: { 'Content-Type': 'application/json' } });
  await page.waitForSelector('.card[data-boat="ILCA-1"][data-alarm="alarm"]', { timeout: 15000 });
  const { samples, seen } = await page.evaluate(() => ({ samples: window.__samples, seen: window.__alarmSeenMs }));
  const crossing = samples.find((s) => s.recv_ms >= armedMs && Math.abs(s.heel) > threshold);
  assert.ok(crossing, 'a sample above the threshold arrived');
  const latencyMs = seen - crossing.t_ms;
  console.log(`alarm latency: ${latencyMs.toFixed(0)} ms (threshold ${threshold.toFixed(1)} deg)`);
  assert.ok(seen >= armedMs, 'the alarm came after the rule was armed');
  assert.ok(latencyMs > -100 && latencyMs < 2000, `alarm visible ${latencyMs} ms after the crossing`);
  assert.equal(await page.evaluate(() => window.__alarmBadge), 'ALARM');
  assert.equal(await page.getAttribute('.card[data-boat="ILCA-2"]', 'data-alarm'), 'normal');
  await screenshots(page, 'fleet-alarm', 200);
});

test('boat view: the coach sees the rule, active alarms, and saves an edited rule set', async () => {
  await page.evaluate(() => { location.hash = '#/boat/ILCA-1'; });
  await page.waitForSelector('.rules-table tr.rule');
  assert.match(await page.textContent('.rules h2'), /coach/);
  assert.equal(await page.inputValue('.rules-table tr.rule [name="scope"]'), 'boat:ILCA-1');
  // The alarm from the fleet view may have cleared while this view loaded, and the boat sails on:
  // a bear-away or a lull can keep its |heel| under the first band for longer than a wait (the
  // sanitized suite failed so twice). So the band follows the boat as it sails now: the middle of
  // its |heel| over the last 6 s (the page still records the stream), re-armed until a crossing
  // raises the alarm.
  let raised = false;
  for (let attempt = 0; attempt < 4 && !raised; attempt += 1) {
    const recent = (await page.evaluate(() => window.__samples.filter((s) => s.recv_ms > Date.now() - 6000)))
      .map((s) => Math.abs(s.heel));
    if (recent.length > 10) {
      const thr = (Math.min(...recent) + Math.max(...recent)) / 2;
      const rule = { id: 'ilca1-heel', scope: 'boat:ILCA-1', quantity: 'heel', min_deg: -thr, max_deg: thr,
        hold_s: 0, hysteresis_deg: 0.2, level: 'alarm', enabled: true };
      await fleet.rest('/alarms/rules', { method: 'PUT', body: JSON.stringify([rule]), headers: { 'Content-Type': 'application/json' } });
    }
    raised = await page.waitForSelector('.alarms .event[data-level="alarm"]', { timeout: 15000 })
      .then(() => true, () => false);
  }
  assert.ok(raised, 'an active alarm shows in the boat view');
  await page.click('#add-fleet-rule');
  const last = '.rules-table tr.rule:last-child';
  await page.fill(`${last} [name="min_deg"]`, '-45');
  await page.fill(`${last} [name="max_deg"]`, '45');
  await page.selectOption(`${last} [name="level"]`, 'warn');
  await page.click('#save-rules');
  await page.waitForSelector('.rules .status[data-state="ok"]');
  const rules = await fleet.json('/alarms/rules');
  assert.equal(rules.length, 2);
  const fleetRule = rules.find((r) => r.scope === 'fleet');
  assert.deepEqual([fleetRule.min_deg, fleetRule.max_deg, fleetRule.level], [-45, 45, 'warn']);
  // A rule with min above max is refused in the page, the server's set is unchanged.
  await page.fill(`${last} [name="min_deg"]`, '50');
  await page.click('#save-rules');
  await page.waitForSelector('.rules .status[data-state="error"]');
  assert.equal((await fleet.json('/alarms/rules')).length, 2);
  await screenshots(page, 'boat-alarm-rules');
});

test('boat view: the coach acknowledges, then silences, a standing alarm', async () => {
  // A band no dinghy sails in (heel 80..90 deg): ILCA-2's alarm stands, on either tack, while
  // the coach acts on it.
  const rule = { id: 'ilca2-never', scope: 'boat:ILCA-2', quantity: 'heel', min_deg: 80, max_deg: 90, hold_s: 0,
    hysteresis_deg: 1, level: 'alarm', enabled: true };
  await fleet.rest('/alarms/rules', { method: 'PUT', body: JSON.stringify([rule]), headers: { 'Content-Type': 'application/json' } });
  await page.evaluate(() => { location.hash = '#/boat/ILCA-2'; });
  const item = '.alarms .event[data-level="alarm"]';
  await page.waitForSelector(`${item}[data-phase="raised"] .event-ack`, { timeout: 5000 });
  await page.waitForSelector('.card[data-boat="ILCA-2"][data-alarm="alarm"]', { timeout: 2000 });
  await page.click(`${item} .event-ack`);
  await page.waitForSelector(`${item}[data-phase="acknowledged"]`, { timeout: 5000 });
  const id = await page.getAttribute(item, 'data-event');
  await page.click(`${item} .event-silence`);
  await eventually(async () => {
    const ev = (await fleet.json('/alarms/events?boat=ILCA-2')).find((e) => String(e.id) === id);
    return ev && ev.phase === 'silenced' && ev.acknowledged_at;
  }, { what: 'the event acknowledged then silenced on the shore' });
  await screenshots(page, 'boat-alarm-ack', 200);
});

test('no console errors on the alarm pages', () => {
  assert.deepEqual(browser.problems, []);
});
