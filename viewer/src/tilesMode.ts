// The 3D Tiles mode: the planet as `pmc serve` answers it in OGC 3D Tiles
// (docs/specs/tiles-v1.md, the `sphere` frame: the planet as the viewer draws it), loaded and
// drawn by NASA-AMMOS's 3DTilesRendererJS instead of the viewer's own chunk streaming, to compare
// the two paths on the same view. Loaded when the mode is first turned on (a chunk of the build of
// its own: the renderer and three.js's glTF loader).
//
// The tiles' group is placed around the floating origin every frame (tiles.ts: ECEF to the planet
// frame, then -camera, in f64). The tiles pick their levels with the viewer's own screen-space
// error target, in the drawing buffer's pixels as the viewer's selection counts them. Their glTF's
// MeshStandardMaterial keeps its vertex colours (COLOR_0) and is lit by lights that follow the
// viewer's sun, weighted as the terrain shader weighs its own light (shaders.ts: 0.15 ambient,
// 0.2 sky, 0.72 sun). As the terrain does, the tiles mark the stencil (the sea disk is not drawn
// over them) and draw the water themselves over the ground under the sea, from their
// `_WATER_DEPTH`: from orbit a coarse tile's triangles are chords that pass kilometres under the
// sea's sphere, and the sea disk, drawn by depth, covered most of the land.

import * as THREE from 'three';
import { TilesRenderer } from '3d-tiles-renderer';
import type { V3 } from './frames';
import { TERRAIN_STENCIL, type WaterUniforms } from './planetScene';
import { SEA_SURFACE } from './shaders';
import { TILES_QUIET_MS, tilesGroupMatrix, type TilesStats } from './tiles';

export interface TilesViewCallbacks {
  /** What is drawn changed (a tile shown or hidden): the picture and the ground under the camera. */
  onChange(): void;
  /** A tile or the tileset failed to load. */
  onError(message: string): void;
  /** The tileset was read: its `extras.pmc` (frame, terrain). */
  onTileset(frame: string | null, terrain: string | null): void;
}

/** The tiles of one TilesRenderer, their lights, and their place in the scene. */
export class TilesView {
  private readonly tiles: TilesRenderer;
  private readonly lights = new THREE.Group();
  private readonly sun = new THREE.DirectionalLight(0xffffff, 0.72 * Math.PI);
  private readonly sky = new THREE.HemisphereLight(0xffffff, 0x000000, 0.2 * Math.PI);
  private readonly ambient = new THREE.AmbientLight(0xffffff, 0.15 * Math.PI);
  private readonly matrix: number[] = new Array<number>(16);
  private readonly buffer = new THREE.Vector2();
  private quietSince: number | null = null;
  private frame: string | null = null;
  private terrain: string | null = null;
  private disposed = false;

  constructor(
    url: string,
    private readonly scene: THREE.Scene,
    private readonly water: WaterUniforms,
    private readonly callbacks: TilesViewCallbacks,
  ) {
    this.tiles = new TilesRenderer(url);
    const group = this.tiles.group;
    group.name = '3d-tiles';
    // the matrix is set from f64 numbers every frame (`place`), never from position and rotation
    group.matrixAutoUpdate = false;
    const changed = (): void => this.callbacks.onChange();
    this.tiles.addEventListener('tile-visibility-change', changed);
    this.tiles.addEventListener('load-model', (e) => {
      e.scene.traverse((o) => {
        const m = (o as THREE.Mesh).material;
        for (const material of Array.isArray(m) ? m : m ? [m] : []) this.prepare(material);
      });
      changed();
    });
    this.tiles.addEventListener('dispose-model', changed);
    this.tiles.addEventListener('load-root-tileset', (e) => {
      const pmc = (e.tileset.extras as { pmc?: { frame?: unknown; terrain?: unknown } } | undefined)?.pmc;
      this.frame = typeof pmc?.frame === 'string' ? pmc.frame : null;
      this.terrain = typeof pmc?.terrain === 'string' ? pmc.terrain : null;
      this.callbacks.onTileset(this.frame, this.terrain);
      changed();
    });
    this.tiles.addEventListener('load-error', (e) => {
      if (this.disposed) return;
      const what = e.error instanceof Error ? e.error.message : String(e.error);
      this.callbacks.onError(`3D Tiles: cannot load ${String(e.url)}: ${what}`);
    });
    this.scene.add(group);
    this.lights.name = '3d-tiles-lights';
    this.lights.add(this.sun, this.sky, this.ambient);
    this.scene.add(this.lights);
  }

  /**
   * A tile's material as the terrain's: it marks the stencil, and over ground under the sea it
   * draws the water as the terrain shader does (shaders.ts: the light kept through the water's
   * depth along the view, toward the deep water's colour, under the sea's surface).
   */
  private prepare(material: THREE.Material): void {
    material.stencilWrite = true;
    material.stencilRef = TERRAIN_STENCIL;
    material.stencilFunc = THREE.AlwaysStencilFunc;
    material.stencilZPass = THREE.ReplaceStencilOp;
    if (!(material instanceof THREE.MeshStandardMaterial)) return;
    material.customProgramCacheKey = () => 'pmc-tiles-water';
    material.onBeforeCompile = (shader) => {
      Object.assign(shader.uniforms, this.water);
      shader.vertexShader = shader.vertexShader
        .replace('#include <common>', `#include <common>\n${WATER_VERTEX_HEAD}`)
        .replace('#include <begin_vertex>', `#include <begin_vertex>\n${WATER_VERTEX}`);
      shader.fragmentShader = shader.fragmentShader
        .replace('#include <common>', `#include <common>\n${WATER_FRAGMENT_HEAD}`)
        .replace('#include <opaque_fragment>', `${WATER_FRAGMENT}\n#include <opaque_fragment>`);
    };
    material.needsUpdate = true;
  }

  /**
   * The meshes of the tiles drawn, for picking and the ground under the camera (render space, as
   * the chunks): the group's children. Not the group's own raycast, which also casts against the
   * tiles kept active out of view (3DTilesRendererJS parents them to the group without listing
   * them among its children): a hidden coarse tile thousands of kilometres away must not be taken
   * for the ground under the camera (with 0.4, whose active tiles kept stale world matrices, it
   * was, and set the near plane 10 km out: NASA-AMMOS/3DTilesRendererJS#1669).
   */
  meshes(): THREE.Object3D[] {
    const out: THREE.Object3D[] = [];
    for (const scene of this.tiles.group.children) {
      scene.traverse((o) => {
        if ((o as THREE.Mesh).isMesh) out.push(o);
      });
    }
    return out;
  }

  /** Floating origin: the group rotated into the planet frame and moved by -camera (f64). */
  place(camera: V3): void {
    const group = this.tiles.group;
    group.matrix.fromArray(tilesGroupMatrix(camera, this.matrix));
    group.matrixWorldNeedsUpdate = true;
  }

  /**
   * One frame with `camera` (placed, its matrices up to date): the lights follow the sun (`sun`,
   * unit, planet frame) over the place under the camera (`up`, unit), the tiles pick their levels
   * for the drawing buffer of `renderer` at `errorTarget` pixels and load what they lack.
   */
  update(camera: THREE.PerspectiveCamera, renderer: THREE.WebGLRenderer, errorTarget: number, sun: V3, up: V3, now: number): void {
    // (render space has the planet frame's axes: directions are the same in both)
    this.sun.position.set(sun[0], sun[1], sun[2]);
    this.sky.position.set(up[0], up[1], up[2]);
    this.lights.updateMatrixWorld(true);
    const tiles = this.tiles;
    tiles.errorTarget = errorTarget;
    tiles.setCamera(camera);
    // the drawing buffer's pixels, as the viewer's own selection counts them
    // (`setResolutionFromRenderer` takes the CSS size: the same at a device pixel ratio of 1)
    renderer.getDrawingBufferSize(this.buffer);
    tiles.setResolution(camera, this.buffer.x, this.buffer.y);
    tiles.update();
    if (this.busy()) this.quietSince = null;
    else this.quietSince ??= now;
  }

  /** Whether anything is queued, downloading, parsing or being prepared, or the tileset is not read. */
  private busy(): boolean {
    const t = this.tiles;
    const s = statsOf(t);
    return (
      t.root === null ||
      s.queued + s.downloading + s.parsing > 0 ||
      t.downloadQueue.running ||
      t.parseQueue.running ||
      t.processNodeQueue.running
    );
  }

  /** Nothing was queued, downloading or parsing for TILES_QUIET_MS at `now` (the tileset read). */
  settled(now: number): boolean {
    return this.quietSince !== null && now - this.quietSince >= TILES_QUIET_MS;
  }

  stats(now: number): TilesStats {
    const s = statsOf(this.tiles);
    return {
      on: true,
      running: true,
      loaded: s.loaded,
      visible: s.visible,
      active: s.active,
      queued: s.queued,
      downloading: s.downloading,
      parsing: s.parsing,
      failed: s.failed,
      quietMs: this.quietSince === null ? 0 : now - this.quietSince,
      settled: this.settled(now),
      frame: this.frame,
      terrain: this.terrain,
    };
  }

  /** Removes the tiles and their lights from the scene and frees what they hold. */
  dispose(): void {
    this.disposed = true;
    this.scene.remove(this.tiles.group);
    this.scene.remove(this.lights);
    this.tiles.dispose();
    this.sun.dispose();
    this.sky.dispose();
    this.ambient.dispose();
  }
}

/** The tiles' water, in three.js's MeshStandardMaterial (`TilesView.prepare`): the vertex's part. */
const WATER_VERTEX_HEAD = /* glsl */ `
attribute float _water_depth; // the tiles' _WATER_DEPTH: metres under the sea's surface
varying float vPmcWaterDepth;
varying vec3 vPmcRel;         // render space: relative to the eye
`;
const WATER_VERTEX = /* glsl */ `
vPmcWaterDepth = _water_depth;
vPmcRel = (modelMatrix * vec4(transformed, 1.0)).xyz;
`;
/** ...and the fragment's: after the lighting, as in the terrain shader. */
const WATER_FRAGMENT_HEAD = /* glsl */ `
uniform float uWater;
uniform vec3 uWaterShallow;
uniform vec3 uWaterDeep;
uniform float uWaterScale;
uniform vec3 uSeaColour;
uniform vec3 uSkyColour;
uniform vec3 uSunDir;
uniform vec3 uEyeHigh;
uniform float uLighting;
varying float vPmcWaterDepth;
varying vec3 vPmcRel;
${SEA_SURFACE}
`;
const WATER_FRAGMENT = /* glsl */ `
if (uWater > 0.5 && vPmcWaterDepth > 0.0) {
  vec3 pmcUp = normalize(vPmcRel + uEyeHigh);
  vec3 pmcView = normalize(-vPmcRel);
  float cosView = max(abs(dot(pmcView, pmcUp)), 0.2);
  float path = vPmcWaterDepth * 0.5 * (1.0 + 1.0 / cosView);
  float k = 1.0 - exp(-path / max(uWaterScale, 1e-3));
  outgoingLight = mix(outgoingLight * uWaterShallow, uWaterDeep, k);
  if (uLighting > 0.5) outgoingLight = pmcSeaSurface(outgoingLight, pmcUp, pmcView).rgb;
}
`;

/** The counts a TilesRenderer keeps (its `stats`, which its type declarations leave out). */
type RendererStats = Record<'inCache' | 'queued' | 'downloading' | 'parsing' | 'loaded' | 'failed' | 'active' | 'visible', number>;

function statsOf(tiles: TilesRenderer): RendererStats {
  return (tiles as unknown as { stats: RendererStats }).stats;
}
