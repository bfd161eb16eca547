// Loads an elevation model's relief (relief.ts) as the float texture the terrain shader samples.

import * as THREE from 'three';
import { ReliefError, gridAtStride, reliefStride, type ReliefGrid, type ReliefInfo } from './relief';

/**
 * Loads the grid as a float texture (one channel, nearest: the shader interpolates in column
 * and row itself, wrapping in longitude), read with the stride that fits `maxTextureSize`;
 * rejects with a message naming the URL when it cannot be loaded or has another size.
 */
export async function loadReliefTexture(
  info: ReliefInfo,
  base: string,
  maxTextureSize = Infinity,
  signal?: AbortSignal,
): Promise<{ texture: THREE.DataTexture; grid: ReliefGrid }> {
  const stride = reliefStride(info, Math.min(maxTextureSize, 8192));
  const grid = gridAtStride(info, stride);
  const target = new URL(info.url, base);
  if (stride > 1) target.searchParams.set('max', String(Math.max(grid.width, grid.height)));
  const url = target.toString();
  const response = await fetch(url, { signal });
  if (!response.ok) throw new ReliefError(`GET ${url} answered ${response.status}`);
  const served = Number(response.headers.get('x-pmc-grid-stride') ?? '1');
  if (served !== stride) throw new ReliefError(`${url} answered with stride ${served}, expected ${stride}`);
  const bytes = await response.arrayBuffer();
  if (bytes.byteLength !== 4 * grid.width * grid.height) {
    throw new ReliefError(`${url} holds ${bytes.byteLength} bytes, expected ${grid.width} x ${grid.height} f32 values`);
  }
  const values = new Float32Array(bytes.byteLength / 4);
  const view = new DataView(bytes);
  for (let i = 0; i < values.length; i++) values[i] = view.getFloat32(4 * i, true);
  const texture = new THREE.DataTexture(values, grid.width, grid.height, THREE.RedFormat, THREE.FloatType);
  texture.magFilter = THREE.NearestFilter;
  texture.minFilter = THREE.NearestFilter;
  texture.generateMipmaps = false;
  texture.wrapS = THREE.ClampToEdgeWrapping;
  texture.wrapT = THREE.ClampToEdgeWrapping;
  texture.flipY = false;
  texture.needsUpdate = true;
  return { texture, grid };
}
