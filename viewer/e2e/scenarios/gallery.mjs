// Step 16 (with PMC_E2E_GALLERY=1, or PMC_E2E_ONLY=16): the README's gallery, as a user sees
// each view with the sky on: the default planet, the earth preset and the real Earth (ETOPO5
// with NASA's Visible Earth where installed, over the Bay of Naples) from orbit, 100 km (the
// default planet: 1 km), 10 km (100 m), 100 m (10 m) and 2 m above the ground, and a sunset from
// 30 m over the ground; and the README's two pictures of the viewer with its HUD
// (e2e/artifacts/readme-viewer-*.png; PMC_E2E_GALLERY_ONLY=viewer takes those alone). Each descent is
// the levels-of-detail flight of steps 9 and 10 (no crack, no hole at any stop); the pictures
// are e2e/artifacts/gallery-*-view.png and gallery-*-sunset.png.

import { existsSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { DEM_SOURCE, PMC_BIN, artifacts, check, cleanups, log, run } from '../harness.mjs';
import { lodFlight } from '../lodFlight.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { headingPitchOf, positionFromLatLon, sub } = await viewerModule('frames.ts');

export const name = '16. the gallery: the default planet, the earth preset and the real Earth from orbit to 2 m and at sunset, with the sky';

/** NASA's Visible Earth of Debian's xplanet-images. */
const EARTH_JPG = '/usr/share/xplanet/images/earth.jpg';

/**
 * Flies down over (`lat`, `lon`) through `stops`, then, 30 m over the last stop, looks toward a
 * sun 2° over the horizon.
 */
async function descent(t, label, lat, lon, stops) {
  const { hook, ready, shot } = t;
  await hook(() => window.__pmc.sky({ atmosphere: true, sunAzimuth: 135, sunElevation: 40 }));
  await lodFlight(t.flightHarness, { label, lat, lon, stops, pictures: true });
  // the sunset: at the last stop, the camera turned west a little above the horizon, the sun
  // 2° over the horizon ahead: the sea-level horizon, which lies acos(R / (R + h)) under the
  // horizontal (22° from 140 m on the default planet, where a sun 2° over the horizontal stood
  // high in a blue sky)
  const s = await hook(() => window.__pmc.stats());
  const planet = await hook(() => fetch('api/v1/planet').then((r) => r.json()));
  const datum = planet.sea_radius ?? (planet.base_radius + planet.radius) / 2;
  const dip = (Math.acos(datum / (datum + Math.max(0, s.alt + 30))) * 180) / Math.PI;
  await hook(([a, b, h, p]) => window.__pmc.setCamera(a, b, h, 270, p), [lat, lon, s.alt + 30, 4 - dip]);
  await hook((e) => window.__pmc.sky({ atmosphere: true, sunAzimuth: 270, sunElevation: e }), 2 - dip);
  await ready(`${label} at sunset`);
  await shot(`${label}-sunset`);
  await hook(() => window.__pmc.sky({ sunAzimuth: 135, sunElevation: 40 }));
}

export async function scenario(t) {
  const { page, hook } = t;
  // (on the small default planet the horizon lies 49° below it from 1 km: that stop looks down more)
  const stops = (heights, pitches = {}) => [
    { name: 'orbit', height: heights[0], orbit: true },
    ...heights.slice(1).map((h) => ({ name: `${h}m`, height: h, pitch: pitches[h] ?? -15 })),
  ];

  // PMC_E2E_GALLERY_ONLY=viewer,earthlike,earth,dem: some of the pictures (while working on a look)
  const only = (what) => !process.env.PMC_E2E_GALLERY_ONLY || process.env.PMC_E2E_GALLERY_ONLY.split(',').includes(what);

  // the README's two pictures of the viewer as a first visit sees it (the HUD, the go-to box, the
  // tool bar and the scale bar; the side panel folded away): the default planet from orbit, and
  // the close-up of step 5 (a ridge with overhangs and cave mouths over a bay)
  if (only('viewer')) {
    const server = await startBackend(null);
    await page.goto(`${server.url}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15&alt=3000`, { waitUntil: 'load', timeout: 60_000 });
    await page.evaluate(() => localStorage.removeItem('pmc.panel'));
    await page.reload({ waitUntil: 'load' });
    await page.waitForFunction(() => window.__pmc !== undefined && window.__pmc.stats().preset === 'earthlike', null, { timeout: 60_000 });
    await hook(() => window.__pmc.sky({ atmosphere: true, sunAzimuth: 135, sunElevation: 40 }));
    await t.ready('the viewer from orbit');
    // the HUD is refreshed five times a second
    await page.waitForTimeout(500);
    writeFileSync(join(artifacts, 'readme-viewer-orbit.png'), await page.screenshot());
    const planet = await hook(() => fetch('api/v1/planet?preset=earthlike&seed=7').then((r) => r.json()));
    const camRadius = 2250 * (planet.radius / 2000);
    const camera = positionFromLatLon(3, 9, camRadius);
    const { heading, pitch } = headingPitchOf(camera, sub(positionFromLatLon(-10, 8, planet.sea_radius), camera));
    await hook(([h, p, a]) => window.__pmc.setCamera(3, 9, a, h, p), [heading, pitch, camRadius - planet.sea_radius]);
    await t.ready('the viewer close to the ground');
    await page.waitForTimeout(500);
    writeFileSync(join(artifacts, 'readme-viewer-closeup.png'), await page.screenshot());
    await page.goto('about:blank');
    await server.stop();
  }

  // the default planet (earthlike, seed 7: 1.9 km to the sea): grass 5 m over the sea, a beach
  // and a lake ahead, a snowy ridge beyond
  // (as `pmc serve` serves it: not the other steps' coarser test layout)
  if (only('earthlike')) {
    const server = await startBackend(null);
    await page.goto(`${server.url}#preset=earthlike&seed=7&mode=orbit&lat=-34.28&lon=-52.56`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined && window.__pmc.stats().preset === 'earthlike', null, { timeout: 60_000 });
    await descent(t, 'gallery-earthlike', -34.28, -52.56, stops([6000, 1000, 100, 10, 2], { 1000: -60 }));
    await page.goto('about:blank');
    await server.stop();
  }

  // the earth preset at true scale: low land near the equator, 140 m above the sea
  if (only('earth')) {
    const earth = await startBackend(null, { extra: ['--preset', 'earth'] });
    await page.goto(`${earth.url}#preset=earth&seed=7&mode=orbit&lat=5&lon=100`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    await descent(t, 'gallery-earth', 5, 100, stops([12_000_000, 100_000, 10_000, 100, 2]));
    await page.goto('about:blank');
    await earth.stop();
  }
  if (!only('dem')) return;

  // the real Earth: ETOPO5 (where installed) with NASA's picture draped over it, the Bay of
  // Naples
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-gallery-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const dem = join(dir, 'earth.pmcdem');
  const args = ['dem', 'import', DEM_SOURCE, '-o', dem, '--quiet'];
  if (existsSync(EARTH_JPG)) args.push('--imagery', EARTH_JPG);
  const imported = await run(PMC_BIN, args, 300_000);
  check(imported.code === 0, `pmc dem import failed: ${imported.out}`);
  const extra = ['--dem', dem];
  if (existsSync(EARTH_JPG)) extra.push('--imagery', join(dir, 'earth.pmcimg'));
  log(`  the real Earth: ${DEM_SOURCE}${existsSync(EARTH_JPG) ? ` with ${EARTH_JPG}` : ''}`);
  const real = await startBackend(null, { extra });
  await page.goto(`${real.url}#mode=orbit&lat=40.85&lon=14.3`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await descent(t, 'gallery-dem', 40.85, 14.3, stops([12_000_000, 100_000, 10_000, 100, 2]));
  await hook(() => window.__pmc.sky({ atmosphere: false }));
  await page.goto('about:blank');
  await real.stop();
}
