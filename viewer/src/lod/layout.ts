// The planet layout and chunk octree of `pmc-geometry` (faces, Eq. (1) cube-to-sphere, chunk keys,
// levels and neighbours across face edges), as the level-of-detail selection needs them. Every
// formula is evaluated in the same order as the Rust code, so the results carry the same bits.

/** A vector of three numbers. */
export type Vec3 = [number, number, number];

/** Face names in index order (`Face::ALL`). */
export const FACES = ['top', 'bottom', 'north', 'south', 'east', 'west'] as const;

/** A face's frame: `u`, `v` and the outward normal `n`, as integer unit vectors. */
interface Frame {
  u: Vec3;
  v: Vec3;
  n: Vec3;
}

const FRAMES: readonly Frame[] = [
  { u: [-1, 0, 0], v: [0, 0, 1], n: [0, 1, 0] },
  { u: [-1, 0, 0], v: [0, 0, -1], n: [0, -1, 0] },
  { u: [-1, 0, 0], v: [0, 1, 0], n: [0, 0, -1] },
  { u: [-1, 0, 0], v: [0, -1, 0], n: [0, 0, 1] },
  { u: [0, 1, 0], v: [0, 0, 1], n: [1, 0, 0] },
  { u: [0, 0, 1], v: [0, 1, 0], n: [-1, 0, 0] },
];

/** A chunk: face index (0..6), level (0 finest) and indices along `u`, `v` and depth. */
export interface ChunkKey {
  face: number;
  level: number;
  i: number;
  j: number;
  k: number;
}

/** Key order: face, level, i, j, k (the Rust `Ord`). */
export function compareKeys(a: ChunkKey, b: ChunkKey): number {
  return a.face - b.face || a.level - b.level || a.i - b.i || a.j - b.j || a.k - b.k;
}

/** A string naming a key, for sets and maps. */
export const keyId = (c: ChunkKey): string => `${c.face}/${c.level}/${c.i}/${c.j}/${c.k}`;

/** The key's parent in the face's octree. */
export const parentOf = (c: ChunkKey): ChunkKey => ({
  face: c.face,
  level: c.level + 1,
  i: Math.floor(c.i / 2),
  j: Math.floor(c.j / 2),
  k: Math.floor(c.k / 2),
});

/** The eight children in key order (child `n` has bits i = n>>2, j = n>>1, k = n&1); none at level 0. */
export function childrenOf(c: ChunkKey): ChunkKey[] {
  if (c.level === 0) return [];
  const out: ChunkKey[] = [];
  for (let n = 0; n < 8; n++) {
    out.push({
      face: c.face,
      level: c.level - 1,
      i: 2 * c.i + ((n >> 2) & 1),
      j: 2 * c.j + ((n >> 1) & 1),
      k: 2 * c.k + (n & 1),
    });
  }
  return out;
}

/** The sides of a chunk, in `SideMask` bit order. */
export const SIDES = ['u_min', 'u_max', 'v_min', 'v_max', 'inner', 'outer'] as const;
/** A side by its index in {@link SIDES}: axis `side >> 1`, at the axis's largest index when odd. */
export type Side = 0 | 1 | 2 | 3 | 4 | 5;

/** Seed 000 Eq. (1): a point of the cube surface to the unit sphere. */
export function cubeToSphere(c: Vec3): Vec3 {
  const x2 = c[0] * c[0];
  const y2 = c[1] * c[1];
  const z2 = c[2] * c[2];
  return [
    c[0] * Math.sqrt(1.0 - y2 * 0.5 - z2 * 0.5 + (y2 * z2) / 3.0),
    c[1] * Math.sqrt(1.0 - z2 * 0.5 - x2 * 0.5 + (z2 * x2) / 3.0),
    c[2] * Math.sqrt(1.0 - x2 * 0.5 - y2 * 0.5 + (x2 * y2) / 3.0),
  ];
}

const THIRD = 1.0 / 3.0;

/**
 * {@link faceUvToSphere} with products by 1/3 where it divides by 3 (within a few units in the last
 * place of it), written into `out` at `at` without allocating: an estimate for searches.
 */
export function faceUvDirectionEstimate(face: number, u: number, v: number, out: Float64Array, at: number): void {
  const f = FRAMES[face];
  const x = f.n[0] + u * f.u[0] + v * f.v[0];
  const y = f.n[1] + u * f.u[1] + v * f.v[1];
  const z = f.n[2] + u * f.u[2] + v * f.v[2];
  const x2 = x * x;
  const y2 = y * y;
  const z2 = z * z;
  out[at] = x * Math.sqrt(1.0 - y2 * 0.5 - z2 * 0.5 + y2 * z2 * THIRD);
  out[at + 1] = y * Math.sqrt(1.0 - z2 * 0.5 - x2 * 0.5 + z2 * x2 * THIRD);
  out[at + 2] = z * Math.sqrt(1.0 - x2 * 0.5 - y2 * 0.5 + x2 * y2 * THIRD);
}

/** The unit-sphere direction of face coordinates `(u, v)` in `[-1, 1]^2`. */
export function faceUvToSphere(face: number, u: number, v: number): Vec3 {
  const f = FRAMES[face];
  const c: Vec3 = [0, 0, 0];
  for (let a = 0; a < 3; a++) c[a] = f.n[a] + u * f.u[a] + v * f.v[a];
  return cubeToSphere(c);
}

/** Layout parameters, named as in the paper and the vectors file. */
export interface LayoutParams {
  n_c: number;
  n_t: number;
  d_b: number;
  l_d: number;
  d_c: number;
}

/** A planet layout: the chunk octree per face over the face and the depth axis. */
export class Layout {
  readonly n_c: number;
  readonly n_t: number;
  readonly d_b: number;
  readonly l_d: number;
  readonly d_c: number;
  private readonly perSide: number[] = [];
  private readonly perDepth: number[] = [];
  private readonly spans: number[] = [];

  constructor(p: LayoutParams) {
    const whole = (x: number): boolean => Number.isInteger(x) && x >= 1;
    if (!whole(p.n_c) || !whole(p.n_t) || p.n_t > 128 || !whole(p.d_c)) {
      throw new Error('n_c and d_c must be whole numbers of at least 1, n_t between 1 and 128');
    }
    if (!(Number.isFinite(p.l_d) && p.l_d > 0) || !(Number.isFinite(p.d_b) && p.d_b >= p.l_d)) {
      throw new Error('l_d must be finite and above 0, d_b finite and at least l_d');
    }
    if (p.n_c * p.n_t > 2 ** 24 || p.d_c * p.n_t > 2 ** 24) {
      throw new Error('the layout has more than 2^24 tiles along one axis');
    }
    this.n_c = p.n_c;
    this.n_t = p.n_t;
    this.d_b = p.d_b;
    this.l_d = p.l_d;
    this.d_c = p.d_c;
    // the per-level counts, looked up often by the selection (the same numbers as the formulas)
    for (let level = 0; level <= this.maxLevel(); level++) {
      this.perSide.push(Math.floor(this.n_c / 2 ** level));
      this.perDepth.push(Math.ceil(this.d_c / 2 ** level));
      this.spans.push(this.n_t * 2 ** level);
    }
  }

  /** `N = n_c n_t`: tiles along a face side. */
  faceTiles(): number {
    return this.n_c * this.n_t;
  }

  /** `D = n_t d_c`: tiles along depth. */
  depthTiles(): number {
    return this.n_t * this.d_c;
  }

  /** The radius of voxel layer `k`. */
  layerRadius(k: number): number {
    return this.d_b + this.l_d * k;
  }

  /** The outermost layer's radius. */
  radius(): number {
    return this.layerRadius(this.depthTiles());
  }

  /** The coarsest level: trailing zero bits of `n_c`, or 0 when `n_t` is odd. */
  maxLevel(): number {
    if (this.n_t % 2 === 1) return 0;
    let l = 0;
    while ((this.n_c >> l) % 2 === 0) l++;
    return l;
  }

  /** Chunks per face side at `level`. */
  chunksPerSide(level: number): number {
    return this.perSide[level] ?? Math.floor(this.n_c / 2 ** level);
  }

  /** Chunks along depth at `level`: `ceil(d_c / 2^level)`. */
  depthChunks(level: number): number {
    return this.perDepth[level] ?? Math.ceil(this.d_c / 2 ** level);
  }

  /** Level-0 grid steps along each axis of a level-`level` chunk. */
  chunkSpan(level: number): number {
    return this.spans[level] ?? this.n_t * 2 ** level;
  }

  /** Whether `key` names a chunk of this layout. */
  containsChunk(key: ChunkKey): boolean {
    return (
      key.level <= this.maxLevel() &&
      key.i < this.chunksPerSide(key.level) &&
      key.j < this.chunksPerSide(key.level) &&
      key.k < this.depthChunks(key.level)
    );
  }

  /** All chunks of `level`, in key order. */
  chunks(level: number): ChunkKey[] {
    const n = this.chunksPerSide(level);
    const d = this.depthChunks(level);
    const out: ChunkKey[] = [];
    for (let face = 0; face < 6; face++) {
      for (let i = 0; i < n; i++) {
        for (let j = 0; j < n; j++) {
          for (let k = 0; k < d; k++) out.push({ face, level, i, j, k });
        }
      }
    }
    return out;
  }

  /**
   * The chunk of `level` one step beyond `side` of `key` (across face edges too), or null past the
   * shell's inner or outer boundary (`Layout::neighbour`).
   */
  neighbour(key: ChunkKey, side: Side, level: number): ChunkKey | null {
    if (!this.containsChunk(key) || level > this.maxLevel()) return null;
    const span = this.chunkSpan(key.level);
    let ci = 2 * key.i * span + span;
    let cj = 2 * key.j * span + span;
    let ck = 2 * key.k * span + span;
    switch (side) {
      case 0:
        ci -= 2 * span;
        break;
      case 1:
        ci += 2 * span;
        break;
      case 2:
        cj -= 2 * span;
        break;
      case 3:
        cj += 2 * span;
        break;
      case 4:
        ck -= 2 * span;
        break;
      case 5:
        ck += 2 * span;
        break;
    }
    if (ck < 0) return null;
    const targetSpan = this.chunkSpan(level);
    const k = Math.floor(Math.floor(ck / 2) / targetSpan);
    if (k >= this.depthChunks(level)) return null;
    const at = this.faceIndexDoubled(key.face, ci, cj);
    if (at === null) return null;
    const perSide = this.chunksPerSide(level);
    const i = Math.min(Math.floor(at[1] / (2 * targetSpan)), perSide - 1);
    const j = Math.min(Math.floor(at[2] / (2 * targetSpan)), perSide - 1);
    return { face: at[0], level, i, j, k };
  }

  /** A point in doubled face grid indices of `face` (perhaps past an edge) on the face holding it. */
  private faceIndexDoubled(face: number, ci: number, cj: number): [number, number, number] | null {
    const n2 = 2 * this.faceTiles();
    const outI = ci < 0 || ci > n2;
    const outJ = cj < 0 || cj > n2;
    if (!outI && !outJ) return [face, ci, cj];
    if (outI && outJ) return null;
    const fold = (x: number): [number, number] | null => {
      if (x < -n2 || x > 2 * n2) return null;
      if (x > n2) return [n2, x - n2];
      if (x < 0) return [-n2, -x];
      return [2 * x - n2, 0];
    };
    const fu = fold(ci);
    const fv = fold(cj);
    if (fu === null || fv === null) return null;
    const cn = n2 - 2 * (fu[1] + fv[1]);
    const fr = FRAMES[face];
    const p: Vec3 = [0, 0, 0];
    for (let a = 0; a < 3; a++) p[a] = fr.n[a] * cn + fr.u[a] * fu[0] + fr.v[a] * fv[0];
    const idot = (a: Vec3, b: Vec3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const other = FRAMES.findIndex((f) => idot(f.n, p) === n2);
    if (other < 0) return null;
    const o = FRAMES[other];
    return [other, (idot(o.u, p) + n2) / 2, (idot(o.v, p) + n2) / 2];
  }
}
