// Step 15: the sea by the data: from far away, no sea is drawn over ground 10 m or more above the
// datum (the pixels at the land vertices are the same with the sea on and off), and the sea is
// drawn where the ground lies well below the datum; on an elevation model over the Himalaya and
// the Ganges plain from 2 500 km, and on the default planet from orbit. Then the Strait of
// Gibraltar from 30 km (ETOPO5): the shoreline drawn follows the data's 0 m contour within one
// data cell, the data projected into the screenshot through the terrain under each pixel.

import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { PMC_BIN, artifacts, check, cleanups, importedDem, log, run, viewerDir } from '../harness.mjs';
import { readDemGrid } from '../demGrid.mjs';
import { colourAt, visiblePlaces } from '../places.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { deltaE76 } = await viewerModule('colour.ts');
const { latLonFromPosition } = await viewerModule('frames.ts');

export const name = '15. the sea by the data: from far away no sea pixel over ground 10 m above the datum, the sea over ground below it (an elevation model over the Himalaya, the default planet); at Gibraltar from 30 km the shoreline within one data cell of the 0 m contour';

/**
 * The view `cam` with the sea on and off (lighting on, as a user sees it): at every vertex whose
 * triangles all lie `land` metres or more above the datum, the pixel or one beside it is the same
 * in both; the pixel at most vertices whose triangles all lie `deep` metres or more below it
 * changes.
 */
async function seaOnlyBelowDatum(t, label, cam, land, deep) {
  const { hook, ready, shot } = t;
  await hook((c) => window.__pmc.setCamera(...c), cam);
  await hook(() => window.__pmc.debug({ sea: true }));
  await ready(`${label} with the sea`);
  const withSea = await shot(`${label}-sea`);
  // (away from the limb, where a pixel holds a mountain's silhouette and the sea behind it)
  const places = await visiblePlaces(hook, 20000, () => true, { minFacing: 0.3, minUpFacing: 0.5 });
  await hook(() => window.__pmc.debug({ sea: false }));
  await ready(`${label} without the sea`);
  const without = await shot(`${label}-nosea`);
  await hook(() => window.__pmc.debug({ sea: true }));
  const high = places.filter((p) => p.ringMin >= land);
  const low = places.filter((p) => p.height <= -deep && p.ringMin <= -deep);
  // the vertex's pixel and the four beside it all changed (a vertex lands within a pixel of where
  // it projects, and a pixel at a ridge may hold water beyond it)
  const changed = (p, dx, dy) => deltaE76(colourAt(withSea, p.screen[0] + dx, p.screen[1] + dy), colourAt(without, p.screen[0] + dx, p.screen[1] + dy)) > 1;
  const seaOverLand = high.filter((p) => [[0, 0], [-1, 0], [1, 0], [0, -1], [0, 1]].every(([dx, dy]) => changed(p, dx, dy)));
  const seaOverSea = low.filter((p) => changed(p, 0, 0));
  log(`  ${label}: ${seaOverLand.length} of ${high.length} vertices ${land} m or more above the datum under sea; ${seaOverSea.length} of ${low.length} vertices ${deep} m or more below it under sea`);
  for (const p of seaOverLand.slice(0, 5)) log(`    sea over land at ${p.screen.map((v) => v.toFixed(0))}: height ${p.height.toFixed(1)} m`);
  check(high.length >= 100, `${label}: only ${high.length} land vertices in view`);
  check(seaOverLand.length === 0, `${label}: the sea is drawn over ${seaOverLand.length} vertices of ground ${land} m or more above the datum: see ${label}-sea.png`);
  if (low.length > 0) check(seaOverSea.length >= 0.9 * low.length, `${label}: the sea is missing over ${low.length - seaOverSea.length} of ${low.length} vertices ${deep} m under the datum`);
}

/**
 * The view `cam` of the elevation model `grid` (the one served) with the sea on and off, lighting
 * off: a pixel is sea where the two differ. Every `step`-th pixel whose terrain (picked under it)
 * lies inside the data: a sea pixel must have a data point at or below 0 m within one data cell,
 * a land pixel one at or above 0 m (the drawn shoreline is within one cell of the data's 0 m
 * contour), and nearly every pixel must agree with the sign of the data's bilinear interpolant.
 */
async function shorelineFollowsData(t, label, grid, cam, step = 16) {
  const { hook, ready, shot } = t;
  await hook((c) => window.__pmc.setCamera(...c), cam);
  await hook(() => window.__pmc.debug({ sea: true, lighting: false }));
  await ready(`${label} with the sea`);
  const withSea = await shot(`${label}-sea`);
  const picks = await hook(
    ([w, h, s]) => {
      const out = [];
      for (let y = s / 2; y < h; y += s) for (let x = s / 2; x < w; x += s) out.push({ x, y, hit: window.__pmc.pick(x, y) });
      return out;
    },
    [withSea.width, withSea.height, step],
  );
  await hook(() => window.__pmc.debug({ sea: false }));
  await ready(`${label} without the sea`);
  const without = await shot(`${label}-nosea`);
  await hook(() => window.__pmc.debug({ sea: true, lighting: true }));
  await ready(`${label}, as a user sees it`);
  await shot(`${label}-view`);

  let sea = 0;
  let land = 0;
  let agree = 0;
  const far = [];
  /** Per pixel: x, y, latitude, longitude, sea (1) or land (0), the interpolant, the extremes within a cell. */
  const rows = [];
  for (const p of picks) {
    if (!p.hit) continue;
    const { lat, lon } = latLonFromPosition(p.hit.point);
    if (!grid.covers(lat, lon, 1)) continue;
    const isSea = deltaE76(colourAt(withSea, p.x, p.y), colourAt(without, p.x, p.y)) > 1;
    const { min, max } = grid.around(lat, lon, 1);
    const data = grid.bilinear(lat, lon);
    rows.push([p.x, p.y, +lat.toFixed(5), +lon.toFixed(5), isSea ? 1 : 0, Math.round(data), min, max]);
    if (isSea) sea++;
    else land++;
    if (isSea === data < 0) agree++;
    if ((isSea && min > 0) || (!isSea && max < 0)) far.push({ ...p, lat, lon, isSea, data, min, max });
  }
  const n = sea + land;
  writeFileSync(join(artifacts, `${label}-pixels.json`), JSON.stringify(rows));
  log(
    `  ${label}: ${n} pixels over the data, ${sea} sea, ${land} land; ${agree} (${((100 * agree) / Math.max(1, n)).toFixed(1)}%) agree with the sign of the data's bilinear interpolant; ` +
      `${far.length} farther than one data cell from the 0 m contour`,
  );
  for (const p of far.slice(0, 5)) {
    log(`    ${p.isSea ? 'sea' : 'land'} at pixel ${p.x}, ${p.y} (${p.lat.toFixed(3)}, ${p.lon.toFixed(3)}): data ${p.data.toFixed(0)} m, ${p.min} .. ${p.max} m within a cell`);
  }
  check(n >= 0.5 * picks.length, `${label}: only ${n} of ${picks.length} pixels show the data`);
  check(sea >= 0.1 * n && land >= 0.1 * n, `${label}: ${sea} sea and ${land} land pixels: the view misses the coast`);
  check(far.length === 0, `${label}: ${far.length} pixels drawn as ${far[0]?.isSea ? 'sea' : 'land'} farther than one data cell from the data's 0 m contour: see ${label}-sea.png`);
  check(agree >= 0.97 * n, `${label}: only ${agree} of ${n} pixels agree with the sign of the data's interpolant`);
}

export async function scenario(t) {
  const { page, hook, consoleProblems, failedResponses } = t;
  const dem = await importedDem();
  const server = await startBackend(null, { extra: ['--dem', dem] });
  await page.goto(`${server.url}#mode=orbit&lat=26&lon=86`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await hook(() => window.__pmc.mode('orbit'));
  // the Himalaya, the Ganges plain and the Bay of Bengal from 2 500 km
  await seaOnlyBelowDatum(t, 'sea-himalaya', [24, 86, 2_500_000, 0, -90], 10, 50);
  await page.goto('about:blank');
  await server.stop();
  const planet = await startBackend(null);
  await page.goto(`${planet.url}#mode=orbit`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await hook(() => window.__pmc.mode('orbit'));
  await seaOnlyBelowDatum(t, 'sea-earthlike', [20, 30, 6000, 0, -90], 2, 2);
  await page.goto('about:blank');
  await planet.stop();

  // the Strait of Gibraltar from 30 km, straight down, heights interpolated bilinearly (the sea
  // is where that interpolant is below 0 m: the detail noise fades out toward the datum)
  const coastSource = resolve(viewerDir, '../crates/pmc-dem/tests/fixtures/landmarks/coast.cdf');
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-sea-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const coast = join(dir, 'coast.pmcdem');
  const coastImport = await run(PMC_BIN, ['dem', 'import', coastSource, '-o', coast, '--quiet'], 300_000);
  check(coastImport.code === 0, `pmc dem import failed: ${coastImport.out}`);
  const strait = await startBackend(null, { extra: ['--dem', coast, '--interpolation', 'bilinear'] });
  await page.goto(`${strait.url}#mode=fly&lat=35.9&lon=-5.6`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await hook(() => window.__pmc.mode('fly'));
  await shorelineFollowsData(t, 'sea-gibraltar', readDemGrid(coastSource), [35.9, -5.6, 30_000, 0, -90]);
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await strait.stop();
}
