// The cost of one drawn frame under the software renderer of the end-to-end tests: the earth
// preset at 1024 x 640 from orbit, 10 km, 100 m and 2 m over the mountains at 39° N 0° E, each
// view loaded, then drawn again N times (the time from asking for a frame to the GPU having
// finished it, read back one pixel). Not a test: a measurement for docs/BENCHMARKS.md.
//
//   PMC_BIN=target/debug/pmc node e2e/drawCost.mjs [draws per view, default 5]
//   PMC_DRAW_VIEWS='100 m,2 m'  only these views
//   PMC_DRAW_DEBUG='{"backfaces":true,"plain":true}'  with these debug flags (the test modes)

import { openBrowser } from './browser.mjs';
import { cleanup, log } from './harness.mjs';
import { startBackend } from './servers.mjs';

const N = Number(process.argv[2] ?? 5);
const VIEWS = [
  ['orbit', 39, 0, 12_000_000, 0, -90],
  ['10 km', 39, 0, 16_491, 90, -20],
  ['100 m', 39, 0, 6_591, 90, -5],
  ['2 m', 39, 0, 6_493.2, 90, -5],
];

try {
  const { page, hook } = await openBrowser();
  const server = await startBackend(null, { extra: ['--preset', 'earth'] });
  await page.goto(`${server.url}#mode=fly&lat=39&lon=0&alt=12000000&pitch=-90`, { waitUntil: 'load', timeout: 60_000 });
  await page.waitForFunction(() => window.__pmc !== undefined, null, { timeout: 30_000 });
  if (process.env.PMC_DRAW_DEBUG) await hook((f) => window.__pmc.debug(f), JSON.parse(process.env.PMC_DRAW_DEBUG));
  for (const [label, lat, lon, alt, heading, pitch] of VIEWS.filter(([l]) => !process.env.PMC_DRAW_VIEWS || process.env.PMC_DRAW_VIEWS.split(',').includes(l))) {
    await hook((v) => window.__pmc.setCamera(...v), [lat, lon, alt, heading, pitch]);
    await hook((ms) => window.__pmc.ready(ms), 300_000);
    const ms = await hook(async (n) => {
      const gl = document.querySelector('canvas').getContext('webgl2');
      const px = new Uint8Array(4);
      const times = [];
      for (let i = 0; i < n; i++) {
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        const d0 = window.__pmc.stats().draws;
        const t0 = performance.now();
        window.__pmc.redraw();
        await new Promise((resolve) => {
          const poll = () => (window.__pmc.stats().draws > d0 ? resolve() : requestAnimationFrame(poll));
          requestAnimationFrame(poll);
        });
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        times.push(performance.now() - t0);
      }
      return times.sort((a, b) => a - b);
    }, N);
    const s = await hook(() => window.__pmc.stats());
    log(`${label}: ${s.shown} chunks, ${s.triangles} triangles; a frame ${ms.map((x) => x.toFixed(0)).join(' ')} ms (median ${ms[Math.floor(ms.length / 2)].toFixed(0)})`);
  }
} finally {
  await cleanup();
}
