// Step 10: the Earth at true scale: orbit and 2 m over an ocean floor, orbit, 10 km, 100 m and 2 m
// over mountains, no crack or hole, no jitter at 6.4e6 m.

import { check, log } from '../harness.mjs';
import { lodFlight } from '../lodFlight.mjs';
import { startBackend } from '../servers.mjs';

export const name = '10. the Earth at true scale: orbit and 2 m over an ocean floor, orbit, 10 km, 100 m and 2 m over mountains, no crack or hole, no jitter at 6.4e6 m, no grid in the haze from orbit';

export async function scenario(t) {
  const { page, ready, hook, flightHarness } = t;
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
  // the haze from orbit over the open sea (5° N, 100° E; the sky on): smooth. The aerial
  // perspective of a coarse chunk's triangles, which sag 1.8 km under the sphere between their
  // vertices, drew the mesh's grid into it: the luminance's mean absolute Laplacian over the sea
  // was 0.94, and is 0.33 with the haze taken at the place's own height
  await hook(() => window.__pmc.mode('orbit'));
  await hook(() => window.__pmc.setCamera(5, 100, 12_000_000, 0, -90));
  await hook(() => window.__pmc.sky({ atmosphere: true }));
  await ready('the Earth from orbit with the sky');
  const hazed = await t.shot('lod-earth-orbit-haze');
  await hook(() => window.__pmc.sky({ atmosphere: false }));
  const lum = (x, y) => {
    const i = 4 * (y * hazed.width + x);
    return 0.2126 * hazed.data[i] + 0.7152 * hazed.data[i + 1] + 0.0722 * hazed.data[i + 2];
  };
  let sum = 0;
  let n = 0;
  for (let y = 221; y < 290; y++) {
    for (let x = 421; x < 619; x++) {
      sum += Math.abs(4 * lum(x, y) - lum(x - 1, y) - lum(x + 1, y) - lum(x, y - 1) - lum(x, y + 1));
      n++;
    }
  }
  log(`  the haze over the sea from orbit: mean absolute Laplacian ${(sum / n).toFixed(3)}`);
  check(sum / n < 0.6, `the haze over the sea from orbit has the mesh's grid in it (mean absolute Laplacian ${(sum / n).toFixed(3)}): see lod-earth-orbit-haze.png`);
  await page.goto('about:blank');
  await server.stop();
}
