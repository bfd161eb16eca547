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

import { chunkSphere, angleBetween, len, sphereDistance, type BoundingSphere } from './bounds';
import {
  childrenOf,
  compareKeys,
  keyId,
  parentOf,
  type ChunkKey,
  type Layout,
  type Side,
  type Vec3,
} from './layout';

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

/** The offset's side along `axis` (0 u, 1 v, 2 depth), or null for no step. */
function sideOf(axis: number, d: number): Side | null {
  if (d === 0) return null;
  return (2 * axis + (d > 0 ? 1 : 0)) as Side;
}

/** The chunk of `key`'s level at `offset` [du, dv, dk] from it (`pmc_lod::adjacent`). */
export function adjacent(layout: Layout, key: ChunkKey, offset: [number, number, number]): ChunkKey | null {
  if (offset.some((d) => d < -1 || d > 1 || !Number.isInteger(d)) || offset.every((d) => d === 0)) return null;
  if (!layout.containsChunk(key)) return null;
  const level = key.level;
  const su = sideOf(0, offset[0]);
  const sv = sideOf(1, offset[1]);
  let cur: ChunkKey | null = key;
  if (su !== null && sv !== null) {
    const first = layout.neighbour(cur, su, level);
    if (first === null) return null;
    if (first.face === cur.face) {
      cur = layout.neighbour(first, sv, level);
    } else {
      const other = layout.neighbour(cur, sv, level);
      if (other === null || other.face !== cur.face) return null;
      cur = layout.neighbour(other, su, level);
    }
  } else if (su !== null || sv !== null) {
    cur = layout.neighbour(cur, (su ?? sv) as Side, level);
  }
  if (cur === null) return null;
  const sd = sideOf(2, offset[2]);
  if (sd !== null) cur = layout.neighbour(cur, sd, level);
  return cur;
}

/** The 26 offsets in lexicographic order. */
const OFFSETS: [number, number, number][] = [];
for (let a = -1; a <= 1; a++) {
  for (let b = -1; b <= 1; b++) {
    for (let c = -1; c <= 1; c++) if (a !== 0 || b !== 0 || c !== 0) OFFSETS.push([a, b, c]);
  }
}

const existingChildren = (layout: Layout, key: ChunkKey): ChunkKey[] =>
  childrenOf(key).filter((c) => layout.containsChunk(c));

/** The leaves of the octree being balanced. */
class Tree {
  readonly leaves = new Map<string, ChunkKey>();
  private readonly maxLevel: number;

  constructor(
    private readonly layout: Layout,
    roots: ChunkKey[],
    splits: ChunkKey[],
    cap: number,
  ) {
    this.maxLevel = layout.maxLevel();
    for (const r of roots) this.leaves.set(keyId(r), r);
    for (const s of splits) this.split(s);
    // The roots alone are all of one level: balanced already.
    if (splits.length > 0) this.balance(cap);
  }

  split(key: ChunkKey): ChunkKey[] {
    this.leaves.delete(keyId(key));
    const children = existingChildren(this.layout, key);
    for (const c of children) this.leaves.set(keyId(c), c);
    return children;
  }

  covering(cell: ChunkKey): ChunkKey | null {
    let c = cell;
    for (;;) {
      const leaf = this.leaves.get(keyId(c));
      if (leaf !== undefined) return leaf;
      if (c.level >= this.maxLevel) return null;
      c = parentOf(c);
    }
  }

  levelAt(cell: ChunkKey): number {
    const leaf = this.covering(cell);
    return leaf === null ? cell.level - 1 : leaf.level;
  }

  mustSplit(key: ChunkKey, cap: number): boolean {
    if (key.level <= cap) return false;
    const children = childrenOf(key);
    for (let n = 0; n < children.length; n++) {
      const child = children[n];
      if (!this.layout.containsChunk(child)) continue;
      const out = [((n >> 2) & 1) * 2 - 1, ((n >> 1) & 1) * 2 - 1, (n & 1) * 2 - 1];
      const towards = (mask: number): [number, number, number] => [
        mask & 1 ? out[0] : 0,
        mask & 2 ? out[1] : 0,
        mask & 4 ? out[2] : 0,
      ];
      for (let mask = 1; mask < 8; mask++) {
        const cell = adjacent(this.layout, child, towards(mask));
        if (cell !== null && this.covering(cell) === null) return true;
      }
      for (const [p, q] of [
        [1, 2],
        [1, 4],
        [2, 4],
      ]) {
        const bp = adjacent(this.layout, child, towards(p));
        const bq = adjacent(this.layout, child, towards(q));
        const ac = adjacent(this.layout, child, towards(p | q));
        if (bp !== null && bq !== null && ac !== null) {
          if (Math.min(key.level, this.levelAt(ac)) > Math.max(this.levelAt(bp), this.levelAt(bq))) return true;
        }
      }
    }
    return false;
  }

  balance(cap: number): void {
    let candidates = [...this.leaves.values()];
    for (;;) {
      const splits = candidates.filter((k) => this.leaves.has(keyId(k)) && this.mustSplit(k, cap));
      if (splits.length === 0) return;
      const next = new Map<string, ChunkKey>();
      for (const s of splits) for (const c of this.split(s)) next.set(keyId(c), c);
      for (const s of splits) {
        for (const o of OFFSETS) {
          const cell = adjacent(this.layout, s, o);
          const leaf = cell === null ? null : this.covering(cell);
          if (leaf !== null) next.set(keyId(leaf), leaf);
        }
      }
      candidates = [...next.values()];
    }
  }

  coarser(key: ChunkKey): number {
    let mask = 0;
    for (let side = 0; side < 6; side++) {
      const cell = this.layout.neighbour(key, side as Side, key.level);
      if (cell === null) continue;
      const leaf = this.covering(cell);
      if (leaf !== null && leaf.level === key.level + 1) mask |= 1 << side;
    }
    return mask;
  }
}

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

/**
 * The chunks to draw for `view`: `errors[L]` is each level's geometric error in metres, `occluder`
 * the radius of a ball solid at every level (0: no horizon culling). Throws on malformed input.
 */
export function selectLod(
  layout: Layout,
  errors: number[],
  occluder: number,
  view: LodView,
  params: LodParams,
): LodSelection {
  checkInput(layout, errors, occluder, view, params);
  const cap = Math.min(params.finestLevel, layout.maxLevel());
  const spheres = new Map<string, BoundingSphere>();
  const sphere = (k: ChunkKey): BoundingSphere => {
    const id = keyId(k);
    let s = spheres.get(id);
    if (s === undefined) {
      s = chunkSphere(layout, k);
      spheres.set(id, s);
    }
    return s;
  };
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
  // Balance, and the budget by bisection over the prefix of the splits.
  const build = (n: number): Tree => new Tree(layout, roots, splits.slice(0, n), cap);
  let tree = build(splits.length);
  if (tree.leaves.size > params.maxChunks && splits.length > 0) {
    truncated = true;
    let lo = 0;
    let hi = splits.length;
    while (hi - lo > 1) {
      const mid = lo + Math.floor((hi - lo) / 2);
      if (build(mid).leaves.size <= params.maxChunks) lo = mid;
      else hi = mid;
    }
    tree = build(lo);
  }
  const keys = [...tree.leaves.values()].sort(compareKeys);
  const chunks = keys.map((key): SelectedChunk => {
    const s = sphere(key);
    const inView = view.frustum === null || sphereInFrustum(view.frustum, s);
    return { key, coarser: tree.coarser(key), drawn: inView && !sphereBelowHorizon(view.eye, occluder, s) };
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
