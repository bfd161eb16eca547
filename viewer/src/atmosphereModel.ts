// The atmosphere as numbers: which planet has which atmosphere, its parameters scaled to the
// planet, the sun's direction from an azimuth and an elevation, and a reference implementation of
// the single-scattering sky that the shaders of atmosphere.ts evaluate (the same formulas, the
// same sample counts), so that the unit tests can check the colours the GPU draws. Pure: no
// three.js, no DOM.
//
// The model (after Nishita's single scattering, as in Bruneton and Neyret's "Precomputed
// Atmospheric Scattering", 2008, without the precomputed tables and the multiple scattering):
// air (Rayleigh) and aerosols (Mie) whose densities fall off exponentially with the height above
// the ground sphere; light reaching a point of the view ray from the sun is attenuated along the
// way by the optical depth toward the sun, scattered toward the eye by the phase functions, and
// attenuated again on its way to the eye. The optical depth toward the sun is not marched but
// taken from an approximation of the Chapman function (the optical depth of an exponential
// atmosphere along a slant ray, relative to the vertical one), which also gives the planet's
// shadow: a ray toward a sun below the horizon passes its tangent point under the ground, where
// the density grows without bound.

import { DEG, type Enu, type V3 } from './frames';

/** The atmospheres the viewer draws. */
export type AtmosphereKind = 'earth' | 'mars';

/** An atmosphere around a planet: metres, scattering coefficients per metre. */
export interface AtmosphereParams {
  kind: AtmosphereKind;
  /** Radius of the ground sphere the heights are measured from (the planet's datum). */
  groundRadius: number;
  /** Thickness of the shell drawn above the ground sphere. */
  top: number;
  /** Rayleigh scattering at the ground (red, green, blue) and its scale height. */
  rayleigh: V3;
  rayleighHeight: number;
  /** Extinction of the Rayleigh layer: its scattering plus what it absorbs (Mars's fine dust). */
  rayleighExtinction: V3;
  /** Mie scattering and extinction at the ground, its scale height and asymmetry `g`. */
  mie: V3;
  mieExtinction: V3;
  mieHeight: number;
  mieG: number;
  /**
   * The sun's light reaches the air through as many scale heights as on the real planet: its
   * path's Chapman function is taken for at least this many scale heights of radius (the real
   * planet's R / H). On a small planet with a relatively thick shell a sun on the horizon would
   * otherwise shine through a fifth of the air it crosses on the Earth, and hardly redden.
   */
  sunPathX: number;
  /**
   * The sun's irradiance times the exposure, per channel: scattered light L shows as
   * 1 - exp(-L). Its colour is the white balance of a camera for which the sun straight overhead
   * (seen through the air) is white.
   */
  sun: V3;
}

/** What the planet description tells about the atmosphere (from `GET /api/v1/planet`). */
export interface PlanetAtmosphereInfo {
  preset: string | null;
  terrain?: { kind: string; name: string };
  sea_radius: number | null;
}

/**
 * The atmosphere of a planet: Earth's for the Earth-like presets and for elevation models (of
 * the Earth), Mars's for `mars`, none for the Moon and the bare sphere. Another preset has
 * Earth's air when it has a sea, none otherwise.
 */
export function atmosphereKind(info: PlanetAtmosphereInfo): AtmosphereKind | null {
  const name = (info.preset ?? (info.terrain?.kind === 'dem' ? 'dem' : (info.terrain?.name ?? ''))).toLowerCase();
  switch (name) {
    case 'earth':
    case 'earthlike':
    case 'dem':
      return 'earth';
    case 'mars':
      return 'mars';
    case 'moon':
    case 'sphere':
      return null;
    default:
      return info.sea_radius !== null ? 'earth' : null;
  }
}

/** A real atmosphere: the planet radius it belongs to and its coefficients there. */
interface Reference {
  radius: number;
  rayleigh: V3;
  /** Absorption in the Rayleigh layer. */
  absorption: V3;
  rayleighHeight: number;
  mie: V3;
  /** Mie extinction over scattering (absorbing dust above 1). */
  mieAbsorption: number;
  mieHeight: number;
  mieG: number;
  sunIntensity: number;
  /** Whether the camera's white balance makes the sun overhead white (else the raw colours). */
  whiteBalance: boolean;
}

/** Earth: Bruneton and Neyret's coefficients (680, 550, 440 nm), 6360 km. */
export const EARTH_REFERENCE: Readonly<Reference> = {
  radius: 6_360_000,
  rayleigh: [5.8e-6, 13.5e-6, 33.1e-6],
  absorption: [0, 0, 0],
  rayleighHeight: 8000,
  mie: [21e-6, 21e-6, 21e-6],
  mieAbsorption: 1 / 0.9,
  mieHeight: 1200,
  mieG: 0.76,
  sunIntensity: 15,
  whiteBalance: true,
};

/**
 * Mars: a thin, dusty atmosphere. The fine dust that fills it scatters red more than blue (it
 * absorbs blue: a butterscotch sky), so it takes the molecular term's place with the colours
 * turned round; the coarser dust (the Mie term) scatters strongly forward and a little more in
 * blue, which makes the blue glow around a setting sun.
 */
export const MARS_REFERENCE: Readonly<Reference> = {
  radius: 3_390_000,
  rayleigh: [26e-6, 14e-6, 5e-6],
  absorption: [2e-6, 9e-6, 15e-6],
  rayleighHeight: 11_100,
  mie: [2.5e-6, 3.2e-6, 5.0e-6],
  mieAbsorption: 1.4,
  mieHeight: 11_100,
  mieG: 0.82,
  sunIntensity: 12,
  whiteBalance: false,
};

/** The shell drawn reaches this many Rayleigh scale heights above the ground. */
export const TOP_SCALE_HEIGHTS = 7;

/**
 * The atmosphere of `kind` around a planet whose ground (datum) is `groundRadius` and whose
 * highest terrain rises `relief` metres above it. Scale heights shrink with the radius, as on a
 * smaller copy of the real planet, but never below half the relief: the procedural planets are
 * a few kilometres across with mountains of a tenth of their radius, and a true-to-scale air of a
 * few metres would leave the mountains in vacuum and show no sky at all. The coefficients shrink
 * by as much as the scale heights grow, so the optical depth straight up (scattering times scale
 * height, what gives the sky its colour) stays the real planet's.
 */
export function atmosphereParams(kind: AtmosphereKind, groundRadius: number, relief: number): AtmosphereParams {
  const ref = kind === 'mars' ? MARS_REFERENCE : EARTH_REFERENCE;
  const rayleighHeight = Math.max((ref.rayleighHeight * groundRadius) / ref.radius, 0.5 * Math.max(0, relief));
  const stretch = rayleighHeight / ref.rayleighHeight;
  const per = (c: V3): V3 => [c[0] / stretch, c[1] / stretch, c[2] / stretch];
  const mie = per(ref.mie);
  const rayleigh = per(ref.rayleigh);
  const absorption = per(ref.absorption);
  const rayleighExtinction: V3 = [rayleigh[0] + absorption[0], rayleigh[1] + absorption[1], rayleigh[2] + absorption[2]];
  const mieExtinction: V3 = [mie[0] * ref.mieAbsorption, mie[1] * ref.mieAbsorption, mie[2] * ref.mieAbsorption];
  const mieHeight = ref.mieHeight * stretch;
  // white balance: the sun at the zenith, seen from the ground, is white
  const overhead = [0, 1, 2].map((c) => (ref.whiteBalance ? Math.exp(rayleighExtinction[c]! * rayleighHeight + mieExtinction[c]! * mieHeight) : 1));
  const lum = 0.2126 * overhead[0]! + 0.7152 * overhead[1]! + 0.0722 * overhead[2]!;
  return {
    kind,
    groundRadius,
    top: TOP_SCALE_HEIGHTS * rayleighHeight,
    rayleigh,
    rayleighHeight,
    rayleighExtinction,
    mie,
    mieExtinction,
    mieHeight,
    mieG: ref.mieG,
    sunPathX: ref.radius / ref.rayleighHeight,
    sun: [(ref.sunIntensity * overhead[0]!) / lum, (ref.sunIntensity * overhead[1]!) / lum, (ref.sunIntensity * overhead[2]!) / lum],
  };
}

/**
 * The atmosphere of a planet (null: none) from its description and its datum and highest
 * terrain (planetParams' shape).
 */
export function atmosphereOf(info: PlanetAtmosphereInfo, shape: { datum: number; outer: number }): AtmosphereParams | null {
  const kind = atmosphereKind(info);
  return kind ? atmosphereParams(kind, shape.datum, shape.outer - shape.datum) : null;
}

/** The sun's place in the sky: degrees clockwise from north, and above the horizon. */
export interface SunAngles {
  azimuth: number;
  elevation: number;
}

/** Where the sun stands by default: south-east-ish of north, well up (the viewer's old sun). */
export const DEFAULT_SUN: Readonly<SunAngles> = { azimuth: 57.5, elevation: 56.9 };

/** The unit direction toward the sun at `azimuth` and `elevation` (degrees) in the frame `enu`. */
export function sunDirection(enu: Enu, azimuth: number, elevation: number): V3 {
  const a = azimuth * DEG;
  const e = elevation * DEG;
  const h = Math.cos(e);
  const s = Math.sin(e);
  const x = h * Math.sin(a);
  const y = h * Math.cos(a);
  return [
    x * enu.east[0] + y * enu.north[0] + s * enu.up[0],
    x * enu.east[1] + y * enu.north[1] + s * enu.up[1],
    x * enu.east[2] + y * enu.north[2] + s * enu.up[2],
  ];
}

// ---- the reference of the shaders ---------------------------------------------------------------

/** Samples along the view ray: the sky, and at most for the terrain's aerial perspective (a step per half scale height). */
export const SKY_SAMPLES = 12;
export const AERIAL_SAMPLES = 6;

/**
 * How thick the air between the eye and a surface counts, of the sky's: a surface's aerial
 * perspective takes this share of the path's optical depth (transmittance `T^k`) and of its
 * scattered light (`1 - exp(-k L)`). The ground is lit on the scale of its albedo (a white surface
 * facing the sun shows about white), while the sky is exposed for a sun of `sun` irradiance: a
 * sunlit field of albedo 0.1 then shows 0.1 against a horizon sky near 0.8, eight times darker,
 * where a camera sees the horizon sky two or three times as bright as the field. Through the
 * whole air that field drowned: the real Earth from 10 km a blue-grey veil with no land in it,
 * the earth preset's continent pale blue from orbit. A third of it keeps the air's colour, its
 * growth with distance and the blue it gives the ground seen from orbit, and leaves the ground
 * readable to the horizon.
 */
export const SURFACE_SCATTER = 0.35;

/** Rayleigh phase function (per steradian) at the cosine `nu` of the scattering angle. */
export function rayleighPhase(nu: number): number {
  return (3 / (16 * Math.PI)) * (1 + nu * nu);
}

/** Cornette-Shanks phase function (a Henyey-Greenstein lobe that also has Rayleigh's shape). */
export function miePhase(nu: number, g: number): number {
  const g2 = g * g;
  const k = (3 / (8 * Math.PI)) * ((1 - g2) / (2 + g2));
  return (k * (1 + nu * nu)) / Math.pow(Math.max(1e-4, 1 + g2 - 2 * g * nu), 1.5);
}

/**
 * Chapman function approximation for a point at `x` scale heights from the centre and a ray
 * with zenith cosine `mu` >= 0: the optical depth to infinity over the vertical one. Along the
 * ray the height grows about as mu t + t^2 / 2r, so the depth is sqrt(pi x / 2) erfcx(a) with
 * a = mu sqrt(x / 2) and erfcx the scaled complementary error function, here the rational
 * approximation 2 / (sqrt(pi) (2.3193 a + sqrt(1.52 a^2 + 4)) / sqrt(pi)) of Bruneton and
 * Neyret's analytic optical depth: exact along the horizon (sqrt(pi x / 2)), 1 / mu far from it,
 * within 3 % of a brute-force march at every angle (tested).
 */
export function chapmanUp(x: number, mu: number): number {
  const a = mu * Math.sqrt(0.5 * x);
  return Math.sqrt(6.2831853 * x) / (2.3193 * a + Math.sqrt(1.52 * a * a + 4));
}

/** The exponent of exp() is kept below this (a ray deep in the planet's shadow). */
const MAX_EXPONENT = 50;

/**
 * Density-weighted length (metres of air at ground density) from the point `h` metres above a
 * ground sphere of radius `R`, out to infinity along a ray of zenith cosine `mu`, for scale
 * height `H`. A ray below the horizon runs down to its tangent point and up again (twice the
 * horizontal depth there, less the depth of the ray turned up); a tangent point under the
 * ground gives a depth that grows without bound: the planet's shadow, soft at its edge.
 */
export function slantDepth(R: number, h: number, mu: number, H: number, xMin = 0): number {
  const r = R + h;
  const x = Math.max(r / H, xMin);
  if (mu >= 0) return H * Math.exp(-h / H) * chapmanUp(x, mu);
  const s = Math.sqrt(Math.max(0, 1 - mu * mu));
  const ht = h - (r * mu * mu) / (1 + s); // the tangent point's height, without cancelling large numbers
  const tangent = 2 * H * Math.exp(Math.min(MAX_EXPONENT, -ht / H)) * Math.sqrt(1.5707963 * Math.max((r * s) / H, xMin));
  return Math.max(0, tangent - H * Math.exp(-h / H) * chapmanUp(x, -mu));
}

/** The optical depth toward the sun from `h` above the ground with the sun at zenith cosine `mu`. */
function sunDepth(a: AtmosphereParams, h: number, mu: number): V3 {
  const dr = slantDepth(a.groundRadius, h, mu, a.rayleighHeight, a.sunPathX);
  const dm = slantDepth(a.groundRadius, h, mu, a.mieHeight, a.sunPathX * (a.rayleighHeight / a.mieHeight));
  return [
    a.rayleighExtinction[0] * dr + a.mieExtinction[0] * dm,
    a.rayleighExtinction[1] * dr + a.mieExtinction[1] * dm,
    a.rayleighExtinction[2] * dr + a.mieExtinction[2] * dm,
  ];
}

/** Where a ray from the camera meets the shell: the stretch inside the air, and the ground. */
export interface RaySpan {
  /** Distances along the ray where it enters and leaves the air (enter = exit = 0: it misses). */
  enter: number;
  exit: number;
  /** The distance where the ray meets the ground sphere before leaving the air, else null. */
  ground: number | null;
}

/**
 * The span of a ray from a camera `h` metres above the ground sphere (at least a millimetre
 * is used) in a direction of zenith cosine `mu`. The ground's and the top's quadratics take
 * r^2 - R^2 as h (2R + h), so a camera on the ground of an Earth-sized planet stays exact in f32.
 */
export function raySpan(a: AtmosphereParams, h: number, mu: number): RaySpan {
  const R = a.groundRadius;
  const hc = Math.max(h, 1e-3);
  const r = R + hc;
  const b = r * mu;
  const cTop = (hc - a.top) * (2 * R + hc + a.top);
  const dTop = b * b - cTop;
  if (dTop < 0) return { enter: 0, exit: 0, ground: null };
  const q = Math.sqrt(dTop);
  const exit = -b + q;
  if (exit <= 0) return { enter: 0, exit: 0, ground: null };
  const enter = Math.max(0, -b - q);
  const cGround = hc * (2 * R + hc);
  const dGround = b * b - cGround;
  if (mu < 0 && dGround >= 0) {
    const tg = -b - Math.sqrt(dGround);
    if (tg > 0 && tg < exit) return { enter, exit, ground: tg };
  }
  return { enter, exit, ground: null };
}

/** Light scattered toward the eye along a stretch of a ray, and the transmittance of the stretch. */
export interface Scattered {
  light: V3;
  transmittance: V3;
}

/**
 * Single scattering along the ray from a camera at `camera` (planet frame, the centre at the
 * origin) in the unit direction `dir`, from `t0` to `t1` metres, in `samples` steps (midpoints),
 * with the sun in the unit direction `sun`. `light` is in units of the sun's intensity.
 */
export function scatter(a: AtmosphereParams, camera: V3, dir: V3, sun: V3, t0: number, t1: number, samples: number): Scattered {
  const light: V3 = [0, 0, 0];
  const depth: V3 = [0, 0, 0];
  const dt = (t1 - t0) / samples;
  const nu = dir[0] * sun[0] + dir[1] * sun[1] + dir[2] * sun[2];
  const pr = rayleighPhase(nu);
  const pm = miePhase(nu, a.mieG);
  for (let i = 0; i < samples; i++) {
    const t = t0 + (i + 0.5) * dt;
    const p: V3 = [camera[0] + dir[0] * t, camera[1] + dir[1] * t, camera[2] + dir[2] * t];
    const r = Math.hypot(p[0], p[1], p[2]);
    const h = r - a.groundRadius;
    const rhoR = Math.exp(-Math.max(h, 0) / a.rayleighHeight);
    const rhoM = Math.exp(-Math.max(h, 0) / a.mieHeight);
    const ext = [0, 1, 2].map((c) => a.rayleighExtinction[c]! * rhoR + a.mieExtinction[c]! * rhoM);
    const muS = (p[0] * sun[0] + p[1] * sun[1] + p[2] * sun[2]) / r;
    const ts = sunDepth(a, Math.max(h, 0), muS);
    for (let c = 0; c < 3; c++) {
      const half = depth[c]! + 0.5 * ext[c]! * dt;
      const s = a.rayleigh[c]! * rhoR * pr + a.mie[c]! * rhoM * pm;
      light[c] += Math.exp(-half - ts[c]!) * s * dt;
      depth[c] += ext[c]! * dt;
    }
  }
  return {
    light: [light[0] * a.sun[0], light[1] * a.sun[1], light[2] * a.sun[2]],
    transmittance: [Math.exp(-depth[0]), Math.exp(-depth[1]), Math.exp(-depth[2])],
  };
}

/** The display value of scattered light: 1 - exp(-L) per channel (linear RGB, 0..1). */
export function exposure(l: V3): V3 {
  return [1 - Math.exp(-l[0]), 1 - Math.exp(-l[1]), 1 - Math.exp(-l[2])];
}

/** The colour of space (linear RGB): the viewer's background far from any planet. */
export const SPACE: Readonly<V3> = [0.004, 0.006, 0.012];

/** Half the sun's apparent diameter as drawn, radians (twice the real sun's, to be seen). */
export const SUN_RADIUS = 0.0093;
/** The sun disc's radiance over the sky's scale. */
export const SUN_DISC = 60;

/**
 * The sky's colour (linear RGB, 0..1) seen from `camera` (planet frame) in the unit direction
 * `dir` with the sun toward `sun`: the light scattered along the ray through the air, the sun's
 * disc, and space seen through it. The sky is drawn where no terrain is: a ray that meets the
 * ground sphere there (the terrain is not loaded, or lower than the datum) shows the sky at the
 * horizon in its direction, not a dark ground. Without an atmosphere (null), space.
 */
export function skyColour(a: AtmosphereParams | null, camera: V3, viewDir: V3, sun: V3): V3 {
  if (!a) return [...SPACE];
  const r = Math.hypot(camera[0], camera[1], camera[2]);
  const up: V3 = [camera[0] / r, camera[1] / r, camera[2] / r];
  let dir = viewDir;
  const mu = dir[0] * up[0] + dir[1] * up[1] + dir[2] * up[2];
  let span = raySpan(a, r - a.groundRadius, mu);
  const bent = span.ground !== null;
  if (bent) {
    const h = Math.max(r - a.groundRadius, 1e-3);
    const muH = -Math.sqrt(h * (2 * a.groundRadius + h)) / (a.groundRadius + h) + 1e-4;
    const across: V3 = [dir[0] - up[0] * mu, dir[1] - up[1] * mu, dir[2] - up[2] * mu];
    const l = Math.hypot(across[0], across[1], across[2]);
    const k = Math.sqrt(Math.max(0, 1 - muH * muH));
    dir = l > 1e-6 ? [(across[0] / l) * k + up[0] * muH, (across[1] / l) * k + up[1] * muH, (across[2] / l) * k + up[2] * muH] : dir;
    span = { ...raySpan(a, h, muH), ground: null };
  }
  let light: V3 = [0, 0, 0];
  let trans: V3 = [1, 1, 1];
  if (span.exit > span.enter) {
    const s = scatter(a, camera, dir, sun, span.enter, span.exit, SKY_SAMPLES);
    light = s.light;
    trans = s.transmittance;
  }
  if (!bent) {
    // the disc seen along the sun's path (the one the air it lights sees), not the view ray's
    const nu = dir[0] * sun[0] + dir[1] * sun[1] + dir[2] * sun[2];
    const disc = sunDisc(nu) * SUN_DISC;
    const h = Math.max(r - a.groundRadius, 1e-3);
    const ts = sunDepth(a, h, (up[0] * sun[0] + up[1] * sun[1] + up[2] * sun[2]));
    light = [0, 1, 2].map((c) => light[c]! + disc * a.sun[c]! * Math.exp(-ts[c]!)) as V3;
  }
  const e = exposure(light);
  return [e[0] + SPACE[0] * trans[0], e[1] + SPACE[1] * trans[1], e[2] + SPACE[2] * trans[2]];
}

/** The sun's disc at the cosine `nu` of the angle from its centre: 1 inside, a soft edge. */
export function sunDisc(nu: number): number {
  const inner = Math.cos(SUN_RADIUS);
  const outer = Math.cos(SUN_RADIUS * 1.3);
  const t = Math.min(1, Math.max(0, (nu - outer) / (inner - outer)));
  return t * t * (3 - 2 * t);
}

/**
 * Aerial perspective: `colour` (linear RGB) of a surface at `rel` (planet frame, from the
 * camera at `camera`) seen through the air between: attenuated by the transmittance, plus
 * the light scattered on the way (exposed as the sky is), through `SURFACE_SCATTER` of the air. Unchanged without
 * an atmosphere.
 */
export function aerialPerspective(a: AtmosphereParams | null, colour: V3, camera: V3, rel: V3, sun: V3): V3 {
  if (!a) return colour;
  const d = Math.hypot(rel[0], rel[1], rel[2]);
  if (d <= 0) return colour;
  const dir: V3 = [rel[0] / d, rel[1] / d, rel[2] / d];
  const r = Math.hypot(camera[0], camera[1], camera[2]);
  const mu = (dir[0] * camera[0] + dir[1] * camera[1] + dir[2] * camera[2]) / r;
  // to the surface or out of the air; a chord between two heights may dip under the ground
  // sphere (density as on the ground there), so the ground does not end it
  const span = raySpan(a, r - a.groundRadius, mu);
  const t1 = Math.min(d, span.exit);
  if (t1 <= span.enter) return colour;
  // a step per half scale height, at most AERIAL_SAMPLES: near terrain costs one or two
  const n = Math.min(AERIAL_SAMPLES, Math.max(1, Math.ceil((2 * (t1 - span.enter)) / a.rayleighHeight)));
  const s = scatter(a, camera, dir, sun, span.enter, t1, n);
  const k = SURFACE_SCATTER;
  const e = exposure([k * s.light[0], k * s.light[1], k * s.light[2]]);
  const tr = s.transmittance.map((x) => Math.pow(x, k));
  return [colour[0] * tr[0]! + e[0], colour[1] * tr[1]! + e[1], colour[2] * tr[2]! + e[2]];
}
