// Imagery draped on a planet: `/api/v1/planet`'s `imagery` block (docs/specs/http-api-v1.md), an
// equirectangular picture (row 0 the north edge, column 0 the west edge, sRGB) that the terrain
// shader samples per pixel by latitude and longitude. The contract and the lookup are pure; the
// texture loader uses three.js and the DOM.

import * as THREE from 'three';

/** The `imagery` block of `/api/v1/planet`. */
export interface ImageryInfo {
  /** Where the picture is served (relative to the page, e.g. `/api/v1/imagery`). */
  url: string;
  /** Degrees of the picture's outer cell edges: west, east, south, north. */
  extent: [number, number, number, number];
  width: number;
  height: number;
  /** Content digest: a new picture gets a new texture. */
  digest: string;
}

/** A malformed `imagery` block. */
export class ImageryError extends Error {
  constructor(message: string) {
    super(`imagery: ${message}`);
    this.name = 'ImageryError';
  }
}

const isObject = (x: unknown): x is Record<string, unknown> => typeof x === 'object' && x !== null && !Array.isArray(x);

/**
 * The imagery of a planet description (its `imagery` field): null when absent or null, else the
 * block checked; throws an `ImageryError` saying what is wrong when malformed.
 */
export function parseImagery(planet: unknown): ImageryInfo | null {
  if (!isObject(planet)) throw new ImageryError('the planet description is not an object');
  const raw = planet['imagery'];
  if (raw === undefined || raw === null) return null;
  if (!isObject(raw)) throw new ImageryError(`expected an object or null, got ${JSON.stringify(raw)}`);
  const { url, extent, width, height, digest } = raw;
  if (typeof url !== 'string' || url.length === 0) throw new ImageryError(`url ${JSON.stringify(url)} is not a non-empty string`);
  if (!Array.isArray(extent) || extent.length !== 4 || !extent.every((x) => typeof x === 'number' && Number.isFinite(x))) {
    throw new ImageryError(`extent ${JSON.stringify(extent)} is not four finite numbers [west, east, south, north]`);
  }
  const [west, east, south, north] = extent as [number, number, number, number];
  if (!(east > west) || east - west > 360) {
    throw new ImageryError(`extent west ${west} to east ${east}: east must exceed west by at most 360 degrees`);
  }
  if (!(north > south) || south < -90 || north > 90) {
    throw new ImageryError(`extent south ${south} to north ${north}: need -90 <= south < north <= 90`);
  }
  for (const [name, v] of [['width', width], ['height', height]] as const) {
    if (typeof v !== 'number' || !Number.isInteger(v) || v < 1 || v > 65536) {
      throw new ImageryError(`${name} ${JSON.stringify(v)} is not a whole number of pixels in 1..65536`);
    }
  }
  if (typeof digest !== 'string') throw new ImageryError(`digest ${JSON.stringify(digest)} is not a string`);
  return { url, extent: [west, east, south, north], width: width as number, height: height as number, digest };
}

/**
 * Where latitude/longitude (degrees) fall in the picture, as the shader computes it: `u` from the
 * west edge (0) to the east edge (1), longitude taken modulo 360 into the extent (so a picture
 * spanning the antimeridian has no seam), `v` from the north edge (0) to the south edge (1);
 * null outside the extent.
 */
export function imageryUv(info: Pick<ImageryInfo, 'extent'>, lat: number, lon: number): [number, number] | null {
  const [west, east, south, north] = info.extent;
  const span = east - west;
  const u = ((((lon - west) % 360) + 360) % 360) / span;
  const v = (north - lat) / (north - south);
  if (u > 1 || v < 0 || v > 1) return null;
  return [u, v];
}

/** Size of one picture cell on the ground at the equator, metres, on a sphere of `radius`. */
export function imageryCellMetres(info: Pick<ImageryInfo, 'extent' | 'width' | 'height'>, radius: number): number {
  const [west, east, south, north] = info.extent;
  const du = (east - west) / info.width;
  const dv = (north - south) / info.height;
  return (Math.max(du, dv) * Math.PI * radius) / 180;
}

/**
 * The size the server answers `?max=` with: the picture halved (each side rounded down, at least
 * 1) as few times as needed for both sides to be at most `max` pixels.
 */
export function halvedSize(width: number, height: number, max: number): [number, number] {
  let w = width;
  let h = height;
  while (w > max || h > max) {
    w = Math.max(1, Math.floor(w / 2));
    h = Math.max(1, Math.floor(h / 2));
  }
  return [w, h];
}

/**
 * Loads the picture as a texture (sRGB, mipmapped, wrapping in longitude when it spans the whole
 * circle); rejects with a message naming the URL when it cannot be loaded or has another size
 * than the block says (halved, when larger than `maxTextureSize`, by the server's `?max=`).
 */
export async function loadImageryTexture(
  info: ImageryInfo,
  base: string,
  maxTextureSize = Infinity,
  signal?: AbortSignal,
): Promise<THREE.Texture> {
  const target = new URL(info.url, base);
  // larger than the GPU takes: the server's halved copy (`?max=`)
  const [width, height] = halvedSize(info.width, info.height, maxTextureSize);
  if (width !== info.width || height !== info.height) target.searchParams.set('max', String(maxTextureSize));
  const url = target.toString();
  const response = await fetch(url, { signal });
  if (!response.ok) throw new ImageryError(`GET ${url} answered ${response.status}`);
  const blob = await response.blob();
  let bitmap: ImageBitmap;
  try {
    bitmap = await createImageBitmap(blob, { imageOrientation: 'flipY', colorSpaceConversion: 'none' });
  } catch (e) {
    throw new ImageryError(`${url} is not a picture the browser can decode (${String(e)})`);
  }
  if (bitmap.width !== width || bitmap.height !== height) {
    bitmap.close();
    throw new ImageryError(`${url} is ${bitmap.width} x ${bitmap.height} pixels, expected ${width} x ${height}`);
  }
  const texture = new THREE.Texture(bitmap);
  // the bitmap is already flipped (row 0 = north at v = 1)
  texture.flipY = false;
  texture.colorSpace = THREE.SRGBColorSpace;
  texture.wrapS = info.extent[1] - info.extent[0] >= 360 ? THREE.RepeatWrapping : THREE.ClampToEdgeWrapping;
  texture.wrapT = THREE.ClampToEdgeWrapping;
  texture.magFilter = THREE.LinearFilter;
  texture.minFilter = THREE.LinearMipmapLinearFilter;
  texture.generateMipmaps = true;
  texture.anisotropy = 4;
  texture.needsUpdate = true;
  return texture;
}
