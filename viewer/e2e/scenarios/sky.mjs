// Step 12: the sky. On the default planet (Earth's air): from the ground at noon the sky is blue;
// with the sun 1° over the horizon the sky over the sun is redder than at noon; from orbit a
// glow of the air lies beyond the planet's edge (and nothing with the atmosphere off); the
// terrain seen from orbit is hazed toward the sky's blue. On Mars the noon sky is butterscotch
// and bluer around a setting sun; on the Moon the sky stays black; the back-face test mode draws
// no atmosphere.

import { check, log } from '../harness.mjs';
import { viewerModule } from '../viewerModule.mjs';

const { DEG, latLonFromPosition } = await viewerModule('frames.ts');

export const name = '12. the sky: blue at noon, red at sunset, the limb glow from orbit, haze, black on the Moon';

/** Vertical field of view of the viewer's camera, degrees (cameraController.ts's FOV). */
const FOV = 50;

/** Mean sRGB colour of the pixels of `img` that `keep(x, y)` accepts. */
function meanOf(img, keep) {
  const sum = [0, 0, 0];
  let n = 0;
  for (let y = 0; y < img.height; y++) {
    for (let x = 0; x < img.width; x++) {
      if (!keep(x, y)) continue;
      const i = 4 * (y * img.width + x);
      sum[0] += img.data[i];
      sum[1] += img.data[i + 1];
      sum[2] += img.data[i + 2];
      n++;
    }
  }
  return { colour: n ? sum.map((v) => v / n) : [0, 0, 0], n };
}

const fmt = (c) => `rgb(${c.map((v) => v.toFixed(0)).join(', ')})`;

/** Pixels a point at `deg` degrees from the view's centre lies from the centre of the canvas. */
const pixelsOff = (img, deg) => (Math.tan(deg * DEG) / Math.tan((FOV / 2) * DEG)) * (img.height / 2);

export async function scenario(t) {
  const { page, hook, ready, shot } = t;
  await page.goto(`${t.shared.pageBase}#preset=earthlike&seed=7&mode=orbit&lat=-10&lon=8`, {
    waitUntil: 'load',
    timeout: 60_000,
  });
  await page.waitForFunction(() => window.__pmc !== undefined && window.__pmc.stats().preset === 'earthlike', null, { timeout: 60_000 });
  await ready('the default planet');
  // (the other steps run with the atmosphere off: see browser.mjs)
  const sky0 = await hook(() => window.__pmc.sky({ atmosphere: true }));
  check(sky0.kind === 'earth' && sky0.drawn, `the default planet's sky: ${JSON.stringify(sky0)}`);

  /** The ground under (lat, lon): metres above the datum, measured by the fly mode. */
  const groundUnder = async (lat, lon) => {
    await hook(([a, b]) => window.__pmc.setCamera(a, b, 400, 0, -89), [lat, lon]);
    await ready(`above ${lat}, ${lon}`);
    const s = await hook(
      () =>
        new Promise((resolve) => {
          const f0 = window.__pmc.stats().frames;
          const poll = () => {
            const st = window.__pmc.stats();
            if (st.frames >= f0 + 8 && st.aboveGround !== null) resolve(st);
            else setTimeout(poll, 50);
          };
          poll();
        }),
    );
    return s.alt - s.aboveGround;
  };
  /**
   * A screenshot, and whether the loaded terrain lies under the canvas pixels of `regions`
   * (predicates of x, y; picked once per 32 px cell, in one call: a pick is a ray cast).
   */
  const view = async (label, ...regions) => {
    const img = await shot(label);
    const cells = new Set();
    for (let y = 0; y < img.height; y++) {
      for (let x = 0; x < img.width; x++) {
        if (regions.some((r) => r(x, y))) cells.add(`${Math.floor(x / 32)},${Math.floor(y / 32)}`);
      }
    }
    const terrain = new Set(
      await hook((list) => list.filter((c) => {
        const [cx, cy] = c.split(',').map(Number);
        return window.__pmc.pick(32 * cx + 16, 32 * cy + 16) !== null;
      }), [...cells]),
    );
    const isSky = (x, y) => {
      const c = `${Math.floor(x / 32)},${Math.floor(y / 32)}`;
      if (!cells.has(c)) throw new Error(`pixel ${x}, ${y} outside the regions picked`);
      return !terrain.has(c);
    };
    return { img, isSky };
  };

  // ---- from orbit: the limb glow, and the haze over the terrain ----
  const planet = await hook(() => fetch('api/v1/planet?preset=earthlike&seed=7').then((r) => r.json()));
  const datum = planet.sea_radius;
  const outer = planet.surface_bounds[1];
  const camR = datum + 3 * (outer - datum) + 2.2 * datum;
  await hook(() => window.__pmc.mode('orbit'));
  await hook((a) => window.__pmc.setCamera(-10, 8, a, 0, -90), camR - datum);
  await hook(() => window.__pmc.sky({ sunAzimuth: 90, sunElevation: 45 }));
  await ready('orbit');
  const W = 1024; // the harness's viewport (VIEWPORT in harness.mjs)
  const Hpx = 640;
  /** Pixels whose view ray passes `lo` to `hi` metres from the planet's centre (at its closest). */
  const ring = (lo, hi) => {
    const a = (r) => (Math.tan(Math.asin(Math.min(1, r / camR))) / Math.tan((FOV / 2) * DEG)) * (Hpx / 2);
    const p0 = a(lo);
    const p1 = a(hi);
    return (x, y) => {
      const d = Math.hypot(x - W / 2, y - Hpx / 2);
      return d >= p0 && d <= p1;
    };
  };
  const glowRing = ring(outer + 0.1 * (outer - datum), outer + 1.2 * (outer - datum));
  const farRing = ring(1.45 * datum, 1.5 * datum);
  // the middle of the planet's disc: terrain (and sea) only
  const discMiddle = ring(0, 0.7 * datum);
  // no terrain rises into the ring: no need to pick it
  const orbit = await view('sky-orbit');
  const glow = meanOf(orbit.img, glowRing);
  const far = meanOf(orbit.img, farRing);
  const disc = meanOf(orbit.img, discMiddle);
  log(`  orbit ${(camR - datum).toFixed(0)} m above the datum: beyond the edge ${fmt(glow.colour)} (${glow.n} px), far out ${fmt(far.colour)} (${far.n} px), the terrain ${fmt(disc.colour)}`);
  check(glow.n > 1000, `the ring beyond the planet's edge is not in the view (${glow.n} px)`);
  check(glow.colour[2] > 20 && glow.colour[2] > glow.colour[0], `no blue glow beyond the planet's edge: ${fmt(glow.colour)} (sky-orbit.png)`);
  const space = (await hook(() => window.__pmc.stats())).background;
  const near = (c, d) => c.every((v, i) => Math.abs(v - d[i]) <= 3);
  check(near(far.colour, space), `space far from the planet is ${fmt(far.colour)}, not the black of space ${fmt(space)} (sky-orbit.png)`);

  await hook(() => window.__pmc.setAtmosphere(false));
  await ready('orbit without air');
  const bare = await view('sky-orbit-off');
  const bareGlow = meanOf(bare.img, glowRing);
  const bareDisc = meanOf(bare.img, discMiddle);
  const blueShare = (c) => c[2] / Math.max(1, c[0] + c[1] + c[2]);
  log(`  the atmosphere off: beyond the edge ${fmt(bareGlow.colour)}, the terrain ${fmt(bareDisc.colour)}; blue share of the terrain ${blueShare(disc.colour).toFixed(3)} with the air, ${blueShare(bareDisc.colour).toFixed(3)} without`);
  check(near(bareGlow.colour, space), `the ring beyond the edge is ${fmt(bareGlow.colour)} without the atmosphere, not the black of space (sky-orbit-off.png)`);
  // (terrain counts a third of the air, SURFACE_SCATTER in atmosphereModel.ts: measured +0.015)
  check(blueShare(disc.colour) > blueShare(bareDisc.colour) + 0.01, `the terrain seen from orbit is not hazed toward blue by the air (sky-orbit.png, sky-orbit-off.png)`);
  await hook(() => window.__pmc.setAtmosphere(true));

  // a place over the sea, at least 5 m deep, near the middle of the orbit view
  let sea = await hook(([w, h, r]) => {
    for (let d = 0; d < 200; d += 8) {
      for (const [x, y] of [[w / 2 + d, h / 2], [w / 2 - d, h / 2], [w / 2, h / 2 + d], [w / 2, h / 2 - d]]) {
        const p = window.__pmc.pick(x, y);
        if (p && Math.hypot(...p.point) < r - 5) return p.point;
      }
    }
    return null;
  }, [orbit.img.width, orbit.img.height, datum]);
  check(sea !== null, 'no sea near the middle of the orbit view (sky-orbit.png)');
  sea = latLonFromPosition(sea);
  log(`  the sea at ${sea.lat.toFixed(2)}, ${sea.lon.toFixed(2)}`);

  // ---- from the ground: noon, then sunset, looking east ----
  // over the sea, 3 m above it: the horizon dips 3.2° on a planet of 1.9 km (from a hill 30 m
  // high it dips 10°, and a sun 2° up is far from setting there)
  await hook(() => window.__pmc.mode('fly'));
  await hook(([a, b]) => window.__pmc.setCamera(a, b, 3, 90, 12), [sea.lat, sea.lon]);
  await hook(() => window.__pmc.sky({ sunAzimuth: 90, sunElevation: 60 }));
  await ready('the ground at noon');
  // the sky over the sun at sunset: 3 to 12 degrees over it, 20 degrees either side
  const cx = W / 2;
  const cy = Hpx / 2;
  const px = { height: Hpx };
  const overSun = (x, y) => {
    const up = pixelsOff(px, 4 - 12); // the sun 1° up, the view 12° up: 11° below the centre
    const top = pixelsOff(px, 13 - 12);
    return Math.abs(x - cx) < pixelsOff(px, 20) && y < cy - up && y > cy - top;
  };
  const upper = (x, y) => y < Hpx / 3;
  const noon = await view('sky-noon', overSun, upper);
  const noonSky = meanOf(noon.img, (x, y) => upper(x, y) && noon.isSky(x, y));
  const noonOverSun = meanOf(noon.img, (x, y) => overSun(x, y) && noon.isSky(x, y));
  log(`  noon: the upper third's sky ${fmt(noonSky.colour)} (${noonSky.n} px); over the sunset's sun ${fmt(noonOverSun.colour)} (${noonOverSun.n} px)`);
  check(noonSky.n > 0.1 * noon.img.width * noon.img.height, `too little sky in the noon view (${noonSky.n} px): see sky-noon.png`);
  const [r0, g0, b0] = noonSky.colour;
  check(b0 > r0 + 25 && b0 > g0, `the noon sky is not blue: ${fmt(noonSky.colour)} (sky-noon.png)`);

  await hook(() => window.__pmc.sky({ sunElevation: 1 }));
  await ready('the ground at sunset');
  const sunset = await view('sky-sunset', overSun);
  const sunsetOverSun = meanOf(sunset.img, (x, y) => overSun(x, y) && sunset.isSky(x, y) && noon.isSky(x, y));
  const redness = (c) => c[0] / Math.max(1, c[2]);
  log(
    `  sunset (sun 1° up): over the sun ${fmt(sunsetOverSun.colour)} (${sunsetOverSun.n} px), red/blue ${redness(sunsetOverSun.colour).toFixed(2)} ` +
      `against ${redness(noonOverSun.colour).toFixed(2)} at noon`,
  );
  check(sunsetOverSun.n > 2000, `too little sky over the setting sun (${sunsetOverSun.n} px): see sky-sunset.png`);
  check(
    redness(sunsetOverSun.colour) > 1.25 * redness(noonOverSun.colour) && sunsetOverSun.colour[0] > sunsetOverSun.colour[2],
    `the sky over the setting sun is not redder than at noon: ${fmt(sunsetOverSun.colour)} against ${fmt(noonOverSun.colour)} (sky-sunset.png)`,
  );

  // ---- the back-face test mode draws no atmosphere ----
  await hook(() => window.__pmc.debug({ backfaces: true }));
  const backfaces = await hook(() => window.__pmc.sky());
  await hook(() => window.__pmc.debug({ backfaces: false }));
  check(!backfaces.drawn && backfaces.atmosphere, `the atmosphere is drawn in the back-face mode: ${JSON.stringify(backfaces)}`);

  // ---- Mars: butterscotch at noon, blue around the setting sun ----
  await hook(() => window.__pmc.setPlanet('mars', '7'));
  await hook(() => window.__pmc.mode('fly'));
  const marsGround = await groundUnder(-10, 8);
  await hook((a) => window.__pmc.setCamera(-10, 8, a, 90, 12), marsGround + 3);
  await hook(() => window.__pmc.sky({ sunAzimuth: 90, sunElevation: 60 }));
  await ready('Mars at noon');
  const marsNoon = await view('sky-mars-noon', overSun, upper);
  const marsSky = meanOf(marsNoon.img, (x, y) => upper(x, y) && marsNoon.isSky(x, y));
  const marsNoonOverSun = meanOf(marsNoon.img, (x, y) => overSun(x, y) && marsNoon.isSky(x, y));
  await hook(() => window.__pmc.sky({ sunElevation: 1 }));
  await ready('Mars at sunset');
  const marsSunset = await view('sky-mars-sunset', overSun);
  const marsOverSun = meanOf(marsSunset.img, (x, y) => overSun(x, y) && marsSunset.isSky(x, y) && marsNoon.isSky(x, y));
  log(`  Mars: the noon sky ${fmt(marsSky.colour)}; over the setting sun ${fmt(marsOverSun.colour)} against ${fmt(marsNoonOverSun.colour)} at noon`);
  check((await hook(() => window.__pmc.sky())).kind === 'mars', 'Mars has not its own atmosphere');
  check(marsSky.colour[0] > marsSky.colour[2] + 10, `the Mars noon sky is not butterscotch: ${fmt(marsSky.colour)} (sky-mars-noon.png)`);
  check(redness(marsOverSun.colour) < redness(marsNoonOverSun.colour), `the Mars sky over the setting sun is not bluer than at noon (sky-mars-sunset.png)`);

  // ---- the Moon: no air, a black sky ----
  await hook(() => window.__pmc.setPlanet('moon', '7'));
  const moonPlanet = await hook(() => fetch('api/v1/planet?preset=moon&seed=7').then((r) => r.json()));
  // over the highest ground (altitudes are above the middle of the shell on a planet without sea)
  const moonTop = (moonPlanet.surface_bounds ?? [0, moonPlanet.radius])[1] - (moonPlanet.base_radius + moonPlanet.radius) / 2;
  await hook((a) => window.__pmc.setCamera(-10, 8, a, 90, 12), moonTop + 3);
  await hook(() => window.__pmc.sky({ sunAzimuth: 90, sunElevation: 60 }));
  await ready('the Moon from the ground');
  const moon = await view('sky-moon', upper);
  const moonSky = meanOf(moon.img, (x, y) => upper(x, y) && moon.isSky(x, y));
  const moonState = await hook(() => window.__pmc.sky());
  log(`  the Moon: the sky ${fmt(moonSky.colour)} (${moonSky.n} px), ${JSON.stringify({ kind: moonState.kind, drawn: moonState.drawn })}`);
  check(moonState.kind === null && !moonState.drawn, `the Moon has an atmosphere: ${JSON.stringify(moonState)}`);
  check(moonSky.n > 0.05 * moon.img.width * moon.img.height && near(moonSky.colour, space), `the Moon's sky is ${fmt(moonSky.colour)}, not the black of space ${fmt(space)} (sky-moon.png)`);

  // back to the default planet and its default sun
  await hook(() => window.__pmc.sky({ sunAzimuth: 57.5, sunElevation: 56.9 }));
  await hook(() => window.__pmc.setPlanet('earthlike', '7'));
  await ready('earthlike again');
  check(t.consoleProblems.length === 0, `console messages:\n  ${t.consoleProblems.join('\n  ')}`);
  check(t.failedResponses.length === 0, `failed responses:\n  ${t.failedResponses.join('\n  ')}`);
}
