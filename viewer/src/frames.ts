// Planet-frame geometry in f64 (JS numbers): lat/lon/altitude <-> position, the local
// east/north/up frame, camera bases whose "up" is the local radial direction, and the floating
// origin offsets. Pure: no three.js, no DOM.
//
// Frame (docs/specs/http-api-v1.md): Y-up, right-handed, metres, planet-centred; +Y the north
// pole, longitude 0 on +Z, 90 E on +X:  dir(lat, lon) = (cos lat sin lon, sin lat, cos lat cos lon).

export type V3 = [number, number, number];

export const DEG = Math.PI / 180;

export const add = (a: V3, b: V3): V3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const sub = (a: V3, b: V3): V3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const scale = (a: V3, s: number): V3 => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a: V3, b: V3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a: V3, b: V3): V3 => [
  a[1] * b[2] - a[2] * b[1],
  a[2] * b[0] - a[0] * b[2],
  a[0] * b[1] - a[1] * b[0],
];
export const length = (a: V3): number => Math.hypot(a[0], a[1], a[2]);
export function normalize(a: V3): V3 {
  const l = length(a);
  return l > 0 ? [a[0] / l, a[1] / l, a[2] / l] : [0, 1, 0];
}
/** a + b * s */
export const addScaled = (a: V3, b: V3, s: number): V3 => [
  a[0] + b[0] * s,
  a[1] + b[1] * s,
  a[2] + b[2] * s,
];

/** Unit direction of latitude/longitude (degrees). */
export function directionFromLatLon(latDeg: number, lonDeg: number): V3 {
  const lat = latDeg * DEG;
  const lon = lonDeg * DEG;
  const c = Math.cos(lat);
  return [c * Math.sin(lon), Math.sin(lat), c * Math.cos(lon)];
}

/** Planet-frame position at `latDeg`, `lonDeg`, `radius` metres from the centre. */
export function positionFromLatLon(latDeg: number, lonDeg: number, radius: number): V3 {
  return scale(directionFromLatLon(latDeg, lonDeg), radius);
}

export interface LatLonRadius {
  lat: number;
  lon: number;
  radius: number;
}

/** Latitude and longitude (degrees, lon in (-180, 180]) and distance from the centre. */
export function latLonFromPosition(p: V3): LatLonRadius {
  const radius = length(p);
  if (radius === 0) return { lat: 0, lon: 0, radius: 0 };
  const lat = Math.atan2(p[1], Math.hypot(p[0], p[2])) / DEG;
  const lon = p[0] === 0 && p[2] === 0 ? 0 : Math.atan2(p[0], p[2]) / DEG;
  return { lat, lon, radius };
}

export interface Enu {
  east: V3;
  north: V3;
  up: V3;
}

/**
 * The local east/north/up frame at a planet-frame point (right-handed: east x north = up).
 * At the poles east follows longitude 0 (east = +X), so the frame never degenerates.
 */
export function enuAt(p: V3): Enu {
  const up = normalize(p);
  const { lon } = latLonFromPosition(p);
  const l = lon * DEG;
  const east: V3 = [Math.cos(l), 0, -Math.sin(l)];
  const north = cross(up, east);
  return { east, north: normalize(north), up };
}

export interface CameraBasis {
  /** Unit view direction. */
  forward: V3;
  /** Unit screen-right direction. */
  right: V3;
  /** Unit screen-up direction (right x up = -forward). */
  up: V3;
}

/**
 * The camera basis at `p` looking along `headingDeg` (clockwise from north, toward east) and
 * `pitchDeg` (above the horizon; -90 looks straight down). The local radial direction is "up":
 * with pitch 0 the screen's up is the radial direction; looking straight down, heading 0 puts
 * north at the top of the screen.
 */
export function cameraBasis(p: V3, headingDeg: number, pitchDeg: number): CameraBasis {
  const { east, north, up } = enuAt(p);
  const h = headingDeg * DEG;
  const pt = pitchDeg * DEG;
  const horiz = add(scale(north, Math.cos(h)), scale(east, Math.sin(h)));
  const forward = normalize(add(scale(horiz, Math.cos(pt)), scale(up, Math.sin(pt))));
  const right = normalize(add(scale(east, Math.cos(h)), scale(north, -Math.sin(h))));
  const camUp = normalize(cross(right, forward));
  return { forward, right, up: camUp };
}

/** Heading and pitch (degrees) of the view direction `forward` in the local frame at `p`. */
export function headingPitchOf(p: V3, forward: V3): { heading: number; pitch: number } {
  const { east, north, up } = enuAt(p);
  const f = normalize(forward);
  const s = Math.max(-1, Math.min(1, dot(f, up)));
  const pitch = Math.asin(s) / DEG;
  let heading = Math.atan2(dot(f, east), dot(f, north)) / DEG;
  if (heading < 0) heading += 360;
  return { heading, pitch };
}

/** Wraps a longitude to (-180, 180]. */
export function wrapLon(lon: number): number {
  let l = ((lon + 180) % 360 + 360) % 360 - 180;
  if (l === -180) l = 180;
  return l;
}

/** Wraps a heading to [0, 360). */
export function wrapHeading(h: number): number {
  return ((h % 360) + 360) % 360;
}

/**
 * Floating origin: the render-space position of a planet-frame point when the camera sits at the
 * render origin. The subtraction happens in f64, before anything is rounded to f32, so a chunk
 * near the camera lands at a small, exactly representable offset even at Earth radius.
 */
export function relativeToCamera(point: V3, camera: V3, out: V3 = [0, 0, 0]): V3 {
  out[0] = point[0] - camera[0];
  out[1] = point[1] - camera[1];
  out[2] = point[2] - camera[2];
  return out;
}

/**
 * Eye-relative positions from high and low f32 parts (as CesiumJS draws its globe): every vertex
 * of a chunk at its planet-frame place `origin + positions + low` (summed in f64: the same sum,
 * in the same order, as the server's), split into `high = f32(p)` and `low = f32(p - high)`.
 * The terrain shader draws `(high - eyeHigh) + (low - eyeLow)` with the eye split the same way
 * (`splitHighLow`), so the copies of a border vertex in two chunks, which the server's low parts
 * bring to the same place far below a micrometre, rasterise identically whatever their chunks'
 * origins: no hairline gap between chunks. `low` null: the positions alone.
 */
export function splitPositions(
  origin: V3,
  positions: Float32Array,
  low: Float32Array | null,
): { high: Float32Array; low: Float32Array } {
  const n = positions.length;
  const high = new Float32Array(n);
  const rest = new Float32Array(n);
  for (let i = 0; i < n; i++) {
    const p = origin[i % 3]! + positions[i]! + (low ? low[i]! : 0);
    const h = Math.fround(p);
    high[i] = h;
    rest[i] = p - h;
  }
  return { high, low: rest };
}

/** A planet-frame point split into high and low f32 parts (see `splitPositions`). */
export function splitHighLow(p: V3): { high: V3; low: V3 } {
  const high: V3 = [Math.fround(p[0]), Math.fround(p[1]), Math.fround(p[2])];
  return { high, low: [Math.fround(p[0] - high[0]), Math.fround(p[1] - high[1]), Math.fround(p[2] - high[2])] };
}

/**
 * `x mod period` in [0, period), computed in f64. The terrain shader takes each chunk origin
 * modulo the period of its noise lattice, so the noise of `origin + position` stays continuous
 * across chunks while every number the GPU sees stays small.
 */
export function modPositive(x: number, period: number): number {
  const r = x % period;
  return r < 0 ? r + period : r;
}

/** Distance from `camera` to the horizon of a sphere of `radius` (0 when inside it). */
export function horizonDistance(cameraRadius: number, radius: number): number {
  return cameraRadius > radius ? Math.sqrt(cameraRadius * cameraRadius - radius * radius) : 0;
}
