// Level-of-detail selection over the chunk octree: the rule of the `pmc-lod` crate (its crate
// docs state it with the formula), implemented the same way so that both select the same chunks
// for the same view; `crates/pmc-lod/tests/data/selection-vectors.json` holds shared cases.
//
// 1. Refine from the roots (every chunk of the coarsest level), nearest chunk first, while
//    errors[L] * h / (2 tan(fov / 2) * d) > maxPixelError, d the distance from the eye to the
//    chunk's bounding sphere, down to finestLevel.
// 2. Split leaves until no leaf touches (across a side, edge or corner, across face edges too) a
//    leaf more than one level finer, and no edge has leaves alternating coarse, fine, coarse, fine.
// 3. Over the budget maxChunks, keep the longest prefix of the splits of step 1 whose balanced
//    tree fits (bisection): the farthest chunks stay coarser.
// 4. Mark leaves outside the frustum or below the horizon as not drawn; give each leaf the sides
//    across which the leaf region is one level coarser.
//
// Computed as the crate computes it: bounding spheres from one cap per chunk column, kept between
// calls; the octree, its balance in rounds and the leaf test in `tree.ts`.

import {
  angleBetween,
  capSphere,
  columnCap,
  layerRange,
  len,
  sphereDistance,
  type BoundingSphere,
  type Cap,
} from './bounds';
import { childrenOf, compareKeys, keyId, type ChunkKey, type Layout, type Vec3 } from './layout';
import { Tree } from './tree';

export { adjacent } from './tree';

/** A frustum plane `[nx, ny, nz, d]`: inside where `n . p + d >= 0`. */
export type Plane = [number, number, number, number];

/** Where the camera is and how it projects. */
export interface LodView {
  /** The eye, planet-centred, in metres. */
  eye: Vec3;
  /** Six planes, or null to draw everything above the horizon. */
  frustum: Plane[] | null;
  /** The viewport's height in pixels. */
  viewportHeightPx: number;
  /** The vertical field of view in radians, in (0, pi). */
  fovY: number;
}

/** How fine the selection may get. */
export interface LodParams {
  /** The largest screen-space error in pixels (2 by default in the Rust crate). */
  maxPixelError: number;
  /** The finest level the selection may reach. */
  finestLevel: number;
  /** The most chunks the selection may hold (the roots are always selected). */
  maxChunks: number;
}

/** One selected chunk. */
export interface SelectedChunk {
  key: ChunkKey;
  /** Bit n set when the leaf region across side n (u_min, u_max, v_min, v_max, inner, outer) is one level coarser. */
  coarser: number;
  /** False when the chunk's sphere is outside the frustum or below the horizon. */
  drawn: boolean;
}

/** The selected leaves, in key order. */
export interface LodSelection {
  chunks: SelectedChunk[];
  /** Whether the budget cut refinement. */
  truncated: boolean;
}

const MARGIN = 1e-9;
const dot = (a: Vec3, b: Vec3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/** Whether some point of the sphere may lie inside the frustum (`pmc_lod::sphere_in_frustum`). */
export function sphereInFrustum(planes: Plane[], s: BoundingSphere): boolean {
  return planes.every((p) => {
    const n: Vec3 = [p[0], p[1], p[2]];
    const l = len(n);
    const nc = dot(n, s.center);
    const v = nc + p[3];
    const slack = MARGIN * (Math.abs(nc) + Math.abs(p[3]) + s.radius * l);
    return v >= -s.radius * l - slack;
  });
}

/** Whether the whole sphere is hidden by a solid ball of radius `occluder` (`pmc_lod::sphere_below_horizon`). */
export function sphereBelowHorizon(eye: Vec3, occluder: number, s: BoundingSphere): boolean {
  const e = len(eye);
  if (!(occluder > 0 && Number.isFinite(occluder) && Number.isFinite(e) && e > occluder)) return false;
  const axis: Vec3 = [eye[0] / e, eye[1] / e, eye[2] / e];
  const plane = (occluder * occluder) / e;
  if (dot(s.center, axis) + s.radius >= plane - MARGIN * e) return false;
  const to: Vec3 = [s.center[0] - eye[0], s.center[1] - eye[1], s.center[2] - eye[2]];
  const d = len(to);
  if (Number.isNaN(d) || d <= s.radius * (1.0 + MARGIN)) return false;
  const alpha = Math.asin(occluder / e);
  const fromAxis = angleBetween([to[0] / d, to[1] / d, to[2] / d], [-axis[0], -axis[1], -axis[2]]);
  const spread = fromAxis + Math.asin(Math.min(s.radius / d, 1.0));
  return spread < alpha * (1.0 - MARGIN) - MARGIN;
}

const existingChildren = (layout: Layout, key: ChunkKey): ChunkKey[] =>
  childrenOf(key).filter((c) => layout.containsChunk(c));

/** A min-heap of refinement candidates: nearest first, ties by key. */
class CandidateHeap {
  private readonly items: { distance: number; key: ChunkKey }[] = [];

  private less(a: number, b: number): boolean {
    const x = this.items[a];
    const y = this.items[b];
    return x.distance < y.distance || (x.distance === y.distance && compareKeys(x.key, y.key) < 0);
  }

  private swap(a: number, b: number): void {
    const t = this.items[a];
    this.items[a] = this.items[b];
    this.items[b] = t;
  }

  push(distance: number, key: ChunkKey): void {
    this.items.push({ distance, key });
    let n = this.items.length - 1;
    while (n > 0) {
      const p = (n - 1) >> 1;
      if (!this.less(n, p)) break;
      this.swap(n, p);
      n = p;
    }
  }

  pop(): { distance: number; key: ChunkKey } | undefined {
    const top = this.items[0];
    const last = this.items.pop();
    if (top === undefined || last === undefined) return undefined;
    if (this.items.length > 0) {
      this.items[0] = last;
      let n = 0;
      for (;;) {
        const l = 2 * n + 1;
        const r = l + 1;
        let m = n;
        if (l < this.items.length && this.less(l, m)) m = l;
        if (r < this.items.length && this.less(r, m)) m = r;
        if (m === n) break;
        this.swap(n, m);
        n = m;
      }
    }
    return top;
  }
}

function checkInput(layout: Layout, errors: number[], occluder: number, view: LodView, params: LodParams): void {
  if (errors.length !== layout.maxLevel() + 1) {
    throw new Error(`the error table needs ${layout.maxLevel() + 1} entries`);
  }
  if (errors.some((e) => !(Number.isFinite(e) && e >= 0))) {
    throw new Error('level errors must be finite and at least 0');
  }
  if (!(Number.isFinite(occluder) && occluder >= 0)) {
    throw new Error('the occluder radius must be finite and at least 0');
  }
  if (!view.eye.every(Number.isFinite)) throw new Error('the eye must be a finite point');
  if (!(Number.isFinite(view.viewportHeightPx) && view.viewportHeightPx > 0)) throw new Error('bad viewport height');
  if (!(Number.isFinite(view.fovY) && view.fovY > 0 && view.fovY < Math.PI)) throw new Error('bad field of view');
  if (view.frustum !== null) {
    if (view.frustum.length !== 6) throw new Error('a frustum has six planes');
    for (const p of view.frustum) {
      if (!p.every(Number.isFinite) || p[0] * p[0] + p[1] * p[1] + p[2] * p[2] === 0) {
        throw new Error('bad frustum plane');
      }
    }
  }
  if (!(Number.isFinite(params.maxPixelError) && params.maxPixelError > 0)) throw new Error('bad pixel error bound');
}

/** The most spheres a {@link SphereCache} keeps: a few selections' worth. */
const MAX_CACHED_SPHERES = 200_000;

/**
 * The bounding spheres of one layout's chunks, computed once: each from the cap of its column
 * (shared by the chunks of the column, and the costly part), kept by face and level under a
 * number naming the column or the chunk (a string where the layout's numbers would pass 2^53).
 */
class SphereCache {
  private readonly caps = new Map<number, Map<number | string, Cap>>();
  private readonly spheres = new Map<number, Map<number | string, BoundingSphere>>();
  private count = 0;
  private readonly exact: boolean;

  constructor(private readonly layout: Layout) {
    const side = layout.chunksPerSide(0);
    this.exact = side * side * layout.depthChunks(0) <= Number.MAX_SAFE_INTEGER;
  }

  /** Whether this cache holds spheres of `layout`'s chunks. */
  serves(layout: Layout): boolean {
    const l = this.layout;
    const same = l.n_c === layout.n_c && l.n_t === layout.n_t && l.d_c === layout.d_c;
    return l === layout || (same && l.d_b === layout.d_b && l.l_d === layout.l_d);
  }

  /** The bounding sphere of chunk `k` (`chunkSphere`). */
  sphere(k: ChunkKey): BoundingSphere {
    const group = k.face * 32 + k.level;
    const side = this.layout.chunksPerSide(k.level);
    const column = k.i * side + k.j;
    const id = this.exact ? column * this.layout.depthChunks(k.level) + k.k : `${k.i}/${k.j}/${k.k}`;
    let spheres = this.spheres.get(group);
    if (spheres === undefined) {
      spheres = new Map();
      this.spheres.set(group, spheres);
    }
    let s = spheres.get(id);
    if (s !== undefined) return s;
    if (this.count >= MAX_CACHED_SPHERES) {
      this.caps.clear();
      this.spheres.clear();
      this.count = 0;
      spheres = new Map();
      this.spheres.set(group, spheres);
    }
    let caps = this.caps.get(group);
    if (caps === undefined) {
      caps = new Map();
      this.caps.set(group, caps);
    }
    let c = caps.get(column);
    if (c === undefined) {
      c = columnCap(this.layout, k.face, k.level, k.i, k.j);
      caps.set(column, c);
    }
    const [r0, r1] = layerRange(this.layout, k.level, k.k);
    s = capSphere(c, r0, r1);
    spheres.set(id, s);
    this.count++;
    return s;
  }
}

/** The sphere caches, by the map the caller keeps between calls (see {@link selectLod}). */
const sphereCaches = new WeakMap<Map<string, BoundingSphere>, SphereCache>();

/**
 * The chunks to draw for `view`: `errors[L]` is each level's geometric error in metres, `occluder`
 * the radius of a ball solid at every level (0: no horizon culling). Passing the same `spheres`
 * map from one call to the next for the same layout keeps the chunks' bounding spheres between
 * them (in a bounded cache that the map names); the map receives each selected chunk's sphere
 * by `keyId`. Throws on malformed input.
 */
export function selectLod(
  layout: Layout,
  errors: number[],
  occluder: number,
  view: LodView,
  params: LodParams,
  spheres: Map<string, BoundingSphere> = new Map(),
): LodSelection {
  checkInput(layout, errors, occluder, view, params);
  const cap = Math.min(params.finestLevel, layout.maxLevel());
  let cache = sphereCaches.get(spheres);
  if (cache === undefined || !cache.serves(layout)) {
    cache = new SphereCache(layout);
    sphereCaches.set(spheres, cache);
  }
  const sphere = cache.sphere.bind(cache);
  // Refinement, nearest first.
  const roots = layout.chunks(layout.maxLevel());
  const splits: ChunkKey[] = [];
  let truncated = false;
  if (roots.length > params.maxChunks) {
    truncated = true;
  } else {
    const scale = view.viewportHeightPx / (2.0 * Math.tan(0.5 * view.fovY));
    const heap = new CandidateHeap();
    for (const r of roots) heap.push(sphereDistance(sphere(r), view.eye), r);
    let count = roots.length;
    for (let c = heap.pop(); c !== undefined; c = heap.pop()) {
      if (c.key.level <= cap) continue;
      if (!(errors[c.key.level] * scale > params.maxPixelError * c.distance)) continue;
      const children = existingChildren(layout, c.key);
      if (count - 1 + children.length > params.maxChunks) {
        truncated = true;
        break;
      }
      count += children.length - 1;
      splits.push(c.key);
      for (const k of children) heap.push(sphereDistance(sphere(k), view.eye), k);
    }
  }
  // Balance, and the budget by bisection over the prefix of the splits; balancing may stop as
  // soon as the tree holds more than the budget, when only its size matters.
  const budget = params.maxChunks;
  let tree = new Tree(layout);
  tree.build(roots, splits, cap, budget);
  if (tree.leaves > budget && splits.length > 0) {
    truncated = true;
    // the tree of the best prefix so far is kept
    let best = new Tree(layout);
    best.build(roots, [], cap, Infinity);
    let lo = 0;
    let hi = splits.length;
    while (hi - lo > 1) {
      const mid = lo + Math.floor((hi - lo) / 2);
      tree.build(roots, splits.slice(0, mid), cap, budget);
      if (tree.leaves <= budget) {
        lo = mid;
        [tree, best] = [best, tree];
      } else {
        hi = mid;
      }
    }
    tree = best;
  }
  const chunks = tree.leafNodes().map(({ key, node }): SelectedChunk => {
    const s = sphere(key);
    spheres.set(keyId(key), s);
    const inView = view.frustum === null || sphereInFrustum(view.frustum, s);
    return { key, coarser: tree.coarser(node), drawn: inView && !sphereBelowHorizon(view.eye, occluder, s) };
  });
  return { chunks, truncated };
}

/** How many chunks were selected at each level (index = level). */
export function levelHistogram(selection: LodSelection): number[] {
  const out: number[] = [];
  for (const c of selection.chunks) {
    while (out.length <= c.key.level) out.push(0);
    out[c.key.level]++;
  }
  return out;
}
