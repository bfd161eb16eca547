// Step 14: colour by place, not by mesh: at the same view with lighting off, forcing the terrain
// to level L and then to level L + 1 changes its colour by at most ΔE 3 (CIE76) at the land
// places both levels draw in the same pixel (its centre and its four antialiasing samples on
// the same ground at both levels: where the shape did not change), on the default planet
// (earthlike) from 6 km, on the earth preset from 100 km and on an elevation model (ETOPO5 where
// installed) from 2 500 km, with no place over. Over the elevation model every land place is
// compared, wherever the two levels' surfaces lie: the regression test of "the snow line jumped
// at a chunk border over Tibet". On the default planet: "the shore and the snow line moved with
// the level" (the jitter noise's lattice wrapped differently from chunk to chunk: shaders.ts,
// JITTER_SCALE).

import { check, importedDem, log } from '../harness.mjs';
import { colourAt, quantile, visiblePlaces } from '../places.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { deltaE76 } = await viewerModule('colour.ts');

export const name = '14. colour by place: the same view at levels L and L + 1 differs by at most ΔE 3 on land (lighting off), on earthlike, the earth preset and an elevation model (ETOPO5)';

/** Largest ΔE allowed at a place (CIE76). */
export const MAX_DELTA_E = 3;
/** Land places compared at most per view. */
const MAX_PLACES = 3500;

/** A pixel's centre and its four samples with 4x antialiasing (the standard pattern), pixels. */
const PIXEL_SAMPLES = [[0, 0], [-0.125, -0.375], [0.375, -0.125], [-0.375, 0.125], [0.125, 0.375]];

/** Metres between two planet-frame points along the ground: the part of `q - p` across `p`'s vertical. */
function acrossGround(p, q) {
  const r = Math.hypot(...p);
  const d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
  const along = (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]) / r;
  return Math.hypot(d[0] - (along * p[0]) / r, d[1] - (along * p[1]) / r, d[2] - (along * p[2]) / r);
}

/**
 * The view `cam` ([lat, lon, height, heading, pitch]) with every chunk at level `fine`, then at
 * `fine + 1`: the colour of the pixel of each land vertex of the fine view (the triangles around
 * it at least `minHeight` above the datum, dropping at most `maxDrop` from it) where both levels
 * draw the same ground (the surfaces under the pixel's centre and its four antialiasing samples
 * within `tolerance` metres of each other at the two levels: where the shape did not change),
 * compared. With `acrossOnly`, `tolerance` bounds the distance along the ground alone (the coarse
 * surface may lie anywhere above or below: the same latitude and longitude is the same place for
 * materials that go by the place, not by the mesh). Returns the ΔEs.
 */
export async function compareLevels(t, label, cam, fine, minHeight, tolerance, acrossOnly = false, maxDrop = Infinity) {
  const { hook, ready, shot } = t;
  await hook(() => window.__pmc.debug({ lighting: false }));
  const shots = [];
  const pickAll = async (points) => JSON.parse(await hook((pts) => JSON.stringify(pts.map(([x, y]) => window.__pmc.pick(x, y)?.point ?? null)), points));
  // the places drawn in a vertex's pixel: the surface under its centre and its four antialiasing
  // samples (the pixel's colour is theirs, up to half a pixel from the vertex)
  const samplesOf = (p) => PIXEL_SAMPLES.map(([dx, dy]) => [Math.floor(p.screen[0]) + 0.5 + dx, Math.floor(p.screen[1]) + 0.5 + dy]);
  const same = (a, b) => a !== null && b !== null && (acrossOnly ? acrossGround(a, b) : Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2])) <= tolerance;
  let places = null;
  let fineHits = null;
  for (const level of [fine, fine + 1]) {
    await hook((l) => window.__pmc.lod({ finestLevel: l, maxPixelError: 0.01, maxChunks: 4000 }), level);
    await hook((c) => window.__pmc.setCamera(...c), cam);
    const st = await ready(`${label} at level ${level}`);
    check(st.lod.levelsText === `L${level} ${st.shown}` || st.lod.levelsText.startsWith(`L${level} `), `${label}: the view is not at level ${level} alone: ${st.lod.levelsText}`);
    shots.push(await shot(`${label}-L${level}`));
    if (level === fine) {
      const all = await visiblePlaces(hook, 20000, (p) => p.ringMin >= minHeight && p.level === fine && p.height - p.ringMin <= maxDrop, { minFacing: 0.5 });
      // (at most MAX_PLACES of them, evenly spread: each costs up to five picks at each level)
      const stride = Math.max(1, Math.ceil(all.length / MAX_PLACES));
      places = all.filter((_, i) => i % stride === 0);
      fineHits = await pickAll(places.flatMap(samplesOf));
    }
  }
  // the pixels where both levels draw the same places (the shape did not change there): the
  // centres first, then the other samples of the pixels whose centres agree
  const n = PIXEL_SAMPLES.length;
  const centres = await pickAll(places.map((p) => samplesOf(p)[0]));
  const agree = places.map((_, i) => i).filter((i) => same(fineHits[n * i], centres[i]));
  const rest = await pickAll(agree.flatMap((i) => samplesOf(places[i]).slice(1)));
  const kept = agree.filter((i, j) => rest.slice((n - 1) * j, (n - 1) * (j + 1)).every((b, k) => same(fineHits[n * i + k + 1], b))).map((i) => places[i]);
  log(`  ${label}: ${kept.length} of ${places.length} land places' pixels where level ${fine + 1}'s surface lies within ${tolerance} m ${acrossOnly ? 'along the ground ' : ''}of level ${fine}'s`);
  places = kept;
  const des = places.map((p) => deltaE76(colourAt(shots[0], ...p.screen), colourAt(shots[1], ...p.screen)));
  const over = des.filter((d) => d > MAX_DELTA_E).length;
  if (process.env.PMC_E2E_VERBOSE) {
    const worst = places.map((p, i) => [des[i], p]).sort((x, y) => y[0] - x[0]).slice(0, 8);
    for (const [d, p] of worst) log(`    ΔE ${d.toFixed(1)} at ${p.screen.map((v) => v.toFixed(0))} h ${p.height.toFixed(1)} ring ${p.ringMin.toFixed(1)} facing ${p.facing.toFixed(2)} ${colourAt(shots[0], ...p.screen).map((v) => v.toFixed(0))} vs ${colourAt(shots[1], ...p.screen).map((v) => v.toFixed(0))}`);
  }
  log(
    `  ${label}: levels ${fine} and ${fine + 1}, ${des.length} land places: ΔE median ${quantile(des, 0.5).toFixed(2)}, ` +
      `95 % ${quantile(des, 0.95).toFixed(2)}, 99 % ${quantile(des, 0.99).toFixed(2)}, max ${Math.max(...des).toFixed(2)}, ${over} over ${MAX_DELTA_E}`,
  );
  check(des.length >= 100, `${label}: only ${des.length} land places in view`);
  return des;
}

/** The level most chunks of the view `cam` have when the selection is left to itself. */
async function naturalLevel(t, label, cam) {
  await t.hook((c) => window.__pmc.setCamera(...c), cam);
  const natural = await t.ready(label);
  const counts = [...natural.lod.levelsText.matchAll(/L(\d+) (\d+)/g)].map((m) => [Number(m[1]), Number(m[2])]);
  return counts.sort((a, b) => b[1] - a[1])[0][0];
}

export async function scenario(t) {
  const { page, hook, consoleProblems, failedResponses } = t;
  // the default planet (earthlike, seed 7) from orbit
  const server = await startBackend(null);
  await page.goto(`${server.url}#mode=orbit`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const detail = await hook(() => window.__pmc.lod());
  await hook(() => window.__pmc.mode('orbit'));
  const results = [];
  results.push(['earthlike 1-2', await compareLevels(t, 'levels-earthlike', [20, 30, 6000, 0, -90], 1, 1, 0.5)]);
  results.push(['earthlike 2-3', await compareLevels(t, 'levels-earthlike', [20, 30, 6000, 0, -90], 2, 1, 0.5)]);
  await hook((d) => window.__pmc.lod(d), detail);
  await hook(() => window.__pmc.debug({ lighting: true }));
  await page.goto('about:blank');
  await server.stop();
  // the earth preset at true scale: a mountain range with snow, rock and forest from 100 km
  const earth = await startBackend(null, { extra: ['--preset', 'earth'] });
  await page.goto(`${earth.url}#preset=earth&seed=7&mode=orbit&lat=39&lon=0`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await hook(() => window.__pmc.mode('orbit'));
  const earthCam = [39, 0, 100_000, 0, -90];
  const earthLevel = await naturalLevel(t, 'the earth preset from 100 km', earthCam);
  results.push([`earth ${earthLevel}-${earthLevel + 1}`, await compareLevels(t, 'levels-earth', earthCam, earthLevel, 1, 10)]);
  await hook((d) => window.__pmc.lod(d), detail);
  await hook(() => window.__pmc.debug({ lighting: true }));
  await page.goto('about:blank');
  await earth.stop();
  // an elevation model (by default the one-degree ETOPO60 fixture) over the Himalaya
  const dem = await importedDem();
  const demServer = await startBackend(null, { extra: ['--dem', dem] });
  await page.goto(`${demServer.url}#mode=orbit&lat=29&lon=86`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await hook(() => window.__pmc.mode('orbit'));
  // the level most chunks of the view have, and the next coarser one
  const demLevel = await naturalLevel(t, 'the elevation model over the Himalaya', [29, 86, 2_500_000, 0, -90]);
  // Every land place whose latitude and longitude the two levels share, wherever their surfaces
  // lie in height: "the snow line jumped at a chunk border over Tibet" (a straight seam across
  // the Himalaya from orbit, where a level-L chunk met a level-L+1 one). The materials went by
  // the mesh's interpolated height, and the coarser chunk's triangles pass hundreds of metres
  // under the finer one's peaks; they go by the elevation model's relief now (relief.ts), the
  // same at both levels. A pixel spans 4.5 km here; a place counts where the coarse surface under
  // its pixel lies within 1 km of it along the ground (off the nadir, a surface kilometres lower
  // is met farther out along the ray, at another place), away from the steepest slopes (the
  // triangles round it dropping at most 2 km: the Himalayan front climbs 400 m in a kilometre of
  // ETOPO5's grid, so a kilometre along it is another material).
  results.push([`dem ${demLevel}-${demLevel + 1}`, await compareLevels(t, 'levels-dem', [29, 86, 2_500_000, 0, -90], demLevel, 10, 1000, true, 2000)]);
  await hook((d) => window.__pmc.lod(d), detail);
  await hook(() => window.__pmc.debug({ lighting: true }));
  for (const [what, des] of results) {
    const over = des.filter((d) => d > MAX_DELTA_E);
    check(
      over.length === 0,
      `${what}: ${over.length} of ${des.length} land places change colour by more than ΔE ${MAX_DELTA_E} between levels ` +
        `(median ${quantile(des, 0.5).toFixed(2)}, largest ${Math.max(...des).toFixed(1)})`,
    );
  }
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await demServer.stop();
}
