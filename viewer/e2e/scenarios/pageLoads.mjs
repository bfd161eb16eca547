// Step 1: the page loads without console errors.

import { check, log } from '../harness.mjs';

export const name = '1. the page loads without console errors';

export async function scenario(t) {
  const { pageBase } = t.shared;
  const { page, consoleProblems, failedResponses, ready } = t;
  await page.goto(`${pageBase}#preset=earthlike&seed=7&mode=orbit&lat=20&lon=15`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  const orbitStats = await ready('from orbit');
  t.shared.orbitStats = orbitStats;
  check(orbitStats.preset === 'earthlike' && orbitStats.seed === '7', `planet is ${orbitStats.preset}/${orbitStats.seed}`);
  check(orbitStats.error === null, `the page shows an error: ${orbitStats.error}`);
  // a server without a world: the tools are off and say why
  check(await page.isDisabled('#tool-dig'), 'the Dig tool is enabled on a server without a world');
  const why = await page.textContent('#tools-status');
  check(/^Editing is off: /.test(why ?? ''), `the tools panel does not say why editing is off: "${why}"`);
  log(`  tools: ${why}`);
  check(consoleProblems.length === 0, `console messages:\n  ${consoleProblems.join('\n  ')}`);
  check(failedResponses.length === 0, `failed responses:\n  ${failedResponses.join('\n  ')}`);
}
