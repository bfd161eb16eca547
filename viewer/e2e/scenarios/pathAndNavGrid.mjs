// Step 8: path tool and navigation grid: two clicks draw the path, N overlays the grid by
// component.

import { VIEWPORT, check, fetchText, log } from '../harness.mjs';
import { fractionDifferent } from '../images.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { latLonFromPosition, length, sub } = await viewerModule('frames.ts');
const distance = (a, b) => length(sub(a, b));

// ---- the navigation overlay in pictures ----------------------------------------------------

/** The path's colour (src/navOverlay.ts PATH_COLOUR). */
const PATH_HEX = '#ff29b8';
/** Pixels within `tolerance` (sum over the channels) of colour `hex`. */
function colourPixels(img, hex, tolerance = 30) {
  const c = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    if (Math.abs(img.data[i] - c[0]) + Math.abs(img.data[i + 1] - c[1]) + Math.abs(img.data[i + 2] - c[2]) <= tolerance) n++;
  }
  return n;
}
/** Whether some pixel of the 3 × 3 around (x, y) differs between `a` and `b` (sum over channels > 40). */
function pixelChanged(a, b, x, y) {
  for (let dy = -1; dy <= 1; dy++) {
    for (let dx = -1; dx <= 1; dx++) {
      const i = 4 * ((y + dy) * a.width + (x + dx));
      if (Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2]) > 40) return true;
    }
  }
  return false;
}
/**
 * A detached component of a `/navgrid` answer seen from above: all its nodes in the answer, each
 * the highest node of its column (no cave pocket, nothing over it). The one with the most nodes
 * (the nearest of equals): `{label, nodes, centre, alt (its highest node, metres above `datum`),
 * distance}`, or null.
 */
function detachedFromAbove(a, datum) {
  const n = a.components.length;
  const pts = Array.from({ length: n }, (_, i) => [0, 1, 2].map((k) => a.origin[k] + a.positions[3 * i + k]));
  const top = new Map(); // column (direction) -> highest node
  for (let i = 0; i < n; i++) {
    const r = Math.hypot(...pts[i]);
    const key = pts[i].map((x) => (x / r).toFixed(7)).join(',');
    const j = top.get(key);
    if (j === undefined || r > Math.hypot(...pts[j])) top.set(key, i);
  }
  const isTop = new Set(top.values());
  const byLabel = new Map();
  for (let i = 0; i < n; i++) {
    if (2 * a.component_sizes[i] >= a.total_nodes) continue; // the main grid
    const l = byLabel.get(a.components[i]) ?? [];
    l.push(i);
    byLabel.set(a.components[i], l);
  }
  let best = null;
  for (const [label, idx] of byLabel) {
    if (idx.length !== a.component_sizes[idx[0]] || !idx.every((i) => isTop.has(i))) continue;
    const centre = [0, 1, 2].map((k) => idx.reduce((s, i) => s + pts[i][k], 0) / idx.length);
    const d = distance(centre, a.origin);
    if (!best || idx.length > best.nodes || (idx.length === best.nodes && d < best.distance)) {
      best = { label, nodes: idx.length, centre, distance: d, alt: Math.max(...idx.map((i) => Math.hypot(...pts[i]))) - datum };
    }
  }
  return best;
}

export const name = '8. path tool and navigation grid: two clicks draw the path, N overlays the grid by component';

export async function scenario(t) {
  const { closeup } = t.shared;
  const { page, consoleProblems, failedResponses, hook, ready, waitFor, pathState, gridState, shot } = t;
  const CX = VIEWPORT.width / 2;
  const CY = VIEWPORT.height / 2;
  const apiGet = async (path) => {
    const r = await fetchText(`${closeup.api}api/v1/${path}`, 20_000);
    check(r.status === 200, `GET /api/v1/${path}: ${r.status} ${r.text.slice(0, 300)}`);
    return JSON.parse(r.text);
  };
  const planet = await apiGet('planet?preset=earthlike&seed=7');
  const datum = planet.sea_radius ?? (planet.base_radius + planet.radius) / 2;
  // the ground near (-10°, 8°): the server's path from there to there stands on its highest
  // floor; the close-up looks down at 60° from 120 m above it (two clicks 200 px apart span some
  // tens of metres there)
  const here = await apiGet('path?preset=earthlike&seed=7&from=-10,8&to=-10,8');
  check(here.found && here.waypoints.length === 1, `GET /api/v1/path from (-10°, 8°) to itself: ${JSON.stringify(here).slice(0, 300)}`);
  const g0 = here.waypoints[0];
  check(g0.alt > 5, `the ground near (-10°, 8°) is not land: ${g0.alt.toFixed(1)} m above the datum`);
  const viewHash = `#preset=earthlike&seed=7&mode=fly&lat=${g0.lat}&lon=${g0.lon}&alt=${(g0.alt + 120).toFixed(1)}&heading=0&pitch=-60`;
  log(`  view ${viewHash}`);
  await page.evaluate((h) => (location.hash = h), viewHash);
  await ready('the path close-up');
  const before = await shot('path-before');

  // the Path tool (editing is off on this server: it works all the same), two clicks
  await page.click('#tool-path');
  check((await page.getAttribute('#tool-path', 'aria-pressed')) === 'true', 'the Path button is not shown as pressed');
  check(!(await page.isDisabled('#tool-path')), 'the Path button is disabled on a server without a world');
  check((await hook(() => window.__pmc.stats())).pathTool, 'stats() does not say the Path tool is chosen');
  const [A, B] = [[CX - 100, CY + 40], [CX + 100, CY - 20]];
  await page.mouse.click(...A);
  // (the click is taken by the next animation frame)
  await waitFor(page, 'the start of the path', () => window.__pmc.path().phase !== 'empty', null, pathState, 10_000);
  const p1 = await hook(() => window.__pmc.path());
  check(p1.phase === 'start' && p1.from !== null, `after the first click: ${p1.phase} (${p1.message})`);
  await page.mouse.click(...B);
  await waitFor(page, 'the path', () => !['empty', 'start', 'loading'].includes(window.__pmc.path().phase), null, pathState);
  // the path found is drawn, and its points projected, from the next frame on
  await page
    .waitForFunction(() => { const x = window.__pmc.path(); return x.phase !== 'found' || (x.line > 0 && x.screen.length === x.line); }, null, { timeout: 5_000 })
    .catch(() => undefined);
  const p = await hook(() => window.__pmc.path());
  log(`  ${p.from} -> ${p.to}: ${p.message}`);
  check(p.phase === 'found', `no path between two points of the close-up: ${p.phase}: ${p.message}`);
  check(p.length > 0 && p.steps >= 1 && p.waypoints === p.steps + 1, `path length ${p.length} m, ${p.steps} steps, ${p.waypoints} waypoints`);
  const distance = (m) => (m >= 1000 ? `${(m / 1000).toFixed(2)} km` : `${m.toFixed(1)} m`); // as src/ui.ts formatDistance
  const stepsText = `${p.steps} step${p.steps === 1 ? '' : 's'}`;
  // the smoothed path is what the panels tell and what is drawn
  check(p.smoothed !== null && p.smoothed.legs >= 1 && p.smoothed.length <= p.length * 1.0001,
    `the path found has no smoothed form, or a longer one: ${JSON.stringify(p.smoothed)}, walk ${p.length} m`);
  const legsText = `${p.smoothed.legs} leg${p.smoothed.legs === 1 ? '' : 's'}`;
  const wantStatus = `path: ${distance(p.smoothed.length)} in ${p.smoothed.legs} straight leg${p.smoothed.legs === 1 ? '' : 's'} (grid walk ${distance(p.length)}, ${stepsText})`;
  const wantStats = `${distance(p.smoothed.length)} · ${legsText}`;
  // the panels show the path found from the next frame on (the stats panel within 200 ms)
  await page
    .waitForFunction(
      ([a, b]) => document.querySelector('#path-status')?.textContent?.startsWith(a) && document.querySelector('#s-path')?.textContent === b,
      [wantStatus, wantStats],
      { timeout: 5_000 },
    )
    .catch(() => undefined);
  const shownText = await page.textContent('#path-status');
  check(shownText.startsWith(wantStatus), `the tools panel shows "${shownText}"`);
  const statsText = await page.textContent('#s-path');
  check(statsText === wantStats, `the stats panel shows "${statsText}" for the path`);
  // the server, asked the same, walks the same length, and its smoothed line is the one drawn
  const q = `path?preset=earthlike&seed=7&from=${encodeURIComponent(p.from)}&to=${encodeURIComponent(p.to)}`;
  const direct = await apiGet(q);
  check(direct.found === true && Math.abs(direct.length - p.length) < 1e-9 && direct.steps === p.steps,
    `GET /api/v1/${q}: found ${direct.found}, ${direct.length} m, ${direct.steps} steps; the page shows ${p.length} m, ${p.steps} steps`);
  check(direct.smoothed.length === p.smoothed.length && direct.smoothed.line.length === p.line && p.screen.length === p.line,
    `the smoothed path: ${direct.smoothed.length} m in ${direct.smoothed.line.length} line points from the server; the page shows ${p.smoothed.length} m and draws ${p.screen.length} of ${p.line} points`);
  log(`  smoothed: ${p.smoothed.length.toFixed(1)} m in ${p.smoothed.legs} legs, drawn through ${p.line} points (the walk: ${p.waypoints} waypoints)`);
  // pixels along the drawn path changed (where the terrain hides it, its faint copy shows)
  const after = await shot('path');
  const samples = [];
  for (let i = 1; i < p.screen.length; i++) {
    const [a, b] = [p.screen[i - 1], p.screen[i]];
    if (!a || !b) continue;
    const n = Math.max(1, Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / 3));
    for (let k = 0; k < n; k++) samples.push([a[0] + ((b[0] - a[0]) * k) / n, a[1] + ((b[1] - a[1]) * k) / n]);
  }
  const inside = samples.filter(([x, y]) => x >= 2 && y >= 2 && x < VIEWPORT.width - 2 && y < VIEWPORT.height - 2);
  const changed = inside.filter(([x, y]) => pixelChanged(before, after, Math.round(x), Math.round(y)));
  log(`  ${changed.length} of ${inside.length} pixels sampled along the path changed, ${colourPixels(after, PATH_HEX) - colourPixels(before, PATH_HEX)} more path-coloured pixels`);
  check(inside.length >= 20, `the path is hardly on the screen: ${inside.length} sample pixels`);
  check(changed.length >= 0.8 * inside.length, `only ${changed.length} of ${inside.length} pixels along the path changed`);
  check(colourPixels(after, PATH_HEX) - colourPixels(before, PATH_HEX) > 300, 'the path colour is hardly in the picture');

  // the grid: N, around the camera's ground point
  await page.keyboard.press('n');
  await waitFor(page, 'the nav grid', () => { const g = window.__pmc.navgrid(); return g.nodes > 0 && !g.loading && g.drawn; }, null, gridState);
  check(await page.isChecked('#navgrid'), 'N did not tick the nav grid box');
  const g = await hook(() => window.__pmc.navgrid());
  const main = g.components.find((c) => c.main);
  log(`  grid: ${g.nodes} nodes, ${g.edges} steps, ${g.components.length} components within ${g.shown.range.toFixed(0)} m (planet: ${g.totalNodes} nodes, ${g.totalComponents} components), main ${main ? `${main.label} ${main.hex}` : 'none'}`);
  check(g.error === null, `the grid request failed: ${g.error}`);
  check(g.edges > 0 && main !== undefined && main.size * 2 >= g.totalNodes, `no main grid (with steps) in the overlay: ${JSON.stringify(g.components.slice(0, 3))}`);
  // (the panel shows the grid drawn from the next frame on)
  await page
    .waitForFunction((n) => document.querySelector('#navgrid-status')?.textContent?.includes(`${n.toLocaleString('en-US')} nodes`), g.nodes, { timeout: 5_000 })
    .catch(() => undefined);
  const gridText = await page.textContent('#navgrid-status');
  check(gridText.includes(`${g.nodes.toLocaleString('en-US')} nodes`), `the panel says "${gridText}"`);
  const gridImg = await shot('navgrid');
  const dGrid = fractionDifferent(after, gridImg);
  const mainMore = colourPixels(gridImg, main.hex) - colourPixels(after, main.hex);
  log(`  ${(100 * dGrid).toFixed(1)} % of the pixels changed, ${mainMore} more pixels of the main grid's colour`);
  check(dGrid > 0.01, `the grid overlay changed only ${(100 * dGrid).toFixed(2)} % of the pixels`);
  check(mainMore > 300, `the main grid's colour ${main.hex} is hardly in the picture (${mainMore} pixels more)`);

  // a detached grid seen from above shows in its own colour: find one near (its nodes the top
  // floor of their columns), look straight down at it; the overlay follows the camera
  const near = await apiGet(`navgrid?preset=earthlike&seed=7&x=${g.shown.centre[0]}&y=${g.shown.centre[1]}&z=${g.shown.centre[2]}&range=1500&limit=100000`);
  const island = detachedFromAbove(near, datum);
  check(island !== null, `no detached grid seen from above within 1500 m of the close-up (${near.total_components} components on the planet)`);
  const ia = latLonFromPosition(island.centre);
  log(`  detached component ${island.label}: ${island.nodes} nodes ${island.alt.toFixed(1)} m above the datum at ${ia.lat.toFixed(4)}°, ${ia.lon.toFixed(4)}°, ${island.distance.toFixed(0)} m away`);
  const fetches = g.fetches;
  await hook(([la, lo, al]) => window.__pmc.setCamera(la, lo, al, 0, -89), [ia.lat, ia.lon, island.alt + 60]);
  await ready('above the detached grid');
  await waitFor(page, 'the nav grid above the detached grid', (f) => { const s = window.__pmc.navgrid(); return s.fetches > f && !s.loading && s.drawn; }, fetches, gridState);
  const g2 = await hook(() => window.__pmc.navgrid());
  const it = g2.components.find((c) => c.label === island.label);
  check(it !== undefined && !it.main, `the overlay around the detached grid lacks component ${island.label}: ${JSON.stringify(g2.components.slice(0, 5))}`);
  check((g2.visible[island.label] ?? 0) > 0, `component ${island.label} is not visible from above: on screen ${g2.onScreen[island.label] ?? 0}, visible ${JSON.stringify(g2.visible)}`);
  const withGrid = await shot('navgrid-detached');
  // the checkbox is in the side panel's Debug section
  await t.openPanel(['debug']);
  await page.click('#navgrid');
  await waitFor(page, 'the nav grid off', () => !window.__pmc.navgrid().drawn, null, gridState, 10_000);
  const without = await shot('navgrid-off');
  const itMore = colourPixels(withGrid, it.hex) - colourPixels(without, it.hex);
  const mainMore2 = colourPixels(withGrid, main.hex) - colourPixels(without, main.hex);
  log(`  refetched (${g2.fetches - fetches} more); component ${it.label} ${it.hex}: ${g2.visible[it.label]} nodes visible, ${itMore} more pixels of its colour; ${mainMore2} of the main grid's`);
  check(itMore >= 20, `the detached grid's colour ${it.hex} is not in the picture (${itMore} pixels more)`);
  check(mainMore2 > 100, `the main grid's colour is not in the picture next to the detached grid (${mainMore2} pixels more)`);

  // Esc clears the path (the tool stays), Esc again goes back to Look
  await page.keyboard.press('Escape');
  const cleared = await hook(() => window.__pmc.path());
  check(cleared.phase === 'empty' && cleared.active, `Esc: path ${cleared.phase}, tool ${cleared.active ? 'Path' : 'not Path'}`);
  await page.keyboard.press('Escape');
  check(!(await hook(() => window.__pmc.stats())).pathTool, 'a second Esc did not leave the Path tool');
  check((await page.getAttribute('#tool-look', 'aria-pressed')) === 'true', 'Look is not shown as pressed after Esc');
  check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
  check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
}
