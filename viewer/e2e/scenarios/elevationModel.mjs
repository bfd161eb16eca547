// Step 11: a real planet from an elevation model: imported, seen from orbit and near the ground
// with no crack or hole, land, shelf and deep ocean told apart, a cave dug under a mountain; the
// same model as a height field.

import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { DEM_SOURCE, PMC_BIN, VIEWPORT, check, cleanups, log, run } from '../harness.mjs';
import { crop, fractionDifferent } from '../images.mjs';
import { AS_SEEN, FLAGGED, TINTED_ALLOWED, flaggedPixels, tintedPixels } from '../lodFlight.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { latLonFromPosition, positionFromLatLon } = await viewerModule('frames.ts');
const { parseRelief, gridAtStride, reliefHeightAt } = await viewerModule('relief.ts');

export const name = '11. a real planet from an elevation model: imported, seen from orbit and near the ground with no crack or hole, land, shelf and deep ocean told apart, a cave dug under a mountain; the same model as a height field';

export async function scenario(t) {
  const { page, consoleProblems, failedResponses, hook, ready, waitFor, shot } = t;
  // ETOPO5 where installed (the README's pictures are taken over it), or PMC_E2E_DEM, or the
  // one-degree ETOPO60 fixture of pmc-dem's tests (harness.mjs)
  const source = DEM_SOURCE;
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-dem-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const dem = join(dir, 'earth.pmcdem');
  const imported = await run(PMC_BIN, ['dem', 'import', source, '-o', dem, '--quiet'], 300_000);
  check(imported.code === 0, `pmc dem import failed: ${imported.out}`);
  // PMC_E2E_IMAGERY: an image to drape over it (the README's pictures: NASA's Visible Earth,
  // /usr/share/xplanet/images/earth.jpg of Debian's xplanet-images)
  const imagery = [];
  if (process.env.PMC_E2E_IMAGERY) {
    const img = join(dir, 'earth.pmcimg');
    const made = await run(PMC_BIN, ['imagery', 'import', resolve(process.env.PMC_E2E_IMAGERY), '-o', img, '--quiet'], 120_000);
    check(made.code === 0, `pmc imagery import failed: ${made.out}`);
    imagery.push('--imagery', img);
  }
  const server = await startBackend(null, { world: join(dir, 'earth.pmcw'), extra: ['--dem', dem, ...imagery] });
  // over the East China Sea: China, Korea and Japan, the wide shelf of the Yellow and East
  // China Seas, the deep Philippine Sea
  await page.goto(`${server.url}#mode=orbit&lat=30&lon=127`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const first = await ready('the real Earth from orbit');
  check(first.preset === null, `the server serves the preset ${first.preset}, not the elevation model`);
  const planet = await hook(() => fetch('api/v1/planet').then((x) => x.json()));
  check(planet.terrain?.kind === 'dem' && planet.terrain.file === 'earth.pmcdem', `the planet is ${JSON.stringify(planet.terrain)}`);
  check(planet.materials.includes('deep seabed') && planet.materials.includes('shelf'), `materials ${planet.materials}`);
  // named by its world, its file and its body, in the panel and the title
  const named = 'earth.pmcw · earth.pmcdem · the Earth';
  await page.waitForFunction((n) => document.getElementById('s-planet')?.textContent === n, named, { timeout: 10_000 }).catch(() => undefined);
  const shown = [await page.textContent('#s-planet'), await page.title()];
  check(shown[0] === named && shown[1].startsWith(named), `the planet is named ${JSON.stringify(shown)}, not "${named}"`);
  await hook(() => window.__pmc.mode('orbit'));
  await hook(() => window.__pmc.setCamera(30, 127, 3_000_000, 0, -90));
  await ready('over the East China Sea');
  const view = await shot('dem-shelf-view');
  // the data: the elevation model's source grid, as the server serves it (/api/v1/relief)
  const reliefInfo = parseRelief(planet);
  check(reliefInfo !== null, `the planet of an elevation model has no relief: ${JSON.stringify(planet.relief)}`);
  const reliefGrid = gridAtStride(reliefInfo, 1);
  const reliefValues = new Float32Array(await (await fetch(new URL(reliefInfo.url, server.url))).arrayBuffer());
  check(reliefValues.length === reliefGrid.width * reliefGrid.height, `the relief holds ${reliefValues.length} values`);
  // every 16th pixel: what lies under it (the data's height where the ray meets the ground) and
  // its colour
  const hits = await hook(([w, h]) => {
    const out = [];
    for (let y = 8; y < h; y += 16) {
      for (let x = 8; x < w; x += 16) {
        const hit = window.__pmc.pick(x, y);
        if (hit) out.push({ x, y, point: hit.point });
      }
    }
    return out;
  }, [VIEWPORT.width, VIEWPORT.height]);
  const samples = hits.flatMap(({ x, y, point }) => {
    const { lat, lon } = latLonFromPosition(point);
    const h = reliefHeightAt(reliefGrid, reliefValues, lat, lon);
    return h === null ? [] : [{ x, y, h }];
  });
  const classes = { deep: [], shelf: [], land: [] };
  for (const p of samples) {
    const c = p.h < -1000 ? 'deep' : p.h < -10 && p.h > -180 ? 'shelf' : p.h > 50 ? 'land' : null;
    if (c) {
      const i = 4 * (p.y * view.width + p.x);
      classes[c].push([view.data[i], view.data[i + 1], view.data[i + 2]]);
    }
  }
  const mean = (cs) => cs.reduce((a, c) => a.map((v, k) => v + c[k] / cs.length), [0, 0, 0]);
  const means = Object.fromEntries(Object.entries(classes).map(([k, cs]) => [k, cs.length ? mean(cs) : null]));
  log(`  under the pixels: ${Object.entries(classes).map(([k, cs]) => `${k} ${cs.length} (mean colour ${means[k]?.map((v) => v.toFixed(0)).join(',')})`).join(', ')}`);
  for (const k of Object.keys(classes)) check(classes[k].length >= 10, `only ${classes[k].length} ${k} pixels over the East China Sea`);
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  for (const [a, b] of [['deep', 'shelf'], ['shelf', 'land'], ['deep', 'land']]) {
    check(dist(means[a], means[b]) > 20, `${a} and ${b} look alike: ${means[a]} and ${means[b]}`);
  }
  /** The view from (lat, lon) `height` m above the datum looking `pitch` degrees: no flagged pixel (no crack, no hole); a picture as a user sees it. */
  const look = async (name, lat, lon, height, pitch) => {
    await hook((f) => window.__pmc.debug(f), FLAGGED);
    await hook(([a, b, h, p]) => window.__pmc.setCamera(a, b, h, 0, p), [lat, lon, height, pitch]);
    const st = await ready(name);
    const flaggedImg = await shot(`${name}-flagged`);
    const flagged = flaggedPixels(flaggedImg);
    const tinted = tintedPixels(flaggedImg);
    log(`  ${name}: ${st.shown} chunks shown, levels ${st.lod.levelsText}, ${flagged} flagged pixels, ${tinted} tinted`);
    check(flagged === 0, `${name}: ${flagged} flagged pixels (a crack or a hole): see ${name}-flagged.png`);
    check(tinted <= TINTED_ALLOWED, `${name}: ${tinted} pixels tinted by the back-face flag: see ${name}-flagged.png`);
    await hook((f) => window.__pmc.debug(f), AS_SEEN);
    return shot(`${name}-view`);
  };
  /** The meshed ground at (lat, lon), metres above the datum, and its point (planet frame), from `pmc dem probe`. */
  const groundAt = async (lat, lon) => {
    const p = await run(PMC_BIN, ['dem', 'probe', dem, '--lat', String(lat), '--lon', String(lon), '--json'], 120_000);
    check(p.code === 0, `pmc dem probe failed: ${p.out}`);
    const height = JSON.parse(p.out).meshed[0].height;
    return { height, point: positionFromLatLon(lat, lon, planet.sea_radius + height) };
  };
  // the Himalaya from orbit, and a coast from 30 km: the pictures are the README's
  await hook(() => window.__pmc.mode('orbit'));
  await look('dem-himalaya-orbit', 29, 86, 2_500_000, -90);
  await hook(() => window.__pmc.mode('fly'));
  await look('dem-coast', 35.55, -5.6, 30_000, -35);
  // a cave dug under a mountain of the Alps, seen from 25 m above the ground a little south of
  // it (a coarser detail here: the software renderer of the tests draws slowly)
  const detail = await hook(() => window.__pmc.lod());
  await hook(() => window.__pmc.lod({ maxPixelError: 4, maxChunks: 1000 }));
  const spot = await groundAt(46.5, 8);
  const south = await groundAt(46.4997, 8);
  log(`  the ground under 46.5, 8: ${spot.height.toFixed(1)} m above the datum; 33 m south: ${south.height.toFixed(1)} m`);
  const before = await look('dem-cave-before', 46.4997, 8, south.height + 25, -35);
  const centre = spot.point;
  const r = Math.hypot(...centre);
  // a dig 30 m across, its centre 8 m down: a pit wide enough to show at the levels drawn here
  // (level 3 and coarser, 8 m voxels; a 16 m dig changed a dozen triangles)
  const inward = centre.map((v) => v * (1 - 8 / r));
  const answer = await hook(
    ([c]) => fetch('api/v1/edits', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ brush: 'remove', x: c[0], y: c[1], z: c[2], radius: 30 }) }).then(async (x) => ({ status: x.status, body: await x.json() })),
    [inward],
  );
  check(answer.status === 200 && answer.body.chunks.length > 0, `the dig was answered ${JSON.stringify(answer)}`);
  await waitFor(page, 'the dug chunks', () => window.__pmc.stats().pending === 0, null, () => window.__pmc.stats(), 120_000);
  const after = await look('dem-cave', 46.4997, 8, south.height + 25, -35);
  const w = 400;
  const changed = fractionDifferent(crop(before, VIEWPORT.width / 2, VIEWPORT.height / 2, w, w), crop(after, VIEWPORT.width / 2, VIEWPORT.height / 2, w, w));
  log(`  the dig changed ${(100 * changed).toFixed(1)} % of the ${w} px around it`);
  check(changed > 0.05, `the dig is not visible: ${(100 * changed).toFixed(1)} % of the pixels around it changed`);
  await hook((d) => window.__pmc.lod(d), detail);
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await server.stop();
  // the same model as a height field (--mesher heightfield): 65 x 65 patches streamed as
  // chunks, drawn with no crack or hole (from orbit: the software renderer of the tests draws
  // the finer views slowly)
  const patches = await startBackend(null, { extra: ['--dem', dem, '--mesher', 'heightfield'] });
  await page.goto(`${patches.url}#mode=orbit&lat=28&lon=86.9`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await ready('the height field from orbit');
  const hp = await hook(() => fetch('api/v1/planet').then((x) => x.json()));
  check(hp.layout.n_t === 64 && hp.layout.d_c === 1, `the height field's layout is ${JSON.stringify(hp.layout)}`);
  await hook(() => window.__pmc.mode('orbit'));
  await look('dem-heightfield-orbit', 28, 86.9, 6_000_000, -90);
  check(consoleProblems.length === 0 && failedResponses.length === 0, `${[...consoleProblems, ...failedResponses].join('\n  ')}`);
  await page.goto('about:blank');
  await patches.stop();
}
