// The 3D Tiles mode: the planet as `pmc serve` answers it in OGC 3D Tiles
// (docs/specs/tiles-v1.md, the `sphere` frame: the planet as the viewer draws it), loaded by
// NASA-AMMOS's 3DTilesRendererJS instead of the viewer's own chunk streaming, and drawn by the
// viewer's own terrain shader as the chunks are, to compare the two paths' geometry on the same
// view. Loaded when the mode is first turned on (a chunk of the build of its own: the renderer and
// three.js's glTF loader).
//
// The tiles' group is placed around the floating origin every frame (tiles.ts: ECEF to the planet
// frame, then -camera, in f64). The tiles pick their levels with the viewer's own screen-space
// error target, in the drawing buffer's pixels as the viewer's selection counts them. Each tile's
// mesh, when it loads, is turned into a chunk's (tileTerrain.ts: its vertices in the planet frame
// in high and low f32 parts, relative to the tile's centre, its normals turned, its heights, water
// depths and materials as the chunk's attributes) and drawn with a terrain material of the
// planet's scene (planetScene.ts `terrainMaterial`): the same materials per pixel, sun, sky light,
// haze, water under the sea and stencil as the chunks. A tile's caps (material 255, the sides of
// its solid: docs/specs/tiles-v1.md) are drawn as the rest, from their own attributes, which copy
// those of the surface's border: they look like the ground they close (the shader does not read
// the material id). In rock, every seam between two tiles showed as a dotted line: a cap lies a
// hair outside its tile, so along a seam it pokes centimetres out of the neighbour's ground.

import * as THREE from 'three';
import { useBvh } from './raycast';
import { TilesRenderer } from '3d-tiles-renderer';
import { FACE_NAMES } from './chunkDecode';
import type { PlanetScene } from './planetScene';
import { matrixWithin, tileMeshMatrix, tileTerrain } from './tileTerrain';
import type { V3 } from './frames';
import { TILES_QUIET_MS, tilesGroupMatrix, type TilesStats } from './tiles';

export interface TilesViewCallbacks {
  /** What is drawn changed (a tile shown or hidden): the picture and the ground under the camera. */
  onChange(): void;
  /** A tile or the tileset failed to load. */
  onError(message: string): void;
  /** The tileset was read: its `extras.pmc` (frame, terrain). */
  onTileset(frame: string | null, terrain: string | null): void;
}

/** The tiles of one TilesRenderer and their place in the scene. */
export class TilesView {
  private readonly tiles: TilesRenderer;
  private readonly matrix: number[] = new Array<number>(16);
  private readonly buffer = new THREE.Vector2();
  private quietSince: number | null = null;
  private frame: string | null = null;
  private terrain: string | null = null;
  private disposed = false;

  constructor(
    url: string,
    private readonly scene: THREE.Scene,
    private readonly materials: Pick<PlanetScene, 'terrainMaterial'>,
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
      const meshes: THREE.Mesh[] = [];
      e.scene.traverse((o) => {
        if ((o as THREE.Mesh).isMesh) meshes.push(o as THREE.Mesh);
      });
      for (const mesh of meshes) this.prepare(mesh, e.scene);
      changed();
    });
    this.tiles.addEventListener('dispose-model', (e) => {
      // (the renderer disposes the glTF's own geometries and materials, not those made here)
      e.scene.traverse((o) => {
        const mesh = o as THREE.Mesh;
        if (!mesh.isMesh || mesh.userData['pmcTerrain'] !== true) return;
        mesh.geometry.dispose();
        (mesh.material as THREE.Material).dispose();
      });
      changed();
    });
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
  }

  /**
   * A tile's mesh (in its tile's scene `root`, not yet drawn) as a chunk: its geometry turned into a
   * chunk's, a terrain material, and a matrix that puts it at (its centre - camera) under the
   * tiles' group, as a chunk (tileTerrain.ts). The glTF's geometry and material, never drawn, are
   * the renderer's to dispose with the tile.
   */
  private prepare(mesh: THREE.Mesh, root: THREE.Object3D): void {
    const { geometry, origin } = tileTerrain(mesh.geometry, matrixWithin(mesh, root));
    const parents = mesh === root || !mesh.parent ? new THREE.Matrix4() : matrixWithin(mesh.parent, root);
    mesh.geometry = geometry;
    mesh.material = this.materials.terrainMaterial(origin, faceOf(mesh));
    mesh.matrixAutoUpdate = false;
    tileMeshMatrix(parents, origin, mesh.matrix);
    mesh.matrixWorldNeedsUpdate = true;
    mesh.userData['pmcTerrain'] = true;
    useBvh(mesh);
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
   * One frame with `camera` (placed, its matrices up to date): the tiles pick their levels for the
   * drawing buffer of `renderer` at `errorTarget` pixels and load what they lack.
   */
  update(camera: THREE.PerspectiveCamera, renderer: THREE.WebGLRenderer, errorTarget: number, now: number): void {
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

  /** Removes the tiles from the scene and frees what they hold. */
  dispose(): void {
    this.disposed = true;
    this.scene.remove(this.tiles.group);
    this.tiles.dispose();
  }
}

/** The face of a tile's mesh, from its glTF node's or mesh's name (the chunk key, `face/level/i/j/k`); 0 if none. */
function faceOf(mesh: THREE.Object3D): number {
  for (let o: THREE.Object3D | null = mesh; o; o = o.parent) {
    const face = FACE_NAMES.findIndex((f) => o.name.startsWith(f));
    if (face >= 0) return face;
  }
  return 0;
}

/** The counts a TilesRenderer keeps (its `stats`, which its type declarations leave out). */
type RendererStats = Record<'inCache' | 'queued' | 'downloading' | 'parsing' | 'loaded' | 'failed' | 'active' | 'visible', number>;

function statsOf(tiles: TilesRenderer): RendererStats {
  return (tiles as unknown as { stats: RendererStats }).stats;
}
