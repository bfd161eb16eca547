// Step 20: the viewer's 3D Tiles mode. The earth preset seen from orbit and from about 10 km over
// the mountains at 39° N 0° E (the place of step 10's descent), first from PMC's own chunks, then
// from the 3D Tiles `pmc serve` answers (/tiles/sphere/, the planet's sphere frame) loaded by
// 3DTilesRendererJS into the same scene and drawn by the chunks' terrain shader: the mode turns on
// (the `T` key) and off (the panel's button), the link says so (`tiles=1`), the tiles load and
// settle, the planet covers the same pixels as the chunks do and the ground picked under 20 pixels
// is the same place (the tiles are in the right frame, in the right place, at the right scale,
// with nothing missing), in the chunks' colours pixel by pixel. No console error, no failed
// request.
// The 10 km pair is the README's comparison (tilesMode-native.png, tilesMode-tiles.png).

import { check, log } from '../harness.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { deltaE76 } = await viewerModule('colour.ts');

export const name = '20. the 3D Tiles mode: the earth preset from pmc serve\'s 3D Tiles through 3DTilesRendererJS covers the same pixels and the same ground as the chunks, from orbit and 10 km over 39° N 0° E, in the chunks\' colours, no console error';

/**
 * The share of the frame where both pictures agree on whether the planet is drawn, at least
 * (measured: see the log). A planet pixel is one that is not of the background's colour (the
 * atmosphere is off in the steps: the background is flat, space or the sky's blue).
 */
export const AGREEMENT = 0.95;
/** The planet's pixels in both pictures over those in either (intersection over union), at least. */
export const OVERLAP = 0.9;
/** Pixels below the horizon of the 10 km view where the ground is picked in both modes (CSS pixels). */
const PICKS = [100, 300, 512, 724, 924].flatMap((x) => [300, 400, 500, 600].map((y) => [x, y]));
/**
 * How far apart the ground picked under a pixel on the tiles and on the chunks may lie, as a share
 * of its distance (median): the same surface at about the same level, in the same frame (a frame
 * or an axis off puts them kilometres apart).
 */
export const PICK_GAP = 0.005;
/**
 * The tiles are drawn by the chunks' terrain shader (the materials per pixel from the height, the
 * slope, the latitude and noise; the sun, the sky light, the haze, the sea), so their colours are
 * the chunks' but where the two draw other levels' meshes (a snow line a few pixels off, the
 * horizon): the CIE76 difference of the two pictures' mean colours, at most (measured 0.0 from
 * orbit and 0.1 from 10 km; 12 and 17 when the tiles were drawn in their vertex colours by
 * three.js's MeshStandardMaterial)...
 */
export const MEAN_DELTA_E = 3;
/**
 * ...and the share of the pixels where both draw the planet whose colours are more than
 * PIXEL_DELTA_E apart, at most (measured 0.00% from orbit and 0.47% from 10 km, along the snow
 * line and the horizon; 67% and 55% in the vertex colours, in blocks a triangle wide).
 */
export const PIXELS_APART = 0.03;
export const PIXEL_DELTA_E = 10;

/**
 * The warning 3DTilesRendererJS (0.4 and 0.5) prints for every tileset file of 3D Tiles 1.1, what
 * the server writes (glTF contents are 1.1's): the library's, not a problem of the tiles. Counted
 * and said in the log; any other console warning or error fails the step.
 */
const VERSION_WARNING = /^warning: TilesRenderer: tiles versions at 1\.1 or higher have limited support\./;

/** Per pixel of `img`, 1 where the planet is drawn (not within `tol` of the background `bg`). */
function planetMask(img, bg, tol = 12) {
  const mask = new Uint8Array(img.width * img.height);
  for (let p = 0, i = 0; p < mask.length; p++, i += 4) {
    mask[p] = Math.abs(img.data[i] - bg[0]) > tol || Math.abs(img.data[i + 1] - bg[1]) > tol || Math.abs(img.data[i + 2] - bg[2]) > tol ? 1 : 0;
  }
  return mask;
}

/**
 * The mean colour (8-bit sRGB) and luminance of `img`'s pixels where `mask` is set, and the share
 * of them in colour (their channels more than 24 apart: green, sand, the sea; not snow, rock or
 * grey).
 */
function meanColour(img, mask) {
  const sum = [0, 0, 0];
  let n = 0;
  let coloured = 0;
  for (let p = 0, i = 0; p < mask.length; p++, i += 4) {
    if (!mask[p]) continue;
    const px = [img.data[i], img.data[i + 1], img.data[i + 2]];
    for (let c = 0; c < 3; c++) sum[c] += px[c];
    if (Math.max(...px) - Math.min(...px) > 24) coloured++;
    n++;
  }
  const rgb = sum.map((s) => (n > 0 ? s / n : 0));
  return { rgb, luminance: 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2], coloured: n > 0 ? coloured / n : 0 };
}

/** How the planet's pixels of the chunks' picture `a` and the tiles' `b` agree, and their colours. */
function compare(a, b, bg) {
  const ma = planetMask(a, bg);
  const mb = planetMask(b, bg);
  let both = 0;
  let onlyA = 0;
  let onlyB = 0;
  let apart = 0;
  for (let p = 0, i = 0; p < ma.length; p++, i += 4) {
    if (ma[p] && mb[p]) {
      both++;
      const pa = [a.data[i], a.data[i + 1], a.data[i + 2]];
      const pb = [b.data[i], b.data[i + 1], b.data[i + 2]];
      if (deltaE76(pa, pb) > PIXEL_DELTA_E) apart++;
    } else if (ma[p]) onlyA++;
    else if (mb[p]) onlyB++;
  }
  const total = ma.length;
  const colourA = meanColour(a, ma);
  const colourB = meanColour(b, mb);
  return {
    agreement: 1 - (onlyA + onlyB) / total,
    overlap: both / Math.max(1, both + onlyA + onlyB),
    planetA: (both + onlyA) / total,
    planetB: (both + onlyB) / total,
    colourA,
    colourB,
    meanDeltaE: deltaE76(colourA.rgb, colourB.rgb),
    apart: apart / Math.max(1, both),
  };
}

export async function scenario(t) {
  const { page, hook, ready, shot, openPanel, consoleProblems, failedResponses } = t;
  const t0 = Date.now();
  // (the browser's lists are shared with the steps before this one in its lane: this step's own
  // messages are those from here on)
  const [firstProblem, firstFailure] = [consoleProblems.length, failedResponses.length];
  const server = await startBackend(null, { extra: ['--preset', 'earth'] });
  await page.goto(`${server.url}#preset=earth&seed=7&mode=orbit&lat=39&lon=0&alt=12000000`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const tiles = () => hook(() => window.__pmc.tiles());
  /** Waits for the tiles to settle (`__pmc.ready()` in the mode: nothing loading for a while). */
  const tilesReady = async (what) => {
    const t1 = Date.now();
    await hook((ms) => window.__pmc.ready(ms), 120_000);
    const s = await tiles();
    log(`  ${what}: ${s.visible} tiles drawn, ${s.loaded} loaded, ${s.failed} failed, quiet for ${Math.round(s.quietMs)} ms, ${((Date.now() - t1) / 1000).toFixed(1)} s`);
    check(s.on && s.settled && s.loaded > 0 && s.visible > 0, `${what}: the tiles did not load: ${JSON.stringify(s)}`);
    check(s.failed === 0, `${what}: ${s.failed} tiles failed to load`);
    check(s.frame === 'sphere' && s.terrain === 'preset:earth:7', `${what}: the tileset is ${s.terrain} in the ${s.frame} frame`);
    return s;
  };
  const results = [];
  /** Judges the pictures of `view` from the chunks (`a`, saved as `files[0]`) and the tiles (`b`, `files[1]`). */
  const judge = (view, a, b, bg, files) => {
    const c = compare(a, b, bg);
    const fmt = (m) => `rgb ${m.rgb.map((x) => x.toFixed(0)).join(',')}, luminance ${m.luminance.toFixed(0)}, ${(100 * m.coloured).toFixed(1)}% in colour`;
    log(
      `  ${view}: the planet on ${(100 * c.planetA).toFixed(1)}% of the frame from the chunks, ${(100 * c.planetB).toFixed(1)}% from the tiles; ` +
        `they agree on ${(100 * c.agreement).toFixed(2)}% of the pixels, overlap ${(100 * c.overlap).toFixed(2)}%; mean colour: chunks ${fmt(c.colourA)}, tiles ${fmt(c.colourB)}, ` +
        `ΔE ${c.meanDeltaE.toFixed(2)}; ${(100 * c.apart).toFixed(2)}% of the pixels more than ΔE ${PIXEL_DELTA_E} apart`,
    );
    check(c.planetA > 0.2, `${view}: the chunks draw the planet on ${(100 * c.planetA).toFixed(1)}% of the frame only: see ${files[0]}`);
    check(
      c.agreement >= AGREEMENT && c.overlap >= OVERLAP,
      `${view}: the tiles and the chunks agree on ${(100 * c.agreement).toFixed(2)}% of the pixels (at least ${100 * AGREEMENT}%), overlap ${(100 * c.overlap).toFixed(2)}% (at least ${100 * OVERLAP}%): see ${files.join(' and ')}`,
    );
    // the chunks' colours: on the whole, and pixel by pixel (no blocks of vertex colours)
    check(
      c.meanDeltaE <= MEAN_DELTA_E,
      `${view}: the tiles' mean colour is ΔE ${c.meanDeltaE.toFixed(2)} from the chunks' (at most ${MEAN_DELTA_E}; tiles ${fmt(c.colourB)}, chunks ${fmt(c.colourA)}): see ${files.join(' and ')}`,
    );
    check(
      c.apart <= PIXELS_APART,
      `${view}: ${(100 * c.apart).toFixed(2)}% of the pixels more than ΔE ${PIXEL_DELTA_E} apart on the tiles and the chunks (at most ${100 * PIXELS_APART}%): see ${files.join(' and ')}`,
    );
    results.push({ view, ...c });
  };

  // from orbit: the chunks, then the tiles (on by the T key)
  const orbit = await ready('from orbit, the chunks');
  const orbitNative = await shot('tilesMode-orbit-native');
  check(!(await tiles()).on, 'the 3D Tiles mode is on before it was turned on');
  await page.focus('#view');
  await page.keyboard.press('KeyT');
  check((await tiles()).on, 'the T key did not turn the 3D Tiles mode on');
  await tilesReady('from orbit, the tiles');
  const orbitTiles = await shot('tilesMode-orbit-tiles');
  judge('orbit', orbitNative, orbitTiles, orbit.background, ['tilesMode-orbit-native.png', 'tilesMode-orbit-tiles.png']);
  check((await page.evaluate(() => location.hash)).includes('tiles=1'), `the link does not keep the 3D Tiles mode: ${await page.evaluate(() => location.hash)}`);
  const hud = await page.textContent('#hud-tiles');
  check(/3D Tiles · \d+ drawn · \d+ loaded/.test(hud ?? ''), `the HUD says "${hud}"`);
  const stats = await hook(() => window.__pmc.stats());
  check(stats.tiles.on && stats.tiles.loaded > 0, `__pmc.stats().tiles: ${JSON.stringify(stats.tiles)}`);

  // 10 km over the mountains (their snow fields about 6.5 km above the datum), looking east-north-
  // east across them and a valley to the horizon: the tiles first (moving in the mode), then the
  // chunks (off by the panel's button: the view's selection resumes)
  await hook(() => window.__pmc.mode('fly'));
  await hook(() => window.__pmc.setCamera(39, 0, 16_500, 60, -10));
  const nearTiles = await tilesReady('10 km over the mountains, the tiles');
  const tilesImg = await shot('tilesMode-tiles');
  const tilesPicks = await hook((px) => px.map(([x, y]) => window.__pmc.pick(x, y)), PICKS);
  await openPanel(['view']);
  check((await page.textContent('#tiles')) === '3D Tiles: on', `the panel's button says "${await page.textContent('#tiles')}"`);
  await page.click('#tiles');
  check(!(await tiles()).on, "the panel's button did not turn the 3D Tiles mode off");
  check((await page.textContent('#tiles')) === '3D Tiles: off', `the panel's button says "${await page.textContent('#tiles')}"`);
  const near = await ready('10 km over the mountains, the chunks');
  const nativeImg = await shot('tilesMode-native');
  const chunkPicks = await hook((px) => px.map(([x, y]) => window.__pmc.pick(x, y)), PICKS);
  // the ground under the same pixels, picked on the tiles drawn and on the chunks: the same place
  const gaps = [];
  for (const [i, a] of tilesPicks.entries()) {
    const b = chunkPicks[i];
    if (!a || !b) continue;
    gaps.push(Math.hypot(a.point[0] - b.point[0], a.point[1] - b.point[1], a.point[2] - b.point[2]) / b.distance);
  }
  gaps.sort((a, b) => a - b);
  const median = gaps[Math.floor(gaps.length / 2)] ?? Infinity;
  log(
    `  10 km view: the ground under ${gaps.length} of ${PICKS.length} pixels picked on both the tiles and the chunks, ` +
      `apart by ${(100 * median).toFixed(3)}% of its distance (median), ${(100 * (gaps[gaps.length - 1] ?? Infinity)).toFixed(3)}% at most`,
  );
  check(gaps.length >= 0.9 * PICKS.length, `the ground under only ${gaps.length} of ${PICKS.length} pixels is picked on both the tiles and the chunks`);
  check(median < PICK_GAP, `the ground picked on the tiles lies ${(100 * median).toFixed(3)}% of its distance from the chunks' (median; at most ${100 * PICK_GAP}%)`);
  log(`  10 km view: ${near.aboveGround?.toFixed(0)} m over the ground measured on the chunks, ${nearTiles.visible} tiles against ${near.shown} chunks`);
  judge('10km', nativeImg, tilesImg, near.background, ['tilesMode-native.png', 'tilesMode-tiles.png']);

  const versionWarnings = consoleProblems.slice(firstProblem).filter((m) => VERSION_WARNING.test(m)).length;
  // (taken out of the browser's list: the steps after this one in its lane do not see them)
  for (let i = consoleProblems.length - 1; i >= firstProblem; i--) if (VERSION_WARNING.test(consoleProblems[i])) consoleProblems.splice(i, 1);
  log(`  3DTilesRendererJS's warning that 3D Tiles 1.1 has limited support: ${versionWarnings} times (once a tileset file)`);
  const mine = consoleProblems.slice(firstProblem);
  check(mine.length === 0, `console messages:\n  ${mine.join('\n  ')}`);
  const failed = failedResponses.slice(firstFailure);
  check(failed.length === 0, `failed responses:\n  ${failed.join('\n  ')}`);
  log(
    `  3D Tiles mode: ${results.map((r) => `${r.view} ${(100 * r.agreement).toFixed(2)}% agree, colours ΔE ${r.meanDeltaE.toFixed(2)}, ${(100 * r.apart).toFixed(2)}% apart`).join('; ')} (${((Date.now() - t0) / 1000).toFixed(1)} s)`,
  );
  await page.goto('about:blank');
  await server.stop();
}
