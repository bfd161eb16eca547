// Step 19: the planet in CesiumJS, from the 3D Tiles `pmc serve` answers (/tiles/tileset.json):
// the example page (examples/cesium, served at /cesium/) loads them with no console error, and
// with the terrain's back faces drawn magenta no view shows one, over the earth preset and over
// an imported elevation model, from orbit down to 2 m: CesiumJS picks each tile's level on its
// own, and the closed tiles leave no crack into a solid. An edit through the API shows in
// CesiumJS once it fetches the tileset again (the pit is there), and a tileset baked by
// `pmc tiles bake`, hosted by a plain static file server, loads and shows no crack either.

import { createReadStream, existsSync, mkdtempSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { join, normalize, resolve, sep } from 'node:path';
import { PMC_BIN, VIEWPORT, artifacts, check, cleanups, importedDem, log, run, viewerDir } from '../harness.mjs';
import { decodePng } from '../images.mjs';
import { startPmcServe } from '../servers.mjs';

export const name = '19. the planet in CesiumJS from pmc serve\'s 3D Tiles: no console error, and no crack showing a back face (magenta) in any view from orbit to 2 m, over the earth preset, an elevation model and a baked tileset on a static server; an edit shows as a pit';

/** CesiumJS's build, installed by `npm ci` in examples/cesium (scripts/test.sh does it). */
export const CESIUM_JS = resolve(viewerDir, '../examples/cesium/node_modules/cesium/Build/Cesium');

/**
 * Pinholes a view may have: single magenta pixels with none beside them. Measured with CesiumJS
 * refining down to the finest tiles (0.6 to 1.1 million triangles in the views at 100 m and 2 m):
 * 0 to 3 a view, single pixels in the distant half of the view, mostly within a few pixels of the
 * horizon, where far tiles are seen nearly edge-on: the class of pixels PMC's own viewer allows 4
 * of too (lodFlight.mjs, TINTED_ALLOWED). A crack between levels is a line of pixels, a missing
 * tile a region: neither is isolated, and the test allows no two magenta pixels side by side.
 * (Pinholes along the seams of tiles of one level, where CesiumJS's f32 drawing relative to each
 * tile's centre lets a pixel slip between two tiles' edges, are hidden by the caps moved out
 * under the neighbour and joined to the surface by flanges, pmc_tiles::CAP_OFFSET, and by the
 * flagged copy's push of a ten-thousandth of the distance, examples/cesium/index.html: with a
 * hundred-thousandth 8 to 19 such pixels showed a view at 100 m.)
 */
export const PINHOLES_ALLOWED = 4;

/**
 * The size of the flagged views and of the pit's: CesiumJS picks tiles by their error in pixels,
 * so a smaller view loads fewer tiles, with the same freedom to mix levels side by side. At
 * 1024 x 640 the views at 100 m took 66 to 110 s each under software rendering; at 640 x 400,
 * 435 to 501 tiles and 75 s; at 512 x 320 (this size), about two thirds of that.
 */
const FLAG_VIEWPORT = { width: 512, height: 320 };

/**
 * Magenta pixels (the surface's back faces), those of them with no magenta pixel beside them
 * (pinholes), cyan ones (a cap's back face) and pixels of terrain (any other non-black one).
 */
function countPixels(png) {
  const img = decodePng(png);
  const { width, height, data } = img;
  const isMagenta = (x, y) => {
    if (x < 0 || y < 0 || x >= width || y >= height) return false;
    const i = 4 * (y * width + x);
    return data[i] > 180 && data[i + 1] < 90 && data[i + 2] > 180;
  };
  let magenta = 0;
  let isolated = 0;
  let cyan = 0;
  let terrain = 0;
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const i = 4 * (y * width + x);
      const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
      if (isMagenta(x, y)) {
        magenta += 1;
        let alone = true;
        for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) if ((dx || dy) && isMagenta(x + dx, y + dy)) alone = false;
        if (alone) isolated += 1;
      } else if (r < 90 && g > 180 && b > 180) cyan += 1;
      else if (r + g + b > 30) terrain += 1;
    }
  }
  return { magenta, isolated, cyan, terrain, total: width * height };
}

/**
 * The views of one planet: from orbit, then 10 km, 100 m and 2 m over the ground at a place (or
 * the heights given). `tiles` is the tileset's URL (default: the server's own).
 */
async function views(t, label, server, lat, lon, { tiles = null, heights = [10_000, 100, 2] } = {}) {
  const { page } = t;
  // (a screen-space error of 4 pixels: the levels CesiumJS mixes are as unbalanced as at 2, with
  // a quarter of the tiles to load; at most 5 frames a second: while tiles load most frames draw
  // what the one before drew, each a core's work under software rendering. The tiles chosen and
  // the pixels counted were the same as at the display's rate, and the step's software renderer
  // took 110 s of CPU instead of 204 s, 145 s with frames drawn on demand alone)
  const from = tiles ? `tiles=${encodeURIComponent(tiles)}&` : '';
  const url = `${server.base}cesium/?${from}flag=1&sse=4&fps=5&lat=${lat}&lon=${lon}&height=12000000&pitch=-90`;
  await page.setViewportSize(FLAG_VIEWPORT);
  await page.goto(url, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmcCesium !== undefined, null, { timeout: 60_000 });
  const frame = await page.evaluate(() => window.__pmcCesium.info.frame);
  log(`  ${label}: CesiumJS ${await page.evaluate(() => window.__pmcCesium.Cesium.VERSION)}, tiles in the ${frame} frame`);
  const settle = async (what) => {
    const t0 = Date.now();
    await page.evaluate(() => window.__pmcCesium.loaded());
    const s = await page.evaluate(() => {
      const st = window.__pmcCesium.tileset.statistics;
      return { tiles: st.numberOfTilesWithContentReady, triangles: st.numberOfTrianglesSelected };
    });
    return { ...s, seconds: (Date.now() - t0) / 1000, what };
  };
  const look = async (view, what) => {
    const s = await settle(what);
    const png = await page.screenshot({ type: 'png' });
    if (process.env.PMC_E2E_CESIUM_DEBUG) {
      const diff = await page.evaluate(() => {
        const { tileset, backs } = window.__pmcCesium;
        const urls = (ts) => new Set(ts._selectedTiles.map((t) => t.content?.url ?? '?'));
        const [a, b] = [urls(tileset), urls(backs)];
        return { a: a.size, b: b.size, onlyA: [...a].filter((u) => !b.has(u)).slice(0, 5), onlyB: [...b].filter((u) => !a.has(u)).slice(0, 5) };
      });
      log(`    selections: ${JSON.stringify(diff)}`);
      const px = countPixels(png);
      if (px.magenta > 0) {
        const img = decodePng(png);
        for (let i = 0; i < img.data.length; i += 4) {
          const [r, g, b] = [img.data[i], img.data[i + 1], img.data[i + 2]];
          if (r > 180 && g < 90 && b > 180) {
            const x = (i / 4) % img.width;
            const y = Math.floor(i / 4 / img.width);
            const picked = await page.evaluate(([x, y]) => {
              const { viewer, tileset, backs, Cesium } = window.__pmcCesium;
              const at = new Cesium.Cartesian2(x + 0.5, y + 0.5);
              const name = (p) => p?.content?.url ?? p?.detail?.model?.content?.url ?? p?.primitive?.constructor?.name ?? String(p);
              const front = viewer.scene.drillPick(at, 5).map((p) => (p.tileset === backs ? 'B ' : 'A ') + (p.content?.url ?? '?'));
              const ray = viewer.camera.getPickRay(at);
              return { front, ray: [ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y, ray.direction.z] };
            }, [x, y]);
            log(`    magenta at ${x},${y}: ${JSON.stringify(picked)}`);
          }
        }
      }
    }
    const file = join(artifacts, `cesium-${label}-${view}.png`);
    writeFileSync(file, png);
    const px = countPixels(png);
    log(`  ${label} ${view}: ${s.tiles} tiles, ${s.triangles} triangles, ${px.magenta} magenta (the surface's back faces; ${px.isolated} of them pinholes) and ${px.cyan} cyan (caps' back faces) pixels, terrain on ${((100 * px.terrain) / px.total).toFixed(0)}% of the view, ${s.seconds.toFixed(1)} s`);
    check(
      px.magenta === px.isolated && px.isolated <= PINHOLES_ALLOWED,
      `${label} ${view}: ${px.magenta} pixels show a back face (the inside of a solid through a crack), ${px.isolated} of them single (at most ${PINHOLES_ALLOWED} may be); see ${file}`,
    );
    check(px.terrain > px.total * 0.05, `${label} ${view}: the terrain covers ${px.terrain} of ${px.total} pixels; see ${file}`);
  };
  await look('orbit', 'from orbit');
  const ground = await page.evaluate(([la, lo]) => window.__pmcCesium.groundHeight(la, lo), [lat, lon]);
  check(Number.isFinite(ground), `no ground under ${lat}, ${lon}: ${ground}`);
  log(`  ${label}: the ground under ${lat}, ${lon} is ${ground.toFixed(1)} m above the datum`);
  if (label === 'earth') t.shared.cesiumGround = ground;
  const pitches = { 10000: -45, 100: -20, 2: -12 };
  for (const h of heights) {
    const [view, pitch] = [h >= 1000 ? `${h / 1000}km` : `${h}m`, pitches[h] ?? -45];
    await page.evaluate(([la, lo, hh, p]) => window.__pmcCesium.setView({ lat: la, lon: lo, height: hh, heading: 30, pitch: p }), [lat, lon, ground + h, pitch]);
    await look(view, `${h} m over the ground`);
  }
}

/**
 * The page as a user opens it (lit, its sky and globe, the Earth's materials per pixel): from
 * orbit, no console error (the harness checks), and colour on the planet.
 */
async function asSeen(t, server) {
  const { page } = t;
  await page.setViewportSize(VIEWPORT);
  await page.goto(`${server.base}cesium/?lat=39&lon=0&height=12000000`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmcCesium !== undefined, null, { timeout: 60_000 });
  await page.evaluate(() => window.__pmcCesium.loaded());
  const png = await page.screenshot({ type: 'png' });
  const file = join(artifacts, 'cesium-earth-as-seen.png');
  writeFileSync(file, png);
  const img = decodePng(png);
  let coloured = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    const c = [img.data[i], img.data[i + 1], img.data[i + 2]];
    if (Math.max(...c) - Math.min(...c) > 30) coloured += 1;
  }
  const share = coloured / (img.width * img.height);
  log(`  earth as seen from orbit: ${(100 * share).toFixed(0)}% of the view in colour`);
  check(share > 0.1, `the planet as seen in CesiumJS has colour on ${(100 * share).toFixed(1)}% of the view; see ${file}`);
}

/**
 * An edit through the API, then CesiumJS fetching the tileset again: the ground under the place
 * is lower by most of the brush's radius (the pit is there).
 */
async function pit(t, server, lat, lon) {
  const { page } = t;
  // Looking straight down from 1.5 km over the place: the ground under it as drawn (tiles of a
  // few metres' voxels there, at a screen-space error of 4; from 5 km the drawn tiles' voxels
  // straddle a pit of this size). Flagged, so the pit's view is checked for cracks too, and
  // because CesiumJS 1.145 logs WebGL warnings (`uniform3fv: no array`, from Cesium.js itself)
  // when it samples the height of tiles drawn with the page's lit Earth shader (62 of them in
  // this step; none with the unlit flagged one).
  const pitPixels = async (what) => {
    const png = await page.screenshot({ type: 'png' });
    const px = countPixels(png);
    check(px.magenta === px.isolated && px.isolated <= PINHOLES_ALLOWED, `the pit ${what}: ${px.magenta} pixels show a back face`);
    return { png, px };
  };
  await page.setViewportSize(FLAG_VIEWPORT);
  const drawnGround = async (heading) => {
    await page.goto(`${server.base}cesium/?flag=1&sse=4&fps=5&lat=${lat}&lon=${lon}&height=${ground0 + 1500}&pitch=-90&heading=${heading}`, { waitUntil: 'load', timeout: 60_000 });
    await page.waitForFunction(() => window.__pmcCesium !== undefined, null, { timeout: 60_000 });
    await page.evaluate(() => window.__pmcCesium.loaded());
    return page.evaluate(([la, lo]) => window.__pmcCesium.groundHeight(la, lo, { drawn: true }), [lat, lon]);
  };
  const ground0 = t.shared.cesiumGround;
  const before = await drawnGround(0);
  await pitPixels('before the edit');
  const { datumRadius, revision } = await page.evaluate(() => window.__pmcCesium.info);
  check(Number.isFinite(before), `no ground drawn under ${lat}, ${lon}: ${before}`);
  // The place in the planet's frame (http-api-v1.md: Y to the north pole, longitude 0 on +Z); in
  // the WGS84 frame a tile's height above the ellipsoid is the terrain's height above the datum.
  const [a, b] = [(lat * Math.PI) / 180, (lon * Math.PI) / 180];
  const r = datumRadius + before;
  const radius = 60;
  const edit = { brush: 'remove', x: r * Math.cos(a) * Math.sin(b), y: r * Math.sin(a), z: r * Math.cos(a) * Math.cos(b), radius };
  const answer = await fetch(`${server.base}api/v1/edits`, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(edit) });
  check(answer.ok, `the edit was refused: ${answer.status} ${await answer.text()}`);
  // The page fetches tileset.json again (as a reload does): new URLs, the planet as edited.
  const after = await drawnGround(1);
  const revisionAfter = await page.evaluate(() => window.__pmcCesium.info.revision);
  const file = join(artifacts, 'cesium-earth-pit.png');
  const { png, px } = await pitPixels('after the edit');
  writeFileSync(file, png);
  log(`  the pit's view: ${px.magenta} magenta and ${px.cyan} cyan pixels`);
  log(`  the pit: a remove of radius ${radius} m at ${lat}, ${lon}; the ground there drawn at ${before.toFixed(1)} m before, ${after.toFixed(1)} m after (revision ${revision} -> ${revisionAfter}); see ${file}`);
  check(revisionAfter === revision + 1, `the tileset's revision went from ${revision} to ${revisionAfter} after one edit`);
  check(after < before - 0.5 * radius, `CesiumJS draws the ground at ${after} m after the edit, ${before} m before: no pit of radius ${radius} m`);
}

/** A static file server for `dir` (what any web host does), with CORS for the page's origin. */
async function serveFolder(dir) {
  const root = resolve(dir);
  const server = createServer((req, res) => {
    const path = normalize(join(root, decodeURIComponent(new URL(req.url, 'http://x').pathname)));
    if (!path.startsWith(root + sep) || !existsSync(path) || !statSync(path).isFile()) {
      res.writeHead(404, { 'access-control-allow-origin': '*' }).end('not found');
      return;
    }
    const type = path.endsWith('.json') ? 'application/json' : 'model/gltf-binary';
    res.writeHead(200, { 'content-type': type, 'access-control-allow-origin': '*' });
    createReadStream(path).pipe(res);
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  cleanups.push(() => server.close());
  return `http://127.0.0.1:${server.address().port}/`;
}

/** A region of the earth preset baked by `pmc tiles bake`, hosted as plain files: no crack. */
async function baked(t, earth) {
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-bake-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const out = join(dir, 'tiles');
  const args = ['tiles', 'bake', '--quiet', '--preset', 'earth', '--region', '39,0,20000', '--max-level', '11', '-o', out];
  const bake = await run(PMC_BIN, args, 300_000);
  check(bake.code === 0, `pmc ${args.join(' ')} failed: ${bake.out}`);
  const url = `${await serveFolder(out)}tileset.json`;
  log(`  baked: pmc ${args.join(' ')}, hosted at ${url}`);
  await views(t, 'baked', earth, 39, 0, { tiles: url, heights: [10_000] });
}

export async function scenario(t) {
  check(existsSync(join(CESIUM_JS, 'Cesium.js')), `no CesiumJS at ${CESIUM_JS}: run npm ci in examples/cesium`);
  const [firstProblem, firstFailure] = [t.consoleProblems.length, t.failedResponses.length];
  const worldDir = mkdtempSync(join(tmpdir(), 'pmc-e2e-cesium-world-'));
  cleanups.push(() => rmSync(worldDir, { recursive: true, force: true }));
  const earth = await startPmcServe(null, { world: join(worldDir, 'earth.pmcw'), extra: ['--preset', 'earth', '--cesium-js', CESIUM_JS] });
  await asSeen(t, earth);
  await views(t, 'earth', earth, 39, 0);
  await baked(t, earth);
  await pit(t, earth, 39, 0);
  // (the page closed before its server: CesiumJS asks for tiles whenever it draws, and a page
  // left open asked a stopped server for some when the viewport changed; the refusals showed in
  // the next step's console)
  await t.page.goto('about:blank');
  await earth.stop();
  // an elevation model (ETOPO5 where installed)
  const dem = await importedDem();
  const model = await startPmcServe(null, { extra: ['--dem', dem, '--cesium-js', CESIUM_JS] });
  await views(t, 'dem', model, 46.5, 10);
  await t.page.goto('about:blank');
  await model.stop();
  await t.page.setViewportSize(VIEWPORT);
  // No console error and no failed request in any page of this step (the browser's lists are
  // shared with the steps after it in its lane: this step's are taken out).
  const mine = t.consoleProblems.splice(firstProblem);
  const failed = t.failedResponses.splice(firstFailure);
  log(`  console: ${mine.length} messages${mine.length ? `: ${[...new Set(mine)].slice(0, 5).join(' | ')}` : ''}`);
  check(mine.length === 0, `console messages in CesiumJS:\n  ${mine.join('\n  ')}`);
  check(failed.length === 0, `failed responses:\n  ${failed.join('\n  ')}`);
}
