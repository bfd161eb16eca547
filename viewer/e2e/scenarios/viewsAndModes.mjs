// Step 6: debug views, mode switch, walk mode, the URL hash, the keyboard help (?) and H.

import { readFileSync } from 'node:fs';
import { check, log } from '../harness.mjs';
import { decodePng, fractionDifferent } from '../images.mjs';

export const name = '6. debug views, mode switch, walk mode, the URL hash, the keyboard help and hiding the panels';

export async function scenario(t) {
  const { page, consoleProblems, expectedFailures, hook, ready, shot, openPanel } = t;
  await openPanel(['view', 'detail', 'debug', 'stats']);
  await hook(() => window.__pmc.setCamera(20, 15, 3000, 0, -90));
  await hook(() => window.__pmc.mode('orbit'));
  await ready('orbit again');
  const plain = await shot('debug-none');
  for (const [id, name] of [['#faces', 'faces'], ['#wireframe', 'wireframe'], ['#borders', 'borders']]) {
    await page.click(id);
    const img = await shot(`debug-${name}`);
    const diff = fractionDifferent(plain, img);
    log(`  ${name}: ${(100 * diff).toFixed(1)} % of the pixels changed`);
    // the borders are thin lines around each chunk drawn; with levels of detail the view from
    // 3 km holds a few dozen large chunks, so they cover about 1 % of the picture
    const least = name === 'borders' ? 0.004 : 0.02;
    check(diff > least, `toggling ${name} changed only ${(100 * diff).toFixed(2)} % of the pixels`);
    await page.click(id);
  }
  const flags = await hook(() => window.__pmc.debug({}));
  check(!flags.wireframe && !flags.faceColours && !flags.borders, `debug flags left on: ${JSON.stringify(flags)}`);

  // Tab switches to fly, the button back to orbit
  await page.click('#view');
  await page.keyboard.press('Tab');
  check((await hook(() => window.__pmc.stats())).mode === 'fly', 'Tab did not switch to fly');
  await page.click('#mode');
  check((await hook(() => window.__pmc.stats())).mode === 'orbit', 'the mode button did not switch to orbit');

  // walk: the eye settles about 2 m above the ground and W moves it along
  await hook(() => window.__pmc.setCamera(-10, 8, 80, 90, -5));
  await hook(() => window.__pmc.mode('walk'));
  await ready('walking');
  await page.waitForFunction(() => Math.abs((window.__pmc.stats().aboveGround ?? 99) - 2) < 0.25, null, { timeout: 60_000 });
  const w0 = await hook(() => window.__pmc.stats());
  await page.keyboard.down('KeyW');
  await page.waitForFunction((lon) => Math.abs(window.__pmc.stats().lon - lon) > 0.02, w0.lon, { timeout: 60_000 });
  await page.keyboard.up('KeyW');
  await page.waitForFunction(() => Math.abs((window.__pmc.stats().aboveGround ?? 99) - 2) < 0.25, null, { timeout: 60_000 });
  const w1 = await hook(() => window.__pmc.stats());
  log(`  walked from lon ${w0.lon.toFixed(4)} to ${w1.lon.toFixed(4)}, altitude ${w0.alt.toFixed(1)} -> ${w1.alt.toFixed(1)} m, ${w1.aboveGround.toFixed(2)} m above the ground`);
  check(w1.walk && w1.mode === 'fly', `walk mode lost: ${w1.mode}, walk ${w1.walk}`);
  await shot('walk');

  // a reload keeps the planet, the mode and the camera
  await page.waitForFunction(() => location.hash.includes('walk=1'), null, { timeout: 10_000 });
  const hash = await page.evaluate(() => location.hash);
  await page.reload({ waitUntil: 'load' });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const r = await ready('after reload');
  log(`  ${hash}`);
  check(r.preset === 'earthlike' && r.seed === '7' && r.walk, `reload lost the state: ${r.preset}/${r.seed} walk ${r.walk}`);
  check(Math.abs(r.lat - w1.lat) < 1e-3 && Math.abs(r.lon - w1.lon) < 1e-3, `reload moved the camera: ${r.lat},${r.lon} vs ${w1.lat},${w1.lon}`);

  // an API error shows a message and keeps the planet
  expectedFailures.push(/preset=venus/);
  const err = await hook(() => window.__pmc.setPlanet('venus', '7').then(() => null, (e) => String(e.message)));
  check(err !== null, 'setPlanet("venus") did not fail');
  const banner = await page.evaluate(() => (document.getElementById('error').hidden ? null : document.getElementById('error-text').textContent));
  log(`  error banner: ${banner}`);
  check(banner !== null && banner.includes('venus'), `no visible error message for an unknown preset (banner: ${banner})`);
  const after = await hook(() => window.__pmc.stats());
  check(after.preset === 'earthlike' && after.loaded > 0, `the planet changed after a failed switch: ${after.preset}, ${after.loaded} chunks`);
  check((await page.inputValue('#preset')) === 'earthlike', 'the preset picker does not show the current planet');
  await page.click('#error-close');
  check(await page.isHidden('#error'), 'the error banner does not close');

  // the go-to box: a bad place is refused with a message; a good one is flown to along an arc
  // that climbs over both ends, and the streaming converges there
  await page.fill('#goto', '91, 0');
  await page.press('#goto', 'Enter');
  const refused = await page.evaluate(() => (document.getElementById('error').hidden ? null : document.getElementById('error-text').textContent));
  check(refused !== null && refused.includes('beyond the poles'), `no message for a latitude of 91° (banner: ${refused})`);
  await page.click('#error-close');
  const start = await hook(() => window.__pmc.stats());
  await page.fill('#goto', "27°59'N 86°55'E, 300");
  await page.press('#goto', 'Enter');
  const way = await hook(
    () =>
      new Promise((resolve) => {
        const seen = [];
        const t0 = performance.now();
        const poll = () => {
          const s = window.__pmc.stats();
          seen.push([s.lat, s.lon, s.alt, s.flying]);
          if ((!s.flying && seen.length > 1) || performance.now() - t0 > 30_000) resolve(seen);
          else setTimeout(poll, 100);
        };
        poll();
      }),
  );
  const arrived = await ready('after going to 27°59\'N 86°55\'E');
  const highest = Math.max(...way.map((w) => w[2]));
  log(`  go-to: ${way.length} samples on the way, from ${start.alt.toFixed(0)} m to ${arrived.alt.toFixed(0)} m, highest ${highest.toFixed(0)} m; now ${arrived.lat.toFixed(4)}, ${arrived.lon.toFixed(4)}`);
  check(way.filter((w) => w[3]).length >= 5, `the flight was a jump (${way.filter((w) => w[3]).length} samples while flying)`);
  check(Math.abs(arrived.lat - (27 + 59 / 60)) < 1e-6 && Math.abs(arrived.lon - (86 + 55 / 60)) < 1e-6 && Math.abs(arrived.alt - 300) < 1e-6, `the flight ended at ${arrived.lat}, ${arrived.lon}, ${arrived.alt}`);
  check(highest > Math.max(start.alt, 300) + 100, `the flight did not climb on the way (highest ${highest} m)`);
  check(arrived.pending === 0 && arrived.shown > 0, `the streaming did not converge there: ${arrived.shown} shown, ${arrived.pending} pending`);

  // a bookmark of this view: kept in local storage, flown back to from elsewhere
  await page.click('#bookmark-add');
  const marks = await page.$$eval('#bookmarks option', (os) => os.map((o) => o.value).filter((v) => v !== ''));
  const stored = await page.evaluate(() => JSON.parse(localStorage.getItem('pmc.bookmarks') ?? '[]'));
  log(`  bookmarks: ${JSON.stringify(marks)}; stored ${stored.length}`);
  check(marks.length === 1 && stored.length === 1 && stored[0].name === marks[0] && stored[0].planet === 'earthlike · seed 7', `the bookmark was not kept: ${JSON.stringify(stored)}`);
  const flyDone = () => page.waitForFunction(() => !window.__pmc.stats().flying, null, { timeout: 30_000, polling: 100 });
  await page.fill('#goto', '0, 0, 500');
  await page.press('#goto', 'Enter');
  await flyDone();
  await page.selectOption('#bookmarks', marks[0]);
  await page.waitForFunction(() => window.__pmc.stats().flying, null, { timeout: 5_000, polling: 50 }).catch(() => undefined);
  await flyDone();
  const back = await ready('back at the bookmark');
  check(Math.abs(back.lat - (27 + 59 / 60)) < 1e-4 && Math.abs(back.lon - (86 + 55 / 60)) < 1e-4 && Math.abs(back.alt - 300) < 0.1, `the bookmark led to ${back.lat}, ${back.lon}, ${back.alt}`);

  // the detail settings in the link: a pixel error of 1 survives a reload
  await page.fill('#lod-px', '1');
  await page.press('#lod-px', 'Enter');
  await page.waitForFunction(() => location.hash.includes('px=1'), null, { timeout: 10_000 }).catch(() => undefined);
  const linked = await page.evaluate(() => location.hash);
  await page.reload({ waitUntil: 'load' });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const detail = await hook(() => window.__pmc.lod());
  log(`  link with the detail settings: ${linked}`);
  check(linked.includes('px=1') && detail.maxPixelError === 1 && (await page.inputValue('#lod-px')) === '1', `the pixel error did not survive the link: ${linked}, ${JSON.stringify(detail)}`);
  await hook(() => window.__pmc.lod({ maxPixelError: 2 }));
  await ready('back to the default detail');

  // the screenshot button: a PNG of the canvas alone, named by the planet and the place, the
  // picture the page shows with its panels hidden
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 30_000 }), page.click('#screenshot')]);
  const png = decodePng(readFileSync(await download.path()));
  const seen = await shot('screenshot-page');
  const off = fractionDifferent(png, seen);
  log(`  screenshot: ${download.suggestedFilename()}, ${png.width} x ${png.height}, ${(100 * off).toFixed(2)} % of the pixels unlike the page's picture`);
  check(/^pmc-earthlike-seed-7-27\.983N-86\.917E\.png$/.test(download.suggestedFilename()), `the screenshot is named ${download.suggestedFilename()}`);
  check(png.width === seen.width && png.height === seen.height && off < 0.01, `the screenshot (${png.width} x ${png.height}) is not the picture shown (${(100 * off).toFixed(1)} % unlike)`);

  // the planet named in the panel and the title
  const shownName = [await page.textContent('#s-planet'), await page.title()];
  check(shownName[0] === 'earthlike · seed 7' && shownName[1] === 'earthlike · seed 7 — PMC', `the planet is named ${JSON.stringify(shownName)}`);

  // ? shows every shortcut (from the table the handlers use), Esc closes it; H hides every panel
  await page.click('#view');
  check(await page.isHidden('#keys-help'), 'the keyboard help shows before ? is pressed');
  await page.keyboard.press('Shift+Slash');
  check(await page.isVisible('#keys-help'), 'the keyboard help does not show on ?');
  const rows = await page.$$eval('#keys-help th', (ths) => ths.map((th) => th.textContent));
  log(`  keyboard help: ${rows.length} rows: ${rows.join(' | ')}`);
  for (const k of ['W / ↑', 'Tab', 'G', '1', '7', 'Esc', 'Ctrl+Z', 'Ctrl+Shift+Z', 'N', 'H', '?', 'wheel']) {
    check(rows.includes(k), `the keyboard help lacks ${k}`);
  }
  await page.keyboard.press('Escape');
  check(await page.isHidden('#keys-help'), 'Esc does not close the keyboard help');
  const panels = () => page.$$eval('.panel:not(#keys-help)', (els) => els.map((el) => getComputedStyle(el).display));
  check((await panels()).every((d) => d !== 'none'), 'a panel is hidden before H');
  await page.keyboard.press('KeyH');
  check((await panels()).every((d) => d === 'none'), `H leaves panels shown: ${await panels()}`);
  await page.keyboard.press('KeyH');
  check((await panels()).every((d) => d !== 'none'), 'a second H does not bring the panels back');
  check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
}
