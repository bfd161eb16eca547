// The sea surface as a view-dependent disk on the sea sphere, centred under the camera.
// Pure: plain typed arrays, no three.js.
//
// A sphere mesh of planet size would hold f32 vertices hundreds of kilometres from any origin at
// Earth radius, and its flat triangles would sag below the true sphere by s^2 / 8R. Instead the sea
// is one disk of rings around the point under the camera (the nadir), spaced geometrically from a
// few centimetres to the horizon: fine where the camera looks closely, coarse far away, every
// vertex exactly on the sphere and stored relative to the nadir (computed in f64). The disk is
// rebuilt as the camera moves (it is cheap: a few thousand vertices).

import { cross, enuAt, length, normalize, scale, type V3 } from './frames';

export interface SeaDisk {
  /** The nadir: the point of the sea sphere under the camera (planet frame, f64). */
  origin: V3;
  /** f32 x 3 per vertex, relative to `origin`. */
  positions: Float32Array;
  /** Unit radial direction per vertex. */
  normals: Float32Array;
  indices: Uint32Array;
  /** Angular radius of the innermost ring and of the disk, radians. */
  innerAngle: number;
  outerAngle: number;
}

export interface SeaDiskOptions {
  rings?: number;
  segments?: number;
  /** When the camera is below the sea surface: how far to draw it, metres. */
  underwaterRange?: number;
}

/**
 * The disk for a camera at planet-frame `camera` over a sea of radius `seaRadius`. The disk
 * reaches the horizon (slightly past it, so nothing is missing at the silhouette).
 */
export function buildSeaDisk(camera: V3, seaRadius: number, opts: SeaDiskOptions = {}): SeaDisk {
  const rings = opts.rings ?? 64;
  const segments = opts.segments ?? 96;
  const R = seaRadius;
  const d = Math.hypot(camera[0], camera[1], camera[2]);
  const height = Math.abs(d - R);
  const outerAngle =
    d > R
      ? Math.min(Math.PI, Math.acos(R / d) * 1.01 + 1e-4)
      : Math.min(Math.PI / 2, (opts.underwaterRange ?? R) / R);
  const innerAngle = Math.min(outerAngle / rings, Math.max(0.05, 0.02 * height) / R);
  const { east, north, up } = enuAt(d > 0 ? camera : [0, 1, 0]);
  const origin = scale(normalize(up), R);

  const vertexCount = 1 + rings * segments;
  const positions = new Float32Array(vertexCount * 3);
  const normals = new Float32Array(vertexCount * 3);
  normals[0] = up[0];
  normals[1] = up[1];
  normals[2] = up[2];
  const cosPhi = new Float64Array(segments);
  const sinPhi = new Float64Array(segments);
  for (let s = 0; s < segments; s++) {
    const phi = (2 * Math.PI * s) / segments;
    cosPhi[s] = Math.cos(phi);
    sinPhi[s] = Math.sin(phi);
  }
  const ratio = rings > 1 ? Math.pow(outerAngle / innerAngle, 1 / (rings - 1)) : 1;
  let v = 1;
  for (let r = 0; r < rings; r++) {
    const theta = rings > 1 ? innerAngle * Math.pow(ratio, r) : outerAngle;
    const sinT = Math.sin(theta);
    // cos(theta) - 1 without cancellation
    const half = Math.sin(theta / 2);
    const cosM1 = -2 * half * half;
    for (let s = 0; s < segments; s++, v++) {
      const tx = cosPhi[s]! * east[0] + sinPhi[s]! * north[0];
      const ty = cosPhi[s]! * east[1] + sinPhi[s]! * north[1];
      const tz = cosPhi[s]! * east[2] + sinPhi[s]! * north[2];
      const nx = up[0] * (1 + cosM1) + tx * sinT;
      const ny = up[1] * (1 + cosM1) + ty * sinT;
      const nz = up[2] * (1 + cosM1) + tz * sinT;
      positions[3 * v] = R * (up[0] * cosM1 + tx * sinT);
      positions[3 * v + 1] = R * (up[1] * cosM1 + ty * sinT);
      positions[3 * v + 2] = R * (up[2] * cosM1 + tz * sinT);
      normals[3 * v] = nx;
      normals[3 * v + 1] = ny;
      normals[3 * v + 2] = nz;
    }
  }

  // triangles, counter-clockwise seen from outside (from +up)
  const indices = new Uint32Array(3 * segments + 6 * segments * (rings - 1));
  let n = 0;
  for (let s = 0; s < segments; s++) {
    const a = 1 + s;
    const b = 1 + ((s + 1) % segments);
    indices[n++] = 0;
    indices[n++] = a;
    indices[n++] = b;
  }
  for (let r = 0; r + 1 < rings; r++) {
    const inner = 1 + r * segments;
    const outer = inner + segments;
    for (let s = 0; s < segments; s++) {
      const s1 = (s + 1) % segments;
      indices[n++] = inner + s;
      indices[n++] = outer + s;
      indices[n++] = outer + s1;
      indices[n++] = inner + s;
      indices[n++] = outer + s1;
      indices[n++] = inner + s1;
    }
  }
  return { origin, positions, normals, indices, innerAngle, outerAngle };
}

/**
 * Whether a disk built for `builtFor` should be rebuilt for a camera at `camera`: the camera moved
 * sideways by more than the inner ring, or its height over the sea changed by more than 10 %.
 */
export function seaDiskStale(disk: SeaDisk, builtFor: V3, camera: V3, seaRadius: number): boolean {
  const h0 = Math.hypot(builtFor[0], builtFor[1], builtFor[2]) - seaRadius;
  const h1 = Math.hypot(camera[0], camera[1], camera[2]) - seaRadius;
  if (Math.sign(h0) !== Math.sign(h1)) return true;
  if (Math.abs(h1 - h0) > 0.1 * Math.max(0.5, Math.abs(h0))) return true;
  // sideways: the angle between the two nadir directions, on the sea sphere
  const sideways = length(cross(normalize(builtFor), normalize(camera))) * seaRadius;
  return sideways > 0.5 * disk.innerAngle * seaRadius;
}
