// Step 4: switching the preset (select → moon) changes the picture.

import { check, log } from '../harness.mjs';
import { fractionDifferent } from '../images.mjs';

export const name = '4. switching the preset (select → moon) changes the picture';

export async function scenario(t) {
  const { page, hook, ready, shot, openPanel } = t;
  const { orbitImg } = t.shared;
  // the preset picker is in the side panel (folded away on a first visit)
  await openPanel(['planet']);
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
}
