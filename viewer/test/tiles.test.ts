import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { DEG, positionFromLatLon, type V3 } from '../src/frames';
import { ecefToViewer, otherPlanet, tilesGroupMatrix, viewerToEcef } from '../src/tiles';

const close = (a: readonly number[], b: readonly number[], eps: number): void => {
  for (let n = 0; n < 3; n++) expect(Math.abs(a[n]! - b[n]!), `component ${n}: ${a[n]} against ${b[n]}`).toBeLessThan(eps);
};

/** A point on the sphere of radius `r` at `lat`, `lon` in ECEF (docs/specs/tiles-v1.md): Z north, X lon 0, Y 90 E. */
const ecef = (lat: number, lon: number, r: number): V3 => [
  r * Math.cos(lat * DEG) * Math.cos(lon * DEG),
  r * Math.cos(lat * DEG) * Math.sin(lon * DEG),
  r * Math.sin(lat * DEG),
];

describe("the 3D Tiles' frame in the viewer", () => {
  const R = 6_371_000;

  it('puts an ECEF point where frames.ts puts its latitude and longitude', () => {
    close(ecefToViewer(ecef(39, 0, R)), positionFromLatLon(39, 0, R), 1e-6);
    for (const [lat, lon] of [
      [0, 0],
      [0, 90],
      [90, 0],
      [-33.9, 151.2],
      [27.98, 86.92],
      [-60, -120],
    ] as const) {
      close(ecefToViewer(ecef(lat, lon, R + 8848)), positionFromLatLon(lat, lon, R + 8848), 1e-6);
      close(viewerToEcef(positionFromLatLon(lat, lon, R)), ecef(lat, lon, R), 1e-6);
    }
  });

  it('is a rotation: determinant +1, lengths kept', () => {
    const m = new THREE.Matrix4().fromArray(tilesGroupMatrix([0, 0, 0]));
    expect(m.determinant()).toBe(1);
    const p = new THREE.Vector3(1, 2, 3).applyMatrix4(m);
    expect(p.length()).toBeCloseTo(Math.sqrt(14), 12);
  });

  it('places the tiles around the floating origin: rotation, then -camera', () => {
    const camera = positionFromLatLon(39, 0, R + 10_000);
    const m = new THREE.Matrix4().fromArray(tilesGroupMatrix(camera));
    // the ground under the camera, 10 km below it along the local vertical, to the micrometre
    const ground = new THREE.Vector3(...ecef(39, 0, R)).applyMatrix4(m);
    const below = positionFromLatLon(39, 0, -10_000);
    close(ground.toArray(), below, 1e-6);
    // a tile's node translated to 6.4e6 m, a vertex a metre from it: one metre from the eye's
    // offset to the node, whatever the radius (three.js multiplies its matrices in f64)
    const node = new THREE.Matrix4().makeTranslation(...ecef(39, 0.001, R));
    const world = new THREE.Matrix4().multiplyMatrices(m, node);
    const v = new THREE.Vector3(1, 0, 0).applyMatrix4(world);
    const want = ecefToViewer(ecef(39, 0.001, R).map((x, i) => x + (i === 0 ? 1 : 0)) as V3).map((x, i) => x - camera[i]!);
    close(v.toArray(), want, 1e-6);
  });

  it('writes into the array it is given', () => {
    const out = new Array<number>(16).fill(NaN);
    expect(tilesGroupMatrix([1, 2, 3], out)).toBe(out);
    expect(out).toEqual([0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, -2, -3, 1]);
  });
});

describe('the planet of the tiles', () => {
  it('is told apart from the preset shown', () => {
    const earth = { kind: 'preset', name: 'earth', seed: '7' };
    expect(otherPlanet('preset:earth:7', earth)).toBe(false);
    expect(otherPlanet('preset:earth:8', earth)).toBe(true);
    expect(otherPlanet('preset:moon:7', earth)).toBe(true);
    // unknown either way: nothing said
    expect(otherPlanet(null, earth)).toBe(false);
    expect(otherPlanet('preset:earth:7', null)).toBe(false);
    expect(otherPlanet('dem:etopo5', { kind: 'dem', name: 'etopo5', seed: '0' })).toBe(false);
  });
});
