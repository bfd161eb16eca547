// Step 3: moving near the surface elsewhere loads new chunks.

import { check, log } from '../harness.mjs';
import { backgroundOf, fractionNot } from '../images.mjs';

export const name = '3. moving near the surface elsewhere loads new chunks';

export async function scenario(t) {
  const { consoleProblems, chunkRequests, hook, ready, shot } = t;
  const before = await hook(() => window.__pmc.stats());
  const requestsBefore = chunkRequests.length;
  // the far side of the planet, low, looking toward the horizon
  await hook(() => window.__pmc.setCamera(-25, -160, 60, 30, -20));
  const after = await ready('near the surface');
  const newKeys = after.loadedKeys.filter((k) => !before.loadedKeys.includes(k));
  const requests = chunkRequests.length - requestsBefore;
  log(`  ${requests} chunk requests, ${newKeys.length} new chunks loaded, ${before.loadedKeys.length - (after.loadedKeys.length - newKeys.length)} unloaded; mode ${after.mode}`);
  check(requests > 0, 'no chunk asked for after moving the camera');
  check(newKeys.length > 0, 'no new chunk loaded after moving the camera');
  check(after.mode === 'fly', `mode is ${after.mode}, expected fly`);
  const img = await shot('low');
  const frac = fractionNot(img, backgroundOf(img));
  check(frac > 0.2, `the low view is mostly background (${(100 * frac).toFixed(1)} % drawn)`);
  check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
}
