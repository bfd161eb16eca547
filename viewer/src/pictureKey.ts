// What the picture on the screen depends on, as a list of numbers: the frame loop draws only when
// it differs from the one of the last drawn frame (render on demand). A still view over a settled
// planet then costs nothing but the frame callback: on a laptop's GPU that is battery, under a
// software renderer (a remote desktop, a headless browser) it is the whole machine, since one
// frame of a large view takes seconds there and a frame drawn again and again held up everything
// else the page did (chunk uploads, screenshots, the panels).

import * as THREE from 'three';

/** A uniform's value as numbers (numbers, vectors, colours, matrices, arrays of them, textures). */
export function pushUniform(out: number[], value: unknown): void {
  if (typeof value === 'number') {
    out.push(value);
  } else if (typeof value === 'boolean') {
    out.push(value ? 1 : 0);
  } else if (value === null || value === undefined) {
    out.push(Number.NaN);
  } else if (Array.isArray(value)) {
    for (const v of value) pushUniform(out, v);
  } else if (value instanceof THREE.Texture) {
    // a texture stands for its pixels by identity and version (bumped on every upload)
    out.push(value.id, value.version);
  } else if (value instanceof THREE.Color) {
    out.push(value.r, value.g, value.b);
  } else if (typeof (value as { toArray?: unknown }).toArray === 'function') {
    // vectors, matrices, quaternions
    for (const v of (value as { toArray(): number[] }).toArray()) out.push(v);
  } else {
    throw new Error(`pictureKey: a uniform of an unexpected kind (${Object.prototype.toString.call(value)})`);
  }
}

/** Pushes every uniform's value of `uniforms` (in their own order, which never changes). */
export function pushUniforms(out: number[], uniforms: Record<string, { value: unknown }>): void {
  for (const key in uniforms) pushUniform(out, uniforms[key]!.value);
}

/**
 * The key of the last drawn picture: `changed(key)` says whether a new key differs from it,
 * `drew(key)` remembers the key of a frame that drew, `invalidate()` forces the next draw.
 */
export class PictureKey {
  private last: number[] | null = null;

  /** Whether a picture drawn with `key` would differ from the last one drawn. */
  changed(key: readonly number[]): boolean {
    const last = this.last;
    if (last === null || last.length !== key.length) return true;
    for (let i = 0; i < key.length; i++) {
      // (NaN stands for "none": equal to itself here)
      if (last[i] !== key[i] && !(Number.isNaN(last[i]) && Number.isNaN(key[i]))) return true;
    }
    return false;
  }

  /** A frame drew the picture of `key`. */
  drew(key: readonly number[]): void {
    this.last = key.slice();
  }

  /** The next frame draws whatever its key. */
  invalidate(): void {
    this.last = null;
  }
}
