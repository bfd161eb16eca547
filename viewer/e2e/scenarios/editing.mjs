// Step 7: editing: dig with the mouse, a second browser follows, undo/redo, reload, restart.

import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { CHROMIUM, chromiumArgs, VIEWPORT, check, cleanups, fetchText, log, withTimeout } from '../harness.mjs';
import { crop, fractionDifferent } from '../images.mjs';
import { startBackend } from '../servers.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { latLonFromPosition, length, sub } = await viewerModule('frames.ts');
const distance = (a, b) => length(sub(a, b));

export const name = '7. editing: dig with the mouse, a second browser follows, undo/redo, reload, restart';

export async function scenario(t) {
  const { page, consoleProblems, failedResponses, watchPage, hookOn, readyOn, waitFor, pathState, gridState, shotOf } = t;
  // the first browser's page is done: stop it drawing (software rendering shares the CPU)
  await page.goto('about:blank');
  // a fresh world on a server of its own (the default layout: voxels ~12 m wide, 4 m tall)
  const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-world-'));
  cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
  const world = join(dir, 'e2e.pmcw');
  let server = await startBackend(null, { world });
  const apiGet = async (path) => {
    const r = await fetchText(`${server.api}api/v1/${path}`, 10_000);
    check(r.status === 200, `GET /api/v1/${path}: ${r.status} ${r.text}`);
    return JSON.parse(r.text);
  };
  const planet = await apiGet('planet');
  check(planet.edit?.enabled === true, `/api/v1/planet says editing is off: ${JSON.stringify(planet.edit)}`);
  check(existsSync(world), `the server did not create the world file ${world}`);

  // two browsers, each with its own context (own cookies, connections, event stream)
  const browser = await withTimeout(
    chromium.launch({ executablePath: CHROMIUM, headless: true, args: chromiumArgs() }),
    60_000,
    'launching a second Chromium',
  );
  cleanups.push(() => browser.close());
  const ctxA = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  const ctxB = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  const A = await ctxA.newPage();
  const B = await ctxB.newPage();
  for (const [p, label] of [[A, 'A'], [B, 'B']]) {
    p.setDefaultTimeout(60_000);
    watchPage(p, label);
  }
  const hA = hookOn(A);
  const hB = hookOn(B);
  const CX = VIEWPORT.width / 2;
  const CY = VIEWPORT.height / 2;
  const pickAt = (h) => h(([x, y]) => window.__pmc.pick(x, y), [CX, CY]);
  const statsOf = (h) => h(() => window.__pmc.stats());
  const waitRevision = (p, revision) =>
    p.waitForFunction(
      (r) => {
        const e = window.__pmc.stats().edit;
        return e.revision === r && !e.inFlight;
      },
      revision,
      { timeout: 60_000 },
    );
  const open = async (p, url, what) => {
    await p.goto(url, { waitUntil: 'load', timeout: 60_000 });
    await p.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
    return readyOn(p, what);
  };
  const WINDOW = 240; // pixels around the click compared between screenshots
  const windowDiff = (a, b) => fractionDifferent(crop(a, CX, CY, WINDOW, WINDOW), crop(b, CX, CY, WINDOW, WINDOW));

  // both open the page 200 m above (-10°, 8°); A finds the ground there, and the close-up view,
  // 80 m above it looking down at 60°, goes into both pages' URL hash
  const start = `${server.url}#preset=earthlike&seed=7&mode=fly&lat=-10&lon=8&alt=200&heading=0&pitch=-89`;
  await Promise.all([open(A, start, 'A from 200 m'), open(B, start, 'B from 200 m')]);
  // (200 px right of the centre: a snowfield, where the dug rock shows well)
  const ground = await hA(([x, y]) => window.__pmc.pick(x, y), [CX + 200, CY]);
  check(ground !== null, 'no terrain in the view from 200 m above (-10°, 8°)');
  const groundAlt = Math.hypot(...ground.point) - planet.sea_radius;
  check(groundAlt > 5, `the ground chosen near (-10°, 8°) is not land: ${groundAlt.toFixed(1)} m above the sea`);
  const at = latLonFromPosition(ground.point);
  const viewHash =
    `#preset=earthlike&seed=7&mode=fly&lat=${at.lat.toFixed(5)}&lon=${at.lon.toFixed(5)}` +
    `&alt=${(groundAlt + 80).toFixed(1)}&heading=0&pitch=-60`;
  log(`  view ${viewHash}`);
  await Promise.all([A, B].map((p) => p.evaluate((h) => (location.hash = h), viewHash)));
  const [sA0, sB0] = await Promise.all([readyOn(A, 'A at the close-up'), readyOn(B, 'B at the close-up')]);
  for (const p of [A, B]) {
    const h = await p.evaluate(() => location.hash);
    check(h === viewHash, `the URL hash changed to ${h}`);
  }
  for (const [p, s0, label] of [[A, sA0, 'A'], [B, sB0, 'B']]) {
    check(s0.edit.enabled && s0.edit.error === null, `${label}: editing is off or failed: ${JSON.stringify(s0.edit)}`);
    await p.waitForFunction(() => window.__pmc.stats().edit.push === 'open', null, { timeout: 30_000 });
  }
  check(await A.isDisabled('#tool-dig') === false, 'the Dig button is disabled on an editable world');
  const rev0 = sA0.edit.revision;
  const pickA0 = await pickAt(hA);
  const pickB0 = await pickAt(hB);
  check(pickA0 !== null && pickB0 !== null, 'no terrain under the centre of the close-up');
  check(Math.abs(pickA0.distance - pickB0.distance) < 0.05, `A and B do not show the same view: ${pickA0.distance} vs ${pickB0.distance} m`);
  check(pickA0.distance < 120, `the terrain under the cursor is ${pickA0.distance.toFixed(1)} m away: not a close-up`);
  log(`  before: terrain ${pickA0.distance.toFixed(2)} m from the camera (chunk ${pickA0.key}), revision ${rev0}`);
  const beforeA = await shotOf(A, 'edit-before');

  // A: a path across the spot to dig and the nav grid; both follow the edit below
  await A.click('#tool-path');
  // (right of the tools panel, which covers the bottom left up to x = 370)
  await A.mouse.click(CX - 90, CY + 50);
  await A.mouse.click(CX + 150, CY - 50);
  // (the clicks are taken by the next animation frame: the path is empty until then)
  await waitFor(A, 'A: the path', () => !['empty', 'start', 'loading'].includes(window.__pmc.path().phase), null, pathState);
  const pathA0 = await hA(() => window.__pmc.path());
  check(pathA0.phase === 'found' && pathA0.revision === rev0, `A: no path across the close-up before the dig: ${pathA0.phase} (${pathA0.message}), revision ${pathA0.revision}`);
  await hA(() => window.__pmc.navgrid(true));
  await waitFor(A, 'A: the nav grid', () => { const g = window.__pmc.navgrid(); return g.drawn && !g.loading; }, null, gridState);
  const gridA0 = await hA(() => window.__pmc.navgrid());
  check(gridA0.shown.revision === rev0 && gridA0.error === null, `A: the grid shown is of revision ${gridA0.shown.revision} (${gridA0.error})`);

  // A: Dig with the mouse, radius 16 m, one click at the centre
  await A.click('#tool-dig');
  check(!(await statsOf(hA)).pathTool, 'choosing Dig did not leave the Path tool');
  check((await A.getAttribute('#tool-dig', 'aria-pressed')) === 'true', 'the Dig button is not shown as pressed');
  await A.fill('#brush-radius', '16');
  await A.press('#brush-radius', 'Enter');
  let sA = await statsOf(hA);
  check(sA.edit.tool === 'dig' && sA.edit.settings.radius === 16, `tool ${sA.edit.tool}, radius ${sA.edit.settings.radius} (wanted dig, 16)`);
  await A.mouse.move(CX - 40, CY - 40);
  await A.mouse.move(CX, CY, { steps: 4 });
  await A.waitForFunction(() => window.__pmc.stats().cursor, null, { timeout: 10_000 });
  await A.mouse.click(CX, CY);
  await waitRevision(A, rev0 + 1);
  sA = await statsOf(hA);
  check(sA.edit.error === null, `the dig failed: ${sA.edit.error}`);
  check(sA.edit.sent === 1, `${sA.edit.sent} edits sent for one click`);
  await A.waitForFunction((r) => document.getElementById('s-edits')?.textContent?.startsWith(`rev ${r} · 1 active`), rev0 + 1, { timeout: 10_000 });
  const list1 = await apiGet('edits');
  check(
    list1.edits.length === 1 && list1.active === 1 && list1.edits[0].active && list1.edits[0].brush === 'remove' && list1.edits[0].radius === 16,
    `GET /api/v1/edits after the dig: ${JSON.stringify(list1)}`,
  );
  const dug = distance(list1.edits[0].center, pickA0.point);
  check(dug < 0.5, `the edit is ${dug.toFixed(2)} m from the point clicked`);
  // the path was asked again and the grid fetched again for the new revision
  await waitFor(A, 'A: the path and the grid after the dig', (r) => { const p = window.__pmc.path(); const g = window.__pmc.navgrid(); return p.revision === r && !p.refreshing && g.shown?.revision === r && !g.loading; }, rev0 + 1,
    () => { const { screen: _s, ...path } = window.__pmc.path(); const { components: _c, onScreen: _o, visible: _v, ...grid } = window.__pmc.navgrid(); return { path, grid }; });
  const pathA1 = await hA(() => window.__pmc.path());
  const gridA1 = await hA(() => window.__pmc.navgrid());
  log(`  path ${pathA0.message} -> ${pathA1.message} (${pathA1.requests} requests); grid ${gridA0.nodes} -> ${gridA1.nodes} nodes, ${gridA1.fetches} fetches`);
  check(pathA1.requests === pathA0.requests + 1 && ['found', 'none'].includes(pathA1.phase), `A: the path did not follow the edit: ${pathA1.phase}, ${pathA1.requests} requests`);
  check(gridA1.fetches === gridA0.fetches + 1 && gridA1.error === null, `A: the grid did not follow the edit: ${gridA1.fetches} fetches, ${gridA1.error}`);
  await hA(() => window.__pmc.navgrid(false));
  await A.keyboard.press('Escape'); // clears the path (the pictures below compare the terrain)
  check((await hA(() => window.__pmc.path())).phase === 'empty', 'Esc did not clear the path');
  // Look again (no brush cursor in the pictures), then let the edited chunks arrive
  await A.click('#tool-look');
  await A.waitForFunction(() => !window.__pmc.stats().cursor, null, { timeout: 10_000 });
  await readyOn(A, 'A after the dig');
  const pickA1 = await pickAt(hA);
  check(pickA1 !== null, 'no terrain under the centre after the dig');
  log(`  after the dig: ${pickA1.distance.toFixed(2)} m (${(pickA1.distance - pickA0.distance).toFixed(2)} m deeper), ${sA.reloads} chunk reloads in A`);
  check(pickA1.distance > pickA0.distance + 4, `A: no hole under the cursor (${pickA0.distance.toFixed(2)} -> ${pickA1.distance.toFixed(2)} m)`);
  const afterA = await shotOf(A, 'edit-after');
  const dA = windowDiff(beforeA, afterA);
  log(`  A: ${(100 * dA).toFixed(1)} % of the ${WINDOW} px window around the click changed`);
  check(dA > 0.15, `A: only ${(100 * dA).toFixed(1)} % of the pixels around the click changed`);

  // B saw it by itself (server push, then a reload of the edited chunks)
  await waitRevision(B, rev0 + 1);
  await readyOn(B, 'B after the push');
  const sB1 = await statsOf(hB);
  const pickB1 = await pickAt(hB);
  check(sB1.reloads > 0, 'B reloaded no chunk after the push');
  check(pickB1 !== null && Math.abs(pickB1.distance - pickA1.distance) < 0.05, `B does not show the hole: ${pickB1?.distance} m vs A ${pickA1.distance} m`);
  const afterB = await shotOf(B, 'edit-page-b');
  const dB = windowDiff(beforeA, afterB); // the same view as A's before the dig
  log(`  B: ${sB1.reloads} chunk reloads, ${(100 * dB).toFixed(1)} % of the window changed`);
  check(dB > 0.15, `B: only ${(100 * dB).toFixed(1)} % of the pixels around the hole changed`);

  // undo with the button: the ground comes back, in A and in B
  await A.click('#undo');
  await waitRevision(A, rev0 + 2);
  await readyOn(A, 'A after undo');
  const pickA2 = await pickAt(hA);
  check(pickA2 !== null && Math.abs(pickA2.distance - pickA0.distance) < 0.05, `undo did not restore the ground: ${pickA2?.distance} m, before the dig ${pickA0.distance} m`);
  await waitRevision(B, rev0 + 2);
  await readyOn(B, 'B after undo');
  const pickB2 = await pickAt(hB);
  check(pickB2 !== null && Math.abs(pickB2.distance - pickB0.distance) < 0.05, `B did not follow the undo: ${pickB2?.distance} m vs ${pickB0.distance} m`);
  check((await apiGet('edits')).active === 0, 'the server still lists an active edit after undo');

  // redo with Ctrl+Shift+Z: the hole is back
  await A.keyboard.press('Control+Shift+Z');
  await waitRevision(A, rev0 + 3);
  await readyOn(A, 'A after redo');
  const pickA3 = await pickAt(hA);
  check(pickA3 !== null && Math.abs(pickA3.distance - pickA1.distance) < 0.05, `redo did not bring the hole back: ${pickA3?.distance} m vs ${pickA1.distance} m`);
  const list3 = await apiGet('edits');
  check(list3.revision === rev0 + 3 && list3.active === 1 && list3.redo === 0, `GET /api/v1/edits after redo: ${JSON.stringify(list3)}`);
  await waitRevision(B, rev0 + 3);
  await ctxB.close(); // B is done: A reloads faster alone

  // a reload of A still shows it
  await A.reload({ waitUntil: 'load' });
  await A.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  await readyOn(A, 'A reloaded');
  const pickA4 = await pickAt(hA);
  check(pickA4 !== null && Math.abs(pickA4.distance - pickA1.distance) < 0.05, `after a reload: ${pickA4?.distance} m, the hole was ${pickA1.distance} m`);
  const reloadedA = await shotOf(A, 'edit-reloaded');
  const dR = windowDiff(beforeA, reloadedA);
  check(dR > 0.15, `after a reload only ${(100 * dR).toFixed(1)} % of the pixels around the hole differ from before the dig`);

  // a new server on the same world file still has it (the edit was saved)
  await A.goto('about:blank');
  await server.stop();
  server = await startBackend(null, { world });
  const list5 = await apiGet('edits');
  check(list5.active === 1 && distance(list5.edits[0].center, list1.edits[0].center) < 1e-6, `the restarted server lists ${JSON.stringify(list5)}`);
  const s5 = await open(A, server.url + viewHash, 'A on the restarted server');
  check(s5.edit.enabled, `editing is off after the restart: ${s5.edit.reason}`);
  const pickA5 = await pickAt(hA);
  check(pickA5 !== null && Math.abs(pickA5.distance - pickA1.distance) < 0.05, `after the restart: ${pickA5?.distance} m, the hole was ${pickA1.distance} m`);
  const restarted = await shotOf(A, 'edit-restarted');
  const dS = windowDiff(beforeA, restarted);
  log(`  reload: ${(100 * dR).toFixed(1)} %, restart: ${(100 * dS).toFixed(1)} % of the window differ from before the dig`);
  check(dS > 0.15, `after the restart only ${(100 * dS).toFixed(1)} % of the pixels around the hole differ from before the dig`);
  await ctxA.close();
  check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
  check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
}
