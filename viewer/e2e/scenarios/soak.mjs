// Step 18: a soak of teleports at true scale. Fifteen random places (a fixed seed) over the earth
// preset and fifteen over an imported elevation model (ETOPO5 where installed), each served with a
// small chunk cache (`--cache-mb 24`: the server drops and generates chunks again as a user who
// roams does), in small windows. At each place the camera is put 12 km over the datum looking
// down, then 100 m over the ground it found there, looking ahead: both views must converge (the
// selection's chunks exactly shown, nothing pending), and no view may wait longer than three times
// the median of its kind on its planet (a stalled view shows as one far past the others). Where a
// view does not converge, the viewer's streaming state and the server's job table are printed.
// The page is loaded with `#aa=0` (no antialiasing): the soak times streaming, not the renderer.

import { DEM_SOURCE, VIEWPORT, check, fetchText, importedDem, log } from '../harness.mjs';
import { quantile } from '../places.mjs';
import { startBackend } from '../servers.mjs';

export const name = '18. a soak of 30 teleports at true scale (the earth preset and ETOPO5, a small chunk cache): every view converges, none waits over 3x the median of its kind';

/** Teleports per planet. */
const PLACES = 15;
/** How long a view may take before the step reports it as stalled. */
const VIEW_MS = 90_000;
/**
 * The soak's windows, smaller than the other steps' (the software renderer draws them faster, and
 * a smaller window selects fewer chunks): the view from 12 km only finds the ground.
 */
const HIGH_WINDOW = { width: 256, height: 160 };
const LOW_WINDOW = { width: 384, height: 240 };

/** A small deterministic generator (mulberry32). */
function random(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

/** Places spread over the sphere (uniform in area), between 70° S and 70° N. */
function places(seed, n) {
  const next = random(seed);
  const out = [];
  while (out.length < n) {
    const lat = (Math.asin(2 * next() - 1) * 180) / Math.PI;
    const lon = 360 * next() - 180;
    if (Math.abs(lat) <= 70) out.push({ lat: Math.round(lat * 1e4) / 1e4, lon: Math.round(lon * 1e4) / 1e4 });
  }
  return out;
}

/** Runs the teleports over the planet `server` serves; returns the views' times by kind. */
async function soak(t, label, server, seed) {
  const { page, hook } = t;
  // without antialiasing (`aa=0`, which the link keeps): the soak times the streaming, and under
  // the software renderer multisampling about doubles every frame's cost
  await page.goto(`${server.url}#mode=fly&lat=0&lon=0&alt=12000000&pitch=-90&aa=0`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const attributes = await page.evaluate(() => document.querySelector('canvas').getContext('webgl2').getContextAttributes());
  check(attributes.antialias === false, `${label}: #aa=0 in the link gives a context without antialiasing (${JSON.stringify(attributes)})`);
  await hook((ms) => window.__pmc.ready(ms), VIEW_MS);
  /** Waits for the view to converge; on a stall, says what the page and the server were doing. */
  const converge = async (what) => {
    const t0 = Date.now();
    try {
      await hook((ms) => window.__pmc.ready(ms), VIEW_MS);
    } catch (e) {
      const page = await hook(() => {
        const s = window.__pmc.stats();
        return { stats: s, pending: window.__pmc.pendingRequests?.() ?? null };
      }).catch((err) => `(no state: ${err.message})`);
      const jobs = await fetchText(`${server.url}api/v1/stats`).catch((err) => `(no stats: ${err.message})`);
      throw new Error(`${label}: ${what} did not converge within ${VIEW_MS / 1000} s (${e.message}); page ${JSON.stringify(page).slice(0, 1500)}; server ${jobs.slice(0, 800)}`);
    }
    return (Date.now() - t0) / 1000;
  };
  const times = { high: [], low: [] };
  for (const [n, p] of places(seed, PLACES).entries()) {
    await page.setViewportSize(HIGH_WINDOW);
    await hook(([lat, lon]) => window.__pmc.setCamera(lat, lon, 12_000, 0, -90), [p.lat, p.lon]);
    const high = await converge(`12 km over ${p.lat}, ${p.lon}`);
    const s = await hook(() => window.__pmc.stats());
    // the ground under the camera, measured on the chunks shown (the datum where none is found)
    const ground = s.aboveGround === null ? 0 : Math.max(0, s.alt - s.aboveGround);
    await page.setViewportSize(LOW_WINDOW);
    await hook(([lat, lon, alt]) => window.__pmc.setCamera(lat, lon, alt, 0, -15), [p.lat, p.lon, ground + 100]);
    const low = await converge(`100 m over ${p.lat}, ${p.lon}`);
    const after = await hook(() => window.__pmc.stats());
    times.high.push(high);
    times.low.push(low);
    log(`  ${label} ${n + 1}: ${p.lat}, ${p.lon} (ground ${ground.toFixed(0)} m): 12 km ${high.toFixed(1)} s, 100 m ${low.toFixed(1)} s (${after.shown} chunks, ${after.requested} requests, ${after.failed} failed)`);
  }
  for (const [kind, list] of Object.entries(times)) {
    const median = quantile(list, 0.5);
    const worst = Math.max(...list);
    log(`  ${label}, ${kind === 'high' ? '12 km' : '100 m'} views: median ${median.toFixed(2)} s, longest ${worst.toFixed(2)} s (${(worst / median).toFixed(2)}x)`);
    // (a view that converges within two seconds is no stall, whatever the median)
    check(worst <= Math.max(3 * median, 2), `${label}: a ${kind === 'high' ? '12 km' : '100 m'} view waited ${worst.toFixed(1)} s, over 3x the median ${median.toFixed(2)} s`);
  }
  return times;
}

export async function scenario(t) {
  const { page } = t;
  try {
    const earth = await startBackend(null, { extra: ['--preset', 'earth', '--cache-mb', '24'] });
    await soak(t, 'earth', earth, 7);
    const dem = await importedDem();
    const model = await startBackend(null, { extra: ['--dem', dem, '--cache-mb', '24'] });
    await soak(t, /etopo5/i.test(DEM_SOURCE) ? 'ETOPO5' : 'the elevation model', model, 11);
  } finally {
    await page.setViewportSize(VIEWPORT);
  }
}
