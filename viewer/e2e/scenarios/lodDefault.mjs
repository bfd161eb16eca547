// Step 9: levels of detail on the default planet: orbit to 2 m, a zoom down and back up, no crack,
// no hole.

import { lodFlight } from '../lodFlight.mjs';
import { startBackend } from '../servers.mjs';

export const name = '9. levels of detail on the default planet: orbit to 2 m, a zoom down and back up, no crack, no hole';

export async function scenario(t) {
  const { page, ready, flightHarness } = t;
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
}
