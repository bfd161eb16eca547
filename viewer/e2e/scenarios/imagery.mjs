// Step 13: imagery draped by place: a planet whose `/planet` names a picture (a front server adds
// the `imagery` block and serves a synthetic equirectangular PNG) is coloured from it: from
// orbit, with lighting off, the colour drawn at the vertices of land chunks is the picture's
// colour at their latitude and longitude within 3 % per channel, around the antimeridian too.

import { check, log } from '../harness.mjs';
import { equirectPng, sampleEquirect, startImageryFront } from '../imageryFront.mjs';
import { decodePng } from '../images.mjs';
import { colourAt, quantile, visiblePlaces } from '../places.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { latLonFromPosition } = await viewerModule('frames.ts');

export const name = '13. imagery: from orbit, lighting off, the colour at the vertices of land chunks is the picture\'s at their latitude and longitude within 3 % per channel';

/** Largest difference per channel, of 255. */
const TOLERANCE = 0.03 * 255;

export async function scenario(t) {
  const { page, hook, ready, shot, consoleProblems, failedResponses } = t;
  const server = await startBackend(null);
  const extent = [-180, 180, -90, 90];
  const png = equirectPng(512, 256);
  const picture = decodePng(png);
  const front = await startImageryFront(server.api, png, extent);
  await page.goto(`${front.url}#mode=orbit`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await ready('a planet with imagery');
  const planet = await hook(() => fetch('api/v1/planet').then((x) => x.json()));
  check(planet.imagery?.width === 512 && planet.imagery?.url === '/api/v1/imagery', `the planet's imagery block is ${JSON.stringify(planet.imagery)}`);
  await hook(() => window.__pmc.mode('orbit'));
  await hook(() => window.__pmc.debug({ lighting: false }));
  const height = 3 * (planet.sea_radius ?? planet.radius);
  for (const [label, lat, lon] of [['imagery-orbit', 20, 30], ['imagery-antimeridian', -10, 180]]) {
    await hook((c) => window.__pmc.setCamera(...c), [lat, lon, height, 0, -90]);
    await ready(label);
    const img = await shot(label);
    // land vertices: the picture colours land, not the sea. From orbit the sea goes by the
    // planet's relief (its ground on 11.7 m cells, relief.ts), which lies within a voxel of the
    // mesh: the triangles round a vertex at least 2 m above the datum (0.5 m let in coast
    // vertices under the relief's sea, 2 of 326 in one run)
    const places = await visiblePlaces(hook, 4000, (p) => p.ringMin >= 2, { minFacing: 0.5 });
    const errors = [];
    let seam = 0;
    for (const p of places) {
      const ll = latLonFromPosition(p.point);
      if (Math.abs(Math.abs(ll.lon) - 180) < 10) seam++;
      const want = sampleEquirect(picture, extent, ll.lat, ll.lon);
      // the vertex's pixel, or one beside it (rasterised, a vertex lands within a pixel of where
      // it projects, and a neighbouring triangle may own the pixel it falls in)
      let best = Infinity;
      for (const [dx, dy] of [[0, 0], [-1, 0], [1, 0], [0, -1], [0, 1]]) {
        const got = colourAt(img, p.screen[0] + dx, p.screen[1] + dy);
        best = Math.min(best, Math.max(...[0, 1, 2].map((k) => Math.abs(got[k] - want[k]))));
      }
      errors.push(best);
    }
    const over = errors.filter((e) => e > TOLERANCE).length;
    if (process.env.PMC_E2E_VERBOSE) {
      places.forEach((p, i) => {
        if (errors[i] > TOLERANCE) log(`    ${errors[i].toFixed(1)} at ${p.screen.map((v) => v.toFixed(1))} h ${p.height.toFixed(1)} ring ${p.ringMin.toFixed(1)} facing ${p.facing.toFixed(2)} key ${p.key}`);
      });
    }
    log(
      `  ${label}: ${places.length} land vertices (${seam} within 10° of the antimeridian): largest channel difference ` +
        `median ${quantile(errors, 0.5).toFixed(1)}, 99 % ${quantile(errors, 0.99).toFixed(1)}, max ${Math.max(...errors).toFixed(1)} of 255; ${over} over ${TOLERANCE.toFixed(1)}`,
    );
    check(places.length >= 100, `${label}: only ${places.length} land vertices in view`);
    if (label === 'imagery-antimeridian') check(seam >= 20, `${label}: only ${seam} land vertices near the antimeridian`);
    check(over === 0, `${label}: ${over} of ${places.length} land vertices differ from the picture by more than 3 % in a channel (largest ${Math.max(...errors).toFixed(1)} of 255): see ${label}.png`);
  }
  await hook(() => window.__pmc.debug({ lighting: true }));
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await front.stop();
  await server.stop();
}
