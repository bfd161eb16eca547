// Step 2: the planet is drawn (orbit screenshot mostly not background).

import { check, log } from '../harness.mjs';
import { backgroundOf, colourCount, fractionNot } from '../images.mjs';

export const name = '2. the planet is drawn (orbit screenshot mostly not background)';

export async function scenario(t) {
  const { shot } = t;
  const { orbitStats } = t.shared;
  const orbitImg = await shot('orbit');
  t.shared.orbitImg = orbitImg;
  const bg = backgroundOf(orbitImg);
  const frac = fractionNot(orbitImg, bg);
  log(`  background rgb(${bg.join(',')}), ${(100 * frac).toFixed(1)} % of the pixels are planet, ${colourCount(orbitImg)} colours`);
  check(frac > 0.2, `only ${(100 * frac).toFixed(1)} % of the orbit screenshot differs from the background`);
  check(orbitStats.triangles > 1000, `only ${orbitStats.triangles} triangles loaded`);
}
