// Browser-test harness: a REAL shore_server and REAL boat_node processes on their own DDS domain
// and a free HTTP port (loopback only), and Debian's chromium driven by playwright-core.
// Everything started here is stopped in `after` hooks and, as a last resort, on process exit.
import { spawn } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const here = dirname(fileURLToPath(import.meta.url));
export const root = resolve(here, '../..');
export const binDir = process.env.TELLTALE_BIN_DIR || join(root, 'build/bin');
export const artifacts = process.env.TELLTALE_E2E_ARTIFACTS || join(root, 'tests/artifacts');
const require = createRequire(join(root, 'web/package.json'));
const { chromium } = require('playwright-core');

const children = new Set();
process.on('exit', () => {
  for (const c of children) c.kill('SIGKILL');
});
for (const sig of ['SIGINT', 'SIGTERM']) {
  process.on(sig, () => {
    for (const c of children) c.kill('SIGKILL');
    process.exit(130);
  });
}

function start(cmd, args, readyPattern, timeoutMs = 15000) {
  const child = spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  children.add(child);
  let out = '';
  const ready = new Promise((resolveReady, reject) => {
    const timer = setTimeout(() => reject(new Error(`${cmd} not ready in ${timeoutMs} ms:\n${out}`)), timeoutMs);
    const onData = (d) => {
      out += d;
      const m = readyPattern.exec(out);
      if (m) {
        clearTimeout(timer);
        resolveReady(m);
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', (d) => { out += d; });
    child.on('error', (err) => {
      children.delete(child);
      clearTimeout(timer);
      reject(new Error(`${cmd}: ${err.message}`));
    });
    child.on('exit', (code) => {
      children.delete(child);
      clearTimeout(timer);
      reject(new Error(`${cmd} exited (${code}) before ready:\n${out}`));
    });
  });
  child.output = () => out;
  return { child, ready };
}

export async function stop(child, signal = 'SIGINT') {
  if (child.exitCode !== null || child.signalCode !== null) return;
  const exited = new Promise((r) => child.once('exit', r));
  child.kill(signal);
  const t = setTimeout(() => child.kill('SIGKILL'), 5000);
  await exited;
  clearTimeout(t);
  children.delete(child);
}

// A DDS domain in 150-199 for one test file: `slot` differs per file, the run's base is random
// so two runs on one machine (two worktrees, a demo) are unlikely to share a domain.
// TELLTALE_E2E_DOMAIN_BASE pins the base.
const domainBase = Number(process.env.TELLTALE_E2E_DOMAIN_BASE ?? Math.floor(Math.random() * 50));
export function domainFor(slot) {
  return 150 + ((domainBase + slot) % 50);
}

// A shore server plus boats on their own DDS domain and a free HTTP port.
export async function startFleet({ domain, boats = [] }) {
  const dir = mkdtempSync(join(tmpdir(), 'telltale-e2e-'));
  const token = `e2e-${Math.random().toString(36).slice(2)}`;
  const shore = start(join(binDir, 'shore_server'), ['--domain', String(domain), '--http-port', '0',
    '--db', join(dir, 'fleet.db'), '--coach-token', token, '--web-dir', join(root, 'web')],
  /shore_server ready: (http:\/\/127\.0\.0\.1:\d+\/)/);
  const url = (await shore.ready)[1];
  const fleet = {
    url, token, dir, domain, shore: shore.child, boats: new Map(),
    async addBoat(id, extra = [], key = id) {
      // The boat's session log goes to the run's temp dir, not the current directory (unless
      // `extra` names one).
      const log = extra.includes('--log-dir') ? [] : ['--log-dir', join(dir, 'boat_log')];
      const b = start(join(binDir, 'boat_node'), ['--domain', String(domain), '--boat-id', id,
        ...log, ...extra],
        /boat_node ready/);
      await b.ready;
      this.boats.set(key, b.child);
      return b.child;
    },
    async addAthlete(id, extra = []) {
      const w = start(join(binDir, 'wearable_node'), ['--domain', String(domain), '--athlete-id', id, ...extra],
        /wearable_node ready/);
      await w.ready;
      this.boats.set(`athlete:${id}`, w.child);
      return w.child;
    },
    async rest(path, init = {}) {
      const res = await fetch(`${url}api/v1${path}`, {
        ...init, headers: { Authorization: `Bearer ${token}`, ...(init.headers ?? {}) } });
      const text = await res.text();
      if (!res.ok) throw new Error(`${init.method ?? 'GET'} ${path}: ${res.status} ${text}`);
      return text;
    },
    async json(path, init) {
      return JSON.parse(await this.rest(path, init));
    },
    // The simulated dinghy sits level for ~10 s after its node starts, then bears away and heels
    // (boat_node's default `sim` source). Tests that need a heeled boat wait for it here.
    async waitHeeled(ids, minDeg = 5, timeoutMs = 30000) {
      await eventually(async () => {
        const boats = await this.json('/boats');
        return ids.every((id) => Math.abs(boats.find((b) => b.id === id)?.heel_deg ?? 0) > minDeg);
      }, { timeoutMs, intervalMs: 250, what: `${ids} heeled beyond ${minDeg} deg` });
    },
    async stop() {
      await Promise.all([...this.boats.values()].map((c) => stop(c)));
      await stop(this.shore);
      rmSync(dir, { recursive: true, force: true });
    },
  };
  try {
    for (const id of boats) await fleet.addBoat(id);
  } catch (err) {
    await fleet.stop();
    throw err;
  }
  return fleet;
}

export const CHROMIUM_ARGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync'];

// A fresh chromium profile; every page records console errors, page errors, failed requests
// and any request that would leave the loopback interface (those are blocked).
export async function startBrowser() {
  const profile = mkdtempSync(join(tmpdir(), 'telltale-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.TELLTALE_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: CHROMIUM_ARGS,
    viewport: { width: 1440, height: 900 },
    acceptDownloads: true,
  });
  const problems = [];
  await context.route('**/*', (route) => {
    const u = new URL(route.request().url());
    if (u.protocol === 'data:' || u.hostname === '127.0.0.1') return route.continue();
    problems.push(`external request blocked: ${u.href}`);
    return route.abort();
  });
  const watch = (page) => {
    page.on('console', (m) => { if (m.type() === 'error') problems.push(`console error: ${m.text()}`); });
    page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    page.on('requestfailed', (r) => {
      // An EventSource torn down by a navigation is not a failure of the page.
      if (!r.url().includes('/api/v1/stream')) problems.push(`request failed: ${r.url()} ${r.failure()?.errorText}`);
    });
  };
  context.on('page', watch);
  context.pages().forEach(watch);
  return {
    context,
    problems,
    async page() {
      return context.pages()[0] ?? context.newPage();
    },
    async close() {
      await context.close().catch(() => {});
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

export const SIZES = { phone: { width: 390, height: 844 }, laptop: { width: 1440, height: 900 } };

// Screenshots of the current view at phone and laptop sizes: tests/artifacts/<name>-<size>.png.
export async function screenshots(page, name, settleMs = 600) {
  mkdirSync(artifacts, { recursive: true });
  const files = [];
  for (const [size, vp] of Object.entries(SIZES)) {
    await page.setViewportSize(vp);
    await page.waitForTimeout(settleMs);
    // Every view fits the width of a phone and a laptop: no sideways scrolling.
    const scrollWidth = await page.evaluate(() => document.documentElement.scrollWidth);
    if (scrollWidth > vp.width) throw new Error(`${name}: page is ${scrollWidth} px wide at ${size} (${vp.width} px)`);
    const file = join(artifacts, `${name}-${size}.png`);
    await page.screenshot({ path: file, fullPage: true });
    files.push(file);
  }
  await page.setViewportSize(SIZES.laptop);
  return files;
}

export async function login(page, fleet, hash = '#/fleet') {
  await page.goto(`${fleet.url}#token=${fleet.token}`);
  await page.waitForSelector('#connection[data-state="live"]', { timeout: 10000 });
  if (hash !== '#/fleet') await page.evaluate((h) => { location.hash = h; }, hash);
}

export async function eventually(fn, { timeoutMs = 5000, intervalMs = 100, what = 'condition' } = {}) {
  const end = Date.now() + timeoutMs;
  let last;
  while (Date.now() < end) {
    try {
      const v = await fn();
      if (v) return v;
    } catch (err) {
      last = err;
    }
    await new Promise((r) => setTimeout(r, intervalMs));
  }
  throw new Error(`timed out waiting for ${what}${last ? `: ${last.message}` : ''}`);
}
