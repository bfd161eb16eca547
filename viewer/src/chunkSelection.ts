// Which chunks to request and which to unload, given the camera. Pure: no three.js, no DOM.

import type { V3 } from './frames';

export interface ChunkBounds {
  key: string;
  /** Bounding sphere centre, planet frame, metres (f64). */
  center: V3;
  radius: number;
}

export interface SelectionInput {
  /** Camera position, planet frame, f64. */
  camera: V3;
  /** Load range, metres: chunks whose bounding sphere comes within it are wanted. */
  range: number;
  /** Candidates, e.g. from `/api/v1/chunks` (any order). */
  candidates: readonly ChunkBounds[];
  /** Whether a bounding sphere touches the view frustum. */
  inFrustum: (center: V3, radius: number) => boolean;
  /** Chunks loaded now (with their bounds, to decide unloading). */
  loaded: ReadonlyMap<string, ChunkBounds>;
  /** Keys requested and not answered yet. */
  pending: ReadonlySet<string> | ReadonlyMap<string, ChunkBounds>;
  /** Keys not to request now (e.g. failed recently and waiting for a retry). */
  blocked?: ReadonlySet<string>;
  /** At most this many requests in flight (default 6). */
  maxConcurrent?: number;
  /** Unload beyond `range * unloadFactor` (default 1.25: hysteresis). */
  unloadFactor?: number;
}

export interface Selection {
  /** Keys to request now, most urgent first (at most `maxConcurrent - pending`). */
  request: string[];
  /** Loaded keys beyond the unload distance. */
  unload: string[];
  /** Pending keys beyond the unload distance (requests worth cancelling). */
  cancel: string[];
  /** Wanted chunks neither loaded nor pending (including those requested now). */
  missing: number;
}

export const DEFAULT_MAX_CONCURRENT = 6;
export const DEFAULT_UNLOAD_FACTOR = 1.25;

/** Distance from `p` to the sphere (0 inside it). */
export function sphereDistance(p: V3, center: V3, radius: number): number {
  const d = Math.hypot(center[0] - p[0], center[1] - p[1], center[2] - p[2]);
  return Math.max(0, d - radius);
}

export function selectChunks(input: SelectionInput): Selection {
  const max = input.maxConcurrent ?? DEFAULT_MAX_CONCURRENT;
  const unloadRange = input.range * (input.unloadFactor ?? DEFAULT_UNLOAD_FACTOR);
  const { camera, loaded, pending } = input;

  const wanted: { key: string; distance: number; visible: boolean }[] = [];
  for (const c of input.candidates) {
    if (loaded.has(c.key) || pending.has(c.key)) continue;
    const distance = sphereDistance(camera, c.center, c.radius);
    if (distance > input.range) continue;
    wanted.push({ key: c.key, distance, visible: input.inFrustum(c.center, c.radius) });
  }
  const missing = wanted.length;
  const blocked = input.blocked;
  const free = Math.max(0, max - pending.size);
  const request: string[] = [];
  if (free > 0) {
    wanted.sort(
      (a, b) =>
        Number(b.visible) - Number(a.visible) ||
        a.distance - b.distance ||
        (a.key < b.key ? -1 : a.key > b.key ? 1 : 0),
    );
    for (const w of wanted) {
      if (request.length >= free) break;
      if (blocked?.has(w.key)) continue;
      request.push(w.key);
    }
  }

  const unload: string[] = [];
  for (const [key, c] of loaded) {
    if (sphereDistance(camera, c.center, c.radius) > unloadRange) unload.push(key);
  }
  const cancel: string[] = [];
  if (pending instanceof Map) {
    for (const [key, c] of pending as ReadonlyMap<string, ChunkBounds>) {
      if (sphereDistance(camera, c.center, c.radius) > unloadRange) cancel.push(key);
    }
  }
  return { request, unload, cancel, missing };
}

/**
 * Whether the chunk list must be fetched again: never fetched, or the camera moved more than
 * `fraction` of the range since, or the range changed by more than `fraction` of itself.
 */
export function needsRequery(
  last: { camera: V3; range: number } | null,
  camera: V3,
  range: number,
  fraction = 0.25,
): boolean {
  if (!last) return true;
  const moved = Math.hypot(
    camera[0] - last.camera[0],
    camera[1] - last.camera[1],
    camera[2] - last.camera[2],
  );
  if (moved > fraction * last.range) return true;
  return Math.abs(range - last.range) > fraction * last.range;
}

export interface PlanetExtent {
  /** Lowest radius that can hold surface (or the sea, whichever is higher). */
  innerRadius: number;
  /** Highest radius that can hold surface. */
  outerRadius: number;
}

/**
 * The load range for a camera `cameraRadius` metres from the centre: up to the horizon of the
 * lowest visible surface plus the distance behind it from which the highest terrain can still
 * stick out, at least `minRange`, at most `maxRange`.
 */
export function loadRange(
  cameraRadius: number,
  extent: PlanetExtent,
  minRange: number,
  maxRange = Infinity,
): number {
  const inner = Math.min(extent.innerRadius, extent.outerRadius);
  const r = Math.max(cameraRadius, inner);
  const toHorizon = Math.sqrt(Math.max(0, r * r - inner * inner));
  const beyond = Math.sqrt(Math.max(0, extent.outerRadius ** 2 - inner ** 2));
  return Math.min(maxRange, Math.max(minRange, toHorizon + beyond));
}
