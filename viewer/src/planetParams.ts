// Numbers the viewer derives from `/api/v1/planet`: the datum that altitudes and heights refer
// to, the radial extent of the surface, and the shading parameters (the material model and the
// frequencies of the shader's place noises). Pure.

import type { PlanetInfo, Vec3Tuple } from './api';
import type { PlanetShape } from './cameraModel';
import type { PlanetExtent } from './chunkSelection';
import { materialModel, type MaterialModel } from './materials';
import { JITTER_SCALE, NOISE_PERIOD_CELLS } from './shaders';

/** Wavelength of the finest place noise's first octave (detail near the ground), metres. */
export const DETAIL_WAVELENGTH = 4;

export interface PlanetParams {
  shape: PlanetShape;
  extent: PlanetExtent;
  seaRadius: number | null;
  /** Metres from the datum to the highest terrain (scale of the height bands). */
  bandHeight: number;
  /** Metres above the datum where snow starts. */
  snowHeight: number;
  snowAmount: number;
  /** Metres of water that absorb most light. */
  waterScale: number;
  /** Noise frequency, cycles per metre, and its period in metres (two tiles per cycle). */
  noiseFreq: number;
  noisePeriod: number;
  /** The detail noise near the ground: cycles per metre and period in metres. */
  detailFreq: number;
  detailPeriod: number;
  /**
   * The large-scale noise (forests, deserts): cells per unit of direction, each 40 tiles or
   * MACRO_CELL_SHARE of the radius, whichever is larger.
   */
  macroFreq: number;
  /** The material model: one function of the place, this planet's parameters. */
  materials: MaterialModel;
  /** Palette colours scaled to a mean luminance of 1 (multiplied into the vertex colour). */
  paletteA: Vec3Tuple;
  paletteB: Vec3Tuple;
  /** Width of a chunk at the surface, metres. */
  chunkWidth: number;
}

const luminance = (c: Vec3Tuple): number => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];

/**
 * The smallest cell of the large-scale noise, as a share of the radius: forests and deserts come
 * in regions of 127 km and more on the Earth. At true scale 40 tiles were 80 m, and from 10 km
 * the lowlands were a camouflage of sand and forest patches a few hundred metres across (the
 * gallery's `earth-10000m`); on the small planets 40 tiles are larger and stay.
 */
export const MACRO_CELL_SHARE = 0.02;

export function planetParams(p: PlanetInfo): PlanetParams {
  const sea = p.sea_radius;
  const datum = sea ?? (p.base_radius + p.radius) / 2;
  const bounds = p.surface_bounds ?? [p.base_radius, p.radius];
  const outer = Math.max(bounds[1], datum);
  const lowest = bounds[0];
  const inner = Math.max(lowest, sea ?? -Infinity);
  const bandHeight = Math.max(1, outer - datum);
  const chunkWidth = ((Math.PI / 2) * datum) / Math.max(1, p.layout.n_c);
  const tile = chunkWidth / Math.max(1, p.layout.n_t);
  const noiseFreq = 1 / Math.max(1e-3, 2 * tile);
  const detailFreq = 1 / DETAIL_WAVELENGTH;
  const mean = Math.max(1e-3, (luminance(p.palette.a) + luminance(p.palette.b)) / 2);
  const norm = (c: Vec3Tuple): Vec3Tuple => [c[0] / mean, c[1] / mean, c[2] / mean];
  return {
    shape: { datum, outer, inner: lowest },
    extent: { innerRadius: inner, outerRadius: outer },
    seaRadius: sea,
    bandHeight,
    snowHeight: 0.6 * bandHeight,
    snowAmount: sea !== null ? 1 : 0.3,
    waterScale: sea !== null ? Math.max(2, (sea - lowest) / 3) : 1,
    noiseFreq,
    // a period of every octave of the place noise, its lowest (the jitter's) included
    noisePeriod: NOISE_PERIOD_CELLS / (JITTER_SCALE * noiseFreq),
    detailFreq,
    detailPeriod: NOISE_PERIOD_CELLS / detailFreq,
    macroFreq: datum / Math.max(1e-3, 40 * tile, MACRO_CELL_SHARE * datum),
    materials: materialModel(p, datum),
    paletteA: norm(p.palette.a),
    paletteB: norm(p.palette.b),
    chunkWidth,
  };
}
