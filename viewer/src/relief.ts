// The relief of an elevation-model planet: `/api/v1/planet`'s `relief` block and the grid at
// `/api/v1/relief` (docs/specs/http-api-v1.md). The terrain shader takes the materials' height
// (snow line, shelf, sea) from it, per pixel by latitude and longitude, wherever a pixel spans a
// good part of a data cell: the data do not depend on the level of detail a chunk was meshed at,
// while a coarse chunk's interpolated heights pass hundreds of metres under a finer one's peaks
// from orbit (the snow line jumped at a chunk border between two levels over Tibet). Pure, with no
// imports (the e2e steps load it too); the texture loader is reliefTexture.ts.

/** The `relief` block of `/api/v1/planet`. */
export interface ReliefInfo {
  /** Where the grid is served (relative to the page, e.g. `/api/v1/relief`). */
  url: string;
  width: number;
  height: number;
  /** Degrees: sample (c, r) lies at `lonFirst + c lonStep`, `latFirst + r latStep` (row 0 south). */
  lonFirst: number;
  lonStep: number;
  latFirst: number;
  latStep: number;
  /** The columns go round the whole circle. */
  wraps: boolean;
  /** Metres of the planet above its sea radius per metre of the data. */
  scale: number;
  /** Content digest of the elevation model. */
  digest: string;
}

/** The grid as served at a stride: its axes, and how rows past its ends are treated. */
export interface ReliefGrid extends Omit<ReliefInfo, 'url' | 'digest'> {
  /** A global grid whose southern (northern) row lies within one step of the pole: beyond it, that row's values. */
  clampSouth: boolean;
  clampNorth: boolean;
}

/** A malformed `relief` block or grid. */
export class ReliefError extends Error {
  constructor(message: string) {
    super(`relief: ${message}`);
    this.name = 'ReliefError';
  }
}

const isObject = (x: unknown): x is Record<string, unknown> => typeof x === 'object' && x !== null && !Array.isArray(x);
const finiteNumber = (x: unknown): x is number => typeof x === 'number' && Number.isFinite(x);

/**
 * The relief of a planet description (its `relief` field): null when absent or null, else the
 * block checked; throws a `ReliefError` saying what is wrong when malformed.
 */
export function parseRelief(planet: unknown): ReliefInfo | null {
  if (!isObject(planet)) throw new ReliefError('the planet description is not an object');
  const raw = planet['relief'];
  if (raw === undefined || raw === null) return null;
  if (!isObject(raw)) throw new ReliefError(`expected an object or null, got ${JSON.stringify(raw)}`);
  const { url, width, height, lon_first, lon_step, lat_first, lat_step, wraps, scale, digest, encoding } = raw;
  if (typeof url !== 'string' || url.length === 0) throw new ReliefError(`url ${JSON.stringify(url)} is not a non-empty string`);
  if (encoding !== 'f32le') throw new ReliefError(`encoding ${JSON.stringify(encoding)} is not f32le`);
  for (const [name, v] of [['width', width], ['height', height]] as const) {
    if (typeof v !== 'number' || !Number.isInteger(v) || v < 2 || v > 1 << 20) {
      throw new ReliefError(`${name} ${JSON.stringify(v)} is not a whole number of samples in 2..${1 << 20}`);
    }
  }
  for (const [name, v] of [['lon_first', lon_first], ['lat_first', lat_first], ['scale', scale]] as const) {
    if (!finiteNumber(v)) throw new ReliefError(`${name} ${JSON.stringify(v)} is not a finite number`);
  }
  for (const [name, v] of [['lon_step', lon_step], ['lat_step', lat_step]] as const) {
    if (!finiteNumber(v) || !(v > 0)) throw new ReliefError(`${name} ${JSON.stringify(v)} is not a positive number of degrees`);
  }
  if (typeof wraps !== 'boolean') throw new ReliefError(`wraps ${JSON.stringify(wraps)} is not a boolean`);
  if (typeof digest !== 'string') throw new ReliefError(`digest ${JSON.stringify(digest)} is not a string`);
  return {
    url,
    width: width as number,
    height: height as number,
    lonFirst: lon_first as number,
    lonStep: lon_step as number,
    latFirst: lat_first as number,
    latStep: lat_step as number,
    wraps,
    scale: scale as number,
    digest,
  };
}

/** Most samples of a relief texture (64 MiB of f32): a finer grid is read with a stride. */
export const MAX_RELIEF_SAMPLES = 1 << 24;

/**
 * The stride the viewer reads the grid with: the smallest power of two that brings both sides
 * to at most `maxSide` samples and their product to at most `maxSamples`.
 */
export function reliefStride(info: Pick<ReliefInfo, 'width' | 'height'>, maxSide: number, maxSamples = MAX_RELIEF_SAMPLES): number {
  let s = 1;
  const fits = (k: number): boolean => {
    const w = Math.ceil(info.width / k);
    const h = Math.ceil(info.height / k);
    return w <= maxSide && h <= maxSide && w * h <= maxSamples;
  };
  while (s < 2 ** 30 && !fits(s)) s *= 2;
  return s;
}

/** The grid the server answers at stride `stride` (every `stride`-th sample from the first). */
export function gridAtStride(info: ReliefInfo, stride: number): ReliefGrid {
  const wraps = info.wraps && info.width % stride === 0;
  const height = Math.ceil(info.height / stride);
  const latStep = info.latStep * stride;
  const latLast = info.latFirst + (height - 1) * latStep;
  return {
    width: Math.ceil(info.width / stride),
    height,
    lonFirst: info.lonFirst,
    lonStep: info.lonStep * stride,
    latFirst: info.latFirst,
    latStep,
    wraps,
    // as the planet's own heights (pmc-dem's source grid): a global grid reaching within one
    // step of a pole takes that row's values beyond it
    clampSouth: wraps && info.latFirst - latStep <= -90 + 1e-9,
    clampNorth: wraps && latLast + latStep >= 90 - 1e-9,
    scale: info.scale,
  };
}

/** Metres of one data cell on the ground along a meridian, on a sphere of `radius`. */
export function reliefCellMetres(grid: Pick<ReliefGrid, 'latStep'>, radius: number): number {
  return (grid.latStep * Math.PI * radius) / 180;
}

/**
 * The relief's height (metres of the planet above its sea radius) at latitude/longitude
 * (degrees), bilinear in column and row as the shader computes it; null off a regional grid.
 */
export function reliefHeightAt(grid: ReliefGrid, values: ArrayLike<number>, lat: number, lon: number): number | null {
  const w = grid.width;
  const h = grid.height;
  let x = ((((lon - grid.lonFirst) % 360) + 360) % 360) / grid.lonStep;
  let y = (lat - grid.latFirst) / grid.latStep;
  const tol = 1e-6;
  if (y < 0) {
    if (!grid.clampSouth && y < -tol) return null;
    y = 0;
  } else if (y > h - 1) {
    if (!grid.clampNorth && y > h - 1 + tol) return null;
    y = h - 1;
  }
  if (grid.wraps) {
    x %= w;
  } else if (x > w - 1) {
    if (x > w - 1 + tol) return null;
    x = w - 1;
  }
  const c0 = Math.min(Math.floor(x), w - 1);
  const r0 = Math.min(Math.floor(y), h - 1);
  const c1 = grid.wraps ? (c0 + 1) % w : Math.min(c0 + 1, w - 1);
  const r1 = Math.min(r0 + 1, h - 1);
  const fx = x - c0;
  const fy = y - r0;
  const at = (c: number, r: number): number => values[r * w + c]!;
  const south = at(c0, r0) + (at(c1, r0) - at(c0, r0)) * fx;
  const north = at(c0, r1) + (at(c1, r1) - at(c0, r1)) * fx;
  return (south + (north - south) * fy) * grid.scale;
}
