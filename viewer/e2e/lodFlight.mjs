// The levels of detail seen as a user sees them: a flight from orbit to the ground, with back faces
// drawn in a flagged colour (magenta, no sea). From outside a closed surface no back face can be
// seen, so a flagged pixel is a crack between chunks or a hole where a chunk is missing. At every
// stop, and in the frames taken while the levels change on the way there, no pixel may be flagged;
// the stats panel's level histogram must follow the height; a still camera must give the same
// picture twice (no jitter, also at 6.4e6 m from the planet's centre).
//
// The flagged pictures draw the ground in one lit colour (the debug flag `plain`, a program of its
// own with the same geometry and depth): they are about the geometry, and under the software
// renderer the full shading of the materials' noises costs nine tenths of a frame (the Earth at
// 2 m: 8.9 s against 1.0 s). The pictures as users see them (`pictures`) and the two of the still
// camera (`jitter`: the noises are where an imprecise position shows first) are fully shaded.

/** The debug flags of the flagged pictures: back faces in the flag colour, the ground plain. */
export const FLAGGED = { backfaces: true, plain: true };
/** The debug flags of the pictures as users see them. */
export const AS_SEEN = { backfaces: false, plain: false };

/**
 * Pixels the back-face flag colour (#ff00ff) tints: red and blue both over green by more than 20
 * (no colour of the terrain, the sea or the sky of the test mode is so), so a gap that shows the
 * inside in a single antialiasing sample of a pixel counts. Until the back faces' depth offset was
 * found compiled out under three.js's former define (`shaders.ts`), thousands of pixels along the
 * silhouettes of small relief were tinted in a view from 10 km (a back face meeting its front
 * face at the same depth) and only pixels fully of the flag colour were counted; now 0 a view
 * are on the default planet, and on the earth preset 0 but on its far horizon: one pixel at the
 * horizon of the ocean floor from 2 m, two at the horizon from 10 km over the mountains, in the
 * same places run after run (TINTED_ALLOWED). Measured there: not the selection's frustum or
 * horizon culling (the same pixels with both off), not the depth's resolution (the same with back
 * faces pushed two pixels' depth slope back); the back face is a coarse chunk's (levels 2 to 3,
 * kilometres away, read from a level-coded flag colour), seen edge-on.
 */
export function tintedPixels(img) {
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    const g = img.data[i + 1];
    if (img.data[i] - g > 20 && img.data[i + 2] - g > 20) n++;
  }
  return n;
}

/** Tinted pixels a view may have (measured: 0 to 2, on the far horizon of the earth preset). */
export const TINTED_ALLOWED = 4;

/** Pixels fully of the back-face flag colour (a gap a pixel wide or more). */
export function flaggedPixels(img) {
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    if (255 - img.data[i] + img.data[i + 1] + (255 - img.data[i + 2]) <= 60) n++;
  }
  return n;
}

/**
 * Pixels of background colour `bg` (within 6, summed over the channels) in `img` that are not of
 * that colour in `ref`: places where nothing is drawn that are drawn in the converged picture.
 */
export function newBackground(img, ref, bg) {
  const is = (d, i) => Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) <= 6;
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    if (is(img.data, i) && !is(ref.data, i)) n++;
  }
  return n;
}

/** Pixels that differ at all between two images of the same size (every pixel when they do not). */
export function differingPixels(a, b) {
  if (a.width !== b.width || a.height !== b.height) return a.width * a.height;
  let n = 0;
  for (let i = 0; i < a.data.length; i += 4) {
    if (a.data[i] !== b.data[i] || a.data[i + 1] !== b.data[i + 1] || a.data[i + 2] !== b.data[i + 2]) n++;
  }
  return n;
}

/** The lowest and highest level with a chunk shown in a histogram (index = level), or null. */
export function levelRange(levels) {
  const used = levels.flatMap((n, l) => (n > 0 ? [l] : []));
  return used.length === 0 ? null : { min: used[0], max: used[used.length - 1] };
}

/**
 * Flies down over (`lat`, `lon`) through `stops` (`{ name, height, pitch }`: metres above the
 * ground, the first from orbit looking at the planet's centre, the others looking north `pitch`
 * degrees, by default 15° below the horizon), then looking straight down at the heights of `zoom` (metres above the ground, down
 * and back up), checking each as the file header says, and the pictures on the way of the zoom.
 * `t` is the harness: `{ page, hook, ready, shot, log, check, problems }`, `problems()` giving the
 * console errors and failed responses so far. Screenshots are `${label}-${stop}.png` (flagged) and,
 * with `pictures`, `${label}-${stop}-view.png` (as a user sees it). With `jitter` (a radius in
 * metres), two pictures of the still camera at the last stop, at least that far from the centre,
 * must be identical. Returns the stops' stats.
 */
export async function lodFlight(t, { label, lat, lon, stops, zoom = [], pictures = false, jitter = 0 }) {
  const { hook, ready, shot, log, check } = t;
  await hook((f) => window.__pmc.debug(f), FLAGGED);
  const seen = [];
  // the ground under the place, from the meshes loaded around it: refined at every stop
  let ground = null;
  /** The stats once the fly mode has measured the ground (every few frames) on what is shown. */
  const measured = () =>
    hook(
      () =>
        new Promise((resolve) => {
          const f0 = window.__pmc.stats().frames;
          const t0 = performance.now();
          const poll = () => {
            const s = window.__pmc.stats();
            if ((s.frames >= f0 + 8 && s.aboveGround !== null) || performance.now() - t0 > 30_000) resolve(s);
            else setTimeout(poll, 50);
          };
          poll();
        }),
    );
  const place = async (stop) => {
    if (stop.orbit) {
      await hook(() => window.__pmc.mode('orbit'));
      await hook(([a, b, h]) => window.__pmc.setCamera(a, b, h, 0, -90), [lat, lon, stop.height]);
      return;
    }
    if (ground === null) {
      // measure from twice the height of the first stop above the datum (above the mountains)
      await hook(() => window.__pmc.mode('fly'));
      await hook(([a, b, h]) => window.__pmc.setCamera(a, b, h, 0, -90), [lat, lon, 2 * stop.height]);
      await ready(`${label}: above the place`);
      const s = await measured();
      check(s.aboveGround !== null, `${label}: no ground found under ${lat}, ${lon}`);
      log(`  the ground under ${lat}, ${lon}: ${(s.alt - s.aboveGround).toFixed(1)} m above the datum`);
      ground = s.alt - s.aboveGround;
    }
    await hook(() => window.__pmc.mode('fly'));
    const pitch = stop.down ? -90 : (stop.pitch ?? -15);
    await hook(([a, b, h, p]) => window.__pmc.setCamera(a, b, h, 0, p), [lat, lon, ground + stop.height, pitch]);
  };
  /** Measures the ground under the camera again (from the chunks shown); returns the height above it. */
  const remeasure = async () => {
    const s = await measured();
    if (s.aboveGround === null) return null;
    ground = s.alt - s.aboveGround;
    return s.aboveGround;
  };

  /**
   * Goes to `stop` taking pictures while the chunks change (at most `frames`), then waits until
   * it has converged; every picture must be free of flagged pixels and show no more background
   * below the horizon than the converged one.
   */
  const visit = async (stop, frames) => {
    const t0 = Date.now();
    await place(stop);
    const during = [];
    for (let n = 0; n < frames; n++) {
      const s = await hook(() => window.__pmc.stats());
      if (s.ready) break;
      const img = await shot(`${label}-${stop.name}-during-${n}`);
      during.push({ img, pending: s.pending, levels: s.lod.levelsText, background: s.background });
    }
    let s = await ready(`${label} ${stop.name}`);
    if (!stop.orbit) {
      // the ground was measured from coarser chunks: once more from those shown now
      const above = await remeasure();
      if (above !== null && Math.abs(above - stop.height) > Math.max(0.25, 0.1 * stop.height)) {
        await place(stop);
        s = await ready(`${label} ${stop.name}, ${stop.height} m above the ground measured again`);
      }
    }
    // the panel shows the histogram (it updates a few times a second)
    await hook(() => new Promise((r) => setTimeout(r, 400)));
    const panel = await t.page.textContent('#s-levels');
    const img = await shot(`${label}-${stop.name}`);
    const flagged = flaggedPixels(img);
    const tinted = tintedPixels(img);
    const range = levelRange(s.lod.levels);
    log(
      `  ${stop.name}: camera ${s.alt.toFixed(1)} m above the datum, ${s.aboveGround?.toFixed(1)} m above the ground; ${s.shown} chunks shown, ${s.triangles} triangles, levels ${s.lod.levelsText} ` +
        `(panel "${panel}"), ${flagged} flagged pixels, ${tinted} tinted, ${during.length} pictures while loading, ${((Date.now() - t0) / 1000).toFixed(1)} s`,
    );
    check(flagged === 0, `${label} ${stop.name}: ${flagged} flagged pixels (a crack or a hole): see ${label}-${stop.name}.png`);
    check(tinted <= TINTED_ALLOWED, `${label} ${stop.name}: ${tinted} pixels tinted by the back-face flag (at most ${TINTED_ALLOWED}): see ${label}-${stop.name}.png`);
    check(range !== null, `${label} ${stop.name}: no chunk shown`);
    check(panel === s.lod.levelsText, `${label} ${stop.name}: the panel says "${panel}", the stats "${s.lod.levelsText}"`);
    for (const [n, d] of during.entries()) {
      const f = flaggedPixels(d.img);
      const ft = tintedPixels(d.img);
      // a hole shows the background where the converged picture has terrain (the background
      // colour of that moment: it follows the altitude)
      const holes = newBackground(d.img, img, d.background);
      log(`    while loading (${d.pending} pending, ${d.levels}): ${f} flagged, ${ft} tinted, ${holes} background pixels where terrain is drawn once converged`);
      check(f === 0, `${label} on the way to ${stop.name}: ${f} flagged pixels (a crack or a hole): see ${label}-${stop.name}-during-${n}.png`);
      check(ft <= TINTED_ALLOWED, `${label} on the way to ${stop.name}: ${ft} pixels tinted by the back-face flag: see ${label}-${stop.name}-during-${n}.png`);
      check(
        holes <= 0.001 * img.width * img.height,
        `${label} on the way to ${stop.name}: ${holes} background pixels where terrain is drawn once converged (a hole): see ${label}-${stop.name}-during-${n}.png`,
      );
    }
    if (pictures) {
      await hook((f) => window.__pmc.debug(f), AS_SEEN);
      await shot(`${label}-${stop.name}-view`);
      await hook((f) => window.__pmc.debug(f), FLAGGED);
    }
    const p = t.problems();
    check(p.length === 0, `${label} ${stop.name}: ${p.join('\n  ')}`);
    return { name: stop.name, stats: s, range, panel };
  };

  // a teleport with a turn brings into view what no earlier view wanted: pictures of the way
  // there would show it missing, so only the converged views are checked on the tour
  for (const stop of stops) seen.push(await visit(stop, 0));

  // the histogram follows the height: the finest level shown never rises on the way down, the
  // orbit shows only coarse chunks, the ground the finest
  for (let i = 1; i < seen.length; i++) {
    check(
      seen[i].range.min <= seen[i - 1].range.min,
      `${label}: finer chunks at ${seen[i - 1].name} (L${seen[i - 1].range.min}) than at ${seen[i].name} (L${seen[i].range.min})`,
    );
  }
  const first = seen[0];
  const last = seen[seen.length - 1];
  check(last.range.min === 0, `${label}: no level-0 chunk at ${last.name} (${last.panel})`);
  check(first.range.min > 0, `${label}: a level-0 chunk from orbit (${first.panel})`);
  check(first.panel !== last.panel, `${label}: the panel's histogram did not change (${first.panel})`);

  if (jitter) {
    // a still camera at the last stop: two pictures some frames apart, the second drawn anew
    // (a still view is not redrawn unless asked), identical, fully shaded
    await hook(() => window.__pmc.debug({ plain: false }));
    const a = await shot(`${label}-still-a`);
    await hook(() => new Promise((r) => setTimeout(r, 500)));
    await hook(
      () =>
        new Promise((resolve) => {
          const d0 = window.__pmc.stats().draws;
          window.__pmc.redraw();
          const poll = () => (window.__pmc.stats().draws > d0 ? resolve() : setTimeout(poll, 20));
          poll();
        }),
    );
    const b = await shot(`${label}-still-b`);
    await hook(() => window.__pmc.debug({ plain: true }));
    const s = await hook(() => window.__pmc.stats());
    const planet = await hook(([p, sd]) => fetch(`api/v1/planet?preset=${p}&seed=${sd}`).then((x) => x.json()), [s.preset, s.seed]);
    const r = (planet.sea_radius ?? (planet.base_radius + planet.radius) / 2) + s.alt;
    const d = differingPixels(a, b);
    log(`  still camera ${s.aboveGround?.toFixed(2)} m above the ground, ${r.toFixed(1)} m from the centre: ${d} pixels differ`);
    const want = stops[stops.length - 1].height;
    check(s.aboveGround !== null && Math.abs(s.aboveGround - want) < 0.5, `${label}: the still camera is ${s.aboveGround} m above the ground, not ${want}`);
    check(d === 0, `${label}: a still camera gives different pictures (${d} pixels): jitter`);
    check(r >= jitter, `${label}: the camera is ${r.toFixed(0)} m from the centre, the test wants at least ${jitter}`);
  }

  if (zoom.length > 0) {
    // straight down, down and back up: every view going down lies inside the one before, so its
    // chunks refine chunks shown (kept until their children are ready); going back up, the
    // children stay until their parents are there again. No picture on the way may have a hole.
    for (const [n, height] of zoom.entries()) {
      const stop = { name: `zoom-${n}-${height}m`, height, down: true };
      seen.push(await visit(stop, n === 0 ? 0 : 4));
    }
  }
  await hook((f) => window.__pmc.debug(f), AS_SEEN);
  return seen;
}
