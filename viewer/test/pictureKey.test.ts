import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { PictureKey, pushUniform, pushUniforms } from '../src/pictureKey';

describe('pictureKey', () => {
  it('turns every kind of uniform value into numbers', () => {
    const out: number[] = [];
    const tex = new THREE.DataTexture(new Uint8Array(4), 1, 1);
    pushUniforms(out, {
      a: { value: 2 },
      b: { value: true },
      c: { value: new THREE.Vector3(1, 2, 3) },
      d: { value: [new THREE.Vector2(4, 5), new THREE.Vector2(6, 7)] },
      e: { value: new THREE.Color(0.5, 0.25, 0.125) },
      f: { value: tex },
      g: { value: null },
    });
    expect(out.slice(0, 12)).toEqual([2, 1, 1, 2, 3, 4, 5, 6, 7, 0.5, 0.25, 0.125]);
    expect(out[12]).toBe(tex.id);
    expect(out[13]).toBe(tex.version);
    expect(Number.isNaN(out[14])).toBe(true);
    expect(out).toHaveLength(15);
    // a texture updated (uploaded again) changes its numbers
    tex.needsUpdate = true;
    const again: number[] = [];
    pushUniform(again, tex);
    expect(again).toEqual([tex.id, out[13]! + 1]);
  });

  it('refuses a uniform it cannot read rather than ignoring it', () => {
    expect(() => pushUniform([], { x: 1 })).toThrow(/unexpected kind/);
  });

  it('says changed until a key is drawn, then only for a different key or after invalidate', () => {
    const k = new PictureKey();
    expect(k.changed([1, 2])).toBe(true);
    k.drew([1, 2]);
    expect(k.changed([1, 2])).toBe(false);
    expect(k.changed([1, 3])).toBe(true);
    expect(k.changed([1, 2, 0])).toBe(true);
    // none (NaN) equals none
    k.drew([Number.NaN]);
    expect(k.changed([Number.NaN])).toBe(false);
    expect(k.changed([0])).toBe(true);
    k.invalidate();
    expect(k.changed([Number.NaN])).toBe(true);
  });

  it('keeps its own copy of the key drawn', () => {
    const k = new PictureKey();
    const key = [1, 2];
    k.drew(key);
    key[0] = 5;
    expect(k.changed([1, 2])).toBe(false);
  });
});
