// Step 17: the viewer as a first visit shows it, at three sizes. The overlays a first visit sees
// (the HUD, the go-to box, the panel's button, the scale bar, the tool bar) cover at most 15 % of
// a 1024 x 640 window (measured from the DOM: the union of their boxes), do not overlap each
// other and stay inside the window at 1024 x 640, 1920 x 1080 and on a 390 x 844 phone; the HUD
// says where the camera is; the side panel opens, remembers that and its folded sections over a
// reload. On the phone (Playwright's touch emulation, touches sent as the browser gets them): one
// finger turns the planet, a pinch zooms, two fingers moved up together tilt. Then the server is
// stopped under a viewer (with a world): the notice says so; once the server is back, an edit is
// made through the API while the page is still offline, and the Retry button reconnects: the
// page's edit stream resumes (it learns the new revision and reloads the edit's chunks) and the
// view converges.

import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { CHROMIUM, chromiumArgs, LAYOUT, READY_MS, artifacts, check, cleanups, log, withTimeout } from '../harness.mjs';
import { startBackend, startPmcServe } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

export const name = '17. the overlays at 1024 x 640, 1920 x 1080 and on a phone (coverage, no overlap, the side panel remembered, touch), the server gone and back';

const { positionFromLatLon } = await viewerModule('frames.ts');

/**
 * An edit body for `POST /api/v1/edits`: a ball of 4 m dug at the datum under (`lat`, `lon`)
 * (the planet frame by the viewer's own frames.ts).
 */
async function editAt(base, lat, lon) {
  const planet = await (await fetch(`${base}api/v1/planet`)).json();
  const datum = planet.sea_radius ?? (planet.base_radius + planet.radius) / 2;
  const [x, y, z] = positionFromLatLon(lat, lon, datum);
  return { brush: 'remove', x, y, z, radius: 4 };
}

/** The largest share of a 1024 x 640 window the first visit's overlays may cover. */
const MAX_COVERAGE = 0.15;

/** The first visit's overlays (the side panel is folded away). */
const DEFAULT_OVERLAYS = ['#hud', '#goto-form', '#panel-toggle', '#scale', '#tools'];

/**
 * In the page: the share of the window under any overlay shown (the union of the boxes of the
 * panels, notices and loading bar, sampled every 2 px), and each default overlay's box.
 */
function measure(ids) {
  const shown = (el) => {
    const cs = getComputedStyle(el);
    const r = el.getBoundingClientRect();
    return cs.display !== 'none' && cs.visibility !== 'hidden' && r.width > 0 && r.height > 0;
  };
  const els = [...document.querySelectorAll('.panel, #notices > *, #loading-bar')].filter(shown);
  const rects = els.map((el) => el.getBoundingClientRect());
  const W = innerWidth;
  const H = innerHeight;
  let covered = 0;
  let total = 0;
  for (let y = 1; y < H; y += 2) {
    for (let x = 1; x < W; x += 2) {
      total++;
      if (rects.some((r) => x >= r.left && x < r.right && y >= r.top && y < r.bottom)) covered++;
    }
  }
  const boxes = {};
  for (const id of ids) {
    const el = document.querySelector(id);
    if (!el || !shown(el)) continue;
    const r = el.getBoundingClientRect();
    boxes[id] = { left: r.left, top: r.top, right: r.right, bottom: r.bottom };
  }
  return { share: covered / total, shown: els.map((el) => `#${el.id}`), boxes, W, H };
}

/** Checks that the boxes lie inside the window and do not overlap (`label`: the window). */
function checkLayout(m, label) {
  const names = Object.keys(m.boxes);
  for (const id of DEFAULT_OVERLAYS) {
    // the scale bar hides where the view's centre is sky
    if (id !== '#scale') check(names.includes(id), `${label}: ${id} is not shown`);
  }
  for (const id of names) {
    const b = m.boxes[id];
    check(b.left >= 0 && b.top >= 0 && b.right <= m.W + 0.5 && b.bottom <= m.H + 0.5, `${label}: ${id} leaves the window: ${JSON.stringify(b)}`);
  }
  for (let i = 0; i < names.length; i++) {
    for (let j = i + 1; j < names.length; j++) {
      const a = m.boxes[names[i]];
      const b = m.boxes[names[j]];
      const overlap = a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
      check(!overlap, `${label}: ${names[i]} and ${names[j]} overlap: ${JSON.stringify(a)} ${JSON.stringify(b)}`);
    }
  }
}

export async function scenario(t) {
  const { pageBase } = t.shared;
  log(`  launching a second ${CHROMIUM} for windows of other sizes and a phone`);
  const browser = await withTimeout(chromium.launch({ executablePath: CHROMIUM, headless: true, args: chromiumArgs() }), 60_000, 'launching Chromium');
  cleanups.push(() => browser.close());
  const problems = [];
  /** A first visit (no stored state) at `viewport`; `touch`: a phone. */
  const open = async (viewport, touch = false) => {
    const context = await browser.newContext({ viewport, deviceScaleFactor: 1, hasTouch: touch, isMobile: touch });
    // the atmosphere off, as in the other steps (the software renderer draws it slowly)
    await context.addInitScript(() => {
      try {
        window.localStorage.setItem('pmc.atmosphere', 'off');
      } catch {
        // about:blank
      }
    });
    const page = await context.newPage();
    page.setDefaultTimeout(60_000);
    page.on('console', (m) => {
      if ((m.type() === 'error' || m.type() === 'warning') && !/GPU stall due to ReadPixels/.test(m.text())) problems.push(`${viewport.width}x${viewport.height} ${m.type()}: ${m.text()}`);
    });
    page.on('pageerror', (e) => problems.push(`uncaught: ${e.message}`));
    return { context, page };
  };
  const ready = async (page, what) => {
    const t0 = Date.now();
    await withTimeout(page.evaluate((ms) => window.__pmc.ready(ms), READY_MS), READY_MS + 10_000, 'ready');
    log(`  ready ${what}: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
    return page.evaluate(() => window.__pmc.stats());
  };
  const stats = (page) => page.evaluate(() => window.__pmc.stats());

  // ---- 1024 x 640: coverage, the HUD, the side panel remembered -------------------------------
  {
    const { context, page } = await open({ width: 1024, height: 640 });
    await page.goto(`${pageBase}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15&alt=3000`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    const s = await ready(page, '1024 x 640, a first visit');
    // the HUD's numbers are refreshed five times a second
    await page.waitForTimeout(400);
    const m = await page.evaluate(measure, DEFAULT_OVERLAYS);
    log(`  1024 x 640: the overlays cover ${(100 * m.share).toFixed(1)} % of the window (${m.shown.join(', ')})`);
    check(m.share <= MAX_COVERAGE, `the first visit's overlays cover ${(100 * m.share).toFixed(1)} % of a 1024 x 640 window (at most ${100 * MAX_COVERAGE} %)`);
    check(!m.shown.includes('#side'), 'the side panel shows on a first visit');
    checkLayout(m, '1024 x 640');
    const hud = await page.evaluate(() => ['hud-planet', 'hud-lat', 'hud-lon', 'hud-alt', 'hud-heading', 'scale-text'].map((id) => document.getElementById(id).textContent));
    log(`  HUD: ${hud.join(' | ')}`);
    check(hud[0] === 'earthlike · seed 7', `the HUD names the planet "${hud[0]}"`);
    check(hud[1] === `${Math.abs(s.lat).toFixed(4)}° N` && hud[2] === `${Math.abs(s.lon).toFixed(4)}° E`, `the HUD's place (${hud[1]} ${hud[2]}) is not the camera's (${s.lat}, ${s.lon})`);
    check(hud[3] === 'alt 3.00 km' && /^heading \d+°$/.test(hud[4]), `the HUD's height and heading: ${hud[3]}, ${hud[4]}`);
    check(/^\d+ (cm|m|km)$/.test(hud[5]) && m.boxes['#scale'] !== undefined, `no scale bar from orbit: "${hud[5]}"`);
    const needle = await page.getAttribute('#compass-needle', 'transform');
    check(needle === `rotate(${(-s.heading).toFixed(1)})`, `the compass points ${needle} for heading ${s.heading}`);
    writeFileSync(join(artifacts, 'overlays-1024.png'), await page.screenshot());

    // the compass faces north
    await page.evaluate(() => window.__pmc.setCamera(20, 15, 3000, 120, -90));
    await page.click('#compass');
    await page.waitForFunction(() => Math.abs(window.__pmc.stats().heading) < 1e-9, null, { timeout: 10_000 });

    // the side panel: opens, is remembered over a reload with its folded sections
    await page.click('#panel-toggle');
    check(await page.isVisible('#side'), 'the ☰ button does not open the side panel');
    check((await page.getAttribute('#panel-toggle', 'aria-expanded')) === 'true', 'the ☰ button does not say the panel is open');
    const opened = await page.evaluate(measure, DEFAULT_OVERLAYS);
    log(`  with the side panel open: ${(100 * opened.share).toFixed(1)} % covered`);
    check(await page.isVisible('#s-chunks'), 'the statistics are folded on a first visit');
    await page.click('#sec-stats > summary');
    await page.click('#sec-debug > summary');
    check(!(await page.isVisible('#s-chunks')) && (await page.isVisible('#wireframe')), 'the sections do not fold and unfold');
    await page.reload({ waitUntil: 'load' });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    check(await page.isVisible('#side'), 'the side panel is closed after a reload');
    check(!(await page.isVisible('#s-chunks')) && (await page.isVisible('#wireframe')), 'the folded sections are not remembered over a reload');
    await page.keyboard.press('KeyP');
    check(await page.isHidden('#side'), 'P does not close the side panel');
    // / puts the caret in the go-to box
    await page.click('#view');
    await page.keyboard.press('Slash');
    check(await page.evaluate(() => document.activeElement?.id === 'goto'), '/ does not put the caret in the go-to box');
    await context.close();
  }

  // ---- 1920 x 1080 ---------------------------------------------------------------------------
  {
    const { context, page } = await open({ width: 1920, height: 1080 });
    await page.goto(`${pageBase}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15&alt=3000`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await ready(page, '1920 x 1080');
    const m = await page.evaluate(measure, DEFAULT_OVERLAYS);
    log(`  1920 x 1080: ${(100 * m.share).toFixed(1)} % covered`);
    check(m.share <= MAX_COVERAGE, `the overlays cover ${(100 * m.share).toFixed(1)} % of a 1920 x 1080 window`);
    checkLayout(m, '1920 x 1080');
    await context.close();
  }

  // ---- a 390 x 844 phone: layout and touch ---------------------------------------------------
  {
    const { context, page } = await open({ width: 390, height: 844 }, true);
    await page.goto(`${pageBase}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15&alt=3000`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await ready(page, 'a 390 x 844 phone');
    const m = await page.evaluate(measure, DEFAULT_OVERLAYS);
    log(`  390 x 844: ${(100 * m.share).toFixed(1)} % covered`);
    checkLayout(m, '390 x 844');
    const bar = await page.evaluate(() => {
      const row = document.querySelector('#tools .tool-row');
      return { scroll: row.scrollWidth, client: row.clientWidth };
    });
    check(bar.scroll <= bar.client + 1, `the phone's tool bar is cut off (${bar.scroll} px in ${bar.client})`);
    writeFileSync(join(artifacts, 'overlays-phone.png'), await page.screenshot());

    const cdp = await context.newCDPSession(page);
    const touch = (type, points) => cdp.send('Input.dispatchTouchEvent', { type, touchPoints: points.map(([x, y], id) => ({ x, y, id })) });
    /** Moves the fingers from `from` to `to` (lists of points) in `n` steps, then lifts them. */
    const gesture = async (from, to, n = 4) => {
      await touch('touchStart', from.slice(0, 1));
      if (from.length > 1) await touch('touchStart', from);
      for (let k = 1; k <= n; k++) {
        await touch('touchMove', from.map(([x, y], i) => [x + ((to[i][0] - x) * k) / n, y + ((to[i][1] - y) * k) / n]));
        await page.waitForTimeout(16);
      }
      await touch('touchEnd', []);
    };
    await page.evaluate(() => window.__pmc.setCamera(20, 15, 3000, 0, -90));
    const s0 = await stats(page);
    // one finger down the screen: the planet turns with it, the camera goes north
    await gesture([[195, 300]], [[195, 500]]);
    await page.waitForFunction((lat) => window.__pmc.stats().lat > lat + 0.5, s0.lat, { timeout: 20_000 });
    const s1 = await stats(page);
    log(`  one finger 200 px down: latitude ${s0.lat.toFixed(3)} -> ${s1.lat.toFixed(3)}°`);
    check(Math.abs(s1.lon - s0.lon) < 0.5 && s1.mode === 'orbit', `one finger moved the camera sideways or out of orbit: ${JSON.stringify([s1.lon, s1.mode])}`);
    // a pinch spreading the fingers from 100 to 250 px apart: closer
    await gesture([[145, 420], [245, 420]], [[70, 420], [320, 420]]);
    await page.waitForFunction((alt) => window.__pmc.stats().alt < alt * 0.8, s1.alt, { timeout: 20_000 });
    const s2 = await stats(page);
    log(`  pinch 100 -> 250 px: altitude ${s1.alt.toFixed(0)} -> ${s2.alt.toFixed(0)} m`);
    check(Math.abs(s2.lat - s1.lat) < 0.2, `the pinch moved the camera: ${s1.lat} -> ${s2.lat}`);
    // two fingers up together: tilted toward the horizon, still orbiting
    await gesture([[145, 600], [245, 600]], [[145, 480], [245, 480]]);
    await page.waitForFunction(() => window.__pmc.stats().pitch > -75, null, { timeout: 20_000 });
    const s3 = await stats(page);
    log(`  two fingers 120 px up: pitch ${s2.pitch.toFixed(1)} -> ${s3.pitch.toFixed(1)}°, ${s3.mode}`);
    check(s3.mode === 'orbit' && Math.abs(s3.alt - s2.alt) < 1e-6 * s2.alt + 1e-6, `the tilt left orbit or changed the height: ${JSON.stringify([s3.mode, s2.alt, s3.alt])}`);
    await ready(page, 'the phone, tilted');
    writeFileSync(join(artifacts, 'overlays-phone-tilted.png'), await page.screenshot());
    await context.close();
  }

  // ---- the server gone and back --------------------------------------------------------------
  {
    // with a world: the edit stream must resume too
    const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-reconnect-'));
    cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
    const world = join(dir, 'reconnect.pmcw');
    const server = await startBackend(LAYOUT, { world });
    const port = Number(new URL(server.api).port);
    const { context, page } = await open({ width: 1024, height: 640 });
    await page.goto(`${server.url}#preset=earthlike&seed=7&mode=orbit&lat=-40&lon=120&alt=3000`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await ready(page, 'before the server stops');
    const before = problems.length;
    // the edit someone will make while the page is away, under the camera (its body computed now,
    // on the first server)
    const body = JSON.stringify(await editAt(server.api, -40, 120));
    // the edit stream stays away until the edit is made: the browser's EventSource retries on its
    // own every few seconds, and when one of its tries reached the restarted server before the
    // edit, the page was told of the edit by the stream (naming only the chunks it changed), not
    // by the hello after it, and the check below failed on the chunks the edit did not touch
    // (the step 17 flake: "chunks shown as they were before the edit", 73 of 121 fetched again)
    const events = '**/api/v1/events**';
    let streamTries = 0;
    await page.route(events, (route) => {
      streamTries++;
      return route.abort('connectionrefused');
    });
    await server.stopApi();
    // the user zooms in: what the view wants next cannot be fetched
    await page.evaluate(() => window.__pmc.setCamera(-40, 120, 1500, 0, -90));
    await page.waitForFunction(() => !window.__pmc.stats().online && !document.getElementById('offline').hidden, null, { timeout: 30_000 });
    const notice = await page.textContent('#offline-text');
    log(`  server stopped: "${notice}"`);
    check(/^The PMC server does not answer \(for \d+ s\): (trying again in \d+ s|trying now…)$/.test(notice ?? ''), `the notice says "${notice}"`);
    // probes 1, 2 and 4 s apart fail; the next waits 8 s
    await page.waitForFunction(() => /trying again in 8 s/.test(document.getElementById('offline-text').textContent), null, { timeout: 30_000 });
    check((await stats(page)).error === null, `a chunk error shows beside the notice: ${(await stats(page)).error}`);
    const again = await startPmcServe(LAYOUT, { port, world });
    // someone edits the world while the page is still offline: the page must learn of it
    const rev0 = (await stats(page)).edit.revision;
    const edit = await fetch(`${again.base}api/v1/edits`, { method: 'POST', headers: { 'content-type': 'application/json' }, body });
    check(edit.status === 200, `the edit through the API: ${edit.status} ${await edit.text()}`);
    check(!(await stats(page)).online, 'the page came back online before its Retry button could be tried (the next probe was 8 s away)');
    check((await stats(page)).edit.revision === rev0, `the page learnt of the edit while its edit stream was held away: ${(await stats(page)).edit.revision}`);
    await page.unroute(events);
    log(`  the edit stream's ${streamTries} tries while the server was away refused; the edit made (revision ${rev0 + 1} on the server)`);
    // the chunks the page asks for once it is back: the page cannot know what the edit it missed
    // changed (the stream's hello gives the revision alone), so every chunk it shows must be one
    // fetched from the server that has the edit (reloaded as stale, or fetched for the first time)
    const fetchedAfter = new Set();
    page.on('request', (req) => {
      const m = /\/api\/v1\/chunk\/([a-z]+\/\d+\/\d+\/\d+\/\d+)/.exec(req.url());
      if (m) fetchedAfter.add(m[1]);
      // (a batch names its chunks in its body)
      if (req.url().includes('/api/v1/chunk-batch')) {
        for (const c of JSON.parse(req.postData() ?? '{"chunks":[]}').chunks) fetchedAfter.add(c.key);
      }
    });
    const t0 = Date.now();
    await page.click('#offline-retry', { timeout: 5_000 });
    // back before the next scheduled probe (8 s after the last): the button's doing
    await page.waitForFunction(() => window.__pmc.stats().online && document.getElementById('offline').hidden, null, { timeout: 5_000 });
    log(`  server back on port ${port}: online again ${((Date.now() - t0) / 1000).toFixed(1)} s after Retry`);
    await page.waitForFunction((r) => window.__pmc.stats().edit.revision === r, rev0 + 1, { timeout: 30_000 });
    const r = await ready(page, 'after reconnecting');
    const notFetched = r.loadedKeys.filter((k) => !fetchedAfter.has(k));
    log(`  the edit made while the page was away: revision ${rev0} -> ${r.edit.revision} in the page; ${r.loadedKeys.length} chunks shown, ${r.loadedKeys.length - notFetched.length} of them fetched after the server came back (${r.reloads} reloaded as stale)`);
    check(r.error === null && Math.abs(r.lat + 40) < 1e-6 && r.loaded > 0, `the view did not converge after reconnecting: ${JSON.stringify([r.error, r.lat, r.loaded])}`);
    // (whether they come as stale chunks reloaded or as chunks of the zoomed view fetched anew is
    // a race between the edit stream's hello and the first chunk answers: the check asked for
    // reloads and failed once when the zoomed view's chunks won)
    check(notFetched.length === 0, `chunks shown as they were before the edit made while the page was away: ${notFetched.slice(0, 10).join(', ')}`);
    // the requests refused while the server was gone were the point (the browser reports them)
    const refused = /Failed to load resource|ERR_CONNECTION_REFUSED|502 \(Bad Gateway\)/;
    problems.splice(before, problems.length - before, ...problems.slice(before).filter((p) => !refused.test(p)));
    await context.close();
    await again.stop();
    await server.stop();
  }
  check(problems.length === 0, `console messages:\n  ${problems.join('\n  ')}`);
  await browser.close();
}
