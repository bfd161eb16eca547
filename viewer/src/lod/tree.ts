// The chunk octree of one selection and its balance, as `pmc_lod`'s `tree` module builds them (its
// module docs explain the structure and why the candidates tested suffice): an arena of nodes in
// typed arrays, each a leaf or split into eight consecutive child slots (a slot past the shell's
// depth holds no chunk); the chunks of a node's level around it on the same face found from its
// parent's, which split nodes remember; steps across face edges and cube corners through
// `adjacent` and a walk down from the root. Leaves are split in rounds: every leaf that must split
// is tested against the tree as it stands, then all of them are split, so the result is the same
// whatever order the candidates are tested in.

import { keyId, type ChunkKey, type Layout, type Side } from './layout';

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

/** The 27 offsets of a 3 x 3 x 3 block, index (du + 1) 9 + (dv + 1) 3 + dk + 1; 13 is the centre. */
const BLOCK: [number, number, number][] = [];
for (let n = 0; n < 27; n++) BLOCK.push([Math.floor(n / 9) - 1, (Math.floor(n / 3) % 3) - 1, (n % 3) - 1]);
const CENTRE = 13;
const blockIndex = (o: readonly number[]): number => (o[0] + 1) * 9 + (o[1] + 1) * 3 + o[2] + 1;

/**
 * For a chunk in child slot h and the chunk at BLOCK[at] from it, at 27 h + at: the latter's
 * parent, as a BLOCK index from the former's parent.
 */
const UP = new Int32Array(8 * 27);
/** ... and its child slot in that parent. */
const SLOT = new Int32Array(8 * 27);
/** For the chunk at BLOCK[at] from a leaf, the mask of its child slots touching the leaf. */
const TOUCH = new Int32Array(27);
/**
 * For child slot n of a leaf and its edges (u, v), (u, depth), (v, depth), at 9 n + 3 e: the BLOCK
 * indices of the chunks beside the child along each axis and across both.
 */
const EDGES = new Int32Array(8 * 9);
/** For child slot h: the BLOCK indices of the parent and the 7 chunks beside it towards the child. */
const OCTANT = new Int32Array(8 * 8);
for (let h = 0; h < 8; h++) {
  const half = [(h >> 2) & 1, (h >> 1) & 1, h & 1];
  for (let at = 0; at < 27; at++) {
    const up = [0, 0, 0];
    let slot = 0;
    for (let a = 0; a < 3; a++) {
      const t = half[a] + BLOCK[at][a];
      up[a] = Math.floor((t + 2) / 2) - 1;
      slot |= ((t + 2) & 1) << (2 - a);
    }
    UP[27 * h + at] = blockIndex(up);
    SLOT[27 * h + at] = slot;
  }
  const out = half.map((x) => 2 * x - 1);
  const pairs = [
    [0, 1],
    [0, 2],
    [1, 2],
  ];
  for (let e = 0; e < 3; e++) {
    const [a, b] = pairs[e];
    const oa = [0, 0, 0];
    oa[a] = out[a];
    const ob = [0, 0, 0];
    ob[b] = out[b];
    const oab = [0, 0, 0];
    oab[a] = out[a];
    oab[b] = out[b];
    EDGES[9 * h + 3 * e] = blockIndex(oa);
    EDGES[9 * h + 3 * e + 1] = blockIndex(ob);
    EDGES[9 * h + 3 * e + 2] = blockIndex(oab);
  }
  for (let o = 0; o < 8; o++) {
    OCTANT[8 * h + o] = blockIndex([(o >> 2) & 1 ? out[0] : 0, (o >> 1) & 1 ? out[1] : 0, o & 1 ? out[2] : 0]);
  }
}
for (let at = 0; at < 27; at++) {
  let mask = 0;
  for (let slot = 0; slot < 8; slot++) {
    const half = [(slot >> 2) & 1, (slot >> 1) & 1, slot & 1];
    let touches = true;
    for (let a = 0; a < 3; a++) {
      const o = BLOCK[at][a];
      if ((o === 1 && half[a] !== 0) || (o === -1 && half[a] !== 1)) touches = false;
    }
    if (touches) mask |= 1 << slot;
  }
  TOUCH[at] = mask;
}
/** The BLOCK index of each side's neighbour, in side order (u_min, u_max, v_min, v_max, inner, outer). */
const SIDE_AT = [
  blockIndex([-1, 0, 0]),
  blockIndex([1, 0, 0]),
  blockIndex([0, -1, 0]),
  blockIndex([0, 1, 0]),
  blockIndex([0, 0, -1]),
  blockIndex([0, 0, 1]),
];

/** No node: a leaf's children, a chunk that does not exist. */
const NONE = -1;
/** A remembered neighbour not looked up yet. */
const UNKNOWN = -2;

/** The leaves and split chunks of the octree of one selection. */
export class Tree {
  private readonly maxLevel: number;
  private readonly perSide: number[] = [];
  private readonly depth: number[] = [];
  // the nodes, field by field: key, parent, first child slot (NONE for a leaf), start of the
  // remembered neighbours (NONE before needed), last round listed, split child slots (bits),
  // whether the slot holds a chunk, whether its level's neighbours all lie on its face
  private cap = 0;
  private count = 0;
  private face: Int32Array = new Int32Array(0);
  private lvl: Int32Array = new Int32Array(0);
  private ci: Int32Array = new Int32Array(0);
  private cj: Int32Array = new Int32Array(0);
  private ck: Int32Array = new Int32Array(0);
  private parent: Int32Array = new Int32Array(0);
  private children: Int32Array = new Int32Array(0);
  private aroundAt: Int32Array = new Int32Array(0);
  private listed: Int32Array = new Int32Array(0);
  private splitChildren: Uint8Array = new Uint8Array(0);
  private exists: Uint8Array = new Uint8Array(0);
  private interior: Uint8Array = new Uint8Array(0);
  private around: Int32Array = new Int32Array(0);
  private aroundCount = 0;
  private leafCount = 0;
  private round = 0;
  private readonly holders = new Int32Array(27);
  private readonly beside = new Int32Array(27);
  private readonly split = new Uint8Array(27);
  private readonly aroundExists = new Uint8Array(27);
  private readonly holdExists = new Uint8Array(27);
  private readonly holdChildren = new Int32Array(27);
  private readonly holdSplit = new Uint8Array(27);
  /**
   * The steps that left a face, by level, then by chunk (a number naming it, or its `keyId` where
   * the layout's numbers would pass 2^53), then by BLOCK index: the chunk reached, or null.
   */
  private readonly offFace: Map<number | string, (ChunkKey | null | undefined)[]>[] = [];
  private readonly exactIds: boolean;

  constructor(private readonly layout: Layout) {
    this.maxLevel = layout.maxLevel();
    for (let l = 0; l <= this.maxLevel; l++) {
      this.perSide.push(layout.chunksPerSide(l));
      this.depth.push(layout.depthChunks(l));
    }
    this.exactIds = 6 * this.perSide[0] * this.perSide[0] * this.depth[0] <= Number.MAX_SAFE_INTEGER;
  }

  /**
   * Makes this the tree of `roots` (every chunk of the coarsest level, in key order) with `splits`
   * applied in order, then balanced; balancing stops once there are more than `limit` leaves
   * (the tree is then only good for its leaf count).
   */
  build(roots: ChunkKey[], splits: ChunkKey[], cap: number, limit: number): void {
    this.count = 0;
    this.aroundCount = 0;
    this.round = 0;
    for (const r of roots) this.push(r.face, r.level, r.i, r.j, r.k, NONE, true);
    this.leafCount = roots.length;
    for (const s of splits) this.splitNode(this.find(s.face, s.level, s.i, s.j, s.k));
    // The roots alone are all of one level: balanced already.
    if (splits.length > 0) this.balance(cap, limit);
  }

  /** How many leaves the tree holds. */
  get leaves(): number {
    return this.leafCount;
  }

  /** The leaves in key order, each with its node. */
  leafNodes(): { key: ChunkKey; node: number }[] {
    const out: { key: ChunkKey; node: number }[] = [];
    for (let n = 0; n < this.count; n++) {
      if (this.exists[n] === 1 && this.children[n] === NONE) out.push({ key: this.key(n), node: n });
    }
    out.sort(
      (a, b) =>
        this.face[a.node] - this.face[b.node] ||
        this.lvl[a.node] - this.lvl[b.node] ||
        this.ci[a.node] - this.ci[b.node] ||
        this.cj[a.node] - this.cj[b.node] ||
        this.ck[a.node] - this.ck[b.node],
    );
    return out;
  }

  private key(n: number): ChunkKey {
    return { face: this.face[n], level: this.lvl[n], i: this.ci[n], j: this.cj[n], k: this.ck[n] };
  }

  private grow(): void {
    const cap = Math.max(64, 2 * this.cap);
    const i32 = (a: Int32Array): Int32Array => {
      const b = new Int32Array(cap);
      b.set(a);
      return b;
    };
    const u8 = (a: Uint8Array): Uint8Array => {
      const b = new Uint8Array(cap);
      b.set(a);
      return b;
    };
    this.face = i32(this.face);
    this.lvl = i32(this.lvl);
    this.ci = i32(this.ci);
    this.cj = i32(this.cj);
    this.ck = i32(this.ck);
    this.parent = i32(this.parent);
    this.children = i32(this.children);
    this.aroundAt = i32(this.aroundAt);
    this.listed = i32(this.listed);
    this.splitChildren = u8(this.splitChildren);
    this.exists = u8(this.exists);
    this.interior = u8(this.interior);
    this.cap = cap;
  }

  private push(face: number, level: number, i: number, j: number, k: number, parent: number, exists: boolean): void {
    if (this.count === this.cap) this.grow();
    const n = this.count++;
    this.face[n] = face;
    this.lvl[n] = level;
    this.ci[n] = i;
    this.cj[n] = j;
    this.ck[n] = k;
    this.parent[n] = parent;
    this.children[n] = NONE;
    this.aroundAt[n] = NONE;
    this.listed[n] = 0;
    this.splitChildren[n] = 0;
    this.exists[n] = exists ? 1 : 0;
    const side = this.perSide[level];
    this.interior[n] = i >= 1 && i + 1 < side && j >= 1 && j + 1 < side ? 1 : 0;
  }

  /** Node `n`'s child slot in its parent: which half of it it holds along u, v and depth. */
  private slotOf(n: number): number {
    return ((this.ci[n] & 1) << 2) | ((this.cj[n] & 1) << 1) | (this.ck[n] & 1);
  }

  /** Splits the leaf `n`: its children that are chunks of the layout become leaves. */
  private splitNode(n: number): void {
    const level = this.lvl[n];
    if (level === 0) return;
    const first = this.count;
    this.children[n] = first;
    const p = this.parent[n];
    if (p !== NONE) this.splitChildren[p] |= 1 << this.slotOf(n);
    this.leafCount -= 1;
    const depth = this.depth[level - 1];
    for (let c = 0; c < 8; c++) {
      const k = 2 * this.ck[n] + (c & 1);
      const exists = k < depth;
      const i = 2 * this.ci[n] + ((c >> 2) & 1);
      const j = 2 * this.cj[n] + ((c >> 1) & 1);
      this.push(this.face[n], level - 1, i, j, k, n, exists);
      if (exists) this.leafCount += 1;
    }
  }

  /** From node `n`, which holds the target chunk, down to the deepest node holding it. */
  private descend(n: number, level: number, i: number, j: number, k: number): number {
    for (;;) {
      const l = this.lvl[n];
      if (this.children[n] === NONE || l <= level) return n;
      const s = l - 1 - level;
      n = this.children[n] + ((((i >> s) & 1) << 2) | (((j >> s) & 1) << 1) | ((k >> s) & 1));
    }
  }

  /** The deepest node holding the chunk (a chunk of the layout). */
  private find(face: number, level: number, i: number, j: number, k: number): number {
    const up = this.maxLevel - level;
    const n = this.perSide[this.maxLevel];
    const d = this.depth[this.maxLevel];
    const root = ((face * n + (i >> up)) * n + (j >> up)) * d + (k >> up);
    return this.descend(root, level, i, j, k);
  }

  private findKey(c: ChunkKey): number {
    return this.find(c.face, c.level, c.i, c.j, c.k);
  }

  /** Whether the chunk at BLOCK[at] from node `n` lies past the shell's depth. */
  private pastDepth(n: number, at: number): boolean {
    const k = this.ck[n] + BLOCK[at][2];
    return k < 0 || k >= this.depth[this.lvl[n]];
  }

  /** Whether the chunk at BLOCK[at] from node `n` lies on its face and within the depth. */
  private onFace(n: number, at: number): boolean {
    const side = this.perSide[this.lvl[n]];
    const i = this.ci[n] + BLOCK[at][0];
    const j = this.cj[n] + BLOCK[at][1];
    return i >= 0 && i < side && j >= 0 && j < side && !this.pastDepth(n, at);
  }

  /**
   * The deepest node holding the chunk at BLOCK[at] from node `n` on the same face, NONE when
   * there is no such chunk or it lies past the face's border; remembered.
   */
  private aroundOf(n: number, at: number): number {
    let base = this.aroundAt[n];
    if (base !== NONE) {
      const known = this.around[base + at];
      if (known === NONE) return NONE;
      if (known !== UNKNOWN && (this.children[known] === NONE || this.lvl[known] === this.lvl[n])) return known;
    } else {
      base = this.aroundCount;
      this.aroundCount += 27;
      if (this.aroundCount > this.around.length) {
        const bigger = new Int32Array(Math.max(27 * 64, 2 * this.around.length));
        bigger.set(this.around);
        this.around = bigger;
      }
      this.around.fill(UNKNOWN, base, base + 27);
      this.aroundAt[n] = base;
    }
    const known = this.around[base + at];
    const o = BLOCK[at];
    let found: number;
    if (known !== UNKNOWN) {
      // a coarser leaf when last looked up, split since
      found = this.descend(known, this.lvl[n], this.ci[n] + o[0], this.cj[n] + o[1], this.ck[n] + o[2]);
    } else if (this.parent[n] === NONE || this.interior[n] === 0) {
      if (!this.onFace(n, at)) found = NONE;
      else if (this.parent[n] === NONE)
        found = this.find(this.face[n], this.lvl[n], this.ci[n] + o[0], this.cj[n] + o[1], this.ck[n] + o[2]);
      else found = this.fromParent(n, at);
    } else {
      found = this.fromParent(n, at);
    }
    this.around[base + at] = found;
    return found;
  }

  /** `aroundOf` node `n` (not a root, the chunk on the face) from what lies around its parent. */
  private fromParent(n: number, at: number): number {
    if (this.pastDepth(n, at)) return NONE;
    const h = this.slotOf(n);
    const up = UP[27 * h + at];
    const holder = up === CENTRE ? this.parent[n] : this.aroundOf(this.parent[n], up);
    if (holder === NONE) return NONE;
    const c = this.children[holder];
    return c === NONE ? holder : c + SLOT[27 * h + at];
  }

  /**
   * The deepest nodes holding the 26 chunks around node `n` (away from the face's border, not a
   * root), into `this.beside`.
   */
  private neighbours(n: number): Int32Array {
    const h = this.slotOf(n);
    const p = this.parent[n];
    const holders = this.holders;
    for (let o = 0; o < 8; o++) {
      const at = OCTANT[8 * h + o];
      holders[at] = at === CENTRE ? p : this.aroundOf(p, at);
    }
    const below = this.ck[n] > 0;
    const above = this.ck[n] + 1 < this.depth[this.lvl[n]];
    const out = this.beside;
    for (let at = 0; at < 27; at++) {
      out[at] = NONE;
      const dk = (at % 3) - 1;
      if (at === CENTRE || (dk < 0 && !below) || (dk > 0 && !above)) continue;
      const holder = holders[UP[27 * h + at]];
      if (holder !== NONE) {
        const c = this.children[holder];
        out[at] = c === NONE ? holder : c + SLOT[27 * h + at];
      }
    }
    return out;
  }

  /**
   * The deepest node holding the chunk of `key`'s level at offset (du, dv, dk) from it, across face
   * edges too (`adjacent`, by index arithmetic when the step stays on the face); NONE when there
   * is no such chunk.
   */
  private stepFind(key: ChunkKey, du: number, dv: number, dk: number): number {
    const side = this.perSide[key.level];
    const i = key.i + du;
    const j = key.j + dv;
    if (i >= 0 && i < side && j >= 0 && j < side) {
      const k = key.k + dk;
      if (k < 0 || k >= this.depth[key.level]) return NONE;
      return this.find(key.face, key.level, i, j, k);
    }
    // steps that leave the face depend on the layout alone: remembered, by level and chunk
    const depth = this.depth[key.level];
    const id = this.exactIds ? ((key.face * side + key.i) * side + key.j) * depth + key.k : keyId(key);
    const byChunk = (this.offFace[key.level] ??= new Map());
    let row = byChunk.get(id);
    if (row === undefined) {
      row = new Array<ChunkKey | null | undefined>(27).fill(undefined);
      byChunk.set(id, row);
    }
    const at = (du + 1) * 9 + (dv + 1) * 3 + dk + 1;
    let c = row[at];
    if (c === undefined) {
      c = adjacent(this.layout, key, [du, dv, dk]);
      row[at] = c;
    }
    return c === null ? NONE : this.findKey(c);
  }

  /** The deepest nodes holding the 26 chunks around node `n`, across face edges too, into `this.beside`. */
  private besideOf(n: number): Int32Array {
    if (this.interior[n] === 1 && this.parent[n] !== NONE) return this.neighbours(n);
    const out = this.beside;
    const key = this.key(n);
    for (let at = 0; at < 27; at++) {
      out[at] = at === CENTRE ? NONE : this.stepFind(key, BLOCK[at][0], BLOCK[at][1], BLOCK[at][2]);
    }
    return out;
  }

  /** Whether the leaf `n` must split (`pmc_lod`'s rule; see the module header). */
  private mustSplit(n: number, cap: number): boolean {
    const level = this.lvl[n];
    if (level <= cap || level === 0) return false;
    if (this.interior[n] === 0 || this.parent[n] === NONE) return this.mustSplitAnywhere(n);
    // what holds the chunks' parents: the leaf's parent and the 7 chunks beside it towards the
    // leaf; for each, whether it exists, its first child slot and, when split, its split children
    const h = this.slotOf(n);
    const p = this.parent[n];
    const there = this.holdExists;
    const firsts = this.holdChildren;
    const splits = this.holdSplit;
    for (let o = 0; o < 8; o++) {
      const at = OCTANT[8 * h + o];
      const q = at === CENTRE ? p : this.aroundOf(p, at);
      there[at] = q === NONE ? 0 : 1;
      firsts[at] = q === NONE ? NONE : this.children[q];
      splits[at] = q === NONE || this.children[q] === NONE ? 0 : this.splitChildren[q];
    }
    const below = this.ck[n] > 0;
    const above = this.ck[n] + 1 < this.depth[level];
    // the chunks around the leaf that exist, and those that are split
    const exists = this.aroundExists;
    const split = this.split;
    let any = false;
    for (let at = 0; at < 27; at++) {
      exists[at] = 0;
      split[at] = 0;
      const dk = (at % 3) - 1;
      if (at === CENTRE || (dk < 0 && !below) || (dk > 0 && !above)) continue;
      const up = UP[27 * h + at];
      const slot = SLOT[27 * h + at];
      exists[at] = there[up];
      if (((splits[up] >> slot) & 1) === 1) {
        // a split chunk of this level: a split child touching the leaf is a split cell
        if ((this.splitChildren[firsts[up] + slot] & TOUCH[at]) !== 0) return true;
        split[at] = 1;
        any = true;
      }
    }
    if (!any) return false;
    const upper = 2 * this.ck[n] + 1 < this.depth[level - 1];
    for (let c = 0; c < 8; c++) {
      if ((c & 1) === 1 && !upper) continue;
      for (let e = 0; e < 3; e++) {
        const a = EDGES[9 * c + 3 * e];
        const b = EDGES[9 * c + 3 * e + 1];
        const across = EDGES[9 * c + 3 * e + 2];
        if (split[a] === 1 && split[b] === 1 && exists[across] === 1 && split[across] === 0) return true;
      }
    }
    return false;
  }

  /** The leaf test for any leaf (on a face's border too), cell by cell. */
  private mustSplitAnywhere(n: number): boolean {
    const level = this.lvl[n];
    const key = this.key(n);
    // the level of the leaf covering a cell, or null when the cell is split or missing
    const cells: (number | null)[] = new Array<number | null>(8).fill(null);
    for (let c = 0; c < 8; c++) {
      const child: ChunkKey = {
        face: key.face,
        level: level - 1,
        i: 2 * key.i + ((c >> 2) & 1),
        j: 2 * key.j + ((c >> 1) & 1),
        k: 2 * key.k + (c & 1),
      };
      if (!this.layout.containsChunk(child)) continue;
      const out = [((c >> 2) & 1) * 2 - 1, ((c >> 1) & 1) * 2 - 1, (c & 1) * 2 - 1];
      for (let mask = 1; mask < 8; mask++) {
        cells[mask] = null;
        const f = this.stepFind(child, mask & 1 ? out[0] : 0, mask & 2 ? out[1] : 0, mask & 4 ? out[2] : 0);
        if (f === NONE) continue;
        // the cells of level L-1 around the child outside this chunk must not be split
        if (this.children[f] !== NONE) return true;
        cells[mask] = this.lvl[f];
      }
      for (const [p, q] of [
        [1, 2],
        [1, 4],
        [2, 4],
      ]) {
        const bp = cells[p];
        const bq = cells[q];
        const ac = cells[p | q];
        if (bp !== null && bq !== null && ac !== null && Math.min(level, ac) > Math.max(bp, bq)) return true;
      }
    }
    return false;
  }

  private list(n: number, out: number[]): void {
    if (this.listed[n] !== this.round) {
      this.listed[n] = this.round;
      out.push(n);
    }
  }

  /** The leaves the first balance round must test: the leaves around split chunks of their level. */
  private firstCandidates(): number[] {
    const out: number[] = [];
    const total = this.count;
    for (let n = 0; n < total; n++) {
      if (this.exists[n] === 0 || this.children[n] === NONE) continue;
      const beside = this.besideOf(n);
      for (let at = 0; at < 27; at++) {
        const b = beside[at];
        if (b !== NONE && this.children[b] === NONE && this.lvl[b] === this.lvl[n]) this.list(b, out);
      }
    }
    return out;
  }

  /** Splits leaves until none must split, in rounds; stops once there are more than `limit` leaves. */
  private balance(cap: number, limit: number): void {
    this.round = 1;
    let candidates = this.firstCandidates();
    const splits: number[] = [];
    for (;;) {
      if (this.leafCount > limit) return;
      splits.length = 0;
      for (const n of candidates) if (this.children[n] === NONE && this.mustSplit(n, cap)) splits.push(n);
      if (splits.length === 0) return;
      this.round += 1;
      candidates = [];
      for (const n of splits) {
        this.splitNode(n);
        const first = this.children[n];
        for (let c = first; c < first + 8; c++) if (this.exists[c] === 1) this.list(c, candidates);
      }
      for (const n of splits) {
        const beside = this.besideOf(n);
        for (let at = 0; at < 27; at++) {
          const b = beside[at];
          if (b !== NONE && this.children[b] === NONE) this.list(b, candidates);
        }
      }
    }
  }

  /** Bit n set when the leaf region across side n of leaf node `n` is one level coarser. */
  coarser(n: number): number {
    let mask = 0;
    const fast = this.interior[n] === 1 && this.parent[n] !== NONE;
    const key = fast ? null : this.key(n);
    for (let side = 0; side < 6; side++) {
      let found = NONE;
      if (fast) {
        found = this.fromParent(n, SIDE_AT[side]);
      } else if (key !== null) {
        const o = BLOCK[SIDE_AT[side]];
        found = this.stepFind(key, o[0], o[1], o[2]);
      }
      if (found !== NONE && this.children[found] === NONE && this.lvl[found] === this.lvl[n] + 1) mask |= 1 << side;
    }
    return mask;
  }
}
