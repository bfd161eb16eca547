// End-to-end tests of the viewer in headless Chromium (software WebGL) against `pmc serve`.
//
//   npm run e2e                      (builds viewer/dist first)
//
// Environment:
//   PMC_BIN         the pmc binary (relative to the working directory; default target/release/pmc
//                   of the repository)
//   CHROMIUM        the browser (default /usr/bin/chromium)
//   PMC_E2E_MOCK=1  use e2e/mockServer.mjs (planets exported by `pmc generate`) instead of
//                   `pmc serve`, for working on the viewer before the server exists
//   PMC_E2E_ONLY=9,10  run only the steps with these numbers (those that stand alone), while
//                   working on them
//   PMC_E2E_DIRECT=1  load the page from `pmc serve` itself even when its embedded viewer is
//                   older than viewer/dist (by default such a binary's API is used behind a small
//                   front server that serves the fresh viewer/dist)
//
// Screenshots go to e2e/artifacts/. Exits non-zero with a message when a test fails; the server
// and the browser are stopped in every case.

import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createServer, request as httpRequest } from 'node:http';
import { tmpdir } from 'node:os';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { backgroundOf, colourCount, crop, decodePng, fractionDifferent, fractionNot } from './images.mjs';
import { flaggedPixels, lodFlight } from './lodFlight.mjs';
import { startMockServer } from './mockServer.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const viewerDir = resolve(here, '..');
const distDir = join(viewerDir, 'dist');
const artifacts = join(here, 'artifacts');
// PMC_BIN is relative to the working directory; the default to the repository's target/
const PMC_BIN = process.env.PMC_BIN ? resolve(process.env.PMC_BIN) : resolve(viewerDir, '../target/release/pmc');
const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
const USE_MOCK = process.env.PMC_E2E_MOCK === '1';
const LAYOUT = { n_c: 4, n_t: 16 };
const VIEWPORT = { width: 1024, height: 640 };
const READY_MS = 240_000;
/** The headless Chromium of every test: software WebGL, nothing from outside. */
const CHROMIUM_ARGS = [
  '--no-sandbox',
  '--disable-gpu',
  '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--no-first-run',
  '--disable-quic',
];
const TOTAL_MS = 20 * 60_000;

const started = Date.now();
const log = (msg) => console.log(`[e2e ${((Date.now() - started) / 1000).toFixed(1)}s] ${msg}`);
const cleanups = [];
let exiting = false;

async function cleanup() {
  while (cleanups.length > 0) {
    const fn = cleanups.pop();
    try {
      await fn();
    } catch (e) {
      console.error(`cleanup: ${e?.message ?? e}`);
    }
  }
}

async function fail(message) {
  if (exiting) return;
  exiting = true;
  console.error(`\nE2E FAILED: ${message}`);
  await cleanup();
  process.exit(1);
}

const watchdog = setTimeout(() => void fail(`the whole run took longer than ${TOTAL_MS / 60000} minutes`), TOTAL_MS);
for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => void fail(`interrupted (${sig})`));

function withTimeout(promise, ms, what) {
  let timer;
  return Promise.race([
    promise.finally(() => clearTimeout(timer)),
    new Promise((_, reject) => {
      timer = setTimeout(() => reject(new Error(`${what}: no answer within ${ms / 1000} s`)), ms);
    }),
  ]);
}

async function fetchText(url, ms = 5000) {
  const res = await withTimeout(fetch(url), ms, `GET ${url}`);
  return { status: res.status, text: await res.text() };
}

async function run(cmd, args, ms) {
  return withTimeout(
    new Promise((res) => {
      const p = spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
      let out = '';
      p.stdout.on('data', (d) => (out += d));
      p.stderr.on('data', (d) => (out += d));
      p.on('error', (e) => res({ code: -1, out: String(e) }));
      p.on('close', (code) => res({ code, out }));
    }),
    ms,
    `${cmd} ${args.join(' ')}`,
  );
}

/**
 * Starts `pmc serve --port 0` with `layout` (null: the default layout) and, when given, `world`
 * (a world file: editing on); reads the port from its "PMC viewer: URL" line. Returns its base URL
 * and a `stop()` (also run at the end).
 */
async function startPmcServe(layout, { world = null, extra = [] } = {}) {
  if (!existsSync(PMC_BIN)) {
    throw new Error(`no pmc binary at ${PMC_BIN}: build it (cargo build --release --bin pmc) or set PMC_BIN`);
  }
  const help = await run(PMC_BIN, ['serve', '--help'], 20_000);
  if (help.code !== 0) {
    throw new Error(
      `${PMC_BIN} has no working \`serve\` command (exit ${help.code}): ${help.out.trim().split('\n')[0]}\n` +
        'Rebuild pmc with the server, or run the tests against the mock with PMC_E2E_MOCK=1.',
    );
  }
  for (const flag of ['--port', '--n-c', '--n-t', ...(world ? ['--world'] : [])]) {
    if (!help.out.includes(flag)) {
      throw new Error(
        `\`pmc serve --help\` does not list ${flag}` +
          (flag === '--world' ? ': this pmc has no editing API; rebuild it (cargo build --release -p pmc-cli)' : ''),
      );
    }
  }
  const args = ['serve', '--port', '0'];
  if (layout) args.push('--n-c', String(layout.n_c), '--n-t', String(layout.n_t));
  if (world) args.push('--world', world);
  args.push(...extra);
  log(`starting ${PMC_BIN} ${args.join(' ')}`);
  const child = spawn(PMC_BIN, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  child.stdout.on('data', (d) => (output += d));
  child.stderr.on('data', (d) => (output += d));
  let exited = null;
  child.on('exit', (code, signal) => (exited = { code, signal }));
  const stop = async () => {
    if (exited) return;
    child.kill('SIGTERM');
    const t = setTimeout(() => child.kill('SIGKILL'), 3000);
    await new Promise((r) => (exited ? r() : child.once('exit', r)));
    clearTimeout(t);
    log(`pmc serve stopped${world ? ` (world ${world})` : ''}`);
  };
  cleanups.push(stop);
  const deadline = Date.now() + 60_000;
  let base = null;
  for (;;) {
    if (exited) throw new Error(`pmc serve exited (${JSON.stringify(exited)}):\n${output}`);
    if (!base) {
      const m = /PMC viewer: (http:\/\/\S+)/.exec(output);
      if (m) base = m[1].endsWith('/') ? m[1] : `${m[1]}/`;
    }
    if (base) {
      try {
        const h = await fetchText(`${base}api/v1/health`, 2000);
        if (h.status === 200 && JSON.parse(h.text).ok === true) break;
      } catch {
        // not listening yet
      }
    }
    if (Date.now() > deadline) {
      throw new Error(`pmc serve did not ${base ? 'answer /api/v1/health' : 'print its "PMC viewer: URL" line'} within 60 s:\n${output}`);
    }
    await new Promise((r) => setTimeout(r, 200));
  }
  return { base, stop };
}

const MIME = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.png': 'image/png', '.svg': 'image/svg+xml', '.json': 'application/json' };

/** Serves viewer/dist and passes /api/ on to `apiBase`: tests the fresh viewer against the real API. */
async function startFront(apiBase) {
  const api = new URL(apiBase);
  const server = createServer((req, res) => {
    if (req.url.startsWith('/api/')) {
      const upstream = httpRequest(
        { host: api.hostname, port: api.port, path: req.url, method: req.method, headers: { ...req.headers, host: api.host } },
        (up) => {
          res.writeHead(up.statusCode, up.headers);
          up.pipe(res);
        },
      );
      upstream.on('error', (e) => {
        res.writeHead(502, { 'content-type': 'application/json' });
        res.end(JSON.stringify({ error: `front: ${e.message}` }));
      });
      req.pipe(upstream);
      return;
    }
    let rel = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    if (rel === '/') rel = '/index.html';
    const file = normalize(join(distDir, rel));
    if (!file.startsWith(distDir + sep) || !existsSync(file)) {
      res.writeHead(404, { 'content-type': 'text/plain' });
      res.end('not found');
      return;
    }
    res.writeHead(200, { 'content-type': MIME[extname(file)] ?? 'application/octet-stream' });
    res.end(readFileSync(file));
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  let closed = false;
  const stop = () =>
    new Promise((r) => {
      if (closed) return r();
      closed = true;
      server.closeAllConnections?.();
      server.close(() => r());
    });
  cleanups.push(stop);
  return { url: `http://127.0.0.1:${server.address().port}/`, stop };
}

/**
 * Starts a server for `layout` (null: the default layout), editing `world` when given. Returns the
 * URL to load the page from (`url`), the server's own (`api`) and `stop()`.
 */
async function startBackend(layout, { world = null, extra = [] } = {}) {
  const what = layout ? `n_c ${layout.n_c}, n_t ${layout.n_t}` : 'the default layout';
  if (USE_MOCK) {
    if (world) throw new Error('the mock server has no editing API');
    log(`starting the mock server (${what}; planets from ${PMC_BIN} generate)`);
    const mock = await startMockServer({ pmcBin: PMC_BIN, layout: layout ?? { n_c: 8, n_t: 32 }, distDir });
    cleanups.push(() => mock.close());
    return { url: mock.url, api: mock.url, stop: async () => undefined };
  }
  const pmc = await startPmcServe(layout, { world, extra });
  const embedded = await fetchText(pmc.base);
  const fresh = readFileSync(join(distDir, 'index.html'), 'utf8');
  if (embedded.text === fresh || process.env.PMC_E2E_DIRECT === '1') {
    log(`testing the viewer embedded in pmc (${embedded.text === fresh ? 'same build as viewer/dist' : 'PMC_E2E_DIRECT=1'})`);
    return { url: pmc.base, api: pmc.base, stop: pmc.stop };
  }
  log('the viewer embedded in pmc differs from viewer/dist (rebuild pmc to embed it): serving viewer/dist in front of the real API');
  const front = await startFront(pmc.base);
  return {
    url: front.url,
    api: pmc.base,
    stop: async () => {
      await front.stop();
      await pmc.stop();
    },
  };
}

// ---- geometry for choosing views (same conventions as src/frames.ts) -------------------------

const DEG = Math.PI / 180;
const dirOf = (lat, lon) => [Math.cos(lat * DEG) * Math.sin(lon * DEG), Math.sin(lat * DEG), Math.cos(lat * DEG) * Math.cos(lon * DEG)];
/** Heading and pitch (degrees) from the camera at (lat, lon, radius) toward a target point. */
function headingPitchToward(lat, lon, radius, target) {
  const up = dirOf(lat, lon);
  const c = up.map((x) => x * radius);
  const f = target.map((x, i) => x - c[i]);
  const len = Math.hypot(...f);
  const east = [Math.cos(lon * DEG), 0, -Math.sin(lon * DEG)];
  const north = [up[1] * east[2] - up[2] * east[1], up[2] * east[0] - up[0] * east[2], up[0] * east[1] - up[1] * east[0]];
  const d = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return { heading: Math.atan2(d(f, east), d(f, north)) / DEG, pitch: Math.asin(d(f, up) / len) / DEG };
}
/** Latitude and longitude (degrees) of a planet-frame point. */
const latLonOf = (p) => ({ lat: Math.atan2(p[1], Math.hypot(p[0], p[2])) / DEG, lon: Math.atan2(p[0], p[2]) / DEG });
const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);

// ---- the navigation overlay in pictures ----------------------------------------------------

/** The path's colour (src/navOverlay.ts PATH_COLOUR). */
const PATH_HEX = '#ff29b8';
/** Pixels within `tolerance` (sum over the channels) of colour `hex`. */
function colourPixels(img, hex, tolerance = 30) {
  const c = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    if (Math.abs(img.data[i] - c[0]) + Math.abs(img.data[i + 1] - c[1]) + Math.abs(img.data[i + 2] - c[2]) <= tolerance) n++;
  }
  return n;
}
/** Whether some pixel of the 3 × 3 around (x, y) differs between `a` and `b` (sum over channels > 40). */
function pixelChanged(a, b, x, y) {
  for (let dy = -1; dy <= 1; dy++) {
    for (let dx = -1; dx <= 1; dx++) {
      const i = 4 * ((y + dy) * a.width + (x + dx));
      if (Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2]) > 40) return true;
    }
  }
  return false;
}
/**
 * A detached component of a `/navgrid` answer seen from above: all its nodes in the answer, each
 * the highest node of its column (no cave pocket, nothing over it). The one with the most nodes
 * (the nearest of equals): `{label, nodes, centre, alt (its highest node, metres above `datum`),
 * distance}`, or null.
 */
function detachedFromAbove(a, datum) {
  const n = a.components.length;
  const pts = Array.from({ length: n }, (_, i) => [0, 1, 2].map((k) => a.origin[k] + a.positions[3 * i + k]));
  const top = new Map(); // column (direction) -> highest node
  for (let i = 0; i < n; i++) {
    const r = Math.hypot(...pts[i]);
    const key = pts[i].map((x) => (x / r).toFixed(7)).join(',');
    const j = top.get(key);
    if (j === undefined || r > Math.hypot(...pts[j])) top.set(key, i);
  }
  const isTop = new Set(top.values());
  const byLabel = new Map();
  for (let i = 0; i < n; i++) {
    if (2 * a.component_sizes[i] >= a.total_nodes) continue; // the main grid
    const l = byLabel.get(a.components[i]) ?? [];
    l.push(i);
    byLabel.set(a.components[i], l);
  }
  let best = null;
  for (const [label, idx] of byLabel) {
    if (idx.length !== a.component_sizes[idx[0]] || !idx.every((i) => isTop.has(i))) continue;
    const centre = [0, 1, 2].map((k) => idx.reduce((s, i) => s + pts[i][k], 0) / idx.length);
    const d = distance(centre, a.origin);
    if (!best || idx.length > best.nodes || (idx.length === best.nodes && d < best.distance)) {
      best = { label, nodes: idx.length, centre, distance: d, alt: Math.max(...idx.map((i) => Math.hypot(...pts[i]))) - datum };
    }
  }
  return best;
}

// ---- the tests --------------------------------------------------------------------------------

const results = [];
/** PMC_E2E_ONLY: a comma-separated list of step numbers to run alone, while working on them. */
const ONLY = process.env.PMC_E2E_ONLY ? new Set(process.env.PMC_E2E_ONLY.split(',').map((x) => x.trim())) : null;
async function step(name, fn) {
  if (ONLY && !ONLY.has(name.split('.')[0])) return;
  const t0 = Date.now();
  log(`▶ ${name}`);
  try {
    await fn();
    results.push({ name, ok: true, s: (Date.now() - t0) / 1000 });
    log(`✔ ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
  } catch (e) {
    results.push({ name, ok: false, s: (Date.now() - t0) / 1000, error: short(e) });
    log(`✘ ${name}: ${short(e)}`);
    throw new Error(`${name}: ${short(e)}`);
  }
}

/** An error's message without the browser log Playwright appends to it. */
function short(e) {
  const m = String(e?.message ?? e);
  const cut = m.search(/\n(Browser logs:|=+ logs =+|Call log:)/);
  return (cut >= 0 ? m.slice(0, cut) : m).slice(0, 2000);
}

function check(cond, message) {
  if (!cond) throw new Error(message);
}

async function main() {
  if (!existsSync(join(distDir, 'index.html'))) throw new Error('viewer/dist is missing: run `npm run build` first');
  if (!existsSync(CHROMIUM)) throw new Error(`no browser at ${CHROMIUM} (install Debian's chromium or set CHROMIUM)`);
  mkdirSync(artifacts, { recursive: true });

  const pageBase = (await startBackend(LAYOUT)).url;

  const profile = mkdtempSync(join(tmpdir(), 'pmc-e2e-chromium-'));
  cleanups.push(() => rmSync(profile, { recursive: true, force: true }));
  log(`launching ${CHROMIUM}`);
  const context = await withTimeout(
    chromium.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      headless: true,
      viewport: VIEWPORT,
      deviceScaleFactor: 1,
      args: CHROMIUM_ARGS,
    }),
    60_000,
    'launching Chromium',
  );
  cleanups.push(() => context.close());
  const page = context.pages()[0] ?? (await context.newPage());
  page.setDefaultTimeout(60_000);

  const consoleProblems = [];
  /** URLs whose failure a test provokes on purpose. */
  const expectedFailures = [];
  // Chromium's software compositor reads the WebGL canvas back to composite it, and the GL driver
  // says so as a console warning; it comes from the browser set-up, not from the page.
  const environmental = /GL Driver Message \(OpenGL, Performance, .*\): GPU stall due to ReadPixels/;
  const failedResponses = [];
  /** Collects console errors and warnings, uncaught errors and failed responses of `p`. */
  const watchPage = (p, label = '') => {
    const tag = label ? `[${label}] ` : '';
    p.on('console', (m) => {
      if (m.type() !== 'error' && m.type() !== 'warning') return;
      if (environmental.test(m.text())) return;
      if (expectedFailures.some((re) => re.test(m.location()?.url ?? ''))) return;
      consoleProblems.push(`${tag}${m.type()}: ${m.text()}`);
    });
    p.on('pageerror', (e) => consoleProblems.push(`${tag}uncaught: ${e.message}`));
    p.on('response', (r) => {
      if (r.status() >= 400 && !expectedFailures.some((re) => re.test(r.url()))) failedResponses.push(`${tag}${r.status()} ${r.url()}`);
    });
  };
  watchPage(page);
  const chunkRequests = [];
  page.on('request', (r) => {
    if (r.url().includes('/api/v1/chunk/')) chunkRequests.push(r.url());
  });

  const hookOn = (p) => (fn, arg) => withTimeout(p.evaluate(fn, arg), READY_MS + 10_000, 'page.evaluate');
  const hook = hookOn(page);
  const readyOn = async (p, what) => {
    const t0 = Date.now();
    await hookOn(p)((ms) => window.__pmc.ready(ms), READY_MS);
    const s = await hookOn(p)(() => window.__pmc.stats());
    log(`  ready ${what}: ${s.loaded} chunks, ${s.triangles} triangles, ${((Date.now() - t0) / 1000).toFixed(1)} s`);
    return s;
  };
  const ready = (what) => readyOn(page, what);
  /** Waits for `pred(arg)` in page `p`; a timeout says what `state()` (in the page) shows then. */
  const waitFor = async (p, what, pred, arg, state, ms = 30_000) => {
    try {
      await p.waitForFunction(pred, arg, { timeout: ms, polling: 100 });
    } catch (e) {
      const now = await hookOn(p)(state).catch((err) => `(no state: ${err.message})`);
      throw new Error(`${what}: not within ${ms / 1000} s; now ${JSON.stringify(now).slice(0, 600)}`);
    }
  };
  const pathState = () => { const { screen: _s, ...rest } = window.__pmc.path(); return rest; };
  const gridState = () => { const { components, onScreen: _o, visible: _v, ...rest } = window.__pmc.navgrid(); return { ...rest, components: components.length }; };
  /** A screenshot of the view of `p` alone (panels hidden), saved under e2e/artifacts. */
  const shotOf = async (p, name) => {
    await p.addStyleTag({ content: '.panel, #loading, #error { visibility: hidden !important; }' }).then((h) => h.evaluate((el) => el.setAttribute('id', 'e2e-hide')));
    // two more frames so the last chunks are on screen
    await hookOn(p)(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => r()))));
    const buf = await p.screenshot({ type: 'png', timeout: 60_000 });
    await p.evaluate(() => document.getElementById('e2e-hide')?.remove());
    writeFileSync(join(artifacts, `${name}.png`), buf);
    return decodePng(buf);
  };
  const shot = (name) => shotOf(page, name);

  let orbitImg;
  let orbitStats;
  /** The server of step 5 (default layout, no world), reused by step 8. */
  let closeup = null;

  await step('1. the page loads without console errors', async () => {
    await page.goto(`${pageBase}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    orbitStats = await ready('from orbit');
    check(orbitStats.preset === 'earthlike' && orbitStats.seed === '7', `planet is ${orbitStats.preset}/${orbitStats.seed}`);
    check(orbitStats.error === null, `the page shows an error: ${orbitStats.error}`);
    // a server without a world: the tools are off and say why
    check(await page.isDisabled('#tool-dig'), 'the Dig tool is enabled on a server without a world');
    const why = await page.textContent('#tools-status');
    check(/^Editing is off: /.test(why ?? ''), `the tools panel does not say why editing is off: "${why}"`);
    log(`  tools: ${why}`);
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
    check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
  });

  await step('2. the planet is drawn (orbit screenshot mostly not background)', async () => {
    orbitImg = await shot('orbit');
    const bg = backgroundOf(orbitImg);
    const frac = fractionNot(orbitImg, bg);
    log(`  background rgb(${bg.join(',')}), ${(100 * frac).toFixed(1)} % of the pixels are planet, ${colourCount(orbitImg)} colours`);
    check(frac > 0.2, `only ${(100 * frac).toFixed(1)} % of the orbit screenshot differs from the background`);
    check(orbitStats.triangles > 1000, `only ${orbitStats.triangles} triangles loaded`);
  });

  await step('4. switching the preset (select → moon) changes the picture', async () => {
    await page.selectOption('#preset', 'moon');
    await page.waitForFunction(() => window.__pmc.stats().preset === 'moon', null, { timeout: 60_000 });
    const s = await ready('moon');
    check(s.seed === '7', `seed changed to ${s.seed}`);
    const moonImg = await shot('moon-orbit');
    const diff = fractionDifferent(orbitImg, moonImg);
    log(`  ${(100 * diff).toFixed(1)} % of the pixels changed`);
    check(diff > 0.15, `only ${(100 * diff).toFixed(1)} % of the pixels changed after switching to moon`);
    check((await page.evaluate(() => location.hash)).includes('preset=moon'), 'the URL hash does not name the new preset');
    await hook(() => window.__pmc.setPlanet('earthlike', '7'));
    await ready('earthlike again');
  });

  await step('3. moving near the surface elsewhere loads new chunks', async () => {
    const before = await hook(() => window.__pmc.stats());
    const requestsBefore = chunkRequests.length;
    // the far side of the planet, low, looking toward the horizon
    await hook(() => window.__pmc.setCamera(-25, -160, 60, 30, -20));
    const after = await ready('near the surface');
    const newKeys = after.loadedKeys.filter((k) => !before.loadedKeys.includes(k));
    const requests = chunkRequests.length - requestsBefore;
    log(`  ${requests} chunk requests, ${newKeys.length} new chunks loaded, ${before.loadedKeys.length - (after.loadedKeys.length - newKeys.length)} unloaded; mode ${after.mode}`);
    check(requests > 0, 'no /api/v1/chunk/ request after moving the camera');
    check(newKeys.length > 0, 'no new chunk loaded after moving the camera');
    check(after.mode === 'fly', `mode is ${after.mode}, expected fly`);
    const img = await shot('low');
    const frac = fractionNot(img, backgroundOf(img));
    check(frac > 0.2, `the low view is mostly background (${(100 * frac).toFixed(1)} % drawn)`);
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
  });

  await step('6. debug views, mode switch, walk mode and the URL hash', async () => {
    await hook(() => window.__pmc.setCamera(20, 15, 3000, 0, -90));
    await hook(() => window.__pmc.mode('orbit'));
    await ready('orbit again');
    const plain = await shot('debug-none');
    for (const [id, name] of [['#faces', 'faces'], ['#wireframe', 'wireframe'], ['#borders', 'borders']]) {
      await page.click(id);
      const img = await shot(`debug-${name}`);
      const diff = fractionDifferent(plain, img);
      log(`  ${name}: ${(100 * diff).toFixed(1)} % of the pixels changed`);
      // the borders are thin lines around each chunk drawn; with levels of detail the view from
      // 3 km holds a few dozen large chunks, so they cover about 1 % of the picture
      const least = name === 'borders' ? 0.004 : 0.02;
      check(diff > least, `toggling ${name} changed only ${(100 * diff).toFixed(2)} % of the pixels`);
      await page.click(id);
    }
    const flags = await hook(() => window.__pmc.debug({}));
    check(!flags.wireframe && !flags.faceColours && !flags.borders, `debug flags left on: ${JSON.stringify(flags)}`);

    // Tab switches to fly, the button back to orbit
    await page.click('#view');
    await page.keyboard.press('Tab');
    check((await hook(() => window.__pmc.stats())).mode === 'fly', 'Tab did not switch to fly');
    await page.click('#mode');
    check((await hook(() => window.__pmc.stats())).mode === 'orbit', 'the mode button did not switch to orbit');

    // walk: the eye settles about 2 m above the ground and W moves it along
    await hook(() => window.__pmc.setCamera(-10, 8, 80, 90, -5));
    await hook(() => window.__pmc.mode('walk'));
    await ready('walking');
    await page.waitForFunction(() => Math.abs((window.__pmc.stats().aboveGround ?? 99) - 2) < 0.25, null, { timeout: 60_000 });
    const w0 = await hook(() => window.__pmc.stats());
    await page.keyboard.down('KeyW');
    await page.waitForFunction((lon) => Math.abs(window.__pmc.stats().lon - lon) > 0.02, w0.lon, { timeout: 60_000 });
    await page.keyboard.up('KeyW');
    await page.waitForFunction(() => Math.abs((window.__pmc.stats().aboveGround ?? 99) - 2) < 0.25, null, { timeout: 60_000 });
    const w1 = await hook(() => window.__pmc.stats());
    log(`  walked from lon ${w0.lon.toFixed(4)} to ${w1.lon.toFixed(4)}, altitude ${w0.alt.toFixed(1)} -> ${w1.alt.toFixed(1)} m, ${w1.aboveGround.toFixed(2)} m above the ground`);
    check(w1.walk && w1.mode === 'fly', `walk mode lost: ${w1.mode}, walk ${w1.walk}`);
    await shot('walk');

    // a reload keeps the planet, the mode and the camera
    await page.waitForFunction(() => location.hash.includes('walk=1'), null, { timeout: 10_000 });
    const hash = await page.evaluate(() => location.hash);
    await page.reload({ waitUntil: 'load' });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    const r = await ready('after reload');
    log(`  ${hash}`);
    check(r.preset === 'earthlike' && r.seed === '7' && r.walk, `reload lost the state: ${r.preset}/${r.seed} walk ${r.walk}`);
    check(Math.abs(r.lat - w1.lat) < 1e-3 && Math.abs(r.lon - w1.lon) < 1e-3, `reload moved the camera: ${r.lat},${r.lon} vs ${w1.lat},${w1.lon}`);

    // an API error shows a message and keeps the planet
    expectedFailures.push(/preset=venus/);
    const err = await hook(() => window.__pmc.setPlanet('venus', '7').then(() => null, (e) => String(e.message)));
    check(err !== null, 'setPlanet("venus") did not fail');
    const banner = await page.evaluate(() => (document.getElementById('error').hidden ? null : document.getElementById('error-text').textContent));
    log(`  error banner: ${banner}`);
    check(banner !== null && banner.includes('venus'), `no visible error message for an unknown preset (banner: ${banner})`);
    const after = await hook(() => window.__pmc.stats());
    check(after.preset === 'earthlike' && after.loaded > 0, `the planet changed after a failed switch: ${after.preset}, ${after.loaded} chunks`);
    check((await page.inputValue('#preset')) === 'earthlike', 'the preset picker does not show the current planet');
    await page.click('#error-close');
    check(await page.isHidden('#error'), 'the error banner does not close');
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
  });

  await step('5. close-up of mountains with caves and overhangs (earthlike seed 7, default layout)', async () => {
    // the README's close-up (`pmc render --lat 3 --lon 9 --distance 2250 --look-at=-10,8`) on the
    // default planet, from its own server: the small e2e planet is too coarse for caves
    closeup = await startBackend(null);
    const base = closeup.url;
    await page.goto(`${base}#preset=earthlike&seed=7&mode=fly`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    const planet = await hook(() => fetch('api/v1/planet?preset=earthlike&seed=7').then((r) => r.json()));
    const camRadius = 2250 * (planet.radius / 2000);
    const target = dirOf(-10, 8).map((x) => x * planet.sea_radius);
    const { heading, pitch } = headingPitchToward(3, 9, camRadius, target);
    const alt = camRadius - planet.sea_radius;
    log(`  radius ${planet.radius} m; camera lat 3, lon 9, ${alt.toFixed(0)} m above sea level, heading ${heading.toFixed(1)}, pitch ${pitch.toFixed(1)}`);
    await hook(([h, p, a]) => window.__pmc.setCamera(3, 9, a, h, p), [heading, pitch, alt]);
    const s = await ready('close-up');
    const img = await shot('closeup');
    const frac = fractionNot(img, backgroundOf(img));
    log(`  ${s.loaded} chunks, ${s.triangles} triangles, ${(100 * frac).toFixed(1)} % not background, ${colourCount(img)} colours`);
    check(frac > 0.3, `the close-up is mostly background (${(100 * frac).toFixed(1)} %)`);
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
    check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
  });

  if (USE_MOCK) {
    log('8. and 7. need the real `pmc serve` (the mock has no /path, /navgrid or editing API): not run with PMC_E2E_MOCK=1');
    return;
  }

  await step('8. path tool and navigation grid: two clicks draw the path, N overlays the grid by component', async () => {
    const CX = VIEWPORT.width / 2;
    const CY = VIEWPORT.height / 2;
    const apiGet = async (path) => {
      const r = await fetchText(`${closeup.api}api/v1/${path}`, 20_000);
      check(r.status === 200, `GET /api/v1/${path}: ${r.status} ${r.text.slice(0, 300)}`);
      return JSON.parse(r.text);
    };
    const planet = await apiGet('planet?preset=earthlike&seed=7');
    const datum = planet.sea_radius ?? (planet.base_radius + planet.radius) / 2;
    // the ground near (-10°, 8°): the server's path from there to there stands on its highest
    // floor; the close-up looks down at 60° from 120 m above it (two clicks 200 px apart span some
    // tens of metres there)
    const here = await apiGet('path?preset=earthlike&seed=7&from=-10,8&to=-10,8');
    check(here.found && here.waypoints.length === 1, `GET /api/v1/path from (-10°, 8°) to itself: ${JSON.stringify(here).slice(0, 300)}`);
    const g0 = here.waypoints[0];
    check(g0.alt > 5, `the ground near (-10°, 8°) is not land: ${g0.alt.toFixed(1)} m above the datum`);
    const viewHash = `#preset=earthlike&seed=7&mode=fly&lat=${g0.lat}&lon=${g0.lon}&alt=${(g0.alt + 120).toFixed(1)}&heading=0&pitch=-60`;
    log(`  view ${viewHash}`);
    await page.evaluate((h) => (location.hash = h), viewHash);
    await ready('the path close-up');
    const before = await shot('path-before');

    // the Path tool (editing is off on this server: it works all the same), two clicks
    await page.click('#tool-path');
    check((await page.getAttribute('#tool-path', 'aria-pressed')) === 'true', 'the Path button is not shown as pressed');
    check(!(await page.isDisabled('#tool-path')), 'the Path button is disabled on a server without a world');
    check((await hook(() => window.__pmc.stats())).pathTool, 'stats() does not say the Path tool is chosen');
    const [A, B] = [[CX - 100, CY + 40], [CX + 100, CY - 20]];
    await page.mouse.click(...A);
    const p1 = await hook(() => window.__pmc.path());
    check(p1.phase === 'start' && p1.from !== null, `after the first click: ${p1.phase} (${p1.message})`);
    await page.mouse.click(...B);
    await waitFor(page, 'the path', () => !['start', 'loading'].includes(window.__pmc.path().phase), null, pathState);
    const p = await hook(() => window.__pmc.path());
    log(`  ${p.from} -> ${p.to}: ${p.message}`);
    check(p.phase === 'found', `no path between two points of the close-up: ${p.phase}: ${p.message}`);
    check(p.length > 0 && p.steps >= 1 && p.waypoints === p.steps + 1, `path length ${p.length} m, ${p.steps} steps, ${p.waypoints} waypoints`);
    const metres = p.length >= 1000 ? `${(p.length / 1000).toFixed(2)} km` : `${p.length.toFixed(1)} m`; // as src/ui.ts formatDistance
    const stepsText = `${p.steps} step${p.steps === 1 ? '' : 's'}`;
    const shownText = await page.textContent('#path-status');
    check(shownText.startsWith(`path: ${metres}, ${stepsText}`), `the tools panel shows "${shownText}"`);
    const statsText = await page.textContent('#s-path');
    check(statsText === `${metres} · ${stepsText}`, `the stats panel shows "${statsText}" for the path`);
    // the server, asked the same, walks the same length
    const q = `path?preset=earthlike&seed=7&from=${encodeURIComponent(p.from)}&to=${encodeURIComponent(p.to)}`;
    const direct = await apiGet(q);
    check(direct.found === true && Math.abs(direct.length - p.length) < 1e-9 && direct.steps === p.steps,
      `GET /api/v1/${q}: found ${direct.found}, ${direct.length} m, ${direct.steps} steps; the page shows ${p.length} m, ${p.steps} steps`);
    // pixels along the drawn path changed (where the terrain hides it, its faint copy shows)
    const after = await shot('path');
    const samples = [];
    for (let i = 1; i < p.screen.length; i++) {
      const [a, b] = [p.screen[i - 1], p.screen[i]];
      if (!a || !b) continue;
      const n = Math.max(1, Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / 3));
      for (let k = 0; k < n; k++) samples.push([a[0] + ((b[0] - a[0]) * k) / n, a[1] + ((b[1] - a[1]) * k) / n]);
    }
    const inside = samples.filter(([x, y]) => x >= 2 && y >= 2 && x < VIEWPORT.width - 2 && y < VIEWPORT.height - 2);
    const changed = inside.filter(([x, y]) => pixelChanged(before, after, Math.round(x), Math.round(y)));
    log(`  ${changed.length} of ${inside.length} pixels sampled along the path changed, ${colourPixels(after, PATH_HEX) - colourPixels(before, PATH_HEX)} more path-coloured pixels`);
    check(inside.length >= 20, `the path is hardly on the screen: ${inside.length} sample pixels`);
    check(changed.length >= 0.8 * inside.length, `only ${changed.length} of ${inside.length} pixels along the path changed`);
    check(colourPixels(after, PATH_HEX) - colourPixels(before, PATH_HEX) > 300, 'the path colour is hardly in the picture');

    // the grid: N, around the camera's ground point
    await page.keyboard.press('n');
    await waitFor(page, 'the nav grid', () => { const g = window.__pmc.navgrid(); return g.nodes > 0 && !g.loading && g.drawn; }, null, gridState);
    check(await page.isChecked('#navgrid'), 'N did not tick the nav grid box');
    const g = await hook(() => window.__pmc.navgrid());
    const main = g.components.find((c) => c.main);
    log(`  grid: ${g.nodes} nodes, ${g.edges} steps, ${g.components.length} components within ${g.shown.range.toFixed(0)} m (planet: ${g.totalNodes} nodes, ${g.totalComponents} components), main ${main ? `${main.label} ${main.hex}` : 'none'}`);
    check(g.error === null, `the grid request failed: ${g.error}`);
    check(g.edges > 0 && main !== undefined && main.size * 2 >= g.totalNodes, `no main grid (with steps) in the overlay: ${JSON.stringify(g.components.slice(0, 3))}`);
    const gridText = await page.textContent('#navgrid-status');
    check(gridText.includes(`${g.nodes.toLocaleString('en-US')} nodes`), `the panel says "${gridText}"`);
    const gridImg = await shot('navgrid');
    const dGrid = fractionDifferent(after, gridImg);
    const mainMore = colourPixels(gridImg, main.hex) - colourPixels(after, main.hex);
    log(`  ${(100 * dGrid).toFixed(1)} % of the pixels changed, ${mainMore} more pixels of the main grid's colour`);
    check(dGrid > 0.01, `the grid overlay changed only ${(100 * dGrid).toFixed(2)} % of the pixels`);
    check(mainMore > 300, `the main grid's colour ${main.hex} is hardly in the picture (${mainMore} pixels more)`);

    // a detached grid seen from above shows in its own colour: find one near (its nodes the top
    // floor of their columns), look straight down at it; the overlay follows the camera
    const near = await apiGet(`navgrid?preset=earthlike&seed=7&x=${g.shown.centre[0]}&y=${g.shown.centre[1]}&z=${g.shown.centre[2]}&range=1500&limit=100000`);
    const island = detachedFromAbove(near, datum);
    check(island !== null, `no detached grid seen from above within 1500 m of the close-up (${near.total_components} components on the planet)`);
    const ia = latLonOf(island.centre);
    log(`  detached component ${island.label}: ${island.nodes} nodes ${island.alt.toFixed(1)} m above the datum at ${ia.lat.toFixed(4)}°, ${ia.lon.toFixed(4)}°, ${island.distance.toFixed(0)} m away`);
    const fetches = g.fetches;
    await hook(([la, lo, al]) => window.__pmc.setCamera(la, lo, al, 0, -89), [ia.lat, ia.lon, island.alt + 60]);
    await ready('above the detached grid');
    await waitFor(page, 'the nav grid above the detached grid', (f) => { const s = window.__pmc.navgrid(); return s.fetches > f && !s.loading && s.drawn; }, fetches, gridState);
    const g2 = await hook(() => window.__pmc.navgrid());
    const it = g2.components.find((c) => c.label === island.label);
    check(it !== undefined && !it.main, `the overlay around the detached grid lacks component ${island.label}: ${JSON.stringify(g2.components.slice(0, 5))}`);
    check((g2.visible[island.label] ?? 0) > 0, `component ${island.label} is not visible from above: on screen ${g2.onScreen[island.label] ?? 0}, visible ${JSON.stringify(g2.visible)}`);
    const withGrid = await shot('navgrid-detached');
    await page.click('#navgrid');
    await waitFor(page, 'the nav grid off', () => !window.__pmc.navgrid().drawn, null, gridState, 10_000);
    const without = await shot('navgrid-off');
    const itMore = colourPixels(withGrid, it.hex) - colourPixels(without, it.hex);
    const mainMore2 = colourPixels(withGrid, main.hex) - colourPixels(without, main.hex);
    log(`  refetched (${g2.fetches - fetches} more); component ${it.label} ${it.hex}: ${g2.visible[it.label]} nodes visible, ${itMore} more pixels of its colour; ${mainMore2} of the main grid's`);
    check(itMore >= 20, `the detached grid's colour ${it.hex} is not in the picture (${itMore} pixels more)`);
    check(mainMore2 > 100, `the main grid's colour is not in the picture next to the detached grid (${mainMore2} pixels more)`);

    // Esc clears the path (the tool stays), Esc again goes back to Look
    await page.keyboard.press('Escape');
    const cleared = await hook(() => window.__pmc.path());
    check(cleared.phase === 'empty' && cleared.active, `Esc: path ${cleared.phase}, tool ${cleared.active ? 'Path' : 'not Path'}`);
    await page.keyboard.press('Escape');
    check(!(await hook(() => window.__pmc.stats())).pathTool, 'a second Esc did not leave the Path tool');
    check((await page.getAttribute('#tool-look', 'aria-pressed')) === 'true', 'Look is not shown as pressed after Esc');
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
    check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
  });

  await step('7. editing: dig with the mouse, a second browser follows, undo/redo, reload, restart', async () => {
    // the first browser's page is done: stop it drawing (software rendering shares the CPU)
    await page.goto('about:blank');
    // a fresh world on a server of its own (the default layout: voxels ~12 m wide, 4 m tall)
    const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-world-'));
    cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
    const world = join(dir, 'e2e.pmcw');
    let server = await startBackend(null, { world });
    const apiGet = async (path) => {
      const r = await fetchText(`${server.api}api/v1/${path}`, 10_000);
      check(r.status === 200, `GET /api/v1/${path}: ${r.status} ${r.text}`);
      return JSON.parse(r.text);
    };
    const planet = await apiGet('planet');
    check(planet.edit?.enabled === true, `/api/v1/planet says editing is off: ${JSON.stringify(planet.edit)}`);
    check(existsSync(world), `the server did not create the world file ${world}`);

    // two browsers, each with its own context (own cookies, connections, event stream)
    const browser = await withTimeout(
      chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS }),
      60_000,
      'launching a second Chromium',
    );
    cleanups.push(() => browser.close());
    const ctxA = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
    const ctxB = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
    const A = await ctxA.newPage();
    const B = await ctxB.newPage();
    for (const [p, label] of [[A, 'A'], [B, 'B']]) {
      p.setDefaultTimeout(60_000);
      watchPage(p, label);
    }
    const hA = hookOn(A);
    const hB = hookOn(B);
    const CX = VIEWPORT.width / 2;
    const CY = VIEWPORT.height / 2;
    const pickAt = (h) => h(([x, y]) => window.__pmc.pick(x, y), [CX, CY]);
    const statsOf = (h) => h(() => window.__pmc.stats());
    const waitRevision = (p, revision) =>
      p.waitForFunction(
        (r) => {
          const e = window.__pmc.stats().edit;
          return e.revision === r && !e.inFlight;
        },
        revision,
        { timeout: 60_000 },
      );
    const open = async (p, url, what) => {
      await p.goto(url, { waitUntil: 'load', timeout: 60_000 });
      await p.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
      return readyOn(p, what);
    };
    const WINDOW = 240; // pixels around the click compared between screenshots
    const windowDiff = (a, b) => fractionDifferent(crop(a, CX, CY, WINDOW, WINDOW), crop(b, CX, CY, WINDOW, WINDOW));

    // both open the page 200 m above (-10°, 8°); A finds the ground there, and the close-up view,
    // 80 m above it looking down at 60°, goes into both pages' URL hash
    const start = `${server.url}#preset=earthlike&seed=7&mode=fly&lat=-10&lon=8&alt=200&heading=0&pitch=-89`;
    await Promise.all([open(A, start, 'A from 200 m'), open(B, start, 'B from 200 m')]);
    // (200 px right of the centre: a snowfield, where the dug rock shows well)
    const ground = await hA(([x, y]) => window.__pmc.pick(x, y), [CX + 200, CY]);
    check(ground !== null, 'no terrain in the view from 200 m above (-10°, 8°)');
    const groundAlt = Math.hypot(...ground.point) - planet.sea_radius;
    check(groundAlt > 5, `the ground chosen near (-10°, 8°) is not land: ${groundAlt.toFixed(1)} m above the sea`);
    const at = latLonOf(ground.point);
    const viewHash =
      `#preset=earthlike&seed=7&mode=fly&lat=${at.lat.toFixed(5)}&lon=${at.lon.toFixed(5)}` +
      `&alt=${(groundAlt + 80).toFixed(1)}&heading=0&pitch=-60`;
    log(`  view ${viewHash}`);
    await Promise.all([A, B].map((p) => p.evaluate((h) => (location.hash = h), viewHash)));
    const [sA0, sB0] = await Promise.all([readyOn(A, 'A at the close-up'), readyOn(B, 'B at the close-up')]);
    for (const p of [A, B]) {
      const h = await p.evaluate(() => location.hash);
      check(h === viewHash, `the URL hash changed to ${h}`);
    }
    for (const [p, s0, label] of [[A, sA0, 'A'], [B, sB0, 'B']]) {
      check(s0.edit.enabled && s0.edit.error === null, `${label}: editing is off or failed: ${JSON.stringify(s0.edit)}`);
      await p.waitForFunction(() => window.__pmc.stats().edit.push === 'open', null, { timeout: 30_000 });
    }
    check(await A.isDisabled('#tool-dig') === false, 'the Dig button is disabled on an editable world');
    const rev0 = sA0.edit.revision;
    const pickA0 = await pickAt(hA);
    const pickB0 = await pickAt(hB);
    check(pickA0 !== null && pickB0 !== null, 'no terrain under the centre of the close-up');
    check(Math.abs(pickA0.distance - pickB0.distance) < 0.05, `A and B do not show the same view: ${pickA0.distance} vs ${pickB0.distance} m`);
    check(pickA0.distance < 120, `the terrain under the cursor is ${pickA0.distance.toFixed(1)} m away: not a close-up`);
    log(`  before: terrain ${pickA0.distance.toFixed(2)} m from the camera (chunk ${pickA0.key}), revision ${rev0}`);
    const beforeA = await shotOf(A, 'edit-before');

    // A: a path across the spot to dig and the nav grid; both follow the edit below
    await A.click('#tool-path');
    // (right of the tools panel, which covers the bottom left up to x = 370)
    await A.mouse.click(CX - 90, CY + 50);
    await A.mouse.click(CX + 150, CY - 50);
    await waitFor(A, 'A: the path', () => !['start', 'loading'].includes(window.__pmc.path().phase), null, pathState);
    const pathA0 = await hA(() => window.__pmc.path());
    check(pathA0.phase === 'found' && pathA0.revision === rev0, `A: no path across the close-up before the dig: ${pathA0.phase} (${pathA0.message}), revision ${pathA0.revision}`);
    await hA(() => window.__pmc.navgrid(true));
    await waitFor(A, 'A: the nav grid', () => { const g = window.__pmc.navgrid(); return g.drawn && !g.loading; }, null, gridState);
    const gridA0 = await hA(() => window.__pmc.navgrid());
    check(gridA0.shown.revision === rev0 && gridA0.error === null, `A: the grid shown is of revision ${gridA0.shown.revision} (${gridA0.error})`);

    // A: Dig with the mouse, radius 16 m, one click at the centre
    await A.click('#tool-dig');
    check(!(await statsOf(hA)).pathTool, 'choosing Dig did not leave the Path tool');
    check((await A.getAttribute('#tool-dig', 'aria-pressed')) === 'true', 'the Dig button is not shown as pressed');
    await A.fill('#brush-radius', '16');
    await A.press('#brush-radius', 'Enter');
    let sA = await statsOf(hA);
    check(sA.edit.tool === 'dig' && sA.edit.settings.radius === 16, `tool ${sA.edit.tool}, radius ${sA.edit.settings.radius} (wanted dig, 16)`);
    await A.mouse.move(CX - 40, CY - 40);
    await A.mouse.move(CX, CY, { steps: 4 });
    await A.waitForFunction(() => window.__pmc.stats().cursor, null, { timeout: 10_000 });
    await A.mouse.click(CX, CY);
    await waitRevision(A, rev0 + 1);
    sA = await statsOf(hA);
    check(sA.edit.error === null, `the dig failed: ${sA.edit.error}`);
    check(sA.edit.sent === 1, `${sA.edit.sent} edits sent for one click`);
    await A.waitForFunction((r) => document.getElementById('s-edits')?.textContent?.startsWith(`rev ${r} · 1 active`), rev0 + 1, { timeout: 10_000 });
    const list1 = await apiGet('edits');
    check(
      list1.edits.length === 1 && list1.active === 1 && list1.edits[0].active && list1.edits[0].brush === 'remove' && list1.edits[0].radius === 16,
      `GET /api/v1/edits after the dig: ${JSON.stringify(list1)}`,
    );
    const dug = distance(list1.edits[0].center, pickA0.point);
    check(dug < 0.5, `the edit is ${dug.toFixed(2)} m from the point clicked`);
    // the path was asked again and the grid fetched again for the new revision
    await waitFor(A, 'A: the path and the grid after the dig', (r) => { const p = window.__pmc.path(); const g = window.__pmc.navgrid(); return p.revision === r && !p.refreshing && g.shown?.revision === r && !g.loading; }, rev0 + 1,
      () => { const { screen: _s, ...path } = window.__pmc.path(); const { components: _c, onScreen: _o, visible: _v, ...grid } = window.__pmc.navgrid(); return { path, grid }; });
    const pathA1 = await hA(() => window.__pmc.path());
    const gridA1 = await hA(() => window.__pmc.navgrid());
    log(`  path ${pathA0.message} -> ${pathA1.message} (${pathA1.requests} requests); grid ${gridA0.nodes} -> ${gridA1.nodes} nodes, ${gridA1.fetches} fetches`);
    check(pathA1.requests === pathA0.requests + 1 && ['found', 'none'].includes(pathA1.phase), `A: the path did not follow the edit: ${pathA1.phase}, ${pathA1.requests} requests`);
    check(gridA1.fetches === gridA0.fetches + 1 && gridA1.error === null, `A: the grid did not follow the edit: ${gridA1.fetches} fetches, ${gridA1.error}`);
    await hA(() => window.__pmc.navgrid(false));
    await A.keyboard.press('Escape'); // clears the path (the pictures below compare the terrain)
    check((await hA(() => window.__pmc.path())).phase === 'empty', 'Esc did not clear the path');
    // Look again (no brush cursor in the pictures), then let the edited chunks arrive
    await A.click('#tool-look');
    await A.waitForFunction(() => !window.__pmc.stats().cursor, null, { timeout: 10_000 });
    await readyOn(A, 'A after the dig');
    const pickA1 = await pickAt(hA);
    check(pickA1 !== null, 'no terrain under the centre after the dig');
    log(`  after the dig: ${pickA1.distance.toFixed(2)} m (${(pickA1.distance - pickA0.distance).toFixed(2)} m deeper), ${sA.reloads} chunk reloads in A`);
    check(pickA1.distance > pickA0.distance + 4, `A: no hole under the cursor (${pickA0.distance.toFixed(2)} -> ${pickA1.distance.toFixed(2)} m)`);
    const afterA = await shotOf(A, 'edit-after');
    const dA = windowDiff(beforeA, afterA);
    log(`  A: ${(100 * dA).toFixed(1)} % of the ${WINDOW} px window around the click changed`);
    check(dA > 0.15, `A: only ${(100 * dA).toFixed(1)} % of the pixels around the click changed`);

    // B saw it by itself (server push, then a reload of the edited chunks)
    await waitRevision(B, rev0 + 1);
    await readyOn(B, 'B after the push');
    const sB1 = await statsOf(hB);
    const pickB1 = await pickAt(hB);
    check(sB1.reloads > 0, 'B reloaded no chunk after the push');
    check(pickB1 !== null && Math.abs(pickB1.distance - pickA1.distance) < 0.05, `B does not show the hole: ${pickB1?.distance} m vs A ${pickA1.distance} m`);
    const afterB = await shotOf(B, 'edit-page-b');
    const dB = windowDiff(beforeA, afterB); // the same view as A's before the dig
    log(`  B: ${sB1.reloads} chunk reloads, ${(100 * dB).toFixed(1)} % of the window changed`);
    check(dB > 0.15, `B: only ${(100 * dB).toFixed(1)} % of the pixels around the hole changed`);

    // undo with the button: the ground comes back, in A and in B
    await A.click('#undo');
    await waitRevision(A, rev0 + 2);
    await readyOn(A, 'A after undo');
    const pickA2 = await pickAt(hA);
    check(pickA2 !== null && Math.abs(pickA2.distance - pickA0.distance) < 0.05, `undo did not restore the ground: ${pickA2?.distance} m, before the dig ${pickA0.distance} m`);
    await waitRevision(B, rev0 + 2);
    await readyOn(B, 'B after undo');
    const pickB2 = await pickAt(hB);
    check(pickB2 !== null && Math.abs(pickB2.distance - pickB0.distance) < 0.05, `B did not follow the undo: ${pickB2?.distance} m vs ${pickB0.distance} m`);
    check((await apiGet('edits')).active === 0, 'the server still lists an active edit after undo');

    // redo with Ctrl+Shift+Z: the hole is back
    await A.keyboard.press('Control+Shift+Z');
    await waitRevision(A, rev0 + 3);
    await readyOn(A, 'A after redo');
    const pickA3 = await pickAt(hA);
    check(pickA3 !== null && Math.abs(pickA3.distance - pickA1.distance) < 0.05, `redo did not bring the hole back: ${pickA3?.distance} m vs ${pickA1.distance} m`);
    const list3 = await apiGet('edits');
    check(list3.revision === rev0 + 3 && list3.active === 1 && list3.redo === 0, `GET /api/v1/edits after redo: ${JSON.stringify(list3)}`);
    await waitRevision(B, rev0 + 3);
    await ctxB.close(); // B is done: A reloads faster alone

    // a reload of A still shows it
    await A.reload({ waitUntil: 'load' });
    await A.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await readyOn(A, 'A reloaded');
    const pickA4 = await pickAt(hA);
    check(pickA4 !== null && Math.abs(pickA4.distance - pickA1.distance) < 0.05, `after a reload: ${pickA4?.distance} m, the hole was ${pickA1.distance} m`);
    const reloadedA = await shotOf(A, 'edit-reloaded');
    const dR = windowDiff(beforeA, reloadedA);
    check(dR > 0.15, `after a reload only ${(100 * dR).toFixed(1)} % of the pixels around the hole differ from before the dig`);

    // a new server on the same world file still has it (the edit was saved)
    await A.goto('about:blank');
    await server.stop();
    server = await startBackend(null, { world });
    const list5 = await apiGet('edits');
    check(list5.active === 1 && distance(list5.edits[0].center, list1.edits[0].center) < 1e-6, `the restarted server lists ${JSON.stringify(list5)}`);
    const s5 = await open(A, server.url + viewHash, 'A on the restarted server');
    check(s5.edit.enabled, `editing is off after the restart: ${s5.edit.reason}`);
    const pickA5 = await pickAt(hA);
    check(pickA5 !== null && Math.abs(pickA5.distance - pickA1.distance) < 0.05, `after the restart: ${pickA5?.distance} m, the hole was ${pickA1.distance} m`);
    const restarted = await shotOf(A, 'edit-restarted');
    const dS = windowDiff(beforeA, restarted);
    log(`  reload: ${(100 * dR).toFixed(1)} %, restart: ${(100 * dS).toFixed(1)} % of the window differ from before the dig`);
    check(dS > 0.15, `after the restart only ${(100 * dS).toFixed(1)} % of the pixels around the hole differ from before the dig`);
    await ctxA.close();
    check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
    check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
  });

  /** The harness of the level-of-detail flights (e2e/lodFlight.mjs). */
  const flightHarness = {
    page,
    hook,
    ready,
    shot,
    log,
    check,
    problems: () => [...consoleProblems, ...failedResponses],
  };

  await step('9. levels of detail on the default planet: orbit to 2 m, a zoom down and back up, no crack, no hole', async () => {
    const server = await startBackend(null);
    await page.goto(`${server.url}#preset=earthlike&seed=7&mode=orbit&lat=-10&lon=8`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await ready('the default planet');
    await lodFlight(flightHarness, {
      label: 'lod-default',
      lat: -10,
      lon: 8,
      stops: [
        { name: 'orbit', height: 6000, orbit: true },
        { name: '500m', height: 500 },
        { name: '50m', height: 50 },
        { name: '2m', height: 2 },
      ],
      zoom: [800, 200, 40, 800],
    });
    await page.goto('about:blank');
    await server.stop();
  });

  await step('10. the Earth at true scale: orbit and 2 m over an ocean floor, orbit, 10 km, 100 m and 2 m over mountains, no crack or hole, no jitter at 6.4e6 m', async () => {
    const server = await startBackend(null, { extra: ['--preset', 'earth'] });
    // the floor of an ocean basin of the earth preset (seed 7), about 3.4 km under the sea (the
    // sea is not drawn with the back-face flag on)
    await page.goto(`${server.url}#preset=earth&seed=7&mode=orbit&lat=27.9&lon=86.9`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    const first = await ready('the Earth from orbit');
    check(first.preset === 'earth', `the server serves ${first.preset}`);
    await lodFlight(flightHarness, {
      label: 'lod-earth',
      lat: 27.9,
      lon: 86.9,
      // (10 km and 100 m are visited over the mountains below)
      // (a zoom down and back up is step 9's; the suite's time goes to the mountains below)
      stops: [
        { name: 'orbit', height: 12_000_000, orbit: true },
        { name: '2m', height: 2 },
      ],
      pictures: true,
      // 6.4e6 m to two figures: the camera is 6 367 551 m from the centre
      jitter: 6.36e6,
    });
    // the same descent over a mountain range with caves (the place `pmc bench-flight --at 39,0`
    // measures), checked the same way; its pictures are the README's
    await lodFlight(flightHarness, {
      label: 'lod-earth-land',
      lat: 39,
      lon: 0,
      stops: [
        { name: 'orbit', height: 12_000_000, orbit: true },
        { name: '10km', height: 10_000 },
        { name: '100m', height: 100 },
        { name: '2m', height: 2 },
      ],
      pictures: true,
    });
    await page.goto('about:blank');
    await server.stop();
  });

  await step('11. a real planet from an elevation model: imported, seen from orbit and near the ground with no crack or hole, land, shelf and deep ocean told apart, a cave dug under a mountain; the same model as a height field', async () => {
    // PMC_E2E_DEM: another equirectangular model to fly over (the README's pictures are taken
    // over ETOPO5); by default the one-degree ETOPO60 fixture of pmc-dem's tests
    const source = process.env.PMC_E2E_DEM ? resolve(process.env.PMC_E2E_DEM) : resolve(viewerDir, '../crates/pmc-dem/tests/fixtures/etopo60.cdf');
    const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-dem-'));
    cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
    const dem = join(dir, 'earth.pmcdem');
    const imported = await run(PMC_BIN, ['dem', 'import', source, '-o', dem, '--quiet'], 300_000);
    check(imported.code === 0, `pmc dem import failed: ${imported.out}`);
    const server = await startBackend(null, { world: join(dir, 'earth.pmcw'), extra: ['--dem', dem] });
    // over the East China Sea: China, Korea and Japan, the wide shelf of the Yellow and East
    // China Seas, the deep Philippine Sea
    await page.goto(`${server.url}#mode=orbit&lat=30&lon=127`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    const first = await ready('the real Earth from orbit');
    check(first.preset === null, `the server serves the preset ${first.preset}, not the elevation model`);
    const planet = await hook(() => fetch('api/v1/planet').then((x) => x.json()));
    check(planet.terrain?.kind === 'dem' && planet.terrain.file === 'earth.pmcdem', `the planet is ${JSON.stringify(planet.terrain)}`);
    check(planet.materials.includes('deep seabed') && planet.materials.includes('shelf'), `materials ${planet.materials}`);
    await hook(() => window.__pmc.mode('orbit'));
    await hook(() => window.__pmc.setCamera(30, 127, 3_000_000, 0, -90));
    await ready('over the East China Sea');
    const view = await shot('dem-shelf-view');
    // every 16th pixel: what lies under it (the height of the ground the ray meets) and its colour
    const samples = await hook(([w, h, sea]) => {
      const out = [];
      for (let y = 8; y < h; y += 16) {
        for (let x = 8; x < w; x += 16) {
          const hit = window.__pmc.pick(x, y);
          if (hit) out.push({ x, y, h: Math.hypot(...hit.point) - sea });
        }
      }
      return out;
    }, [VIEWPORT.width, VIEWPORT.height, planet.sea_radius]);
    const classes = { deep: [], shelf: [], land: [] };
    for (const p of samples) {
      const c = p.h < -1000 ? 'deep' : p.h < -10 && p.h > -180 ? 'shelf' : p.h > 50 ? 'land' : null;
      if (c) {
        const i = 4 * (p.y * view.width + p.x);
        classes[c].push([view.data[i], view.data[i + 1], view.data[i + 2]]);
      }
    }
    const mean = (cs) => cs.reduce((a, c) => a.map((v, k) => v + c[k] / cs.length), [0, 0, 0]);
    const means = Object.fromEntries(Object.entries(classes).map(([k, cs]) => [k, cs.length ? mean(cs) : null]));
    log(`  under the pixels: ${Object.entries(classes).map(([k, cs]) => `${k} ${cs.length} (mean colour ${means[k]?.map((v) => v.toFixed(0)).join(',')})`).join(', ')}`);
    for (const k of Object.keys(classes)) check(classes[k].length >= 10, `only ${classes[k].length} ${k} pixels over the East China Sea`);
    const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    for (const [a, b] of [['deep', 'shelf'], ['shelf', 'land'], ['deep', 'land']]) {
      check(dist(means[a], means[b]) > 20, `${a} and ${b} look alike: ${means[a]} and ${means[b]}`);
    }
    /** The view from (lat, lon) `height` m above the datum looking `pitch` degrees: no flagged pixel (no crack, no hole); a picture as a user sees it. */
    const look = async (name, lat, lon, height, pitch) => {
      await hook(() => window.__pmc.debug({ backfaces: true }));
      await hook(([a, b, h, p]) => window.__pmc.setCamera(a, b, h, 0, p), [lat, lon, height, pitch]);
      const st = await ready(name);
      const flagged = flaggedPixels(await shot(`${name}-flagged`));
      log(`  ${name}: ${st.shown} chunks shown, levels ${st.lod.levelsText}, ${flagged} flagged pixels`);
      check(flagged === 0, `${name}: ${flagged} flagged pixels (a crack or a hole): see ${name}-flagged.png`);
      await hook(() => window.__pmc.debug({ backfaces: false }));
      return shot(`${name}-view`);
    };
    /** The meshed ground at (lat, lon), metres above the datum, and its point (planet frame), from `pmc dem probe`. */
    const groundAt = async (lat, lon) => {
      const p = await run(PMC_BIN, ['dem', 'probe', dem, '--lat', String(lat), '--lon', String(lon), '--json'], 120_000);
      check(p.code === 0, `pmc dem probe failed: ${p.out}`);
      const height = JSON.parse(p.out).meshed[0].height;
      const [la, lo] = [(lat * Math.PI) / 180, (lon * Math.PI) / 180];
      const r = planet.sea_radius + height;
      return { height, point: [r * Math.cos(la) * Math.sin(lo), r * Math.sin(la), r * Math.cos(la) * Math.cos(lo)] };
    };
    // the Himalaya from orbit, and a coast from 30 km: the pictures are the README's
    await hook(() => window.__pmc.mode('orbit'));
    await look('dem-himalaya-orbit', 29, 86, 2_500_000, -90);
    await hook(() => window.__pmc.mode('fly'));
    await look('dem-coast', 35.55, -5.6, 30_000, -35);
    // a cave dug under a mountain of the Alps, seen from 25 m above the ground a little south of
    // it (a coarser detail here: the software renderer of the tests draws slowly)
    const detail = await hook(() => window.__pmc.lod());
    await hook(() => window.__pmc.lod({ maxPixelError: 4, maxChunks: 1000 }));
    const spot = await groundAt(46.5, 8);
    const south = await groundAt(46.4997, 8);
    log(`  the ground under 46.5, 8: ${spot.height.toFixed(1)} m above the datum; 33 m south: ${south.height.toFixed(1)} m`);
    const before = await look('dem-cave-before', 46.4997, 8, south.height + 25, -35);
    const centre = spot.point;
    const r = Math.hypot(...centre);
    const inward = centre.map((v) => v * (1 - 6 / r));
    const answer = await hook(
      ([c]) => fetch('api/v1/edits', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ brush: 'remove', x: c[0], y: c[1], z: c[2], radius: 16 }) }).then(async (x) => ({ status: x.status, body: await x.json() })),
      [inward],
    );
    check(answer.status === 200 && answer.body.chunks.length > 0, `the dig was answered ${JSON.stringify(answer)}`);
    await waitFor(page, 'the dug chunks', () => window.__pmc.stats().pending === 0, null, () => window.__pmc.stats(), 120_000);
    const after = await look('dem-cave', 46.4997, 8, south.height + 25, -35);
    const w = 400;
    const changed = fractionDifferent(crop(before, VIEWPORT.width / 2, VIEWPORT.height / 2, w, w), crop(after, VIEWPORT.width / 2, VIEWPORT.height / 2, w, w));
    log(`  the dig changed ${(100 * changed).toFixed(1)} % of the ${w} px around it`);
    check(changed > 0.05, `the dig is not visible: ${(100 * changed).toFixed(1)} % of the pixels around it changed`);
    await hook((d) => window.__pmc.lod(d), detail);
    check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
    await page.goto('about:blank');
    await server.stop();
    // the same model as a height field (--mesher heightfield): 65 x 65 patches streamed as
    // chunks, drawn with no crack or hole (from orbit: the software renderer of the tests draws
    // the finer views slowly)
    const patches = await startBackend(null, { extra: ['--dem', dem, '--mesher', 'heightfield'] });
    await page.goto(`${patches.url}#mode=orbit&lat=28&lon=86.9`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await ready('the height field from orbit');
    const hp = await hook(() => fetch('api/v1/planet').then((x) => x.json()));
    check(hp.layout.n_t === 64 && hp.layout.d_c === 1, `the height field's layout is ${JSON.stringify(hp.layout)}`);
    await hook(() => window.__pmc.mode('orbit'));
    await look('dem-heightfield-orbit', 28, 86.9, 6_000_000, -90);
    check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
    await page.goto('about:blank');
    await patches.stop();
  });
}

try {
  await main();
  clearTimeout(watchdog);
  await cleanup();
  const total = ((Date.now() - started) / 1000).toFixed(1);
  console.log(`\n${results.map((r) => `${r.ok ? 'ok  ' : 'FAIL'} ${r.name} (${r.s.toFixed(1)} s)`).join('\n')}`);
  console.log(`\nscreenshots in ${artifacts}`);
  console.log(`e2e: ${results.filter((r) => r.ok).length} passed, 0 failed (${total} s)`);
  process.exit(0);
} catch (e) {
  clearTimeout(watchdog);
  if (results.length > 0) {
    console.log(`\n${results.map((r) => `${r.ok ? 'ok  ' : 'FAIL'} ${r.name} (${r.s.toFixed(1)} s)`).join('\n')}`);
  }
  await fail(short(e));
}
