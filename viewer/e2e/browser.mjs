// The browser of the steps: headless Chromium with one page, watched for console errors and
// warnings, uncaught errors and failed responses, and the helpers the steps drive pages with (the
// test hook `window.__pmc`, waiting for a settled view, screenshots).

import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { CHROMIUM, GL, READY_MS, VIEWPORT, artifacts, check, chromiumArgs, cleanups, log, withTimeout } from './harness.mjs';
import { decodePng } from './images.mjs';

/**
 * Launches Chromium with WebGL by `gl` (llvmpipe or swiftshader: see GL in harness.mjs); returns
 * its first page and the helpers, shared by every step.
 */
export async function openBrowser(gl = GL) {
  const profile = mkdtempSync(join(tmpdir(), 'pmc-e2e-chromium-'));
  cleanups.push(() => rmSync(profile, { recursive: true, force: true }));
  log(`launching ${CHROMIUM}`);
  const context = await withTimeout(
    chromium.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      headless: true,
      viewport: VIEWPORT,
      deviceScaleFactor: 1,
      args: chromiumArgs(gl),
    }),
    60_000,
    'launching Chromium',
  );
  cleanups.push(() => context.close());
  // The steps run with the atmosphere off (as a user leaves the sky panel's checkbox), since the
  // software renderer draws the sky and the haze slowly; the sky's step turns it on.
  // PMC_E2E_SKY=1 leaves it on everywhere (for the README's pictures).
  if (process.env.PMC_E2E_SKY !== '1') {
    await context.addInitScript(() => {
      // (about:blank, between the steps, has no storage)
      try {
        window.localStorage.setItem('pmc.atmosphere', 'off');
      } catch {
        // nothing to remember there
      }
    });
  }
  const page = context.pages()[0] ?? (await context.newPage());
  page.setDefaultTimeout(60_000);
  // the software renderer behind WebGL (GL in harness.mjs), said in the log and checked
  const renderer = await page.evaluate(() => {
    const context = document.createElement('canvas').getContext('webgl2');
    if (!context) return 'no WebGL 2';
    const info = context.getExtension('WEBGL_debug_renderer_info');
    return String(context.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : context.RENDERER));
  });
  log(`WebGL 2: ${renderer}`);
  if (!(gl === 'llvmpipe' ? /llvmpipe/ : /SwiftShader/).test(renderer)) {
    throw new Error(`the browser's WebGL is not ${gl} but ${renderer} (Mesa's llvmpipe needs Debian's libegl-mesa0 and libgl1-mesa-dri; PMC_E2E_GL=swiftshader uses Chromium's own)`);
  }

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
      const at = m.location()?.url ? ` (${m.location().url.replace(/^https?:\/\/[^/]+/, '')})` : '';
      consoleProblems.push(`${tag}${m.type()}: ${m.text()}${at}`);
    });
    p.on('pageerror', (e) => consoleProblems.push(`${tag}uncaught: ${e.message}`));
    p.on('response', (r) => {
      if (r.status() >= 400 && !expectedFailures.some((re) => re.test(r.url()))) failedResponses.push(`${tag}${r.status()} ${r.url()}`);
    });
  };
  watchPage(page);
  /** The chunks the page asked for: each of a batch (`POST /api/v1/chunk-batch`), or a request's own. */
  const chunkRequests = [];
  page.on('request', (r) => {
    if (r.url().includes('/api/v1/chunk/')) chunkRequests.push(r.url());
    if (r.url().includes('/api/v1/chunk-batch')) {
      let keys = [];
      try {
        keys = JSON.parse(r.postData() ?? '{}').chunks.map((c) => c.key);
      } catch {
        // not a batch the viewer would send: counted as nothing
      }
      chunkRequests.push(...keys);
    }
  });

  const hookOn = (p) => (fn, arg) => withTimeout(p.evaluate(fn, arg), READY_MS + 10_000, 'page.evaluate');
  const hook = hookOn(page);
  const readyOn = async (p, what) => {
    const t0 = Date.now();
    try {
      await hookOn(p)((ms) => window.__pmc.ready(ms), READY_MS);
    } catch (e) {
      // a view that does not converge: say what the streaming was doing (pending, missing, blocked
      // by a failure's back-off, timed out) for the report
      const s = await hookOn(p)(() => window.__pmc.stats()).catch((err) => `(no stats: ${err.message})`);
      throw new Error(`${what}: ${e.message}; streaming ${JSON.stringify(s).slice(0, 1500)}`);
    }
    const s = await hookOn(p)(() => window.__pmc.stats());
    log(`  ready ${what}: ${s.loaded} chunks, ${s.triangles} triangles, ${((Date.now() - t0) / 1000).toFixed(1)} s (${s.draws} draws in ${s.frames} frames so far, a draw ${Math.round(s.drawMs)} ms)`);
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
    await p.addStyleTag({ content: '.panel, #notices, #loading-bar { visibility: hidden !important; }' }).then((h) => h.evaluate((el) => el.setAttribute('id', 'e2e-hide')));
    // two more frames so the last chunks are on screen
    await hookOn(p)(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => r()))));
    const buf = await p.screenshot({ type: 'png', timeout: 60_000 });
    await p.evaluate(() => document.getElementById('e2e-hide')?.remove());
    writeFileSync(join(artifacts, `${name}.png`), buf);
    return decodePng(buf);
  };
  const shot = (name) => shotOf(page, name);
  /**
   * Opens the side panel of `p` (as a click on ☰ does) with `sections` unfolded (their
   * `data-section` names: stats, view, planet, detail, debug, sky).
   */
  const openPanelOf = async (p, sections = []) => {
    if ((await p.getAttribute('#panel-toggle', 'aria-expanded')) !== 'true') await p.click('#panel-toggle');
    for (const name of sections) {
      if (!(await p.$eval(`#side details[data-section="${name}"]`, (d) => d.open))) await p.click(`#side details[data-section="${name}"] > summary`);
    }
  };
  const openPanel = (sections) => openPanelOf(page, sections);
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

  return {
    context,
    page,
    consoleProblems,
    expectedFailures,
    failedResponses,
    watchPage,
    chunkRequests,
    hookOn,
    hook,
    readyOn,
    ready,
    waitFor,
    pathState,
    gridState,
    shotOf,
    shot,
    openPanelOf,
    openPanel,
    flightHarness,
  };
}
