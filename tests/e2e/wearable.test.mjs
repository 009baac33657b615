// Wearable view against a real wearable_node (simulated walker): steps, cadence, gait, pose and
// the dead-reckoned track appear and move on.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { domainFor, eventually, login, screenshots, startBrowser, startFleet } from './harness.mjs';

let fleet;
let browser;
let page;

before(async () => {
  fleet = await startFleet({ domain: domainFor(3) });
  await fleet.addAthlete('RUN-1');
  browser = await startBrowser();
  page = await browser.page();
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

const card = '.card.athlete[data-athlete="RUN-1"]';
const num = async (k) => Number(await page.textContent(`${card} .${k}`));

test('wearable view: steps, cadence, gait, pose and a growing track', async () => {
  await login(page, fleet, '#/wearables');
  await page.waitForSelector(card, { timeout: 8000 });
  await eventually(async () => Number.isFinite(await num('steps')), { what: 'a step count' });
  const steps0 = await num('steps');
  await eventually(async () => (await num('steps')) > steps0, { timeoutMs: 6000, what: 'steps to increase' });
  // Cadence needs a few steps to be estimated; then it is a walking or running pace.
  await eventually(async () => (await num('cadence')) > 0, { timeoutMs: 6000, what: 'a cadence' });
  const cadence = await num('cadence');
  assert.ok(cadence > 30 && cadence < 250, `cadence ${cadence} spm`);
  assert.notEqual(await page.textContent(`${card} .gait`), '–');
  assert.notEqual(await page.textContent(`${card} .pose`), '–');
  // The same figures as the REST view of the athlete (the walker moves on in between).
  const rest = (await fleet.json('/athletes')).find((a) => a.id === 'RUN-1');
  assert.ok(Math.abs(rest.steps - (await num('steps'))) < 10, `REST ${rest.steps} vs page`);
  const points = async () => (await page.getAttribute(`${card} .track-line`, 'points')).split(' ').filter(Boolean);
  await eventually(async () => (await points()).length > 5, { timeoutMs: 6000, what: 'track points' });
  const before1 = (await points()).at(-1);
  await eventually(async () => (await points()).at(-1) !== before1, { timeoutMs: 6000, what: 'the track to grow' });
  await screenshots(page, 'wearables-live');
});

test('no console errors on the wearable page', () => {
  assert.deepEqual(browser.problems, []);
});
