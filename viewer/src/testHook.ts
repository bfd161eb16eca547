// The test hook `window.__pmc`, what scripts (the end-to-end tests) read and drive: its types, the
// hook made from the application's operations, and the Path tool's and the nav grid's state as
// the hook shows them (where they lie on the canvas).

import type { SkySettings, SkyState } from './atmosphere';
import type { CameraMode } from './cameraModel';
import type { PickResult } from './cameraController';
import type { StreamerStats } from './chunkStreamer';
import type { EditStatus } from './editSession';
import type { V3 } from './frames';
import type { NavGridStatus, NavOverlayData } from './navOverlay';
import type { PathStatus } from './pathTool';
import type { DebugFlags, SampledVertex } from './planetScene';
import type { Readiness } from './readiness';
import type { TilesStats } from './tiles';
import type { LodSettings } from './viewSelection';

export type ModeName = CameraMode | 'walk';

/** The level-of-detail streaming as `__pmc.stats().lod` shows it. */
export interface PmcLodStats extends Omit<StreamerStats, 'loaded' | 'pending' | 'missing' | 'triangles' | 'vertices' | 'requested' | 'failed' | 'stale' | 'reloading' | 'reloads'> {
  /** The stats panel's histogram line, e.g. `L0 12 · L1 40 · L2 18`. */
  levelsText: string;
  /** The selection's settings. */
  maxPixelError: number;
  maxChunks: number;
  /** The last selection's time, milliseconds, and whether one is running. */
  selectMs: number;
  selecting: boolean;
  /** The last selection was made for the current view. */
  current: boolean;
  /** The planet has no `lod` block (an older server): level 0 everywhere. */
  levelZeroOnly: boolean;
}

export interface PmcStats {
  preset: string | null;
  /** A flight of the go-to box under way. */
  flying: boolean;
  seed: string | null;
  /** Chunks shown, loaded (in the cache, shown or not), pending and wanted but not asked yet. */
  shown: number;
  loaded: number;
  pending: number;
  missing: number;
  /** Triangles and vertices shown. */
  triangles: number;
  vertices: number;
  requested: number;
  failed: number;
  fps: number;
  /** Animation frames so far, and the frames of them that drew (a still, settled view draws nothing). */
  frames: number;
  draws: number;
  /** What a drawn frame costs, milliseconds (the longer of its frame interval and its time on the GPU). */
  drawMs: number;
  lat: number;
  lon: number;
  alt: number;
  heading: number;
  pitch: number;
  aboveGround: number | null;
  mode: CameraMode;
  walk: boolean;
  range: number;
  drawCalls: number;
  ready: boolean;
  error: string | null;
  /** Whether the server answers (false: the server-gone notice shows). */
  online: boolean;
  /** The chunks shown (`face/level/i/j/k`). */
  loadedKeys: string[];
  /** The background colour drawn now (8-bit sRGB): what shows where nothing is drawn. */
  background: [number, number, number];
  lod: PmcLodStats;
  /** Loaded chunks waiting for a refetch after an edit, refetches under way, refetches made. */
  stale: number;
  reloading: number;
  reloads: number;
  /** Whether the brush cursor is drawn. */
  cursor: boolean;
  edit: EditStatus;
  /** The Path tool is chosen (the left button picks the path's ends). */
  pathTool: boolean;
  /**
   * The 3D Tiles mode: whether it is on, and its tiles (loaded, drawn, queued, downloading,
   * parsing, failed; `settled` once nothing was loading for a while). With the mode on, the
   * chunks are not drawn and none is asked for (the chunk counts above are those kept).
   */
  tiles: TilesStats;
}

/** `__pmc.places()`: a vertex of a chunk shown and where it shows on the canvas. */
export interface PmcPlace extends SampledVertex {
  /** CSS pixels from the top left, null where behind the camera. */
  screen: [number, number] | null;
  /** Cosine of the angle between the vertex normal and the direction to the camera. */
  facing: number;
  /** The same for the local vertical (small toward the planet's limb). */
  upFacing: number;
}

/** `__pmc.path()`: the Path tool's state, and where the path drawn lies on the canvas. */
export interface PmcPathHook extends Omit<PathStatus, 'waypoints' | 'line' | 'from' | 'to'> {
  /** The ends as sent to `/path` (`LAT,LON,ALT`), null when not set. */
  from: string | null;
  to: string | null;
  fromPoint: V3 | null;
  toPoint: V3 | null;
  /** Waypoints of the path found (its walk of grid steps). */
  waypoints: number;
  /** Points of the line drawn (the smoothed path's, else the waypoints). */
  line: number;
  /** The drawn (lifted) waypoints on the canvas, CSS pixels; null where behind the camera. */
  screen: ([number, number] | null)[];
  /** The tool is chosen. */
  active: boolean;
}

/** `__pmc.navgrid()`: the overlay's state. */
export interface PmcNavGridHook extends NavGridStatus {
  /** The overlay's objects are in the scene. */
  drawn: boolean;
  /** Per component: its nodes of the overlay in front of the camera and inside the canvas. */
  onScreen: Record<number, number>;
  /** Per component but the main one: those of them the loaded terrain does not hide. */
  visible: Record<number, number>;
}

export interface PmcTestHook {
  stats(): PmcStats;
  /**
   * Resolves when the level-of-detail selection is made for the current view and exactly its
   * chunks are shown, nothing pending.
   */
  ready(timeoutMs?: number): Promise<void>;
  setCamera(lat: number, lon: number, altitude: number, headingDeg?: number, pitchDeg?: number): void;
  setPlanet(preset: string, seed: string | number): Promise<void>;
  /** Switches to `name` ('orbit', 'fly' or 'walk') when given; returns the current mode. */
  mode(name?: ModeName): ModeName;
  /**
   * Sets debug flags and test modes; returns them all. `lighting: false` draws the ground's colour
   * alone (no sun, no haze), `sea: false` no water.
   */
  debug(flags: Partial<DebugFlags>): DebugFlags;
  /** Up to `count` vertices of the chunks shown, spread over them, and where they show. */
  places(count: number): PmcPlace[];
  /** The loaded terrain under canvas pixel (x, y) (CSS pixels from the top left), or null. */
  pick(x: number, y: number): PickResult | null;
  /** The Path tool's state (see PmcPathHook). */
  path(): PmcPathHook;
  /** Turns the nav grid overlay on or off when `on` is given; returns its state. */
  navgrid(on?: boolean): PmcNavGridHook;
  /**
   * The sky: sets the settings given (`atmosphere` on or off, the sun's `sunAzimuth` and
   * `sunElevation` in degrees over the horizon under the camera); returns the state (also the
   * planet's atmosphere `kind`, whether it is `drawn` and the `sunDirection`).
   */
  sky(settings?: Partial<SkySettings>): SkyState;
  /** Turns the atmosphere on or off (`sky({ atmosphere: on })`); returns the state. */
  setAtmosphere(on: boolean): SkyState;
  /**
   * Sets the largest screen-space error (pixels), the chunk budget and the finest level when given
   * (a test mode forces level L everywhere with `{ finestLevel: L, maxPixelError: 0.01 }`);
   * returns them.
   */
  lod(settings?: Partial<LodSettings>): LodSettings;
  /**
   * Draws the next frame even if its picture's key is the last drawn one (the frame loop draws
   * only when the picture changes): a still camera's next picture, drawn anew.
   */
  redraw(): void;
  /**
   * Turns the 3D Tiles mode on or off when `on` is given; returns its state (`stats().tiles`).
   * With the mode on, `ready()` waits for the tiles to settle (nothing queued, downloading or
   * parsing for a while) instead of the chunks.
   */
  tiles(on?: boolean): TilesStats;
}

declare global {
  interface Window {
    __pmc?: PmcTestHook;
  }
}


/** What the hook drives: the application's own operations. */
export interface TestHookTarget {
  readonly readiness: Readiness;
  stats(): PmcStats;
  setCamera(lat: number, lon: number, altitude: number, headingDeg?: number, pitchDeg?: number): void;
  setPlanet(preset: string, seed: string): Promise<void>;
  setMode(mode: CameraMode): void;
  setWalk(walk: boolean): void;
  /** 'walk' when walking, else the camera's mode. */
  modeName(): ModeName;
  /** Sets debug flags; returns them all. */
  setDebug(flags: Partial<DebugFlags>): DebugFlags;
  places(count: number): PmcPlace[];
  pick(x: number, y: number): PickResult | null;
  pathHook(): PmcPathHook;
  navGridHook(): PmcNavGridHook;
  setNavGrid(on: boolean): void;
  /** Sets the sky settings given; returns the sky's state. */
  setSky(settings: Partial<SkySettings>): SkyState;
  setLod(settings: Partial<LodSettings>): void;
  lodSettings(): LodSettings;
  /** The next frame draws, whatever its picture's key. */
  invalidate(): void;
  /** The 3D Tiles mode on or off. */
  setTilesMode(on: boolean): void;
  /** The 3D Tiles mode's state. */
  tilesStats(): TilesStats;
}

export function createTestHook(app: TestHookTarget): PmcTestHook {
  return {
    stats: () => app.stats(),
    ready: (timeoutMs = 120_000) =>
      app.readiness.wait(timeoutMs, () => {
        const s = app.stats();
        return new Error(
          `__pmc.ready() timed out after ${timeoutMs} ms (loaded ${s.loaded}, pending ${s.pending}, ` +
            `missing ${s.missing}, error ${String(s.error)})`,
        );
      }),
    setCamera: (lat, lon, alt, heading, pitch) => app.setCamera(lat, lon, alt, heading, pitch),
    setPlanet: (preset, seed) => app.setPlanet(preset, String(seed)),
    mode: (name) => {
      if (name === 'walk') app.setWalk(true);
      else if (name === 'fly') {
        app.setMode('fly');
        app.setWalk(false);
      } else if (name === 'orbit') app.setMode('orbit');
      return app.modeName();
    },
    debug: (flags) => app.setDebug(flags),
    places: (count) => app.places(count),
    pick: (x, y) => {
      const p = app.pick(x, y);
      return p ? { distance: p.distance, point: p.point, key: p.key } : null;
    },
    path: () => app.pathHook(),
    navgrid: (on) => {
      if (on !== undefined) app.setNavGrid(on);
      return app.navGridHook();
    },
    sky: (settings) => app.setSky(settings ?? {}),
    setAtmosphere: (on) => app.setSky({ atmosphere: on }),
    lod: (settings) => {
      if (settings) app.setLod(settings);
      return { ...app.lodSettings() };
    },
    redraw: () => app.invalidate(),
    tiles: (on) => {
      if (on !== undefined) app.setTilesMode(on);
      return app.tilesStats();
    },
  };
}

/** Where on the canvas a planet-frame point shows (CSS pixels), null where behind the camera. */
export type ToScreen = (p: V3) => [number, number] | null;

/** `__pmc.path()` of the Path tool's state, its drawn waypoints and whether the tool is chosen. */
export function pathHookOf(s: PathStatus, drawn: V3[], toScreen: ToScreen, active: boolean): PmcPathHook {
  const { waypoints: _w, line: _l, from, to, ...rest } = s;
  return {
    ...rest,
    from: from?.query ?? null,
    to: to?.query ?? null,
    fromPoint: from?.point ?? null,
    toPoint: to?.point ?? null,
    waypoints: s.waypoints.length,
    line: s.line.length,
    screen: drawn.map((p) => toScreen(p)),
    active,
  };
}

/** The view `__pmc.navgrid()` counts its nodes in: the canvas, the camera and the terrain picked. */
export interface NavGridView {
  /** Canvas size, CSS pixels. */
  width: number;
  height: number;
  /** The camera of the last frame, planet frame. */
  camera: V3;
  toScreen: ToScreen;
  pick(x: number, y: number): PickResult | null;
}

/** `__pmc.navgrid()` of the loader's state, its overlay and whether the overlay is drawn. */
export function navGridHookOf(st: NavGridStatus, d: NavOverlayData | null, drawn: boolean, view: NavGridView): PmcNavGridHook {
  const onScreen: Record<number, number> = {};
  const w = view.width;
  const h = view.height;
  const visible: Record<number, number> = {};
  if (d) {
    const cam = view.camera;
    for (let i = 0; i < d.count; i++) {
      const p: V3 = [d.origin[0] + d.positions[3 * i]!, d.origin[1] + d.positions[3 * i + 1]!, d.origin[2] + d.positions[3 * i + 2]!];
      const px = view.toScreen(p);
      if (!px || px[0] < 0 || px[0] >= w || px[1] < 0 || px[1] >= h) continue;
      const label = d.labels[i]!;
      onScreen[label] = (onScreen[label] ?? 0) + 1;
      if (label === d.main) continue;
      // not hidden by the terrain: nothing nearer along the ray through its pixel
      const hit = view.pick(px[0], px[1]);
      const dist = Math.hypot(p[0] - cam[0], p[1] - cam[1], p[2] - cam[2]);
      if (!hit || hit.distance > dist - 0.5) visible[label] = (visible[label] ?? 0) + 1;
    }
  }
  return { ...st, drawn, onScreen, visible };
}
