// Bounding spheres of chunks, exactly as `pmc_lod::bounds::chunk_sphere` computes them (see its
// docs for why every vertex lies inside): a cap on the unit sphere holding the image of the chunk
// column's face rectangle, then a sphere holding that cap between the chunk's lowest and highest
// layer radius. Same formulas in the same order, so the same bits up to the last bit of `sin`,
// `cos` and `atan2`.

import { faceUvToSphere, type ChunkKey, type Layout, type Vec3 } from './layout';

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

interface Cap {
  axis: Vec3;
  angle: number;
}

function rectCap(face: number, u0: number, u1: number, v0: number, v1: number, samples: number): Cap {
  const axis = normalize(faceUvToSphere(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1)));
  let angle = 0.0;
  const m = samples;
  for (let s = 0; s <= samples; s++) {
    const t = s / m;
    const u = u0 + (u1 - u0) * t;
    const v = v0 + (v1 - v0) * t;
    for (const [su, sv] of [
      [u, v0],
      [u, v1],
      [u0, v],
      [u1, v],
    ]) {
      angle = Math.max(angle, angleBetween(axis, normalize(faceUvToSphere(face, su, sv))));
    }
  }
  const spacing = Math.max(u1 - u0, v1 - v0) / m;
  return { axis, angle: angle + LIPSCHITZ * 0.5 * spacing };
}

function dist2(r: number, h: number, angle: number): number {
  const s = Math.sin(0.5 * angle);
  return (r - h) * (r - h) + 4.0 * r * h * s * s;
}

function capSphere(cap: Cap, r0: number, r1: number): BoundingSphere {
  const pad = (radius: number): number => radius * RADIUS_FACTOR + 1e-9 * r1;
  if (cap.angle >= MAX_CAP_ANGLE) return { center: [0, 0, 0], radius: pad(r1) };
  const c = Math.cos(cap.angle);
  let best: [number, number] | null = null;
  for (const raw of [r0 * c, r1 * c, (0.5 * (r0 + r1)) / c, r1]) {
    const h = Math.min(Math.max(raw, 0.0), r1);
    const d2 = Math.max(dist2(r0, h, cap.angle), dist2(r1, h, cap.angle));
    if (best === null || d2 < best[1]) best = [h, d2];
  }
  const [h, d2] = best ?? [r1, 0.0];
  return { center: [cap.axis[0] * h, cap.axis[1] * h, cap.axis[2] * h], radius: pad(Math.sqrt(d2)) };
}

const uv = (t: number, n: number): number => (2.0 * t) / n - 1.0;

/** A sphere holding every vertex chunk `key` can have (`key` must be a chunk of `layout`). */
export function chunkSphere(layout: Layout, key: ChunkKey): BoundingSphere {
  const n = layout.faceTiles();
  const s = layout.chunkSpan(key.level);
  const ti = key.i * s;
  const tj = key.j * s;
  const cap = rectCap(key.face, uv(ti, n), uv(ti + s, n), uv(tj, n), uv(tj + s, n), layout.n_t);
  const lo = key.k * s;
  const hi = Math.max(lo, Math.min((key.k + 1) * s, vertexTop(layout, key.level)));
  return capSphere(cap, layout.layerRadius(lo), layout.layerRadius(hi));
}

/**
 * The highest layer a vertex of the level can reach: the first layer of the level's stride at
 * or past the shell's top `D` (every layer from `D` up is air), as in the Rust crate.
 */
export function vertexTop(layout: Layout, level: number): number {
  const stride = 2 ** level;
  return Math.ceil(layout.depthTiles() / stride) * stride;
}
