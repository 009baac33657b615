// Import view: log files dropped on the dashboard are uploaded with a progress bar, imported by
// the shore, and open as sessions in review; a cut file shows its error.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { artifacts, domainFor, eventually, login, screenshots, startBrowser, startFleet } from './harness.mjs';

let fleet;
let browser;
let page;

before(async () => {
  fleet = await startFleet({ domain: domainFor(5) });
  browser = await startBrowser();
  page = await browser.page();
});

after(async () => {
  await browser?.close();
  await fleet?.stop();
});

// An Atlas CSV (UTC offset +01:00) of `n` rows at 2 Hz, heeling to and fro, tacking once.
function atlasCsv(n, t0 = Date.UTC(2026, 10, 22, 10, 0, 0)) {
  const rows = ['timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim'];
  for (let i = 0; i < n; i++) {
    const local = new Date(t0 + i * 500 + 3600e3).toISOString().replace('Z', '+01:00');
    const cog = i < n / 2 ? 45 : 315;
    const a = (Math.min(i, n / 2) * 1.5e-5) / Math.SQRT2; // along the first leg, then the second
    const b = (Math.max(0, i - n / 2) * 1.5e-5) / Math.SQRT2;
    rows.push([local, (39.5 + a + b).toFixed(7), (2.5 + a - b).toFixed(7), '6.0',
      cog, cog + 2, (12 * Math.sin(i / 40) * (i < n / 2 ? 1 : -1)).toFixed(1), '6.0'].join(','));
  }
  return `${rows.join('\r\n')}\r\n`;
}

async function drop(files) {
  const dt = await page.evaluateHandle((list) => {
    const d = new DataTransfer();
    for (const f of list) d.items.add(new File([f.text], f.name, { type: 'text/csv' }));
    return d;
  }, files);
  await page.dispatchEvent('.drop-zone', 'dragenter', { dataTransfer: dt });
  await page.dispatchEvent('.drop-zone', 'drop', { dataTransfer: dt });
}

test('import view: dropped files upload with progress and open in review', async () => {
  await login(page, fleet, '#/import');
  await page.waitForSelector('.drop-zone');
  await page.fill('#import-boat', 'ILCA-4');
  await page.fill('#import-pitch', '6');
  const csv = atlasCsv(2400); // 20 minutes
  const cut = atlasCsv(50).slice(0, -25);
  await drop([{ name: 'race1.csv', text: csv }, { name: 'cut.csv', text: cut }]);
  const row = (name) => page.locator('.import-item', { has: page.locator('.import-name', { hasText: name }) });
  await eventually(async () => (await row('race1.csv').getAttribute('data-state')) === 'done',
    { timeoutMs: 15000, what: 'race1.csv imported' });
  await eventually(async () => (await row('cut.csv').getAttribute('data-state')) === 'failed',
    { timeoutMs: 15000, what: 'cut.csv refused' });
  assert.match(await row('race1.csv').locator('.import-status').textContent(), /vakaros_csv, 2400 points/);
  assert.match(await row('cut.csv').locator('.import-status').textContent(), /line 51/);
  assert.equal(Number(await row('race1.csv').locator('progress').getAttribute('value')), 1);
  await screenshots(page, 'import');

  // The same as the shore says, and the session reviews like a live one.
  const sessions = await fleet.json('/sessions?boat=ILCA-4');
  assert.equal(sessions.length, 1);
  assert.equal(sessions[0].samples, 2400);
  await row('race1.csv').locator('a').first().click();
  await page.waitForSelector('[data-view="review"]');
  await eventually(async () => (await page.locator('.review-body').count()) > 0, { timeoutMs: 10000, what: 'review' });
  await page.waitForTimeout(1500);
  await screenshots(page, 'import-review');
  assert.deepEqual(browser.problems, []);
});

// An NMEA log of a boat beating with a wind instrument: RMC at 1 Hz, tacking through 90 deg every
// 60 s on a wind from 200 deg, which its MWD states.
function beatNmea(legs = 6, t0 = Date.UTC(2026, 10, 22, 12, 0, 0)) {
  const sentence = (body) => {
    let sum = 0;
    for (const c of body) sum ^= c.charCodeAt(0);
    return `$${body}*${sum.toString(16).toUpperCase().padStart(2, '0')}\r\n`;
  };
  const dm = (deg, digits) => {
    const a = Math.abs(deg);
    const d = Math.floor(a);
    return `${String(d).padStart(digits, '0')}${((a - d) * 60).toFixed(5).padStart(8, '0')}`;
  };
  let lat = 39.45;
  let lon = -0.3;
  let out = '';
  for (let i = 0; i < legs * 60; i++) {
    const leg = Math.floor(i / 60);
    const from = leg % 2 ? 245 : 155;
    const to = leg % 2 ? 155 : 245;
    const s = i % 60;
    const cog = s >= 57 ? from + ((to - from) * (s - 56)) / 4 : from; // a 4 s tack
    const d = new Date(t0 + i * 1000);
    const hms = `${String(d.getUTCHours()).padStart(2, '0')}${String(d.getUTCMinutes()).padStart(2, '0')}${String(d.getUTCSeconds()).padStart(2, '0')}.00`;
    out += sentence(`GPRMC,${hms},A,${dm(lat, 2)},N,${dm(lon, 3)},W,5.83,${cog.toFixed(1)},221126,,,A`);
    out += sentence('WIMWD,200.0,T,,M,11.7,N,6.0,M');
    lat += (3.0 * Math.cos((cog * Math.PI) / 180)) / 111320;
    lon -= (3.0 * Math.sin((cog * Math.PI) / 180)) / (111320 * Math.cos((lat * Math.PI) / 180));
  }
  return out;
}

test('import view: a log with a wind instrument reviews with the instrument\'s wind', async () => {
  await login(page, fleet, '#/import');
  await page.waitForSelector('.drop-zone');
  await page.fill('#import-boat', 'ILCA-6');
  await drop([{ name: 'beat.nmea', text: beatNmea() }]);
  const row = page.locator('.import-item', { has: page.locator('.import-name', { hasText: 'beat.nmea' }) });
  await eventually(async () => (await row.getAttribute('data-state')) === 'done',
    { timeoutMs: 15000, what: 'beat.nmea imported' });
  const [session] = await fleet.json('/sessions?boat=ILCA-6');
  const rest = await fleet.json(`/sessions/${session.id}/manoeuvres`);
  assert.equal(rest.wind.source, 'instrument');
  assert.equal(rest.wind.from_deg, 200);
  assert.ok(rest.manoeuvres.filter((m) => m.kind === 'tack').length >= 4, JSON.stringify(rest.manoeuvres));
  await login(page, fleet, `#/review?boat=ILCA-6&session=${session.id}`);
  await page.waitForSelector('.manoeuvres[data-state="ready"]', { timeout: 10000 });
  const hint = await page.textContent('.manoeuvres p.hint');
  assert.match(hint, /Wind from 200° \(the boat's wind instrument, spread ±0°; the tacks say \d+° \([+−]\d+\.\d°\)\)/);
  assert.deepEqual(browser.problems, []);
});

test('import view: the progress bar moves while a file uploads', async () => {
  await login(page, fleet, '#/import');
  await page.waitForSelector('.drop-zone');
  await page.fill('#import-boat', 'ILCA-5');
  // A slow link (250 kB/s up), so the upload is seen under way: 8000 s at 2 Hz, ~1.3 MB.
  const cdp = await browser.context.newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.emulateNetworkConditions',
    { offline: false, latency: 0, downloadThroughput: -1, uploadThroughput: 250 * 1024 });
  await drop([{ name: 'long.csv', text: atlasCsv(16000) }]);
  const item = page.locator('.import-item', { has: page.locator('.import-name', { hasText: 'long.csv' }) });
  const values = [];
  await eventually(async () => {
    const v = Number(await item.locator('progress').getAttribute('value'));
    values.push(v);
    return v > 0.1 && v < 0.4;
  }, { timeoutMs: 15000, intervalMs: 50, what: 'the upload under way' });
  mkdirSync(artifacts, { recursive: true });
  await page.screenshot({ path: join(artifacts, 'import-progress-laptop.png') });
  await cdp.send('Network.emulateNetworkConditions',
    { offline: false, latency: 0, downloadThroughput: -1, uploadThroughput: -1 });
  await eventually(async () => (await item.getAttribute('data-state')) === 'done',
    { timeoutMs: 30000, what: 'long.csv imported' });
  // The bar only ever moved forward.
  assert.ok(values.every((v, i) => i === 0 || v >= values[i - 1]), `progress ${values}`);
  assert.deepEqual(browser.problems, []);
});
