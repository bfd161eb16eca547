// What to show and what to fetch, given a level-of-detail selection (`lod/select.ts`) and the
// chunks loaded so far. Pure: no three.js, no DOM, no network.
//
// The selection names the chunks wanted now (its drawn leaves, each with its seams mask). Until
// they are all loaded, what is shown must still cover the view: a chunk being refined stays until
// every wanted chunk below it has arrived, a chunk being coarsened is replaced by its parent only
// once the parent is there, and a chunk whose seams changed keeps its old variant until the new one
// arrives. `chooseDisplay` computes that set; the streamer (`chunkStreamer.ts`) keeps the state.

import { sphereDistance, type BoundingSphere } from './lod/bounds';
import { childrenOf, FACES, parentOf, type ChunkKey, type Layout, type Vec3 } from './lod/layout';

/** The API's name of a chunk: `face/level/i/j/k` with the face's name (`top/0/3/4/1`). */
export function chunkName(key: ChunkKey): string {
  return `${FACES[key.face]}/${key.level}/${key.i}/${key.j}/${key.k}`;
}

/** The key a `face/level/i/j/k` name stands for, or null when it is not one. */
export function parseChunkName(name: string): ChunkKey | null {
  const m = /^([a-z]+)\/(\d+)\/(\d+)\/(\d+)\/(\d+)$/.exec(name);
  if (!m) return null;
  const face = (FACES as readonly string[]).indexOf(m[1]!);
  if (face < 0) return null;
  return { face, level: Number(m[2]), i: Number(m[3]), j: Number(m[4]), k: Number(m[5]) };
}

/** One variant of a chunk: its name and the seams mask it was meshed with. */
export const variantId = (name: string, seams: number): string => `${name}~${seams}`;

/** A leaf of the selection, as the streamer keeps it. */
export interface SelectedLeaf {
  key: ChunkKey;
  name: string;
  /** Sides toward a coarser neighbour (the `seams` of the request). */
  seams: number;
  /** In the view (not culled by the frustum or the horizon): wanted. */
  drawn: boolean;
}

/** The names of every chunk strictly above some leaf: the split chunks of the selection. */
export function splitChunks(leaves: Iterable<SelectedLeaf>, maxLevel: number): Set<string> {
  const out = new Set<string>();
  for (const l of leaves) {
    for (let k = l.key; k.level < maxLevel; ) {
      k = parentOf(k);
      const name = chunkName(k);
      if (out.has(name)) break;
      out.add(name);
    }
  }
  return out;
}

export interface DisplayInput {
  layout: Layout;
  /** Every leaf of the selection by name. */
  leaves: ReadonlyMap<string, SelectedLeaf>;
  /** `splitChunks(leaves)`. */
  split: ReadonlySet<string>;
  /** The loaded variants (seams masks) of each loaded chunk. */
  loaded: ReadonlyMap<string, ReadonlySet<number>>;
  /** Whether some chunk strictly below `name` is loaded. */
  loadedBelow(name: string): boolean;
  /** The variant shown now of each chunk shown. */
  shown: ReadonlyMap<string, number>;
  /** Whether a chunk can be in the picture (its sphere in the frustum and above the horizon). */
  visible(key: ChunkKey): boolean;
}

export interface DisplayChoice {
  /** The variant to show of each chunk to show. No two of them overlap. */
  show: Map<string, number>;
  /** Every part of the view that the selection draws is covered. */
  complete: boolean;
  /** `show` is exactly the drawn leaves of the selection, each with its own seams. */
  exact: boolean;
}

interface Part {
  show: [string, number][];
  complete: boolean;
}

const NOTHING_NEEDED: Part = { show: [], complete: true };
const HOLE: Part = { show: [], complete: false };

function join(parts: Part[]): Part {
  return { show: parts.flatMap((p) => p.show), complete: parts.every((p) => p.complete) };
}

/**
 * The chunks to show: each drawn leaf when it is loaded (its wanted variant, else the variant shown
 * now, else another loaded one); where a leaf is missing, the loaded chunks below it that cover it
 * (the finer chunks being coarsened stay), else the nearest loaded chunk above it (the chunk being
 * refined stays until every wanted chunk below it is there). Never two overlapping chunks; a part
 * of the view is left empty only when nothing loaded covers it.
 */
export function chooseDisplay(input: DisplayInput): DisplayChoice {
  const { layout, leaves, split, loaded, shown } = input;
  const maxLevel = layout.maxLevel();

  const variantOf = (name: string, wanted: number | null): number | null => {
    const set = loaded.get(name);
    if (set === undefined || set.size === 0) return null;
    if (wanted !== null && set.has(wanted)) return wanted;
    const now = shown.get(name);
    if (now !== undefined && set.has(now)) return now;
    return Math.min(...set);
  };

  const existing = (key: ChunkKey): ChunkKey[] => childrenOf(key).filter((c) => layout.containsChunk(c));

  // the region of `key`, a chunk below the selection's leaves or one of them, from loaded chunks
  // at or below it: what is shown stays; else the finest complete cover; else `key` itself
  const below = (key: ChunkKey): Part => {
    const parts = existing(key).map((c): Part => {
      const name = chunkName(c);
      const v = variantOf(name, null);
      if (v !== null && shown.has(name)) return { show: [[name, v]], complete: true };
      if (input.loadedBelow(name)) {
        const finer = below(c);
        if (finer.complete || v === null) return finer;
      }
      if (v !== null) return { show: [[name, v]], complete: true };
      return input.visible(c) ? HOLE : NOTHING_NEEDED;
    });
    return join(parts);
  };

  const cover = (key: ChunkKey, name: string): Part => {
    const leaf = leaves.get(name);
    if (leaf !== undefined) {
      if (!leaf.drawn) return NOTHING_NEEDED;
      const v = variantOf(name, leaf.seams);
      if (v !== null) return { show: [[name, v]], complete: true };
      return input.loadedBelow(name) ? below(key) : HOLE;
    }
    if (!split.has(name)) return NOTHING_NEEDED;
    const inner = join(existing(key).map((c) => cover(c, chunkName(c))));
    if (inner.complete) return inner;
    const v = variantOf(name, null);
    return v !== null ? { show: [[name, v]], complete: true } : inner;
  };

  const show = new Map<string, number>();
  let complete = true;
  for (const root of layout.chunks(maxLevel)) {
    const part = cover(root, chunkName(root));
    complete &&= part.complete;
    for (const [name, v] of part.show) show.set(name, v);
  }
  let drawn = 0;
  let exact = true;
  for (const leaf of leaves.values()) {
    if (!leaf.drawn) continue;
    drawn++;
    if (show.get(leaf.name) !== leaf.seams) exact = false;
  }
  if (show.size !== drawn) exact = false;
  return { show, complete, exact };
}

/** The ratio of pixels to metres at unit distance: `h / (2 tan(fov / 2))`. */
export function pixelScale(viewportHeightPx: number, fovY: number): number {
  return viewportHeightPx / (2 * Math.tan(fovY / 2));
}

/** Added to the priority of a chunk whose place shows nothing yet: holes are filled first. */
export const HOLE_PRIORITY = 1e6;

/**
 * The priority of fetching a wanted chunk (larger first, sent to the server as `priority`): the
 * screen-space error in pixels that showing it removes, `errors[L + 1] h / (2 tan(fov / 2) d)` with
 * `d` the distance from the eye to its sphere (the error of its parent's level, the level it
 * replaces; for the coarsest level its own), capped at `HOLE_PRIORITY`, plus `HOLE_PRIORITY` when
 * nothing covers its place yet. Rounded to hundredths.
 */
export function fetchPriority(
  level: number,
  errors: readonly number[],
  sphere: BoundingSphere,
  eye: Vec3,
  scale: number,
  hole: boolean,
): number {
  const e = errors[Math.min(level + 1, errors.length - 1)] ?? 0;
  const d = sphereDistance(sphere, eye);
  const px = d > 0 ? Math.min(HOLE_PRIORITY, (e * scale) / d) : e > 0 ? HOLE_PRIORITY : 0;
  return Math.round(100 * (px + (hole ? HOLE_PRIORITY : 0))) / 100;
}

/** How many of `names` are at each level (index = level), e.g. `[12, 40, 18]`. */
export function levelHistogram(names: Iterable<string>): number[] {
  const out: number[] = [];
  for (const name of names) {
    const level = Number(name.split('/')[1]);
    if (!Number.isInteger(level) || level < 0) continue;
    while (out.length <= level) out.push(0);
    out[level]!++;
  }
  return out;
}

/** The histogram as the stats panel shows it: `L0 12 · L1 40 · L2 18` (empty levels left out). */
export function formatLevels(histogram: readonly number[]): string {
  const parts = histogram.flatMap((n, level) => (n > 0 ? [`L${level} ${n}`] : []));
  return parts.length > 0 ? parts.join(' · ') : '–';
}

export interface PlanetExtent {
  /** Lowest radius that can hold surface (or the sea, whichever is higher). */
  innerRadius: number;
  /** Highest radius that can hold surface. */
  outerRadius: number;
}

/**
 * How far the camera can see terrain from `cameraRadius` metres from the centre: up to the horizon
 * of the lowest visible surface plus the distance behind it from which the highest terrain can
 * still stick out; at least `minRange`, at most `maxRange`. The far clipping plane.
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
