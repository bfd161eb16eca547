// The material model of the terrain shader: one function of the place (height above the datum,
// slope against the local vertical, latitude, noise, imagery) for every planet, with per-planet
// parameters. The palette and the bands follow the Rust presets' shaders (crates/pmc-density:
// presets/earthlike.rs, earth.rs, mars.rs, moon.rs and terrain/heightfield.rs for elevation
// models), evaluated per pixel instead of per vertex, with smooth transitions, so that a place
// has the same colour at every level of detail. Pure: no three.js, no DOM.

import type { PlanetInfo } from './api';
import { srgb8ToLinear, type Rgb } from './colour';

/** The materials of the model, in the order of the shader's colour arrays. */
export const MATERIAL_SLOTS = ['deep', 'shelf', 'shore', 'low', 'forest', 'dry', 'rock', 'snow', 'dark', 'ice'] as const;
export type MaterialSlot = (typeof MATERIAL_SLOTS)[number];

/** Radius of the Earth, metres (the true scale of the `earth` preset and elevation models). */
export const EARTH_RADIUS = 6_371_000;

/** The heights of a model; every height is metres of the mesh above the datum. */
export interface MaterialModel {
  /** The family of the parameters (`earthlike`, `earth`, `dem`, `mars`, `moon`, `generic`). */
  family: string;
  /** Two colours per material (linear RGB), mixed by noise. */
  colours: Record<MaterialSlot, [Rgb, Rgb]>;
  /** Depth below the datum where the deep seabed starts (the shelf above it). */
  shelfDepth: number;
  /** Height of the shore's sand band above the datum (0: none). */
  shoreHeight: number;
  /** Height above which the lowlands are all forest (Infinity: none). */
  forestFrom: number;
  /** The tree line as a fraction of the local snow line: above it rock. */
  treeLine: number;
  /** The snow line at the equator, and its fall toward the poles: `line (1 - k sin^(2q) lat)^p`. */
  snowLine: number;
  snowLatK: number;
  snowLatQ: number;
  snowLatP: number;
  /** Lowest snow line (the poles). */
  snowMin: number;
  /** Share of the lowlands under forest, and of deserts (in the subtropics), 0..1. */
  forestShare: number;
  dryShare: number;
  /** Below this height the dark material (maria, canyon sand); -Infinity: none. */
  darkHeight: number;
  /** Share of the dark material elsewhere (dunes), by noise, 0..1. */
  darkShare: number;
  /** Cosine of the slope below which rock shows, and above which snow and ice stay. */
  rockSlope: number;
  snowSlope: number;
  /** |sin latitude| above which polar ice lies (above 1: none). */
  iceFrom: number;
  /** Random shift of the height lines, metres. */
  lineJitter: number;
  /** Width of a height transition, metres (the smooth step on each side of a line). */
  blend: number;
}

const pair = (a: Rgb, b: Rgb): [Rgb, Rgb] => [srgb8ToLinear(a), srgb8ToLinear(b)];

// the Rust presets' palettes (sRGB, as their `Material::srgb`)
const SAND = pair([222, 204, 150], [206, 178, 120]);
const GRASS = pair([96, 140, 60], [128, 160, 72]);
const FOREST = pair([36, 80, 38], [56, 98, 46]);
const ROCK = pair([116, 108, 100], [148, 140, 128]);
const SNOW = pair([244, 246, 252], [216, 224, 238]);
const NONE = pair([255, 0, 255], [255, 0, 255]);

/**
 * The material model of `info`'s planet: the preset's, an elevation model's, or a generic one from
 * the planet's two blend colours. `datum` is the radius heights refer to.
 */
export function materialModel(info: PlanetInfo, datum: number): MaterialModel {
  const t = Math.max(1, info.radius - info.base_radius);
  // metres of the mesh per true-scale metre (planets shrunk onto a smaller layout)
  const v = datum / EARTH_RADIUS;
  const family = info.terrain?.kind === 'dem' || (info.preset === null && info.terrain === undefined) ? 'dem' : (info.preset ?? 'generic');
  const base: Omit<MaterialModel, 'family' | 'colours'> = {
    shelfDepth: Infinity,
    shoreHeight: 0,
    forestFrom: Infinity,
    treeLine: Infinity,
    snowLine: Infinity,
    snowLatK: 1,
    snowLatQ: 1,
    snowLatP: 1,
    snowMin: 0,
    forestShare: 0,
    dryShare: 0,
    darkHeight: -Infinity,
    darkShare: 0,
    rockSlope: 0.68,
    snowSlope: 0.5,
    iceFrom: 2,
    lineJitter: 0,
    blend: 0.01 * t,
  };
  switch (family) {
    case 'earthlike':
      // presets/earthlike.rs: sand under the sea and on the beach (0.012 T), grass and forest,
      // forest from 0.10 T, rock from 0.18 T, snow above 0.25 T (1 - 1.28 sin^2 lat)
      return {
        ...base,
        family,
        colours: { deep: SAND, shelf: SAND, shore: SAND, low: GRASS, forest: FOREST, dry: SAND, rock: ROCK, snow: SNOW, dark: NONE, ice: SNOW },
        shoreHeight: 0.012 * t,
        forestFrom: 0.1 * t,
        treeLine: 0.72,
        snowLine: 0.25 * t,
        snowLatK: 1.28,
        snowMin: 0.004 * t,
        forestShare: 0.45,
        rockSlope: 0.62,
        lineJitter: 0.012 * t,
        blend: 0.008 * t,
      };
    case 'earth':
      // presets/earth.rs: seabed, sand on the shore, deserts in the subtropics, grass and forest,
      // rock above 0.72 of the snow line, snow at 5200 m (1 - sin^2 lat)^1.5 (true scale)
      return {
        ...base,
        family,
        colours: {
          deep: pair([118, 108, 86], [92, 88, 76]),
          shelf: pair([118, 108, 86], [92, 88, 76]),
          shore: SAND,
          low: GRASS,
          forest: FOREST,
          dry: SAND,
          rock: ROCK,
          snow: SNOW,
          dark: NONE,
          ice: SNOW,
        },
        shoreHeight: 6 * v,
        treeLine: 0.72,
        snowLine: 5200 * v,
        snowLatP: 1.5,
        forestShare: 0.5,
        dryShare: 0.3,
        lineJitter: 250 * v,
        blend: 120 * v,
      };
    case 'dem':
      // terrain/heightfield.rs: deep seabed below 200 m, shelf, sand on the shore, grass and
      // forest, rock above 0.7 of the snow line, snow at 5500 m (1 - sin^4 lat) (true scale)
      return {
        ...base,
        family,
        colours: {
          deep: pair([46, 62, 92], [58, 70, 96]),
          shelf: pair([96, 120, 118], [120, 128, 110]),
          shore: SAND,
          low: GRASS,
          forest: FOREST,
          dry: SAND,
          rock: ROCK,
          snow: SNOW,
          dark: NONE,
          ice: SNOW,
        },
        shelfDepth: 200 * v,
        shoreHeight: 8 * v,
        treeLine: 0.7,
        snowLine: 5500 * v,
        snowLatQ: 2,
        forestShare: 0.4,
        lineJitter: 150 * v,
        blend: 120 * v,
      };
    case 'mars':
      // presets/mars.rs: rust dust, darker rock on slopes, dark sand in the low ground and dunes,
      // white ice at the poles
      return {
        ...base,
        family,
        colours: {
          deep: NONE,
          shelf: NONE,
          shore: NONE,
          low: pair([196, 108, 66], [168, 86, 52]),
          forest: NONE,
          dry: NONE,
          rock: pair([118, 70, 52], [150, 94, 66]),
          snow: NONE,
          dark: pair([108, 62, 46], [132, 78, 54]),
          ice: pair([238, 238, 242], [212, 216, 226]),
        },
        darkHeight: -0.06 * t,
        darkShare: 0.2,
        rockSlope: 0.7,
        iceFrom: 0.93,
        lineJitter: 0.01 * t,
      };
    case 'moon':
      // presets/moon.rs: bright regolith, dark maria in the low basins, rock on slopes
      return {
        ...base,
        family,
        colours: {
          deep: NONE,
          shelf: NONE,
          shore: NONE,
          low: pair([172, 170, 164], [140, 139, 134]),
          forest: NONE,
          dry: NONE,
          rock: pair([118, 116, 112], [150, 148, 142]),
          snow: NONE,
          dark: pair([84, 84, 88], [106, 105, 104]),
          ice: NONE,
        },
        darkHeight: -0.04 * t,
        rockSlope: 0.75,
        lineJitter: 0.01 * t,
      };
    default: {
      // any other planet: its two blend colours, rock on slopes
      const a = info.palette?.a ?? [0.5, 0.5, 0.5];
      const b = info.palette?.b ?? [0.4, 0.4, 0.4];
      const p: [Rgb, Rgb] = [[a[0], a[1], a[2]], [b[0], b[1], b[2]]];
      return {
        ...base,
        family: 'generic',
        colours: { deep: p, shelf: p, shore: p, low: p, forest: p, dry: p, rock: ROCK, snow: SNOW, dark: p, ice: SNOW },
      };
    }
  }
}

/** A number the shader can hold (f32): infinities become ±1e30. */
const finite = (x: number): number => (x === Infinity ? 1e30 : x === -Infinity ? -1e30 : x);

/** The model as the shader's uniforms. */
export interface MaterialUniforms {
  /** `MATERIAL_SLOTS.length` x 3: the first and second colour of each material. */
  colourA: Float32Array;
  colourB: Float32Array;
  /** shelf depth, shore height, forest-from height, tree line (fraction of the snow line). */
  heights: [number, number, number, number];
  /** snow line, its latitude factor k, exponent q, power p. */
  snow: [number, number, number, number];
  /** forest share, dry share, dark height, dark share. */
  shares: [number, number, number, number];
  /** rock slope, snow slope, ice from, line jitter. */
  slopes: [number, number, number, number];
  /** lowest snow line, transition width. */
  extra: [number, number];
}

export function materialUniforms(m: MaterialModel): MaterialUniforms {
  const colourA = new Float32Array(3 * MATERIAL_SLOTS.length);
  const colourB = new Float32Array(3 * MATERIAL_SLOTS.length);
  MATERIAL_SLOTS.forEach((slot, i) => {
    const [a, b] = m.colours[slot];
    colourA.set(a, 3 * i);
    colourB.set(b, 3 * i);
  });
  return {
    colourA,
    colourB,
    heights: [finite(m.shelfDepth), m.shoreHeight, finite(m.forestFrom), finite(m.treeLine)],
    snow: [finite(m.snowLine), m.snowLatK, m.snowLatQ, m.snowLatP],
    shares: [m.forestShare, m.dryShare, finite(m.darkHeight), m.darkShare],
    slopes: [m.rockSlope, m.snowSlope, m.iceFrom, m.lineJitter],
    extra: [m.snowMin, Math.max(1e-3, m.blend)],
  };
}

/**
 * The snow line (metres above the datum) at a unit direction's `y` (the sine of the latitude):
 * the shader's formula.
 */
export function snowLineAt(m: MaterialModel, sinLat: number): number {
  const s2 = sinLat * sinLat;
  const f = Math.max(0, 1 - m.snowLatK * Math.pow(s2, m.snowLatQ));
  return Math.max(m.snowMin, m.snowLine * Math.pow(f, m.snowLatP));
}

/**
 * Latitude and longitude (degrees) of a planet-frame direction, as the shader computes them per
 * pixel: Y is the polar axis, longitude 0 on +Z and +90 on +X.
 */
export function latLonOfDirection(d: [number, number, number]): { lat: number; lon: number } {
  const r = Math.hypot(d[0], d[1], d[2]);
  if (!(r > 0)) return { lat: 0, lon: 0 };
  const lat = (Math.asin(Math.max(-1, Math.min(1, d[1] / r))) * 180) / Math.PI;
  const lon = (Math.atan2(d[0], d[2]) * 180) / Math.PI;
  return { lat, lon };
}
