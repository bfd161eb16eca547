// The 3D Tiles mode's tiles drawn by the terrain shader, as the chunks are (tilesMode.ts): a tile's
// glTF mesh turned into a chunk's geometry (planetScene.ts `addChunk`), once, when it loads.
//
// A tile's glTF (docs/specs/tiles-v1.md) holds its vertices in `f32` relative to the tile's centre,
// in glTF's Y-up axes; the matrices of its scene (3DTilesRendererJS's turn of Y-up into Z-up, the
// node's translation to the centre, in `f64`) place them in ECEF. Here each vertex is carried into
// ECEF and then into the planet frame (tiles.ts: viewer (x, y, z) = ECEF (Y, Z, X)) in `f64`, and
// written as a chunk's: `position` relative to the tile's centre (the chunk's origin), the place
// split into high and low `f32` parts (frames.ts `splitPositions`), the normal turned into the
// planet frame, and the tile's own attributes as the chunk's (GLTFLoader names a glTF attribute
// it does not know in lower case: `_HEIGHT` is `_height`). The mesh's matrix then makes its
// world matrix the floating origin's translation, centre - camera, as a chunk's (`tileMeshMatrix`):
// the terrain shader draws from the high and low parts alone; three.js's frustum culling and the
// picking read the matrix.

import * as THREE from 'three';
import type { V3 } from './frames';

/** A tile's mesh as a chunk's geometry. */
export interface TileTerrain {
  geometry: THREE.BufferGeometry;
  /** Planet frame, metres (`f64`): the tile's centre, what `position` is relative to. */
  origin: V3;
}

/**
 * The chunk's geometry of a tile's glTF primitive `source` (`position`, `normal`, `_height`,
 * and `color`, `_water_depth`, `_material` where it has them), whose vertices `toEcef` places in
 * ECEF (the product of the matrices of its tile's scene, down to the mesh, in `f64`). Throws when
 * `source` lacks a position, a normal or a height.
 */
export function tileTerrain(source: THREE.BufferGeometry, toEcef: THREE.Matrix4): TileTerrain {
  const pos = source.getAttribute('position');
  const nrm = source.getAttribute('normal');
  const hgt = source.getAttribute('_height');
  if (!pos || !nrm || !hgt) throw new Error('a tile without POSITION, NORMAL or _HEIGHT');
  const e = toEcef.elements;
  // the tile's centre: where the mesh's own origin lands, in the planet frame
  const origin: V3 = [e[13]!, e[14]!, e[12]!];
  const n = pos.count;
  const positions = new Float32Array(3 * n);
  const high = new Float32Array(3 * n);
  const low = new Float32Array(3 * n);
  const normals = new Float32Array(3 * n);
  const nm = new THREE.Matrix3().getNormalMatrix(toEcef).elements;
  for (let i = 0; i < n; i++) {
    const x = pos.getX(i);
    const y = pos.getY(i);
    const z = pos.getZ(i);
    // ECEF, f64
    const ex = e[0]! * x + e[4]! * y + e[8]! * z + e[12]!;
    const ey = e[1]! * x + e[5]! * y + e[9]! * z + e[13]!;
    const ez = e[2]! * x + e[6]! * y + e[10]! * z + e[14]!;
    // the planet frame: (Y, Z, X) of ECEF
    const p0 = ey;
    const p1 = ez;
    const p2 = ex;
    const j = 3 * i;
    positions[j] = p0 - origin[0];
    positions[j + 1] = p1 - origin[1];
    positions[j + 2] = p2 - origin[2];
    high[j] = p0;
    high[j + 1] = p1;
    high[j + 2] = p2;
    low[j] = p0 - high[j]!;
    low[j + 1] = p1 - high[j + 1]!;
    low[j + 2] = p2 - high[j + 2]!;
    const nx = nrm.getX(i);
    const ny = nrm.getY(i);
    const nz = nrm.getZ(i);
    const mx = nm[0]! * nx + nm[3]! * ny + nm[6]! * nz;
    const my = nm[1]! * nx + nm[4]! * ny + nm[7]! * nz;
    const mz = nm[2]! * nx + nm[5]! * ny + nm[8]! * nz;
    const l = Math.hypot(mx, my, mz) || 1;
    normals[j] = my / l;
    normals[j + 1] = mz / l;
    normals[j + 2] = mx / l;
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  g.setAttribute('aPosHigh', new THREE.BufferAttribute(high, 3));
  g.setAttribute('aPosLow', new THREE.BufferAttribute(low, 3));
  g.setAttribute('normal', new THREE.BufferAttribute(normals, 3));
  // linear RGBA in u8 (normalised), as a chunk's and the glTF's COLOR_0
  const colour = source.getAttribute('color');
  const colours = new Uint8Array(4 * n).fill(255);
  if (colour) {
    for (let i = 0; i < n; i++) {
      for (let c = 0; c < Math.min(4, colour.itemSize); c++) {
        colours[4 * i + c] = Math.round(255 * Math.min(1, Math.max(0, colour.getComponent(i, c))));
      }
    }
  }
  g.setAttribute('aColor', new THREE.BufferAttribute(colours, 4, true));
  g.setAttribute('aHeight', scalars(hgt, n));
  g.setAttribute('aWaterDepth', scalars(source.getAttribute('_water_depth'), n));
  g.setAttribute('aMaterial', scalars(source.getAttribute('_material'), n));
  const index = source.getIndex();
  if (index) g.setIndex(new THREE.BufferAttribute((index.array as Uint16Array | Uint32Array).slice(), 1));
  g.computeBoundingSphere();
  g.computeBoundingBox();
  return { geometry: g, origin };
}

/** One `f32` a vertex from `attribute` (0 where there is none). */
function scalars(attribute: THREE.BufferAttribute | THREE.InterleavedBufferAttribute | undefined, n: number): THREE.BufferAttribute {
  const out = new Float32Array(n);
  if (attribute) for (let i = 0; i < n; i++) out[i] = attribute.getX(i);
  return new THREE.BufferAttribute(out, 1);
}

/**
 * The matrix of a tile's mesh drawn with `tileTerrain`'s geometry: its parents' matrices
 * (`parents`: from its tile's scene down to its parent, into ECEF) times it is the planet frame's
 * point `origin` + its vertex, in ECEF. Under the tiles' group (ECEF to the planet frame, then
 * -camera: tiles.ts `tilesGroupMatrix`) its world matrix is then the translation by
 * `origin` - camera, a chunk's.
 */
export function tileMeshMatrix(parents: THREE.Matrix4, origin: V3, out = new THREE.Matrix4()): THREE.Matrix4 {
  // the planet frame's (x, y, z) + origin as ECEF: (z, x, y) + ECEF's origin
  const placed = new THREE.Matrix4().set(0, 0, 1, origin[2], 1, 0, 0, origin[0], 0, 1, 0, origin[1], 0, 0, 0, 1);
  return out.copy(parents).invert().multiply(placed);
}

/**
 * The product of the matrices of `object`'s ancestors from `root` (included) down to `object`
 * (included), each brought up to date from its position, rotation and scale where three.js does
 * so: the object's place in `root`'s parent's frame.
 */
export function matrixWithin(object: THREE.Object3D, root: THREE.Object3D): THREE.Matrix4 {
  const m = new THREE.Matrix4();
  for (let o: THREE.Object3D | null = object; o; o = o.parent) {
    if (o.matrixAutoUpdate) o.updateMatrix();
    m.premultiply(o.matrix);
    if (o === root) break;
  }
  return m;
}
