// Places of the terrain projected into screenshots: vertices of the chunks shown (from the test
// hook's `places`), kept where they are plainly visible, and the colour drawn around them.

import { VIEWPORT } from './harness.mjs';

/**
 * Up to `count` vertices of the chunks shown that are plainly visible: inside the canvas by
 * `margin` pixels, facing the camera (the cosine between normal and view above `minFacing`, and
 * between the local vertical and view above `minUpFacing`: away from the limb),
 * with `keep(place)` true.
 */
export async function visiblePlaces(hook, count, keep = () => true, { margin = 4, minFacing = 0.4, minUpFacing = 0.3 } = {}) {
  // (as JSON text: Playwright's own serialisation of 20 000 places took 4 s, the text 0.4 s)
  const all = JSON.parse(await hook((n) => JSON.stringify(window.__pmc.places(n)), count));
  return all.filter(
    (p) =>
      p.screen !== null &&
      p.screen[0] >= margin &&
      p.screen[0] < VIEWPORT.width - margin &&
      p.screen[1] >= margin &&
      p.screen[1] < VIEWPORT.height - margin &&
      p.facing > minFacing &&
      p.upFacing > minUpFacing &&
      keep(p),
  );
}

/** The mean colour (8-bit sRGB) of the 3 x 3 pixels around (x, y) of a decoded screenshot. */
export function colourAround(img, x, y) {
  const cx = Math.round(x - 0.5);
  const cy = Math.round(y - 0.5);
  const sum = [0, 0, 0];
  let n = 0;
  for (let dy = -1; dy <= 1; dy++) {
    for (let dx = -1; dx <= 1; dx++) {
      const px = Math.min(img.width - 1, Math.max(0, cx + dx));
      const py = Math.min(img.height - 1, Math.max(0, cy + dy));
      const i = 4 * (py * img.width + px);
      sum[0] += img.data[i];
      sum[1] += img.data[i + 1];
      sum[2] += img.data[i + 2];
      n++;
    }
  }
  return sum.map((v) => v / n);
}

/** The colour (8-bit sRGB) of the pixel that (x, y) falls in. */
export function colourAt(img, x, y) {
  const px = Math.min(img.width - 1, Math.max(0, Math.floor(x)));
  const py = Math.min(img.height - 1, Math.max(0, Math.floor(y)));
  const i = 4 * (py * img.width + px);
  return [img.data[i], img.data[i + 1], img.data[i + 2]];
}

/** The `q` quantile (0..1) of `values`. */
export function quantile(values, q) {
  if (values.length === 0) return NaN;
  const s = [...values].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
}
