// The numbers of the slim HUD: the scale bar's length and label, the ground's distance at the
// centre of the view, the loading bar's share, the place and height as the HUD prints them.
// Pure: no DOM, no three.js.

import type { V3 } from './frames';

/** A scale bar: its length on screen (CSS pixels) and the distance it stands for. */
export interface ScaleBar {
  px: number;
  metres: number;
  label: string;
}

/**
 * The longest bar of at most `maxPx` pixels that stands for a round distance (1, 2 or 5 times a
 * power of ten metres) at `metresPerPx`; null when the scale is not a positive finite number.
 */
export function scaleBar(metresPerPx: number, maxPx = 110): ScaleBar | null {
  if (!(Number.isFinite(metresPerPx) && metresPerPx > 0 && maxPx > 0)) return null;
  const most = metresPerPx * maxPx;
  const power = 10 ** Math.floor(Math.log10(most));
  let metres = power;
  for (const m of [5, 2, 1]) {
    if (m * power <= most * (1 + 1e-9)) {
      metres = m * power;
      break;
    }
  }
  return { px: metres / metresPerPx, metres, label: formatScale(metres) };
}

/** A round distance as the scale bar prints it: `50 cm`, `200 m`, `5 km`, `1000 km`. */
export function formatScale(metres: number): string {
  if (metres < 1) return `${Math.round(metres * 100)} cm`;
  if (metres < 1000) return `${Math.round(metres)} m`;
  return `${Math.round(metres / 1000).toLocaleString('en-US')} km`;
}

/**
 * Distance along the unit ray `dir` from `origin` to the sphere of `radius` about the planet's
 * centre (the nearer crossing in front), or null when the ray misses it (the sky). An origin
 * inside the sphere (under the ground) gives the crossing on the way out.
 */
export function rayToSphere(origin: V3, dir: V3, radius: number): number | null {
  const b = origin[0] * dir[0] + origin[1] * dir[1] + origin[2] * dir[2];
  const c = origin[0] ** 2 + origin[1] ** 2 + origin[2] ** 2 - radius * radius;
  const disc = b * b - c;
  if (!(disc >= 0)) return null;
  const root = Math.sqrt(disc);
  // the smaller root, written to keep its digits when b and root are close (the camera metres
  // over a planet millions of metres across)
  const near = c > 0 ? (b < 0 ? c / (-b + root) : Number.NEGATIVE_INFINITY) : -b + root;
  return near > 0 && Number.isFinite(near) ? near : null;
}

/**
 * Metres per CSS pixel at the centre of a perspective view `heightPx` pixels tall with vertical
 * field of view `fovDeg`, the ground `distance` metres away along the view's axis.
 */
export function metresPerPixel(distance: number, fovDeg: number, heightPx: number): number {
  return (2 * distance * Math.tan((fovDeg * Math.PI) / 360)) / Math.max(1, heightPx);
}

/**
 * The loading bar's share done, 0..1: the chunks shown among those shown, loading and missing;
 * null when nothing is loading (the bar hides).
 */
export function loadingShare(shown: number, pending: number, missing: number): number | null {
  const left = Math.max(0, pending) + Math.max(0, missing);
  if (left === 0) return null;
  return Math.max(0, shown) / (Math.max(0, shown) + left);
}

/** A latitude as the HUD prints it: `27.9881° N`. */
export function formatLat(lat: number): string {
  return `${Math.abs(lat).toFixed(4)}° ${lat >= 0 ? 'N' : 'S'}`;
}

/** A longitude as the HUD prints it: `86.9250° E`. */
export function formatLon(lon: number): string {
  return `${Math.abs(lon).toFixed(4)}° ${lon >= 0 ? 'E' : 'W'}`;
}
