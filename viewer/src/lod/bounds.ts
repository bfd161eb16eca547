// Bounding spheres of chunks, exactly as `pmc_lod::bounds::chunk_sphere` computes them (see its
// docs for why every vertex lies inside): a cap on the unit sphere holding the image of the chunk
// column's face rectangle, then a sphere holding that cap between the chunk's lowest and highest
// layer radius. Same formulas in the same order, so the same bits up to the last bit of `sin`,
// `cos` and `atan2`.

import { faceUvDirectionEstimate, faceUvToSphere, type ChunkKey, type Layout, type Vec3 } from './layout';

/** Upper bound of how much the face map stretches lengths. */
export const LIPSCHITZ = 1.02;
/** Every sphere's radius is multiplied by this. */
export const RADIUS_FACTOR = 1.02;
/** Beyond this cap angle a sphere around the planet centre is used. */
const MAX_CAP_ANGLE = 1.5;

/** A sphere, in metres, planet-centred. */
export interface BoundingSphere {
  center: Vec3;
  radius: number;
}

const dot = (a: Vec3, b: Vec3): number => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
/** Length as glam computes it: the square root of the dot product (not `Math.hypot`). */
export const len = (a: Vec3): number => Math.sqrt(dot(a, a));
/** Normalisation as glam computes it: times the reciprocal of the length. */
export function normalize(a: Vec3): Vec3 {
  const r = 1.0 / len(a);
  return [a[0] * r, a[1] * r, a[2] * r];
}
const cross = (a: Vec3, b: Vec3): Vec3 => [
  a[1] * b[2] - b[1] * a[2],
  a[2] * b[0] - b[2] * a[0],
  a[0] * b[1] - b[0] * a[1],
];

/** The angle between two unit vectors, accurate for small angles. */
export const angleBetween = (a: Vec3, b: Vec3): number => Math.atan2(len(cross(a, b)), dot(a, b));

/** Distance from `p` to the sphere (0 inside it). */
export function sphereDistance(s: BoundingSphere, p: Vec3): number {
  const d: Vec3 = [p[0] - s.center[0], p[1] - s.center[1], p[2] - s.center[2]];
  return Math.max(len(d) - s.radius, 0.0);
}

/** A cap on the unit sphere: the directions within `angle` of `axis`. */
export interface Cap {
  axis: Vec3;
  angle: number;
}

/**
 * `rectCap` evaluates `atan2` only for samples whose tangent is within this relative margin of the
 * largest, or within `TANGENT_SLACK` of it.
 */
const RATIO_MARGIN = 1e-9;
/** The absolute margin of `rectCap`'s tangents, for caps so small that the relative one is not enough. */
const TANGENT_SLACK = 1e-12;
/** Tangents above this make `rectCap` evaluate every sample. */
const MAX_RATIO = 1e3;

/**
 * The cap holding the image of a face rectangle, from `samples + 1` samples per side of its
 * border: the largest `atan2(|a x p|, a . p)` over the samples, evaluated only for samples whose
 * tangent (estimated) comes within a relative 1e-9 or an absolute 1e-12 of the largest (the others
 * are smaller by far more than rounding), so the same bits as evaluating every sample
 * (`pmc_lod::bounds::rect_cap`).
 */
function rectCap(face: number, u0: number, u1: number, v0: number, v1: number, samples: number): Cap {
  const axis = normalize(faceUvToSphere(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1)));
  const [ax, ay, az] = axis;
  const m = samples;
  const count = 4 * (samples + 1);
  if (scratch.length < 4 * count) scratch = new Float64Array(4 * count);
  const s4 = scratch;
  let bestSin2 = 0.0;
  let bestCos2 = 1.0;
  let ahead = true;
  let n = 0;
  for (let s = 0; s <= samples; s++) {
    const t = s / m;
    const u = u0 + (u1 - u0) * t;
    const v = v0 + (v1 - v0) * t;
    for (let side = 0; side < 4; side++) {
      const su = side === 0 || side === 1 ? u : side === 2 ? u0 : u1;
      const sv = side === 0 ? v0 : side === 1 ? v1 : v;
      faceUvDirectionEstimate(face, su, sv, s4, 4 * n);
      const px = s4[4 * n];
      const py = s4[4 * n + 1];
      const pz = s4[4 * n + 2];
      const cx = ay * pz - py * az;
      const cy = az * px - pz * ax;
      const cz = ax * py - px * ay;
      const sin2 = cx * cx + cy * cy + cz * cz;
      const cos = ax * px + ay * py + az * pz;
      const cos2 = cos * cos;
      if (cos > 0 && Number.isFinite(sin2) && sin2 <= MAX_RATIO * MAX_RATIO * cos2) {
        if (sin2 * bestCos2 > bestSin2 * cos2) {
          bestSin2 = sin2;
          bestCos2 = cos2;
        }
      } else {
        ahead = false;
      }
      // keep the sample's face coordinates and its squared sine and cosine where its direction was
      s4[4 * n] = su;
      s4[4 * n + 1] = sv;
      s4[4 * n + 2] = sin2;
      s4[4 * n + 3] = cos2;
      n++;
    }
  }
  const low = Math.max(Math.sqrt(bestSin2 / bestCos2) * (1.0 - RATIO_MARGIN) - TANGENT_SLACK, 0.0);
  const threshold = low * low;
  let angle = 0.0;
  for (let q = 0; q < n; q++) {
    if (!ahead || s4[4 * q + 2] >= threshold * s4[4 * q + 3]) {
      const a = angleBetween(axis, normalize(faceUvToSphere(face, s4[4 * q], s4[4 * q + 1])));
      // as `f64::max`: a NaN never wins
      if (a > angle) angle = a;
    }
  }
  const spacing = Math.max(u1 - u0, v1 - v0) / m;
  return { axis, angle: angle + LIPSCHITZ * 0.5 * spacing };
}

/** Room for `rectCap`'s samples. */
let scratch = new Float64Array(0);

/** A sphere holding every point `d r` with `d` in `cap` and `r` in `[r0, r1]`. */
export function capSphere(cap: Cap, r0: number, r1: number): BoundingSphere {
  if (cap.angle >= MAX_CAP_ANGLE) return { center: [0, 0, 0], radius: r1 * RADIUS_FACTOR + 1e-9 * r1 };
  const c = Math.cos(cap.angle);
  const s = Math.sin(0.5 * cap.angle);
  // the squared distance from `h a` to a point at radius `r` and the cap's angle from `a`
  const dist2 = (r: number, h: number): number => (r - h) * (r - h) + 4.0 * r * h * s * s;
  // the best of a few heights, the first on ties
  let bestH = r1;
  let bestD2 = 0.0;
  for (let n = 0; n < 4; n++) {
    const raw = n === 0 ? r0 * c : n === 1 ? r1 * c : n === 2 ? (0.5 * (r0 + r1)) / c : r1;
    const h = Math.min(Math.max(raw, 0.0), r1);
    const d2 = Math.max(dist2(r0, h), dist2(r1, h));
    if (n === 0 || d2 < bestD2) {
      bestH = h;
      bestD2 = d2;
    }
  }
  return {
    center: [cap.axis[0] * bestH, cap.axis[1] * bestH, cap.axis[2] * bestH],
    radius: Math.sqrt(bestD2) * RADIUS_FACTOR + 1e-9 * r1,
  };
}

const uv = (t: number, n: number): number => (2.0 * t) / n - 1.0;

/** The cap of the column of chunks `(face, level, i, j, *)`: shared by every chunk of the column. */
export function columnCap(layout: Layout, face: number, level: number, i: number, j: number): Cap {
  const n = layout.faceTiles();
  const s = layout.chunkSpan(level);
  const ti = i * s;
  const tj = j * s;
  return rectCap(face, uv(ti, n), uv(ti + s, n), uv(tj, n), uv(tj + s, n), layout.n_t);
}

/** The radii of the lowest and highest voxel layer a vertex of chunks `k` of `level` can lie on. */
export function layerRange(layout: Layout, level: number, k: number): [number, number] {
  const s = layout.chunkSpan(level);
  const lo = k * s;
  const hi = Math.max(lo, Math.min((k + 1) * s, vertexTop(layout, level)));
  return [layout.layerRadius(lo), layout.layerRadius(hi)];
}

/** A sphere holding every vertex chunk `key` can have (`key` must be a chunk of `layout`). */
export function chunkSphere(layout: Layout, key: ChunkKey): BoundingSphere {
  const [r0, r1] = layerRange(layout, key.level, key.k);
  return capSphere(columnCap(layout, key.face, key.level, key.i, key.j), r0, r1);
}

/**
 * The highest layer a vertex of the level can reach: the first layer of the level's stride at
 * or past the shell's top `D` (every layer from `D` up is air), as in the Rust crate.
 */
export function vertexTop(layout: Layout, level: number): number {
  const stride = 2 ** level;
  return Math.ceil(layout.depthTiles() / stride) * stride;
}
