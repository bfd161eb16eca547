// Step 5: close-up of mountains with caves and overhangs (earthlike seed 7, default layout).

import { check, log } from '../harness.mjs';
import { backgroundOf, colourCount, fractionNot } from '../images.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { headingPitchOf, positionFromLatLon, sub } = await viewerModule('frames.ts');

export const name = '5. close-up of mountains with caves and overhangs (earthlike seed 7, default layout)';

export async function scenario(t) {
  const { page, consoleProblems, failedResponses, hook, ready, shot } = t;
  // the README's close-up (`pmc render --lat 3 --lon 9 --distance 2250 --look-at=-10,8`) on the
  // default planet, from its own server: the small e2e planet is too coarse for caves
  const closeup = await startBackend(null);
  t.shared.closeup = closeup;
  const base = closeup.url;
  await page.goto(`${base}#preset=earthlike&seed=7&mode=fly`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const planet = await hook(() => fetch('api/v1/planet?preset=earthlike&seed=7').then((r) => r.json()));
  const camRadius = 2250 * (planet.radius / 2000);
  const target = positionFromLatLon(-10, 8, planet.sea_radius);
  const camera = positionFromLatLon(3, 9, camRadius);
  const { heading, pitch } = headingPitchOf(camera, sub(target, camera));
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
}
