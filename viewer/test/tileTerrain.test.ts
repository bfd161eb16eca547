import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { DEG, directionFromLatLon, positionFromLatLon, type V3 } from '../src/frames';
import { planetParams } from '../src/planetParams';
import { PlanetScene } from '../src/planetScene';
import { ecefToViewer, tilesGroupMatrix } from '../src/tiles';
import { matrixWithin, tileMeshMatrix, tileTerrain } from '../src/tileTerrain';
import { EARTHLIKE_INFO } from './fixtures';

const close = (a: readonly number[], b: readonly number[], eps: number): void => {
  expect(a.length).toBe(b.length);
  for (let n = 0; n < a.length; n++) expect(Math.abs(a[n]! - b[n]!), `component ${n}: ${a[n]} against ${b[n]}`).toBeLessThan(eps);
};

/** ECEF (docs/specs/tiles-v1.md): Z north, X lon 0, Y 90 E. */
const ecef = (lat: number, lon: number, r: number): V3 => [
  r * Math.cos(lat * DEG) * Math.cos(lon * DEG),
  r * Math.cos(lat * DEG) * Math.sin(lon * DEG),
  r * Math.sin(lat * DEG),
];
/** glTF's axes of an ECEF vector: (X, Z, -Y). */
const gltf = (e: V3): V3 => [e[0], e[2], -e[1]];

const R = 6_371_000;
/** The tile's centre (its node's translation), a kilometre under the ground at 39 N 0.01 E. */
const centre = ecef(39, 0.01, R - 1000);
/** Its vertices' offsets from the centre (ECEF metres; f32 numbers, as the glTF holds them in glTF's axes). */
const offsets: V3[] = [
  [0, 0, 0],
  [1000.5, -250.25, 3.125],
  [-12345.5, 678.75, 910.5],
  [0.001953125, 4096, -2048],
];
const up = ecef(39, 0.01, 1);

/**
 * A tile's scene as 3DTilesRendererJS makes it of a PMC glTF: the scene rotated from glTF's Y-up
 * to Z-up (its `_upRotationMatrix`), the node translated to the centre, one mesh (the last one is
 * a cap's vertex: material 255).
 */
function tileScene(): { scene: THREE.Group; mesh: THREE.Mesh } {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(offsets.flatMap((o) => gltf(o))), 3));
  g.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(offsets.flatMap(() => gltf(up))), 3));
  g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array([10, 20, 30, 255, 40, 50, 60, 255, 70, 80, 90, 255, 100, 110, 120, 255]), 4, true));
  g.setAttribute('_height', new THREE.BufferAttribute(new Float32Array([5, 6.5, -7, 8]), 1));
  g.setAttribute('_water_depth', new THREE.BufferAttribute(new Float32Array([0, 0, 7, 0]), 1));
  g.setAttribute('_material', new THREE.BufferAttribute(new Float32Array([2, 3, 1, 255]), 1));
  g.setIndex(new THREE.BufferAttribute(new Uint32Array([0, 1, 2, 0, 2, 3]), 1));
  const mesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide }));
  mesh.name = 'top16000';
  const node = new THREE.Object3D();
  node.name = 'top16000';
  node.position.set(...gltf(centre));
  node.add(mesh);
  const scene = new THREE.Group();
  scene.add(node);
  scene.updateMatrix();
  scene.matrix.multiply(new THREE.Matrix4().makeRotationX(Math.PI / 2)).decompose(scene.position, scene.quaternion, scene.scale);
  return { scene, mesh };
}

describe("a 3D Tiles tile's mesh as a chunk's", () => {
  it('puts every vertex at its planet-frame place, relative to the centre and in high and low f32 parts, its normal turned', () => {
    const { scene, mesh } = tileScene();
    const { geometry: g, origin } = tileTerrain(mesh.geometry, matrixWithin(mesh, scene));
    // the centre, in the planet frame (the Y-up turn's cos(90°) = 6e-17 costs nanometres)
    close(origin, ecefToViewer(centre), 1e-6);
    const pos = g.getAttribute('position');
    const high = g.getAttribute('aPosHigh');
    const low = g.getAttribute('aPosLow');
    const nrm = g.getAttribute('normal');
    for (const [i, o] of offsets.entries()) {
      const want = ecefToViewer([centre[0] + o[0], centre[1] + o[1], centre[2] + o[2]]);
      // the place from its high and low parts, to the micrometre at 6.4e6 m
      close([0, 1, 2].map((c) => high.getComponent(i, c) + low.getComponent(i, c)), want, 1e-6);
      for (let c = 0; c < 3; c++) expect(high.getComponent(i, c)).toBe(Math.fround(want[c]!));
      // relative to the centre: the glTF's f32 offset, turned
      close([0, 1, 2].map((c) => pos.getComponent(i, c)), ecefToViewer(o), 1e-6);
      // the normal: the local vertical of frames.ts at that latitude and longitude
      close([0, 1, 2].map((c) => nrm.getComponent(i, c)), directionFromLatLon(39, 0.01), 1e-7);
    }
    // the place is where frames.ts puts the latitude and longitude
    close(
      [0, 1, 2].map((c) => high.getComponent(0, c) + low.getComponent(0, c)),
      positionFromLatLon(39, 0.01, R - 1000),
      1e-6,
    );
    expect([...(g.getAttribute('aHeight').array as Float32Array)]).toEqual([5, 6.5, -7, 8]);
    expect([...(g.getAttribute('aWaterDepth').array as Float32Array)]).toEqual([0, 0, 7, 0]);
    expect([...(g.getAttribute('aMaterial').array as Float32Array)]).toEqual([2, 3, 1, 255]);
    const colour = g.getAttribute('aColor');
    expect(colour.normalized).toBe(true);
    expect([...(colour.array as Uint8Array)].slice(4, 8)).toEqual([40, 50, 60, 255]);
    expect([...g.getIndex()!.array]).toEqual([0, 1, 2, 0, 2, 3]);
    // (bounds relative to the centre, for the frustum culling)
    expect(g.boundingSphere!.radius).toBeLessThan(20_000);
  });

  it("draws at (its place - camera) under the tiles' group, where the ground is picked", () => {
    const { scene, mesh } = tileScene();
    const { geometry, origin } = tileTerrain(mesh.geometry, matrixWithin(mesh, scene));
    const parents = matrixWithin(mesh.parent!, scene);
    mesh.geometry = geometry;
    mesh.matrixAutoUpdate = false;
    tileMeshMatrix(parents, origin, mesh.matrix);
    const camera = positionFromLatLon(39, 0, R + 10_000);
    const group = new THREE.Group();
    group.matrixAutoUpdate = false;
    group.matrix.fromArray(tilesGroupMatrix(camera));
    group.add(scene);
    group.updateMatrixWorld(true);
    // the world matrix: the floating origin's translation, a chunk's
    const e = mesh.matrixWorld.elements;
    close(e.slice(0, 12), [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0], 1e-12);
    close(e.slice(12, 15), [0, 1, 2].map((c) => origin[c]! - camera[c]!), 1e-6);
    // a ray from the eye (the render origin) toward the middle of the first triangle meets it there
    const corners = [0, 1, 2].map((i) => new THREE.Vector3().fromBufferAttribute(geometry.getAttribute('position'), i).applyMatrix4(mesh.matrixWorld));
    const middle = corners.reduce((a, b) => a.add(b), new THREE.Vector3()).divideScalar(3);
    const hits = new THREE.Raycaster(new THREE.Vector3(), middle.clone().normalize()).intersectObject(mesh, false);
    expect(hits.length).toBe(1);
    close(hits[0]!.point.toArray(), middle.toArray(), 1e-3);
    const want = offsets.slice(0, 3).map((o) => ecefToViewer([centre[0] + o[0], centre[1] + o[1], centre[2] + o[2]]));
    close(middle.toArray(), [0, 1, 2].map((c) => (want[0]![c]! + want[1]![c]! + want[2]![c]!) / 3 - camera[c]!), 1e-6);
  });

  it('refuses a mesh without heights', () => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3), 3));
    g.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3), 3));
    expect(() => tileTerrain(g, new THREE.Matrix4())).toThrow(/_HEIGHT/);
  });
});

describe("the terrain's materials", () => {
  it("are the chunks' and the tiles': the planet's noise periods, the debug flags, until disposed", () => {
    const scene = new PlanetScene();
    const origin: V3 = [1.5e6, 4.9e6, 3.9e6];
    const early = scene.terrainMaterial(origin, 2);
    const params = planetParams(EARTHLIKE_INFO);
    scene.setPlanet(params);
    const material = scene.terrainMaterial(origin, 2);
    for (const m of [early, material]) {
      const mod = m.uniforms['uOriginMod']!.value as THREE.Vector3;
      close(mod.toArray(), origin.map((x) => x % params.noisePeriod), 1e-6);
      expect(m.stencilWrite).toBe(true);
    }
    expect(material.uniforms['uEyeHigh']).toBe(early.uniforms['uEyeHigh']);
    scene.setDebug({ wireframe: true, backfaces: true });
    expect(material.wireframe).toBe(true);
    expect(material.side).toBe(THREE.DoubleSide);
    material.dispose();
    scene.setDebug({ wireframe: false, backfaces: false });
    expect(material.wireframe).toBe(true);
    expect(early.wireframe).toBe(false);
    expect(early.side).toBe(THREE.FrontSide);
    scene.dispose();
  });
});
