// The three.js side: chunk meshes, the sea, debug overlays and materials, all drawn around a
// floating origin. Every frame `place(camera)` sets each object's position to
// (its planet-frame origin - camera position), computed in f64; the three.js camera stays at the
// render origin, so nothing jitters at any planet radius.

import * as THREE from 'three';
import type { DecodedChunk } from './chunkDecode';
import { boundaryEdges } from './boundaryEdges';
import { modPositive, relativeToCamera, type V3 } from './frames';
import type { PlanetParams } from './planetParams';
import { buildSeaDisk, seaDiskStale, type SeaDisk } from './seaGeometry';
import { seaFragment, seaVertex, terrainFragment, terrainVertex } from './shaders';

/** Debug colours of the six faces (top, bottom, north, south, east, west), linear RGB. */
export const FACE_COLOURS: [number, number, number][] = [
  [0.9, 0.25, 0.2],
  [0.2, 0.75, 0.3],
  [0.2, 0.4, 0.95],
  [0.95, 0.8, 0.2],
  [0.85, 0.3, 0.85],
  [0.2, 0.85, 0.85],
];

export const SKY_COLOUR = new THREE.Color(0.52, 0.66, 0.85); // linear, for aerial perspective
/** Background near the ground (a clear sky) and far out (space), linear RGB. */
const SKY_BACKGROUND = new THREE.Color(0.23, 0.42, 0.75);
const SPACE_BACKGROUND = new THREE.Color(0.004, 0.006, 0.012);

interface ChunkObject {
  key: string;
  /** The seams mask of the variant shown. */
  seams: number;
  origin: V3;
  face: number;
  mesh: THREE.Mesh<THREE.BufferGeometry, THREE.ShaderMaterial>;
  borders: THREE.LineSegments | null;
  triangles: number;
}

export interface DebugFlags {
  wireframe: boolean;
  faceColours: boolean;
  borders: boolean;
  /**
   * Test mode: back faces drawn in pure magenta (#ff00ff), no sea. From outside a closed surface no
   * back face can be seen, so a magenta pixel is a crack or a hole.
   */
  backfaces: boolean;
}

export class PlanetScene {
  readonly scene = new THREE.Scene();
  private readonly terrainGroup = new THREE.Group();
  private readonly chunks = new Map<string, ChunkObject>();
  private readonly shared = {
    uSunDir: { value: new THREE.Vector3(0, 1, 0) },
    uPaletteA: { value: new THREE.Vector3(1, 1, 1) },
    uPaletteB: { value: new THREE.Vector3(1, 1, 1) },
    uPaletteStrength: { value: 0.35 },
    uBandHeight: { value: 100 },
    uSnowHeight: { value: 60 },
    uSnowAmount: { value: 1 },
    uWaterShallow: { value: new THREE.Vector3(0.55, 0.8, 0.85) },
    uWaterDeep: { value: new THREE.Vector3(0.01, 0.05, 0.14) },
    uWaterScale: { value: 10 },
    uDebugFace: { value: 0 },
    uNoiseFreq: { value: 0.01 },
    uSkyColour: { value: new THREE.Vector3(SKY_COLOUR.r, SKY_COLOUR.g, SKY_COLOUR.b) },
    uFogDistance: { value: 10000 },
    uBackfaceFlag: { value: 0 },
  };
  private params: PlanetParams | null = null;
  private flags: DebugFlags = { wireframe: false, faceColours: false, borders: false, backfaces: false };
  private readonly borderMaterial = new THREE.LineBasicMaterial({
    color: 0xffee33,
    depthTest: true,
    transparent: false,
  });

  private sea: THREE.Mesh<THREE.BufferGeometry, THREE.ShaderMaterial> | null = null;
  private seaDisk: SeaDisk | null = null;
  private seaBuiltFor: V3 | null = null;
  private readonly seaMaterial = new THREE.ShaderMaterial({
    vertexShader: seaVertex,
    fragmentShader: seaFragment,
    uniforms: {
      uSunDir: this.shared.uSunDir,
      uSeaColour: { value: new THREE.Vector3(0.02, 0.13, 0.3) },
      uSkyColour: this.shared.uSkyColour,
      uFogDistance: this.shared.uFogDistance,
    },
    transparent: true,
    depthWrite: false,
    side: THREE.FrontSide,
  });

  private readonly background = SPACE_BACKGROUND.clone();

  /** The brush cursor: a translucent ball of the brush radius and a ring across it. */
  private readonly cursor = new THREE.Group();
  private readonly cursorBallMaterial = new THREE.MeshBasicMaterial({
    color: 0xffffff,
    transparent: true,
    opacity: 0.22,
    depthWrite: false,
  });
  private readonly cursorRingMaterial = new THREE.LineBasicMaterial({
    color: 0xffffff,
    transparent: true,
    opacity: 0.9,
    depthTest: false,
    depthWrite: false,
  });

  constructor() {
    this.scene.background = this.background;
    this.scene.add(this.terrainGroup);
    const ball = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16), this.cursorBallMaterial);
    ball.renderOrder = 20; // after the sea
    const ringPoints: THREE.Vector3[] = [];
    for (let i = 0; i < 64; i++) {
      const a = (i / 64) * Math.PI * 2;
      ringPoints.push(new THREE.Vector3(Math.cos(a), 0, Math.sin(a)));
    }
    const ring = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(ringPoints), this.cursorRingMaterial);
    ring.renderOrder = 21;
    this.cursor.add(ball, ring);
    this.cursor.name = 'brush-cursor';
    this.cursor.visible = false;
    this.scene.add(this.cursor);
  }

  /**
   * Shows the brush cursor at `at` (render space: relative to the camera) with `radius` metres,
   * its ring across the local vertical `up`, in `colour` (linear RGB); null hides it.
   */
  setBrushCursor(at: V3 | null, radius = 1, up: V3 = [0, 1, 0], colour: [number, number, number] = [1, 1, 1]): void {
    if (!at) {
      this.cursor.visible = false;
      return;
    }
    this.cursor.visible = true;
    this.cursor.position.set(at[0], at[1], at[2]);
    this.cursor.scale.setScalar(Math.max(1e-3, radius));
    this.cursor.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(up[0], up[1], up[2]).normalize());
    this.cursorBallMaterial.color.setRGB(colour[0], colour[1], colour[2]);
    this.cursorRingMaterial.color.setRGB(colour[0], colour[1], colour[2]);
  }

  brushCursorVisible(): boolean {
    return this.cursor.visible;
  }

  /** Background between space (0) and a clear sky seen from the ground (1). */
  setSky(amount: number): void {
    const t = Math.max(0, Math.min(1, amount));
    this.background.copy(SPACE_BACKGROUND).lerp(SKY_BACKGROUND, t);
  }

  /** The background colour drawn now, as 8-bit sRGB (what a screenshot shows where nothing is drawn). */
  backgroundRgb(): [number, number, number] {
    const c = this.background.clone().convertLinearToSRGB();
    return [Math.round(c.r * 255), Math.round(c.g * 255), Math.round(c.b * 255)];
  }

  /** Sets the planet's shading parameters and rebuilds the sea (chunks are cleared separately). */
  setPlanet(params: PlanetParams): void {
    this.params = params;
    const s = this.shared;
    s.uPaletteA.value.set(...params.paletteA);
    s.uPaletteB.value.set(...params.paletteB);
    s.uBandHeight.value = params.bandHeight;
    s.uSnowHeight.value = params.snowHeight;
    s.uSnowAmount.value = params.snowAmount;
    s.uWaterScale.value = params.waterScale;
    s.uNoiseFreq.value = params.noiseFreq;
    s.uFogDistance.value = 6 * params.shape.outer;
    this.removeSea();
    if (params.seaRadius !== null) {
      const geometry = new THREE.BufferGeometry();
      this.sea = new THREE.Mesh(geometry, this.seaMaterial);
      this.sea.name = 'sea';
      this.sea.frustumCulled = false;
      this.sea.renderOrder = 10; // after the terrain
      this.sea.matrixAutoUpdate = true;
      this.sea.visible = !this.flags.backfaces;
      this.scene.add(this.sea);
    }
  }

  private removeSea(): void {
    if (this.sea) {
      this.scene.remove(this.sea);
      this.sea.geometry.dispose();
      this.sea = null;
    }
    this.seaDisk = null;
    this.seaBuiltFor = null;
  }

  /** Sun direction (planet frame, unit). */
  setSun(dir: V3): void {
    this.shared.uSunDir.value.set(dir[0], dir[1], dir[2]).normalize();
  }

  /** Shows variant `seams` of chunk `key`, replacing the one shown; an empty chunk shows nothing. */
  addChunk(key: string, seams: number, chunk: DecodedChunk): void {
    this.removeChunk(key);
    if (chunk.indexCount === 0 || !this.params) return;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(chunk.positions, 3));
    g.setAttribute('normal', new THREE.BufferAttribute(chunk.normals, 3, true));
    g.setAttribute('aColor', new THREE.BufferAttribute(chunk.colors, 4, true));
    g.setAttribute('aHeight', new THREE.BufferAttribute(chunk.heights, 1));
    g.setAttribute('aWaterDepth', new THREE.BufferAttribute(chunk.waterDepths, 1));
    g.setAttribute('aMaterial', new THREE.BufferAttribute(chunk.materials, 1));
    g.setIndex(new THREE.BufferAttribute(chunk.indices, 1));
    const origin = chunk.origin;
    // bounds of the vertices, relative to the chunk origin (for three.js's frustum culling)
    g.computeBoundingSphere();
    g.computeBoundingBox();

    const period = this.params.noisePeriod;
    const material = new THREE.ShaderMaterial({
      vertexShader: terrainVertex,
      fragmentShader: terrainFragment,
      uniforms: {
        ...this.shared,
        uOrigin: { value: new THREE.Vector3(origin[0], origin[1], origin[2]) },
        uOriginMod: {
          value: new THREE.Vector3(
            modPositive(origin[0], period),
            modPositive(origin[1], period),
            modPositive(origin[2], period),
          ),
        },
        uFaceColour: { value: new THREE.Vector3(...(FACE_COLOURS[chunk.face] ?? [1, 1, 1])) },
      },
      wireframe: this.flags.wireframe,
      // with the back-face flag on, faces seen from inside the solid are drawn (in magenta)
      side: this.flags.backfaces ? THREE.DoubleSide : THREE.FrontSide,
    });
    if (this.flags.borders) {
      material.polygonOffset = true;
      material.polygonOffsetFactor = 1;
      material.polygonOffsetUnits = 1;
    }
    const mesh = new THREE.Mesh(g, material);
    mesh.name = key;
    mesh.userData['seams'] = seams;
    mesh.userData['level'] = chunk.level;
    mesh.frustumCulled = true;
    mesh.matrixAutoUpdate = true;
    const obj: ChunkObject = {
      key,
      seams,
      origin,
      face: chunk.face,
      mesh,
      borders: null,
      triangles: chunk.indexCount / 3,
    };
    this.chunks.set(key, obj);
    this.terrainGroup.add(mesh);
    if (this.flags.borders) this.addBorders(obj, chunk.indices, chunk.vertexCount);
  }

  private addBorders(obj: ChunkObject, indices: ArrayLike<number>, vertexCount: number): void {
    const edges = boundaryEdges(indices, vertexCount);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', obj.mesh.geometry.getAttribute('position'));
    g.setIndex(new THREE.BufferAttribute(edges, 1));
    g.boundingSphere = obj.mesh.geometry.boundingSphere!.clone();
    const lines = new THREE.LineSegments(g, this.borderMaterial);
    lines.name = `${obj.key}#borders`;
    obj.mesh.add(lines);
    obj.borders = lines;
  }

  private removeBorders(obj: ChunkObject): void {
    if (!obj.borders) return;
    obj.mesh.remove(obj.borders);
    obj.borders.geometry.dispose();
    obj.borders = null;
  }

  removeChunk(key: string): void {
    const obj = this.chunks.get(key);
    if (!obj) return;
    this.removeBorders(obj);
    this.terrainGroup.remove(obj.mesh);
    obj.mesh.geometry.dispose();
    obj.mesh.material.dispose();
    this.chunks.delete(key);
  }

  clearChunks(): void {
    for (const key of [...this.chunks.keys()]) this.removeChunk(key);
  }

  setDebug(flags: Partial<DebugFlags>): void {
    const next = { ...this.flags, ...flags };
    const bordersChanged = next.borders !== this.flags.borders;
    this.flags = next;
    this.shared.uDebugFace.value = next.faceColours ? 1 : 0;
    this.shared.uBackfaceFlag.value = next.backfaces ? 1 : 0;
    if (this.sea) this.sea.visible = !next.backfaces;
    for (const obj of this.chunks.values()) {
      const m = obj.mesh.material;
      m.wireframe = next.wireframe;
      m.side = next.backfaces ? THREE.DoubleSide : THREE.FrontSide;
      m.polygonOffset = next.borders;
      m.polygonOffsetFactor = 1;
      m.polygonOffsetUnits = 1;
      m.needsUpdate = true;
      if (bordersChanged) {
        if (next.borders) {
          const index = obj.mesh.geometry.getIndex();
          if (index) {
            this.addBorders(obj, index.array as ArrayLike<number>, obj.mesh.geometry.getAttribute('position').count);
          }
        } else {
          this.removeBorders(obj);
        }
      }
    }
  }

  debug(): DebugFlags {
    return { ...this.flags };
  }

  /** Floating origin: places every object relative to the camera (f64 in, small f32 out). */
  place(camera: V3): void {
    const rel: V3 = [0, 0, 0];
    for (const obj of this.chunks.values()) {
      relativeToCamera(obj.origin, camera, rel);
      obj.mesh.position.set(rel[0], rel[1], rel[2]);
    }
    this.placeSea(camera);
  }

  private placeSea(camera: V3): void {
    if (!this.sea || !this.params || this.params.seaRadius === null) return;
    const R = this.params.seaRadius;
    if (!this.seaDisk || !this.seaBuiltFor || seaDiskStale(this.seaDisk, this.seaBuiltFor, camera, R)) {
      const disk = buildSeaDisk(camera, R, { underwaterRange: 4 * this.params.chunkWidth });
      const g = this.sea.geometry;
      g.dispose();
      const ng = new THREE.BufferGeometry();
      ng.setAttribute('position', new THREE.BufferAttribute(disk.positions, 3));
      ng.setAttribute('normal', new THREE.BufferAttribute(disk.normals, 3));
      ng.setIndex(new THREE.BufferAttribute(disk.indices, 1));
      this.sea.geometry = ng;
      this.seaDisk = disk;
      this.seaBuiltFor = [camera[0], camera[1], camera[2]];
      const below = Math.hypot(camera[0], camera[1], camera[2]) < R;
      this.seaMaterial.side = below ? THREE.BackSide : THREE.FrontSide;
    }
    const rel = relativeToCamera(this.seaDisk.origin, camera);
    this.sea.position.set(rel[0], rel[1], rel[2]);
  }

  /** Chunk meshes for raycasting (walk mode). */
  terrainMeshes(): THREE.Object3D[] {
    return this.terrainGroup.children;
  }

  chunkCount(): number {
    return this.chunks.size;
  }

  /** The variant shown of chunk `key` (its seams mask), or undefined when none is drawn. */
  shownSeams(key: string): number | undefined {
    return this.chunks.get(key)?.seams;
  }

  triangleCount(): number {
    let n = 0;
    for (const c of this.chunks.values()) n += c.triangles;
    return n;
  }

  seaVisible(): boolean {
    return this.sea !== null;
  }

  dispose(): void {
    this.clearChunks();
    this.removeSea();
    this.seaMaterial.dispose();
    this.borderMaterial.dispose();
    this.cursorBallMaterial.dispose();
    this.cursorRingMaterial.dispose();
  }
}
