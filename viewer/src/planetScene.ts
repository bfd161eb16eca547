// The three.js side: chunk meshes, the sea, debug overlays and materials, all drawn around a
// floating origin. Every frame `place(camera)` sets each object's position to
// (its planet-frame origin - camera position), computed in f64; the three.js camera stays at the
// render origin, so nothing jitters at any planet radius.

import * as THREE from 'three';
import { useBvh } from './raycast';
import { Atmosphere, type SkySettings } from './atmosphere';
import { SPACE, type AtmosphereParams } from './atmosphereModel';
import type { DecodedChunk } from './chunkDecode';
import { boundaryEdges } from './boundaryEdges';
import { modPositive, relativeToCamera, splitHighLow, splitPositions, type V3 } from './frames';
import { imageryCellMetres, type ImageryInfo } from './imagery';
import { reliefCellMetres, type ReliefGrid } from './relief';
import { materialUniforms } from './materials';
import { pushUniform, pushUniforms } from './pictureKey';
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

/** The stencil value every terrain pixel writes; the sea disk draws only where it is not. */
export const TERRAIN_STENCIL = 1;

export const SKY_COLOUR = new THREE.Color(0.52, 0.66, 0.85); // linear, for aerial perspective
/** Background near the ground (a clear sky) and far out (space), linear RGB. */
const SKY_BACKGROUND = new THREE.Color(0.23, 0.42, 0.75);
const SPACE_BACKGROUND = new THREE.Color(...SPACE);

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
  /**
   * Test mode: the ground in one colour lit by the sun, without its materials and noises (the
   * same geometry and depth). For pictures that check the geometry (cracks and holes with
   * `backfaces`): under a software renderer the full shading is most of a frame's cost.
   */
  plain: boolean;
  /** Sun and sky light and haze (off, test mode: the ground's colour alone, the same at every level). */
  lighting: boolean;
  /** The sea: water where the ground is below the datum, and the sea disk (off, test mode: neither). */
  sea: boolean;
}

/** A vertex of a chunk shown (`PlanetScene.sampleVertices`). */
export interface SampledVertex {
  /** Planet frame, metres (f64: the chunk origin plus the f32 offset). */
  point: V3;
  /** Metres above the datum, and the lowest height of the triangles around it. */
  height: number;
  ringMin: number;
  /** Unit normal. */
  normal: V3;
  key: string;
  level: number;
}

export class PlanetScene {
  readonly scene = new THREE.Scene();
  private readonly terrainGroup = new THREE.Group();
  private readonly chunks = new Map<string, ChunkObject>();
  /** Every terrain material not disposed yet (`terrainMaterial`): the chunks' and the 3D Tiles mode's tiles'. */
  private readonly terrainMaterials = new Set<THREE.ShaderMaterial>();
  /** The sky and the aerial perspective (atmosphere.ts); its uniforms are in every terrain material. */
  readonly atmosphere = new Atmosphere();
  private readonly shared = {
    ...this.atmosphere.uniforms,
    uSunDir: { value: new THREE.Vector3(0, 1, 0) },
    // the eye's place in high and low f32 parts (frames.ts splitPositions)
    uEyeHigh: { value: new THREE.Vector3() },
    uEyeLow: { value: new THREE.Vector3() },
    uMatA: { value: Array.from({ length: 10 }, () => new THREE.Vector3(1, 1, 1)) },
    uMatB: { value: Array.from({ length: 10 }, () => new THREE.Vector3(1, 1, 1)) },
    uMatHeights: { value: new THREE.Vector4(1e30, 0, 1e30, 1e30) },
    uMatSnow: { value: new THREE.Vector4(1e30, 1, 1, 1) },
    uMatShares: { value: new THREE.Vector4(0, 0, -1e30, 0) },
    uMatSlopes: { value: new THREE.Vector4(0.68, 0.5, 2, 0) },
    uMatExtra: { value: new THREE.Vector2(0, 1) },
    uMacroFreq: { value: 1 },
    uDatum: { value: 1 },
    uDetailFreq: { value: 0.25 },
    uLighting: { value: 1 },
    uHasSea: { value: 0 },
    uWater: { value: 1 },
    uSeaColour: { value: new THREE.Vector3(0.02, 0.13, 0.3) },
    uImagery: { value: null as THREE.Texture | null },
    uHasImagery: { value: 0 },
    uImageryExtent: { value: new THREE.Vector4(-Math.PI, Math.PI, -Math.PI / 2, Math.PI / 2) },
    uImageryCell: { value: 1 },
    uRelief: { value: null as THREE.Texture | null },
    uHasRelief: { value: 0 },
    uReliefAxes: { value: new THREE.Vector4(-Math.PI, 1, -Math.PI / 2, 1) },
    uReliefGrid: { value: new THREE.Vector4(1, 1, 0, 0) },
    uReliefScale: { value: new THREE.Vector2(1, 1) },
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
  /** The camera of the last `place` (planet frame): where a chunk added since is placed at once. */
  private camera: V3 | null = null;
  private flags: DebugFlags = {
    wireframe: false,
    faceColours: false,
    borders: false,
    backfaces: false,
    plain: false,
    lighting: true,
    sea: true,
  };
  /** A 1 x 1 stand-in for the imagery texture while a planet has none. */
  private readonly noImagery = new THREE.DataTexture(new Uint8Array([128, 128, 128, 255]), 1, 1);
  /** A 1 x 1 stand-in for the relief texture while a planet has none. */
  private readonly noRelief = new THREE.DataTexture(new Float32Array([0]), 1, 1, THREE.RedFormat, THREE.FloatType);
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
      uSeaColour: this.shared.uSeaColour,
      uSkyColour: this.shared.uSkyColour,
      uWaterDeep: this.shared.uWaterDeep,
      uFogDistance: this.shared.uFogDistance,
      uLighting: this.shared.uLighting,
      ...this.atmosphere.uniforms,
    },
    transparent: true,
    depthWrite: false,
    side: THREE.FrontSide,
    // only where no terrain is drawn: the terrain draws the sea itself over ground below the
    // datum, and the disk can never cover land (however coarse the mesh, however far the view)
    stencilWrite: true,
    stencilRef: TERRAIN_STENCIL,
    stencilFunc: THREE.NotEqualStencilFunc,
    stencilFail: THREE.KeepStencilOp,
    stencilZFail: THREE.KeepStencilOp,
    stencilZPass: THREE.KeepStencilOp,
  });

  private readonly background = SPACE_BACKGROUND.clone();
  /**
   * Changes to what is drawn that neither the camera nor a uniform shows (objects added, removed,
   * shown or hidden, materials switched), counted for the picture's key (see `pushPictureKey`).
   */
  private changes = 0;

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
    this.noImagery.needsUpdate = true;
    this.noRelief.needsUpdate = true;
    this.shared.uRelief.value = this.noRelief;
    this.scene.background = this.background;
    this.scene.add(this.terrainGroup);
    this.scene.add(this.atmosphere.sky);
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

  /**
   * Pushes onto `out` what the picture of this scene depends on besides the camera: the changes
   * counted, the background, every shading uniform (the atmosphere's too), the sea's side and the
   * brush cursor. Two frames with the same key (and the same camera) draw the same picture.
   */
  pushPictureKey(out: number[]): void {
    out.push(this.changes, this.background.r, this.background.g, this.background.b);
    pushUniforms(out, this.shared);
    out.push(this.seaMaterial.side, this.sea?.visible ? 1 : 0, this.atmosphere.sky.visible ? 1 : 0);
    const c = this.cursor;
    if (c.visible) {
      out.push(1, ...c.position.toArray(), ...c.scale.toArray(), ...c.quaternion.toArray());
      pushUniform(out, this.cursorBallMaterial.color);
    } else {
      out.push(0);
    }
  }

  /** The background colour drawn now, as 8-bit sRGB (what a screenshot shows where nothing is drawn). */
  backgroundRgb(): [number, number, number] {
    const c = this.background.clone().convertLinearToSRGB();
    return [Math.round(c.r * 255), Math.round(c.g * 255), Math.round(c.b * 255)];
  }

  /** Sets the planet's shading parameters and rebuilds the sea (chunks are cleared separately). */
  setPlanet(params: PlanetParams): void {
    this.params = params;
    this.changes++;
    const s = this.shared;
    const m = materialUniforms(params.materials);
    for (let i = 0; i < s.uMatA.value.length; i++) {
      s.uMatA.value[i]!.fromArray(m.colourA, 3 * i);
      s.uMatB.value[i]!.fromArray(m.colourB, 3 * i);
    }
    s.uMatHeights.value.set(...m.heights);
    s.uMatSnow.value.set(...m.snow);
    s.uMatShares.value.set(...m.shares);
    s.uMatSlopes.value.set(...m.slopes);
    s.uMatExtra.value.set(...m.extra);
    s.uMacroFreq.value = params.macroFreq;
    s.uDatum.value = params.shape.datum;
    s.uDetailFreq.value = params.detailFreq;
    s.uHasSea.value = params.seaRadius !== null ? 1 : 0;
    s.uWaterScale.value = params.waterScale;
    s.uNoiseFreq.value = params.noiseFreq;
    for (const m of this.terrainMaterials) this.originMod(m);
    this.setImagery(null, null);
    this.setRelief(null, null);
    this.syncFog();
    this.removeSea();
    if (params.seaRadius !== null) {
      const geometry = new THREE.BufferGeometry();
      this.sea = new THREE.Mesh(geometry, this.seaMaterial);
      this.sea.name = 'sea';
      this.sea.frustumCulled = false;
      this.sea.renderOrder = 10; // after the terrain
      this.sea.matrixAutoUpdate = true;
      this.sea.visible = !this.flags.backfaces && this.flags.sea;
      this.scene.add(this.sea);
    }
  }

  private removeSea(): void {
    this.changes++;
    if (this.sea) {
      this.scene.remove(this.sea);
      this.sea.geometry.dispose();
      this.sea = null;
    }
    this.seaDisk = null;
    this.seaBuiltFor = null;
  }

  /** The planet's atmosphere (null: none, the black sky of space). */
  setAtmosphere(params: AtmosphereParams | null): void {
    this.atmosphere.setPlanet(params);
    this.syncFog();
  }

  /** Changes the sky settings given (atmosphere, sun); returns them all. */
  setSkySettings(settings: Partial<SkySettings>): SkySettings {
    const all = this.atmosphere.set(settings);
    this.syncFog();
    return all;
  }

  /** The old haze toward a constant sky colour far away, where the atmosphere is not drawn. */
  private syncFog(): void {
    this.shared.uFogDistance.value = this.atmosphere.drawn() || !this.params ? 1e30 : 6 * this.params.shape.outer;
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
    const split = splitPositions(chunk.origin, chunk.positions, chunk.positionsLow);
    g.setAttribute('aPosHigh', new THREE.BufferAttribute(split.high, 3));
    g.setAttribute('aPosLow', new THREE.BufferAttribute(split.low, 3));
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
    const material = this.terrainMaterial(origin, chunk.face);
    const mesh = new THREE.Mesh(g, material);
    mesh.name = key;
    useBvh(mesh);
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
    // placed at once: a chunk added after this frame's `place` kept the render origin until the
    // next one, and three.js's frustum culling dropped it from the frame that drew it; with
    // render on demand no later frame drew it again (a hole over the sea disk)
    if (this.camera) {
      placeChunk(obj, this.camera);
      mesh.updateMatrixWorld();
    }
    this.changes++;
    if (this.flags.borders) this.addBorders(obj, chunk.indices, chunk.vertexCount);
  }

  /**
   * A terrain material (the terrain shader, the uniforms every terrain material shares, the debug
   * flags) for a mesh drawn as a chunk: its `position` relative to `origin` (planet frame, f64),
   * its place in `aPosHigh` and `aPosLow`, and a chunk's attributes (`addChunk`); `face` picks the
   * debug colour. The chunks' and the 3D Tiles mode's tiles' (tileTerrain.ts); kept up to date
   * with the debug flags and the planet until disposed.
   */
  terrainMaterial(origin: V3, face: number): THREE.ShaderMaterial {
    const material = new THREE.ShaderMaterial({
      vertexShader: terrainVertex,
      fragmentShader: terrainFragment,
      uniforms: {
        ...this.shared,
        uOrigin: { value: new THREE.Vector3(origin[0], origin[1], origin[2]) },
        uOriginMod: { value: new THREE.Vector3() },
        uOriginModDetail: { value: new THREE.Vector3() },
        uFaceColour: { value: new THREE.Vector3(...(FACE_COLOURS[face] ?? [1, 1, 1])) },
      },
      // every terrain pixel marks the stencil: the sea disk is not drawn over it
      stencilWrite: true,
      stencilRef: TERRAIN_STENCIL,
      stencilFunc: THREE.AlwaysStencilFunc,
      stencilZPass: THREE.ReplaceStencilOp,
    });
    material.userData['origin'] = [origin[0], origin[1], origin[2]];
    this.originMod(material);
    this.applyFlags(material);
    this.terrainMaterials.add(material);
    material.addEventListener('dispose', () => this.terrainMaterials.delete(material));
    return material;
  }

  /** A terrain material's origin modulo the periods of the planet's noises (computed in f64). */
  private originMod(material: THREE.ShaderMaterial): void {
    const origin = material.userData['origin'] as V3;
    const u = material.uniforms;
    const period = this.params?.noisePeriod ?? 1;
    const detailPeriod = this.params?.detailPeriod ?? 1;
    (u['uOriginMod']!.value as THREE.Vector3).set(...(origin.map((x) => modPositive(x, period)) as V3));
    (u['uOriginModDetail']!.value as THREE.Vector3).set(...(origin.map((x) => modPositive(x, detailPeriod)) as V3));
  }

  /** A terrain material drawn as the debug flags say. */
  private applyFlags(material: THREE.ShaderMaterial): void {
    const flags = this.flags;
    material.wireframe = flags.wireframe;
    // with the back-face flag on, faces seen from inside the solid are drawn (in magenta)
    material.side = flags.backfaces ? THREE.DoubleSide : THREE.FrontSide;
    material.defines = plainDefines(flags.plain);
    material.polygonOffset = flags.borders;
    material.polygonOffsetFactor = 1;
    material.polygonOffsetUnits = 1;
    material.needsUpdate = true;
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
    this.changes++;
  }

  clearChunks(): void {
    for (const key of [...this.chunks.keys()]) this.removeChunk(key);
  }

  setDebug(flags: Partial<DebugFlags>): void {
    const next = { ...this.flags, ...flags };
    const bordersChanged = next.borders !== this.flags.borders;
    this.changes++;
    this.flags = next;
    this.shared.uDebugFace.value = next.faceColours ? 1 : 0;
    this.shared.uBackfaceFlag.value = next.backfaces ? 1 : 0;
    this.shared.uLighting.value = next.lighting ? 1 : 0;
    // the test modes draw no atmosphere: back faces, and the ground's colour without lighting
    this.atmosphere.setSuppressed(next.backfaces || !next.lighting);
    this.syncFog();
    this.shared.uWater.value = next.sea ? 1 : 0;
    if (this.sea) this.sea.visible = !next.backfaces && next.sea;
    for (const m of this.terrainMaterials) this.applyFlags(m);
    for (const obj of this.chunks.values()) {
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
    this.camera = [camera[0], camera[1], camera[2]];
    const eye = splitHighLow(camera);
    this.shared.uEyeHigh.value.set(...eye.high);
    this.shared.uEyeLow.value.set(...eye.low);
    const rel: V3 = [0, 0, 0];
    for (const obj of this.chunks.values()) placeChunk(obj, camera, rel);
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
      this.changes++;
      const below = Math.hypot(camera[0], camera[1], camera[2]) < R;
      this.seaMaterial.side = below ? THREE.BackSide : THREE.FrontSide;
    }
    const rel = relativeToCamera(this.seaDisk.origin, camera);
    this.sea.position.set(rel[0], rel[1], rel[2]);
  }

  /**
   * Draws the chunks, or not (the 3D Tiles mode draws the planet from its tiles instead); hidden,
   * they stay in the scene, and the streamer keeps what it loaded for when they show again.
   */
  setChunksVisible(visible: boolean): void {
    if (this.terrainGroup.visible === visible) return;
    this.terrainGroup.visible = visible;
    this.changes++;
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

  /**
   * Drapes `texture` (the picture `info` describes) on the terrain, or none when null. The
   * texture is the caller's (disposed by it).
   */
  setImagery(texture: THREE.Texture | null, info: ImageryInfo | null): void {
    const s = this.shared;
    if (!texture || !info || !this.params) {
      s.uImagery.value = this.noImagery;
      s.uHasImagery.value = 0;
      return;
    }
    const rad = Math.PI / 180;
    const [west, east, south, north] = info.extent;
    s.uImagery.value = texture;
    s.uHasImagery.value = 1;
    s.uImageryExtent.value.set(west * rad, east * rad, south * rad, north * rad);
    s.uImageryCell.value = imageryCellMetres(info, this.params.shape.datum);
  }

  /**
   * Takes the materials' heights from `texture` (the grid `grid` describes) where a pixel spans
   * a good part of a data cell, or from the mesh alone when null. The texture is the caller's.
   */
  setRelief(texture: THREE.Texture | null, grid: ReliefGrid | null): void {
    const s = this.shared;
    if (!texture || !grid || !this.params) {
      s.uRelief.value = this.noRelief;
      s.uHasRelief.value = 0;
      return;
    }
    const rad = Math.PI / 180;
    s.uRelief.value = texture;
    s.uHasRelief.value = 1;
    s.uReliefAxes.value.set(grid.lonFirst * rad, grid.lonStep * rad, grid.latFirst * rad, grid.latStep * rad);
    s.uReliefGrid.value.set(grid.width, grid.height, grid.wraps ? 1 : 0, (grid.clampSouth ? 1 : 0) + (grid.clampNorth ? 2 : 0));
    s.uReliefScale.value.set(grid.scale, reliefCellMetres(grid, this.params.shape.datum));
  }

  /**
   * Up to `count` vertices of the chunks shown, spread evenly over all of them (test hook): where
   * they are, their height and the lowest height of the triangles around them. The same vertices
   * whatever order the chunks arrived in: the chunks are taken in the order of their keys, and
   * the k-th of `count` samples is the vertex at `k * total / count` of them all. (A whole-number
   * stride of 1 when there were fewer than twice `count` vertices took the first `count` in
   * arrival order, most of the view or little of it: "only 68 land places in view".)
   */
  sampleVertices(count: number): SampledVertex[] {
    const objs = [...this.chunks.values()].sort((a, b) => (a.key < b.key ? -1 : a.key > b.key ? 1 : 0));
    const total = objs.reduce((n, o) => n + o.mesh.geometry.getAttribute('position').count, 0);
    const out: SampledVertex[] = [];
    if (total === 0 || count <= 0) return out;
    const samples = Math.min(count, total);
    const step = total / samples;
    // the next sample's index among all vertices, and the vertices of the chunks before this one
    let k = 0;
    let seen = 0;
    for (const o of objs) {
      const g = o.mesh.geometry;
      const pos = g.getAttribute('position');
      const n = pos.count;
      let next = Math.floor(k * step);
      if (next >= seen + n) {
        seen += n;
        continue;
      }
      const nrm = g.getAttribute('normal');
      const hgt = g.getAttribute('aHeight');
      const index = g.getIndex();
      // the lowest height of the triangles around each vertex
      const ring = new Float64Array(n).fill(Infinity);
      if (index) {
        const ix = index.array as ArrayLike<number>;
        for (let t = 0; t + 2 < ix.length; t += 3) {
          const a = ix[t]!;
          const b = ix[t + 1]!;
          const c = ix[t + 2]!;
          const lo = Math.min(hgt.getX(a), hgt.getX(b), hgt.getX(c));
          ring[a] = Math.min(ring[a]!, lo);
          ring[b] = Math.min(ring[b]!, lo);
          ring[c] = Math.min(ring[c]!, lo);
        }
      }
      for (; k < samples && next < seen + n; k++, next = Math.floor(k * step)) {
        const i = next - seen;
        if (ring[i] === Infinity) continue;
        const nx = nrm.getX(i);
        const ny = nrm.getY(i);
        const nz = nrm.getZ(i);
        const nl = Math.hypot(nx, ny, nz) || 1;
        out.push({
          point: [o.origin[0] + pos.getX(i), o.origin[1] + pos.getY(i), o.origin[2] + pos.getZ(i)],
          height: hgt.getX(i),
          ringMin: ring[i]!,
          normal: [nx / nl, ny / nl, nz / nl],
          key: o.key,
          level: (o.mesh.userData['level'] as number | undefined) ?? 0,
        });
      }
      seen += n;
    }
    return out;
  }

  seaVisible(): boolean {
    return this.sea !== null;
  }

  dispose(): void {
    this.clearChunks();
    this.removeSea();
    this.seaMaterial.dispose();
    this.atmosphere.dispose();
    this.noImagery.dispose();
    this.noRelief.dispose();
    this.borderMaterial.dispose();
    this.cursorBallMaterial.dispose();
    this.cursorRingMaterial.dispose();
  }
}

/** Floating origin: a chunk's mesh at (its origin - camera), computed in f64 (`rel`: scratch). */
function placeChunk(obj: ChunkObject, camera: V3, rel: V3 = [0, 0, 0]): void {
  relativeToCamera(obj.origin, camera, rel);
  obj.mesh.position.set(rel[0], rel[1], rel[2]);
}

/** The terrain material's defines: `PMC_PLAIN` draws the ground in one lit colour (`DebugFlags.plain`). */
function plainDefines(plain: boolean): Record<string, string> {
  return plain ? { PMC_PLAIN: '' } : {};
}
