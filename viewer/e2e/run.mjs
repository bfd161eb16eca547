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
//   PMC_E2E_DEM     the elevation model steps 11, 14 and 15 import (default: NOAA's ETOPO5 of
//                   Debian's ferret-datasets where installed, else pmc-dem's ETOPO60 fixture)
//   PMC_E2E_IMAGERY an image step 11 drapes over it (default: none)
//   PMC_E2E_GALLERY=1  also step 16, the README's gallery (pictures with the sky: see
//                   scenarios/gallery.mjs)
//   PMC_E2E_SKY=1   the atmosphere on in every step (by default only step 12, the sky's, turns it
//                   on: the software renderer draws it slowly)
//   PMC_E2E_LANES=1 one step after the other (by default CesiumJS's, step 19, the 3D Tiles
//                   mode's, step 20, and the default planet's levels of detail, step 9, run in
//                   browsers of their own beside the others; the soak, step 18, runs last and
//                   alone)
//   PMC_E2E_GL      llvmpipe or swiftshader: the software renderer of WebGL (by default Mesa's
//                   llvmpipe where installed; the flights always draw with SwiftShader)
//   PMC_E2E_SERVE_ARGS more options for every `pmc serve`, e.g. '--cache-mb 16' (a stall hunt)
//
// The harness is harness.mjs (settings, log, clean-ups, steps), servers.mjs (pmc serve, the front
// server, the mock) and browser.mjs (Chromium, its page and the helpers the steps use); each step
// is a scenario of its own in scenarios/, and the steps compute their views with the viewer's own
// frame maths (src/frames.ts, loaded by viewerModule.mjs).
//
// Screenshots go to e2e/artifacts/. Exits non-zero with a message when a test fails; the server
// and the browser are stopped in every case.

import { existsSync, mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { openBrowser } from './browser.mjs';
import { CHROMIUM, FLIGHTS_GL, GALLERY, GL, LAYOUT, TOTAL_MS, USE_MOCK, artifacts, cleanup, distDir, fail, log, results, selected, short, started, step } from './harness.mjs';
import * as cesiumTiles from './scenarios/cesiumTiles.mjs';
import * as closeup from './scenarios/closeup.mjs';
import * as editing from './scenarios/editing.mjs';
import * as elevationModel from './scenarios/elevationModel.mjs';
import * as gallery from './scenarios/gallery.mjs';
import * as imagery from './scenarios/imagery.mjs';
import * as levelSwitch from './scenarios/levelSwitch.mjs';
import * as lodDefault from './scenarios/lodDefault.mjs';
import * as lodEarth from './scenarios/lodEarth.mjs';
import * as newChunks from './scenarios/newChunks.mjs';
import * as overlays from './scenarios/overlays.mjs';
import * as pageLoads from './scenarios/pageLoads.mjs';
import * as pathAndNavGrid from './scenarios/pathAndNavGrid.mjs';
import * as planetDrawn from './scenarios/planetDrawn.mjs';
import * as presetSwitch from './scenarios/presetSwitch.mjs';
import * as seaByData from './scenarios/seaByData.mjs';
import * as sky from './scenarios/sky.mjs';
import * as soak from './scenarios/soak.mjs';
import * as tilesMode from './scenarios/tilesMode.mjs';
import * as viewsAndModes from './scenarios/viewsAndModes.mjs';
import { startBackend } from './servers.mjs';

const watchdog = setTimeout(() => void fail(`the whole run took longer than ${TOTAL_MS / 60000} minutes`), TOTAL_MS);
for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => void fail(`interrupted (${sig})`));

/**
 * The scenarios in the order they run: a scenario may go on from what an earlier one left (the
 * page and its planet, the orbit picture of step 2, the server of step 5).
 */
const SCENARIOS = [pageLoads, planetDrawn, presetSwitch, newChunks, viewsAndModes, closeup];
/**
 * Then those that need the real `pmc serve` (the mock has no /path, /navgrid or editing API), and
 * the colours by place and the sea over true-scale planets, and the sea by the data (servers of
 * their own).
 */
const REAL_SERVER_SCENARIOS = [pathAndNavGrid, editing, sky, imagery, overlays, levelSwitch, seaByData];
/**
 * The flights over true-scale planets (the earth preset, an elevation model): after those, in the
 * first lane's own browser for FLIGHTS_GL.
 */
const FIRST_LANE_FLIGHTS = [lodEarth, elevationModel];
/**
 * The planet's 3D Tiles in CesiumJS (the longest step) and in the viewer's 3D Tiles mode, then the
 * default planet's levels of detail, each with servers of their own: in browsers of their own
 * beside the first lane (PMC_E2E_LANES, by default 2), the two lanes of about the same length.
 */
const SECOND_LANE = [cesiumTiles, tilesMode, lodDefault];
/** The steps whose pictures with back faces flagged are drawn by FLIGHTS_GL (harness.mjs). */
const FLIGHTS = new Set([lodEarth, elevationModel, lodDefault]);
/** Then, alone on the machine (it compares the times of its views): the soak. */
const LAST = [soak];
const LANES = Number(process.env.PMC_E2E_LANES ?? 2);

async function main() {
  if (!existsSync(join(distDir, 'index.html'))) throw new Error('viewer/dist is missing: run `npm run build` first');
  if (!existsSync(CHROMIUM)) throw new Error(`no browser at ${CHROMIUM} (install Debian's chromium or set CHROMIUM)`);
  mkdirSync(artifacts, { recursive: true });

  const pageBase = (await startBackend(LAYOUT)).url;
  const browser = await openBrowser();
  const t = {
    ...browser,
    /**
     * What the scenarios hand on: the page's first URL, step 1's stats and step 2's picture from
     * orbit, and the server of step 5 (default layout, no world), reused by step 8.
     */
    shared: { pageBase, orbitStats: null, orbitImg: null, closeup: null },
  };
  // Each lane's browsers, one for each renderer its steps draw with, each opened when a step
  // first needs it: their own pages, consoles and requests (the first lane's default one is t).
  const lanes = [new Map([[GL, t]]), new Map()];
  const browserFor = async (lane, gl) => {
    const browsers = lanes[LANES < 2 ? 0 : lane];
    if (!browsers.has(gl)) browsers.set(gl, { ...(await openBrowser(gl)), shared: t.shared });
    return browsers.get(gl);
  };
  const runOn = async (lane, steps) => {
    for (const s of steps.filter((s) => selected(s.name))) {
      const on = await browserFor(lane, FLIGHTS.has(s) ? FLIGHTS_GL : GL);
      await step(s.name, () => s.scenario(on));
    }
  };
  const firstLane = async () => {
    for (const s of SCENARIOS) await step(s.name, () => s.scenario(t));
    if (USE_MOCK) {
      log('8. and 7. need the real `pmc serve` (the mock has no /path, /navgrid or editing API): not run with PMC_E2E_MOCK=1');
      return;
    }
    for (const s of REAL_SERVER_SCENARIOS) await step(s.name, () => s.scenario(t));
    await runOn(0, FIRST_LANE_FLIGHTS);
  };
  const secondLane = async () => {
    if (!USE_MOCK) await runOn(1, SECOND_LANE);
  };
  if (LANES >= 2 && !USE_MOCK && SECOND_LANE.some((s) => selected(s.name))) {
    await Promise.all([firstLane(), secondLane()]);
  } else {
    await firstLane();
    await secondLane();
  }
  if (!USE_MOCK) for (const s of LAST) await step(s.name, () => s.scenario(t));
  // the README's pictures: asked for (PMC_E2E_GALLERY=1, or PMC_E2E_ONLY naming step 16)
  if (GALLERY) await step(gallery.name, () => gallery.scenario(t));
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
