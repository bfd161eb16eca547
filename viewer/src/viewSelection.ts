// The level-of-detail selection of the camera's view: a planet's level-of-detail data, the
// selection's settings, the selection's input built from the camera of a frame, and when to ask
// for a new selection (the view changed: at once when the camera has stopped, at most every
// 150 ms while it moves).

import * as THREE from 'three';
import type { PlanetInfo } from './api';
import type { LodPlanet } from './chunkStreamer';
import type { V3 } from './frames';
import { Layout } from './lod/layout';
import type { Plane } from './lod/select';
import { planesToPlanetFrame, sameView, type LodSelector, type SelectionResult, type ViewState } from './lodSelector';

/** The selection's settings (the panel's detail fields). */
export interface LodSettings {
  maxPixelError: number;
  maxChunks: number;
  /** The finest level the selection may reach (0 but in a test mode that forces coarser levels). */
  finestLevel: number;
}

export const DEFAULT_LOD: LodSettings = { maxPixelError: 2, maxChunks: 2500, finestLevel: 0 };

export class ViewSelection {
  private lodPlanet: LodPlanet | null = null;
  /** The planet has no `lod` block (an older server): level 0 everywhere. */
  levelZeroOnly = false;
  settings: LodSettings = { ...DEFAULT_LOD };
  /** The last selection's time, milliseconds. */
  selectMs = 0;
  /** The view of the last selection asked for, and of the previous frame. */
  private selectedView: ViewState | null = null;
  private lastView: ViewState | null = null;
  private lastSelectAt = -Infinity;
  private readonly frustum = new THREE.Frustum();
  private readonly projView = new THREE.Matrix4();

  constructor(private readonly selector: LodSelector) {}

  /** A selection is running. */
  get busy(): boolean {
    return this.selector.busy;
  }

  /** Selects for `info`'s planet from now on. */
  setPlanet(info: PlanetInfo, lod: { planet: LodPlanet; levelZeroOnly: boolean }): void {
    this.lodPlanet = lod.planet;
    this.levelZeroOnly = lod.levelZeroOnly;
    this.selector.setPlanet({ layout: info.layout, errors: lod.planet.errors, occluder: lod.planet.occluder });
    this.selectedView = null;
    this.lastView = null;
  }

  /** New settings (the next frame selects again); throws on a pixel error or budget out of range. */
  setSettings(settings: Partial<LodSettings>): void {
    const px = settings.maxPixelError ?? this.settings.maxPixelError;
    const budget = settings.maxChunks ?? this.settings.maxChunks;
    const finest = settings.finestLevel ?? this.settings.finestLevel;
    if (!(Number.isFinite(px) && px > 0) || !(Number.isInteger(budget) && budget >= 1)) {
      throw new Error('the pixel error must be a number above 0 and the chunk budget a whole number of at least 1');
    }
    if (!(Number.isInteger(finest) && finest >= 0)) throw new Error('the finest level must be a whole number of at least 0');
    this.settings = { maxPixelError: px, maxChunks: budget, finestLevel: finest };
  }

  /** A selection arrived. */
  onSelection(r: SelectionResult): void {
    this.selectMs = r.ms;
  }

  /**
   * The frame's view (`camera` at `pos`, planet frame, f64, looking along `forward`): asks for a
   * selection when it differs from the last one selected for, no selection is running and the
   * planet is not `busy` loading.
   */
  frame(camera: THREE.PerspectiveCamera, viewportHeightPx: number, pos: V3, forward: V3, up: V3, now: number, busy: boolean): void {
    this.projView.multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    this.frustum.setFromProjectionMatrix(this.projView);
    const view = this.viewState(camera, viewportHeightPx, pos, forward, up);
    this.maybeSelect(view, now, busy);
    this.lastView = view;
  }

  /** The last selection was asked for the view of the last frame and has arrived. */
  current(): boolean {
    return (
      !this.selector.busy && this.selectedView !== null && this.lastView !== null && sameView(this.lastView, this.selectedView)
    );
  }

  /** The selection's input for the camera of this frame (planet frame, f64). */
  private viewState(camera: THREE.PerspectiveCamera, viewportHeightPx: number, pos: V3, forward: V3, up: V3): ViewState {
    const planes: Plane[] = this.frustum.planes.map((p) => [p.normal.x, p.normal.y, p.normal.z, p.constant]);
    const lod = this.lodPlanet;
    const total = lod ? levelZeroCount(lod.layout) : 0;
    return {
      view: {
        eye: [pos[0], pos[1], pos[2]],
        frustum: planesToPlanetFrame(planes, pos),
        viewportHeightPx: Math.max(1, viewportHeightPx),
        fovY: (camera.fov * Math.PI) / 180,
      },
      params: {
        maxPixelError: this.settings.maxPixelError,
        finestLevel: this.settings.finestLevel,
        // a server without levels of detail: every level-0 chunk, however many the budget allows
        maxChunks: this.levelZeroOnly ? Math.max(this.settings.maxChunks, total) : this.settings.maxChunks,
      },
      forward,
      up,
      near: camera.near,
      far: camera.far,
    };
  }

  /**
   * Starts a selection when the view differs from the last one selected for and no selection is
   * running: at once when the camera has stopped (the same view as the frame before), else at most
   * every 150 ms while it moves.
   */
  private maybeSelect(view: ViewState, now: number, busy: boolean): void {
    if (this.lodPlanet === null || busy || this.selector.busy) return;
    if (this.selectedView !== null && sameView(view, this.selectedView)) return;
    const still = this.lastView !== null && sameView(view, this.lastView);
    if (!still && now - this.lastSelectAt < 150) return;
    if (this.selector.request(view.view, view.params)) {
      this.selectedView = view;
      this.lastSelectAt = now;
    }
  }
}

/** The chunks of level 0 of a layout. */
function levelZeroCount(layout: Layout): number {
  return 6 * layout.chunksPerSide(0) ** 2 * layout.depthChunks(0);
}

/**
 * The level-of-detail data of a planet: `/planet`'s `lod` block, or, from a server without one
 * (every level 0 and nothing else), a table that refines everything to level 0.
 */
export function lodPlanetOf(info: PlanetInfo): { planet: LodPlanet; levelZeroOnly: boolean } {
  const layout = new Layout(info.layout);
  const lod = info.lod;
  if (lod && lod.errors.length === layout.maxLevel() + 1) {
    return { planet: { layout, errors: [...lod.errors], occluder: lod.occluder_radius }, levelZeroOnly: false };
  }
  const errors = Array.from({ length: layout.maxLevel() + 1 }, (_, l) => (l === 0 ? 0 : 1e30));
  return { planet: { layout, errors, occluder: info.surface_bounds?.[0] ?? info.base_radius }, levelZeroOnly: true };
}
