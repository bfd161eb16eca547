// Step 15: the sea by the data: from far away, no sea is drawn over ground 10 m or more above the
// datum (the pixels at the land vertices are the same with the sea on and off), and the sea is
// drawn where the ground lies well below the datum; on an elevation model over the Himalaya and
// the Ganges plain from 2 500 km, and on the default planet from orbit.

import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { PMC_BIN, check, cleanups, log, run, viewerDir } from '../harness.mjs';
import { colourAt, visiblePlaces } from '../places.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { deltaE76 } = await viewerModule('colour.ts');

export const name = '15. the sea by the data: from far away no sea pixel over ground 10 m above the datum, the sea over ground below it (an elevation model over the Himalaya, the default planet)';

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

export async function scenario(t) {
  const { page, hook, consoleProblems, failedResponses } = t;
  const source = process.env.PMC_E2E_DEM ? resolve(process.env.PMC_E2E_DEM) : resolve(viewerDir, '../crates/pmc-dem/tests/fixtures/etopo60.cdf');
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-sea-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const dem = join(dir, 'earth.pmcdem');
  const imported = await run(PMC_BIN, ['dem', 'import', source, '-o', dem, '--quiet'], 300_000);
  check(imported.code === 0, `pmc dem import failed: ${imported.out}`);
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
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await planet.stop();
}
