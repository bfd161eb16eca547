// Step 14: colour by place, not by mesh: at the same view with lighting off, forcing the terrain
// to level L and then to level L + 1 changes its colour by at most ΔE 3 (CIE76) at the land places
// where the two levels' surfaces meet, on the earth preset from 100 km and on an elevation model
// (ETOPO5 where installed) from 2 500 km; on the default planet (earthlike,
// 1.9 km to the sea, a shore band 3 m high) at most 15 % of them differ by more (see SHARE_OVER),
// the median by at most 0.5. Over the elevation model every land place is compared, wherever
// the two levels' surfaces lie: the regression test of "the snow line jumped at a chunk border
// over Tibet".

import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { DEM_SOURCE, PMC_BIN, check, cleanups, log, run } from '../harness.mjs';
import { colourAt, quantile, visiblePlaces } from '../places.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { deltaE76 } = await viewerModule('colour.ts');

export const name = '14. colour by place: the same view at levels L and L + 1 differs by at most ΔE 3 on land (lighting off), on earthlike, the earth preset and an elevation model (ETOPO5)';

/** Largest ΔE allowed at a place (CIE76). */
export const MAX_DELTA_E = 3;
/**
 * The share of places on the default planet allowed over MAX_DELTA_E: on a planet this small the
 * lines between materials lie a metre or two apart in height (the shore's sand band is 3 m
 * high), and the pixel a place falls in is up to 0.7 pixels (7 m of ground) off it, where the
 * coarse level's flat triangles lie up to 0.6 m lower and meet the ray at another place, on
 * another side of a line. The materials' height comes from the planet's ground grid here (the
 * relief, 11.7 m cells), not from the meshes: measured 1 % (levels 1-2) and 6 % (levels 2-3),
 * median 0 (8 % and 13 % with the meshes' heights).
 */
export const SHARE_OVER = 0.08;

/** Metres between two planet-frame points along the ground: the part of `q - p` across `p`'s vertical. */
function acrossGround(p, q) {
  const r = Math.hypot(...p);
  const d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
  const along = (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]) / r;
  return Math.hypot(d[0] - (along * p[0]) / r, d[1] - (along * p[1]) / r, d[2] - (along * p[2]) / r);
}

/**
 * The view `cam` ([lat, lon, height, heading, pitch]) with every chunk at level `fine`, then at
 * `fine + 1`: the colour around each land vertex of the fine view (the triangles around it at
 * least `minHeight` above the datum) where the coarse level's surface passes within `tolerance`
 * metres of it (where the shape did not change: the place under the pixel is the same), compared.
 * With `acrossOnly`, `tolerance` bounds the distance along the ground alone (the coarse surface
 * may lie anywhere above or below: the same latitude and longitude is the same place for
 * materials that go by the place, not by the mesh). Returns the ΔEs.
 */
export async function compareLevels(t, label, cam, fine, minHeight, tolerance, acrossOnly = false, maxDrop = Infinity) {
  const { hook, ready, shot } = t;
  await hook(() => window.__pmc.debug({ lighting: false }));
  const shots = [];
  let places = null;
  for (const level of [fine, fine + 1]) {
    await hook((l) => window.__pmc.lod({ finestLevel: l, maxPixelError: 0.01, maxChunks: 4000 }), level);
    await hook((c) => window.__pmc.setCamera(...c), cam);
    const st = await ready(`${label} at level ${level}`);
    check(st.lod.levelsText === `L${level} ${st.shown}` || st.lod.levelsText.startsWith(`L${level} `), `${label}: the view is not at level ${level} alone: ${st.lod.levelsText}`);
    shots.push(await shot(`${label}-L${level}`));
    if (level === fine + 1) {
      // where the coarse surface lies under each fine vertex's pixel
      const hits = await hook((ps) => ps.map((p) => window.__pmc.pick(p.screen[0], p.screen[1])?.point ?? null), places);
      const kept = [];
      places.forEach((p, i) => {
        const q = hits[i];
        if (!q) return;
        const off = acrossOnly ? acrossGround(p.point, q) : Math.hypot(q[0] - p.point[0], q[1] - p.point[1], q[2] - p.point[2]);
        if (off <= tolerance) kept.push(p);
      });
      log(`  ${label}: ${kept.length} of ${places.length} land places where level ${fine + 1}'s surface lies within ${tolerance} m ${acrossOnly ? 'along the ground ' : ''}of level ${fine}'s`);
      places = kept;
    }
    if (level === fine) places = await visiblePlaces(hook, 20000, (p) => p.ringMin >= minHeight && p.level === fine && p.height - p.ringMin <= maxDrop, { minFacing: 0.5 });
  }
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
  results.push(['earthlike 1-2', SHARE_OVER, await compareLevels(t, 'levels-earthlike', [20, 30, 6000, 0, -90], 1, 1, 0.25)]);
  results.push(['earthlike 2-3', SHARE_OVER, await compareLevels(t, 'levels-earthlike', [20, 30, 6000, 0, -90], 2, 1, 0.25)]);
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
  results.push([`earth ${earthLevel}-${earthLevel + 1}`, 0, await compareLevels(t, 'levels-earth', earthCam, earthLevel, 1, 5)]);
  await hook((d) => window.__pmc.lod(d), detail);
  await hook(() => window.__pmc.debug({ lighting: true }));
  await page.goto('about:blank');
  await earth.stop();
  // an elevation model (by default the one-degree ETOPO60 fixture) over the Himalaya
  const source = DEM_SOURCE;
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-levels-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const dem = join(dir, 'earth.pmcdem');
  const imported = await run(PMC_BIN, ['dem', 'import', source, '-o', dem, '--quiet'], 300_000);
  check(imported.code === 0, `pmc dem import failed: ${imported.out}`);
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
  results.push([`dem ${demLevel}-${demLevel + 1}`, 0, await compareLevels(t, 'levels-dem', [29, 86, 2_500_000, 0, -90], demLevel, 10, 1000, true, 2000)]);
  await hook((d) => window.__pmc.lod(d), detail);
  await hook(() => window.__pmc.debug({ lighting: true }));
  for (const [what, share, des] of results) {
    const over = des.filter((d) => d > MAX_DELTA_E);
    check(
      over.length <= share * des.length && quantile(des, 0.5) <= 0.5,
      `${what}: ${over.length} of ${des.length} land places change colour by more than ΔE ${MAX_DELTA_E} between levels ` +
        `(at most ${(100 * share).toFixed(0)} % allowed; median ${quantile(des, 0.5).toFixed(2)}, largest ${Math.max(...des).toFixed(1)})`,
    );
  }
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await demServer.stop();
}
