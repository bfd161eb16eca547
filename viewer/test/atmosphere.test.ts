import { describe, expect, it } from 'vitest';
import { ATMOSPHERE_KEY, Atmosphere, storeAtmosphere, storedAtmosphere } from '../src/atmosphere';
import {
  DEFAULT_SUN,
  EARTH_REFERENCE,
  MARS_REFERENCE,
  SPACE,
  SURFACE_SCATTER,
  TOP_SCALE_HEIGHTS,
  aerialPerspective,
  atmosphereKind,
  atmosphereOf,
  atmosphereParams,
  chapmanUp,
  miePhase,
  rayleighPhase,
  raySpan,
  skyColour,
  slantDepth,
  sunDirection,
  type AtmosphereParams,
} from '../src/atmosphereModel';
import { addScaled, enuAt, normalize, type V3 } from '../src/frames';

/** The default planet (earthlike, seed 7): sea level and the highest terrain. */
const DATUM = 1884.8;
const RELIEF = 110.7;
const earthlike = (): AtmosphereParams => atmosphereParams('earth', DATUM, RELIEF);
const mars = (): AtmosphereParams => atmosphereParams('mars', 1872, 150);

/** A camera `h` metres above the ground sphere of `a` at the north pole, and its local frame. */
function onGround(a: AtmosphereParams, h = 2): { camera: V3; enu: ReturnType<typeof enuAt> } {
  const camera: V3 = [0, a.groundRadius + h, 0];
  return { camera, enu: enuAt(camera) };
}

const redOverBlue = (c: V3): number => c[0] / c[2];

describe('atmosphereKind', () => {
  it('gives Earth air to the Earth-like presets and elevation models, Mars its own, the Moon none', () => {
    expect(atmosphereKind({ preset: 'earthlike', sea_radius: 1884.8 })).toBe('earth');
    expect(atmosphereKind({ preset: 'earth', sea_radius: 6.371e6 })).toBe('earth');
    expect(atmosphereKind({ preset: null, terrain: { kind: 'dem', name: 'etopo5.pmcdem' }, sea_radius: 6.371e6 })).toBe('earth');
    expect(atmosphereKind({ preset: 'mars', sea_radius: null })).toBe('mars');
    expect(atmosphereKind({ preset: 'moon', sea_radius: null })).toBeNull();
    expect(atmosphereKind({ preset: 'sphere', sea_radius: null })).toBeNull();
  });

  it('gives an unknown preset Earth air with a sea and none without', () => {
    expect(atmosphereKind({ preset: 'ocean-world', sea_radius: 1900 })).toBe('earth');
    expect(atmosphereKind({ preset: 'rock', sea_radius: null })).toBeNull();
  });

  it('makes no atmosphere for the Moon from the planet shape either', () => {
    expect(atmosphereOf({ preset: 'moon', sea_radius: null }, { datum: 1872, outer: 1990 })).toBeNull();
    expect(atmosphereOf({ preset: 'earthlike', sea_radius: DATUM }, { datum: DATUM, outer: DATUM + RELIEF })?.kind).toBe('earth');
  });
});

describe('atmosphereParams', () => {
  it("keeps Earth's coefficients and scale heights at Earth's radius", () => {
    const a = atmosphereParams('earth', EARTH_REFERENCE.radius, 8800);
    expect(a.rayleighHeight).toBeCloseTo(8000, 6);
    expect(a.mieHeight).toBeCloseTo(1200, 6);
    a.rayleigh.forEach((b, i) => expect(b).toBeCloseTo(EARTH_REFERENCE.rayleigh[i]!, 12));
    expect(a.mie[0]).toBeCloseTo(21e-6, 12);
    expect(a.mieExtinction[0]).toBeCloseTo(21e-6 / 0.9, 12);
    expect(a.mieG).toBe(0.76);
    expect(a.top).toBeCloseTo(TOP_SCALE_HEIGHTS * 8000, 6);
    expect(a.sunPathX).toBeCloseTo(6_360_000 / 8000, 9);
  });

  it('scales the default 2 km planet: scale heights from the relief, the optical depth straight up kept', () => {
    const a = earthlike();
    // 8 km x R / 6360 km is 2.4 m: under the mountains; half the relief instead
    expect(a.rayleighHeight).toBeCloseTo(RELIEF / 2, 9);
    expect(a.mieHeight / a.rayleighHeight).toBeCloseTo(1200 / 8000, 9);
    expect(a.top).toBeGreaterThan(RELIEF);
    expect(a.top).toBeLessThan(0.25 * DATUM);
    for (let c = 0; c < 3; c++) {
      expect(a.rayleigh[c]! * a.rayleighHeight).toBeCloseTo(EARTH_REFERENCE.rayleigh[c]! * 8000, 12);
      expect(a.mie[c]! * a.mieHeight).toBeCloseTo(EARTH_REFERENCE.mie[c]! * 1200, 12);
    }
  });

  it('white-balances Earth so that the sun overhead is white, and leaves Mars its colours', () => {
    const e = earthlike();
    expect(e.sun[2]).toBeGreaterThan(e.sun[0]); // blue is lost on the way down: the balance adds it
    const lum = 0.2126 * e.sun[0] + 0.7152 * e.sun[1] + 0.0722 * e.sun[2];
    expect(lum).toBeCloseTo(EARTH_REFERENCE.sunIntensity, 9);
    const m = mars();
    expect(m.sun).toEqual([MARS_REFERENCE.sunIntensity, MARS_REFERENCE.sunIntensity, MARS_REFERENCE.sunIntensity]);
    // Mars's fine dust scatters red most and absorbs blue
    expect(m.rayleigh[0]).toBeGreaterThan(m.rayleigh[2]);
    expect(m.rayleighExtinction[2] - m.rayleigh[2]).toBeGreaterThan(m.rayleighExtinction[0] - m.rayleigh[0]);
  });
});

describe('sunDirection', () => {
  const enu = enuAt([1000, 2000, -500]);
  const close = (a: V3, b: V3, eps = 1e-12): void => a.forEach((v, i) => expect(v).toBeCloseTo(b[i]!, -Math.log10(eps)));

  it('points north at azimuth 0, east at 90, up at elevation 90', () => {
    close(sunDirection(enu, 0, 0), enu.north);
    close(sunDirection(enu, 90, 0), enu.east);
    close(sunDirection(enu, 180, 0), [-enu.north[0], -enu.north[1], -enu.north[2]]);
    close(sunDirection(enu, 123, 90), enu.up);
    close(sunDirection(enu, 0, -90), [-enu.up[0], -enu.up[1], -enu.up[2]]);
  });

  it('is a unit vector at the elevation asked', () => {
    for (const [az, el] of [[10, 20], [200, -5], [359, 1]] as const) {
      const d = sunDirection(enu, az, el);
      expect(Math.hypot(...d)).toBeCloseTo(1, 12);
      expect(Math.asin(d[0] * enu.up[0] + d[1] * enu.up[1] + d[2] * enu.up[2]) / (Math.PI / 180)).toBeCloseTo(el, 9);
    }
  });

  it("puts the default sun where the viewer's sun always stood (up + 0.55 east + 0.35 north)", () => {
    const old = normalize(addScaled(addScaled(enu.up, enu.east, 0.55), enu.north, 0.35));
    close(sunDirection(enu, DEFAULT_SUN.azimuth, DEFAULT_SUN.elevation), old, 1e-3);
  });
});

describe('phase functions and optical depth', () => {
  /** The integral of a phase function over the sphere (midpoint rule in the cosine). */
  const overSphere = (p: (nu: number) => number): number => {
    const n = 20000;
    let sum = 0;
    for (let i = 0; i < n; i++) sum += p(-1 + (2 * (i + 0.5)) / n) * 2 * Math.PI * (2 / n);
    return sum;
  };

  it('normalises the phase functions to one over the sphere', () => {
    expect(overSphere(rayleighPhase)).toBeCloseTo(1, 6);
    expect(overSphere((nu) => miePhase(nu, 0.76))).toBeCloseTo(1, 3);
    expect(overSphere((nu) => miePhase(nu, 0.82))).toBeCloseTo(1, 3);
  });

  it('scatters Mie light forward far more than backward', () => {
    expect(miePhase(1, 0.76) / miePhase(-1, 0.76)).toBeGreaterThan(100);
    expect(rayleighPhase(1)).toBeCloseTo(rayleighPhase(-1), 12);
  });

  /** Metres of air at ground density along the ray, by brute force (fine steps, to 40 H). */
  const marched = (R: number, h: number, mu: number, H: number): number => {
    const r0 = R + h;
    const steps = 200000;
    const len = 40 * H + 2 * Math.sqrt(2 * R * 40 * H);
    const dt = len / steps;
    let sum = 0;
    for (let i = 0; i < steps; i++) {
      const t = (i + 0.5) * dt;
      const r = Math.sqrt(r0 * r0 + t * t + 2 * r0 * t * mu);
      sum += Math.exp(-(r - R) / H) * dt;
      if (r - R > 40 * H && t > -r0 * mu) break;
    }
    return sum;
  };

  it('matches a brute-force march for the sun above the horizon within 3 %', () => {
    for (const [R, H] of [[DATUM, RELIEF / 2], [6_360_000, 8000]] as const) {
      for (const h of [0, 0.5 * H, 2 * H]) {
        for (const mu of [1, 0.5, 0.2, 0.05, 0]) {
          const want = marched(R, h, mu, H);
          expect(Math.abs(slantDepth(R, h, mu, H) - want) / want).toBeLessThan(0.03);
        }
      }
    }
  });

  it('matches it below the horizon while the tangent point is above the ground, within 6 %', () => {
    for (const [R, H] of [[DATUM, RELIEF / 2], [6_360_000, 8000]] as const) {
      const h = 2 * H;
      const muLow = -Math.sqrt(1 - (R / (R + h)) ** 2); // the ray grazing the ground
      for (const mu of [-0.02 * Math.abs(muLow), -0.5 * Math.abs(muLow), 0.8 * muLow]) {
        const want = marched(R, h, mu, H);
        expect(Math.abs(slantDepth(R, h, mu, H) - want) / want).toBeLessThan(0.06);
      }
    }
  });

  it('grows without bound into the planet shadow, smoothly', () => {
    const R = DATUM;
    const H = RELIEF / 2;
    const deep = slantDepth(R, 10, -0.6, H);
    expect(deep).toBeGreaterThan(1e4 * H);
    let last = 0;
    for (let mu = 0.2; mu > -0.6; mu -= 0.01) {
      const d = slantDepth(R, 10, mu, H);
      expect(Number.isFinite(d)).toBe(true);
      expect(d).toBeGreaterThanOrEqual(last * 0.999);
      last = d;
    }
  });

  it('takes the Chapman function as 1 straight up and sqrt(pi x / 2) along the horizon', () => {
    expect(Math.abs(chapmanUp(795, 1) - 1)).toBeLessThan(0.005);
    expect(chapmanUp(795, 0)).toBeCloseTo(Math.sqrt((Math.PI * 795) / 2), 6);
  });
});

describe('raySpan', () => {
  it("keeps a camera 2 m above an Earth-sized planet's ground exact: the ground 0.2° down is where geometry puts it", () => {
    const a = atmosphereParams('earth', 6_360_000, 8800);
    const mu = -Math.sin(0.2 * (Math.PI / 180));
    const span = raySpan(a, 2, mu);
    // distance to the sphere along the ray, solved in a frame where the numbers stay small
    const R = 6_360_000;
    const r = R + 2;
    const b = r * mu;
    const want = -b - Math.sqrt(b * b - 2 * (2 * R + 2));
    expect(span.ground).not.toBeNull();
    expect(span.ground!).toBeCloseTo(want, 3);
    expect(span.enter).toBe(0);
    expect(raySpan(a, 2, 0).ground).toBeNull();
  });

  it('enters the shell from outside and misses it beyond the limb', () => {
    const a = earthlike();
    const h = 3 * DATUM;
    const r = DATUM + h;
    const toCentre = raySpan(a, h, -1);
    expect(toCentre.enter).toBeCloseTo(h - a.top, 6);
    expect(toCentre.ground).toBeCloseTo(h, 6);
    // a ray passing the centre at 1.5 times the top radius
    const muMiss = -Math.sqrt(1 - ((1.5 * (DATUM + a.top)) / r) ** 2);
    expect(raySpan(a, h, muMiss)).toEqual({ enter: 0, exit: 0, ground: null });
  });
});

describe('skyColour', () => {
  it('is blue at the zenith at noon on the default planet', () => {
    const a = earthlike();
    const { camera, enu } = onGround(a);
    const sky = skyColour(a, camera, enu.up, sunDirection(enu, 90, 60));
    expect(sky[2]).toBeGreaterThan(sky[0] * 1.5);
    expect(sky[2]).toBeGreaterThan(sky[1]);
  });

  it('reddens over the sun when it sets, on the default planet and at Earth scale', () => {
    for (const a of [earthlike(), atmosphereParams('earth', 6_360_000, 8800)]) {
      const { camera, enu } = onGround(a);
      const overSun = sunDirection(enu, 90, 6);
      const noon = skyColour(a, camera, overSun, sunDirection(enu, 90, 60));
      const sunset = skyColour(a, camera, overSun, sunDirection(enu, 90, 1));
      expect(redOverBlue(sunset)).toBeGreaterThan(1.3 * redOverBlue(noon));
      expect(sunset[0]).toBeGreaterThan(sunset[2]);
    }
  });

  it('darkens when the sun is well below the horizon', () => {
    const a = earthlike();
    const { camera, enu } = onGround(a);
    const day = skyColour(a, camera, enu.up, sunDirection(enu, 90, 60));
    const night = skyColour(a, camera, enu.up, sunDirection(enu, 90, -40));
    expect(night[2]).toBeLessThan(0.05 * day[2] + SPACE[2]);
  });

  it('is butterscotch at noon on Mars and bluer around the setting sun', () => {
    const a = mars();
    const { camera, enu } = onGround(a);
    const noonSky = skyColour(a, camera, sunDirection(enu, 270, 30), sunDirection(enu, 90, 60));
    expect(noonSky[0]).toBeGreaterThan(noonSky[2] * 1.3);
    const overSun = sunDirection(enu, 90, 5);
    const noon = skyColour(a, camera, overSun, sunDirection(enu, 90, 60));
    const sunset = skyColour(a, camera, overSun, sunDirection(enu, 90, 1));
    expect(redOverBlue(sunset)).toBeLessThan(redOverBlue(noon));
    expect(sunset[2]).toBeGreaterThan(sunset[0]);
  });

  it('is the black of space without an atmosphere (the Moon)', () => {
    const { camera, enu } = onGround(earthlike());
    expect(skyColour(null, camera, enu.up, sunDirection(enu, 90, 30))).toEqual([...SPACE]);
  });

  it('draws a glow beyond the limb from orbit and black space beyond the shell', () => {
    const a = earthlike();
    const camera: V3 = [0, 0, 3.2 * DATUM];
    const sun = normalize([1, 0.3, 1]);
    /** The ray from the camera passing `d` metres from the centre. */
    const past = (d: number): V3 => {
      const s = d / camera[2];
      return [s, 0, -Math.sqrt(1 - s * s)];
    };
    const glow = skyColour(a, camera, past(DATUM + 1.5 * a.rayleighHeight), sun);
    expect(glow[2]).toBeGreaterThan(0.05);
    expect(glow[2]).toBeGreaterThan(glow[0]);
    const beyond = skyColour(a, camera, past(DATUM + a.top + 10), sun);
    beyond.forEach((v, i) => expect(v).toBeCloseTo(SPACE[i]!, 9));
  });

  it('stays finite and in range for every camera height, direction and sun', () => {
    for (const a of [earthlike(), mars(), atmosphereParams('earth', 6_360_000, 8800)]) {
      for (const h of [-5, 0, 1e-3, 2, a.rayleighHeight, a.top, 5 * a.groundRadius]) {
        const camera: V3 = [0, a.groundRadius + h, 0];
        const enu = enuAt(camera);
        for (let el = -90; el <= 90; el += 15) {
          for (let sunEl = -90; sunEl <= 90; sunEl += 30) {
            const c = skyColour(a, camera, sunDirection(enu, 30 + el, el), sunDirection(enu, 80, sunEl));
            for (const v of c) {
              expect(Number.isFinite(v)).toBe(true);
              expect(v).toBeGreaterThanOrEqual(0);
              expect(v).toBeLessThanOrEqual(1.02);
            }
          }
        }
      }
    }
  });
});

describe('aerialPerspective', () => {
  const a = earthlike();
  const { camera, enu } = onGround(a, 30);
  const sun = sunDirection(enu, 90, 50);
  const ground: V3 = [0.1, 0.3, 0.05];

  it('leaves near terrain as it is and hazes far terrain toward the sky', () => {
    const near = aerialPerspective(a, ground, camera, [0, -2, 0.5], sun);
    near.forEach((v, i) => expect(Math.abs(v - ground[i]!)).toBeLessThan(0.01));
    const dir = sunDirection(enu, 0, -1);
    const sky = skyColour(a, camera, dir, sun); // the sky behind, along the same ray
    let lastLight: V3 = [0, 0, 0];
    let lastTrans: V3 = [1, 1, 1];
    let firstLight: V3 | null = null;
    for (const d of [100, 300, 600, 1000, 2000]) {
      const rel: V3 = [dir[0] * d, dir[1] * d, dir[2] * d];
      // the light added (over black) grows (up to the march's discretisation, 6 steps however
      // long the path), the terrain's share (white less black) shrinks
      const light = aerialPerspective(a, [0, 0, 0], camera, rel, sun);
      const white = aerialPerspective(a, [1, 1, 1], camera, rel, sun);
      const trans: V3 = [white[0] - light[0], white[1] - light[1], white[2] - light[2]];
      firstLight ??= light;
      for (let c = 0; c < 3; c++) {
        expect(light[c]).toBeGreaterThan(0.99 * lastLight[c]!);
        expect(trans[c]).toBeLessThan(lastTrans[c]!);
      }
      lastLight = light;
      lastTrans = trans;
    }
    for (let c = 0; c < 3; c++) expect(lastLight[c]).toBeGreaterThan(2 * firstLight![c]!);
    // 2 km away blue terrain is mostly air: the sky's blue, through the share of the air a
    // surface counts (1 - exp(-k L) = 1 - (1 - sky)^k)
    expect(lastTrans[2]).toBeLessThan(Math.pow(0.3, SURFACE_SCATTER));
    expect(lastTrans[2]).toBeLessThan(lastTrans[0]);
    expect(Math.abs(lastLight[2] - (1 - Math.pow(1 - sky[2], SURFACE_SCATTER)))).toBeLessThan(0.03);
  });

  it('changes nothing without an atmosphere', () => {
    expect(aerialPerspective(null, ground, camera, [500, -10, 0], sun)).toEqual(ground);
  });
});

describe('Atmosphere', () => {
  it('is drawn for a planet with air, not without one, not when suppressed or turned off', () => {
    const at = new Atmosphere();
    expect(at.drawn()).toBe(false);
    at.setPlanet(earthlike());
    expect(at.drawn()).toBe(true);
    expect(at.sky.visible).toBe(true);
    expect(at.uniforms.uAtmoOn.value).toBe(1);
    at.setSuppressed(true); // the back-face and lighting-off test modes
    expect(at.drawn()).toBe(false);
    expect(at.sky.visible).toBe(false);
    expect(at.uniforms.uAtmoOn.value).toBe(0);
    at.setSuppressed(false);
    at.set({ atmosphere: false });
    expect(at.state().drawn).toBe(false);
    expect(at.state().atmosphere).toBe(false);
    at.set({ atmosphere: true });
    at.setPlanet(null);
    expect(at.state()).toMatchObject({ kind: null, drawn: false });
    at.dispose();
  });

  it('wraps the azimuth, clamps the elevation and turns the sun at once', () => {
    const at = new Atmosphere();
    at.setPlanet(earthlike());
    const camera: V3 = [0, DATUM + 5, 0];
    at.frame(camera);
    const s = at.set({ sunAzimuth: -90, sunElevation: 120 });
    expect(s.sunAzimuth).toBe(270);
    expect(s.sunElevation).toBe(90);
    at.set({ sunElevation: 0, sunAzimuth: 90 });
    const d = at.state().sunDirection;
    const east = enuAt(camera).east;
    d.forEach((v, i) => expect(v).toBeCloseTo(east[i]!, 9));
    at.uniforms.uAtmoSun.value.toArray().forEach((v, i) => expect(v).toBeCloseTo(east[i]!, 9));
    expect(at.uniforms.uAtmoCamH.value).toBeCloseTo(5, 9);
    at.frame([0, DATUM - 20, 0]); // below the datum: the shell is entered from just above it
    expect(at.uniforms.uAtmoCamH.value).toBe(1e-3);
    at.dispose();
  });
});

describe('the atmosphere checkbox, remembered', () => {
  it('is on by default, off once left off, and on where storage fails', () => {
    const store = new Map<string, string>();
    const fake = { getItem: (k: string) => store.get(k) ?? null, setItem: (k: string, v: string) => void store.set(k, v) };
    const g = globalThis as { localStorage?: unknown };
    const saved = g.localStorage;
    try {
      g.localStorage = fake;
      expect(storedAtmosphere()).toBe(true);
      storeAtmosphere(false);
      expect(store.get(ATMOSPHERE_KEY)).toBe('off');
      expect(storedAtmosphere()).toBe(false);
      storeAtmosphere(true);
      expect(storedAtmosphere()).toBe(true);
      g.localStorage = {
        getItem: () => {
          throw new Error('no storage');
        },
        setItem: () => {
          throw new Error('no storage');
        },
      };
      expect(storedAtmosphere()).toBe(true);
      expect(() => storeAtmosphere(false)).not.toThrow();
    } finally {
      g.localStorage = saved;
    }
  });
});
