// The viewer application: wires the API, the streamer, the scene, the camera model, the input,
// the UI, the URL hash and the test hook together, and runs the frame loop.

import * as THREE from 'three';
import { PmcApi, type PlanetInfo } from './api';
import {
  cameraPosition,
  flyMove,
  flySpeed,
  look,
  maxAltitude,
  minOrbitAltitude,
  orbitDrag,
  orbitZoom,
  toFly,
  toOrbit,
  type CameraMode,
  type CameraState,
} from './cameraModel';
import { ChunkStreamer, type LodPlanet, type StreamerStats } from './chunkStreamer';
import { formatLevels, loadRange } from './chunkSelection';
import { EditSession, type EditStatus } from './editSession';
import { toolByName, toolForKey, type ToolName } from './editTools';
import { addScaled, cameraBasis, enuAt, length, normalize, wrapLon, type V3 } from './frames';
import { Input } from './input';
import { Layout } from './lod/layout';
import type { Plane } from './lod/select';
import { LodSelector, planesToPlanetFrame, sameView, type SelectionResult, type ViewState } from './lodSelector';
import { NavGridLoader, groundPoint, navRange, type NavGridStatus } from './navOverlay';
import { NavScene } from './navScene';
import { PATH_TOOL, PathTool, type PathStatus } from './pathTool';
import { planetParams, type PlanetParams } from './planetParams';
import { PlanetScene, type DebugFlags } from './planetScene';
import { ToolsUi } from './toolsUi';
import { Ui, formatDistance } from './ui';
import { formatHash, parseHash, type UrlState } from './urlState';

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
  frames: number;
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
}

/** `__pmc.path()`: the Path tool's state, and where the path drawn lies on the canvas. */
export interface PmcPathHook extends Omit<PathStatus, 'waypoints' | 'from' | 'to'> {
  /** The ends as sent to `/path` (`LAT,LON,ALT`), null when not set. */
  from: string | null;
  to: string | null;
  fromPoint: V3 | null;
  toPoint: V3 | null;
  /** Waypoints of the path shown. */
  waypoints: number;
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

/** A point of the loaded terrain under a pixel. */
export interface PickResult {
  /** Metres from the camera along the ray. */
  distance: number;
  /** The point, planet frame, metres. */
  point: V3;
  /** The chunk hit. */
  key: string;
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
  debug(flags: Partial<DebugFlags>): DebugFlags;
  /** The loaded terrain under canvas pixel (x, y) (CSS pixels from the top left), or null. */
  pick(x: number, y: number): PickResult | null;
  /** The Path tool's state (see PmcPathHook). */
  path(): PmcPathHook;
  /** Turns the nav grid overlay on or off when `on` is given; returns its state. */
  navgrid(on?: boolean): PmcNavGridHook;
  /** Sets the largest screen-space error (pixels) and the chunk budget when given; returns them. */
  lod(settings?: Partial<LodSettings>): LodSettings;
}

/** The selection's settings (the panel's detail fields). */
export interface LodSettings {
  maxPixelError: number;
  maxChunks: number;
}

export const DEFAULT_LOD: LodSettings = { maxPixelError: 2, maxChunks: 2500 };

declare global {
  interface Window {
    __pmc?: PmcTestHook;
  }
}

const FOV = 50;
const EYE_HEIGHT = 2;
const STEP_CLIMB = 1.5;

export class App {
  private readonly api = new PmcApi('api/v1');
  private readonly renderer: THREE.WebGLRenderer;
  private readonly camera = new THREE.PerspectiveCamera(FOV, 1, 0.05, 1e5);
  private readonly scene = new PlanetScene();
  private readonly navScene = new NavScene();
  private readonly pathTool: PathTool;
  private readonly navLoader: NavGridLoader;
  /** The Path tool is chosen (the editor's tool is Look meanwhile). */
  private pathActive = false;
  private pathDrawn = -1;
  private gridDrawn = -1;
  private navChanged = true;
  /** The world revision the path and the grid were last asked for. */
  private navRevision = 0;
  private readonly streamer: ChunkStreamer;
  private readonly selector: LodSelector;
  private lodPlanet: LodPlanet | null = null;
  private levelZeroOnly = false;
  private lodSettings: LodSettings = { ...DEFAULT_LOD };
  /** The view of the last selection asked for, and of the previous frame. */
  private selectedView: ViewState | null = null;
  private lastView: ViewState | null = null;
  private lastSelectAt = -Infinity;
  private selectMs = 0;
  private readonly ui: Ui;
  private readonly toolsUi: ToolsUi;
  private readonly editor: EditSession;
  private editChanged = true;
  private readonly input: Input;
  private readonly raycaster = new THREE.Raycaster();
  private readonly frustum = new THREE.Frustum();
  private readonly projView = new THREE.Matrix4();

  private params: PlanetParams | null = null;
  private choice: { preset?: string; seed?: string } = {};
  /** The name of the elevation-model planet the server serves, once seen. */
  private servedTerrain: string | null = null;
  private planetRequest = 0;
  private planetBusy: string | null = null;

  private state: CameraState = { lat: 20, lon: 15, alt: NaN, heading: 0, pitch: -90 };
  private mode: CameraMode = 'orbit';
  private walk = false;
  private speedFactor = 1;
  private aboveGround: number | null = null;
  private range = 1;

  private lastFrame = performance.now();
  private frames = 0;
  private fps = 0;
  private fpsFrames = 0;
  private fpsSince = performance.now();
  private lastUiUpdate = 0;
  private lastHashWrite = 0;
  private writtenHash = '';
  private settledFrames = 0;
  private readyWaiters: { resolve: () => void; reject: (e: Error) => void; timer: number }[] = [];
  private error: string | null = null;
  /** The camera of the last frame, planet frame (the floating origin). */
  private cameraPos: V3 = [0, 0, 0];

  constructor(private readonly canvas: HTMLCanvasElement) {
    // a logarithmic depth buffer: the same relative depth precision from 5 cm to the far side of
    // an Earth-sized planet, with no near/far juggling
    this.renderer = new THREE.WebGLRenderer({
      canvas,
      antialias: true,
      powerPreference: 'high-performance',
      logarithmicDepthBuffer: true,
    });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.renderer.outputColorSpace = THREE.SRGBColorSpace;
    this.camera.position.set(0, 0, 0);
    this.camera.matrixAutoUpdate = false;

    this.streamer = new ChunkStreamer(this.api, {
      onShow: (name, seams, chunk) => this.scene.addChunk(name, seams, chunk),
      onHide: (name) => this.scene.removeChunk(name),
      onError: (message) => this.showError(message),
      onRecovered: () => this.clearError(),
    });
    this.selector = new LodSelector(
      typeof Worker === 'function'
        ? () => new Worker(new URL('./lod/worker.ts', import.meta.url), { type: 'module', name: 'pmc-lod' })
        : null,
      (r) => this.onSelection(r),
      (message) => this.showError(message),
    );
    this.ui = new Ui({
      onPlanet: (preset, seed) => void this.setPlanet(preset, seed).catch(() => undefined),
      onMode: (mode) => this.setMode(mode),
      onWalk: (walk) => this.setWalk(walk),
      onDebug: (flags) => {
        this.scene.setDebug(flags);
        this.ui.setDebug(this.scene.debug());
      },
      onNavGrid: (on) => this.setNavGrid(on),
      onLod: (settings) => this.setLod(settings),
    });
    this.scene.scene.add(this.navScene.group);
    this.pathTool = new PathTool({
      fetchPath: (from, to, signal) => this.api.path(this.choice, from, to, signal),
      onChange: () => {
        this.editChanged = true;
      },
    });
    this.navLoader = new NavGridLoader({
      fetchGrid: (at, range, signal) => this.api.navgrid(this.choice, at, range, 20_000, signal),
      onChange: () => {
        this.navChanged = true;
      },
    });
    this.editor = new EditSession({
      api: this.api,
      chunks: this.streamer,
      eventSource: typeof EventSource === 'function' ? (url) => new EventSource(url) : null,
      onChange: () => {
        this.editChanged = true;
      },
    });
    this.toolsUi = new ToolsUi({
      onTool: (tool) => this.chooseTool(tool),
      onPathTool: () => this.choosePathTool(),
      onRadius: (r) => this.editor.setRadius(r),
      onStrength: (st) => this.editor.setStrength(st),
      onMaterial: (m) => this.editor.setMaterial(m),
      onUndo: () => void this.editor.undo(),
      onRedo: () => void this.editor.redo(),
    });
    this.input = new Input(canvas, {
      onToggleMode: () => this.setMode(this.mode === 'orbit' ? 'fly' : 'orbit'),
      onToggleWalk: () => {
        if (this.mode === 'fly') this.setWalk(!this.walk);
      },
      brushActive: () => this.editor.brushActive || this.pathActive,
      onShortcut: (e) => this.shortcut(e),
    });
    canvas.addEventListener('dblclick', () => {
      if (this.mode === 'fly' && !this.editor.brushActive && !this.pathActive) this.input.requestPointerLock();
    });
    window.addEventListener('resize', () => this.resize());
    window.addEventListener('hashchange', () => this.onHashChange());
    this.resize();

    const fromHash = parseHash(location.hash);
    this.applyUrlState(fromHash, false);
    this.choice = { ...(fromHash.preset ? { preset: fromHash.preset } : {}), ...(fromHash.seed ? { seed: fromHash.seed } : {}) };
    this.ui.setMode(this.mode, this.walk);
    this.ui.setDebug(this.scene.debug());
    this.ui.setLod(this.lodSettings);
    window.__pmc = this.testHook();
    this.renderer.setAnimationLoop(() => this.frame());
    void this.loadPlanet(this.choice, true);
  }

  // ---- planet -------------------------------------------------------------------------------

  /** Fetches `/planet` for `choice` and restarts streaming; retries at start-up. */
  private async loadPlanet(choice: { preset?: string; seed?: string }, retry: boolean): Promise<void> {
    const request = ++this.planetRequest;
    this.planetBusy = 'loading planet';
    let attempt = 0;
    for (;;) {
      try {
        const info = await this.api.planet(choice);
        if (request !== this.planetRequest) return;
        this.applyPlanet(info);
        this.clearError();
        return;
      } catch (e) {
        if (request !== this.planetRequest) return;
        const message = e instanceof Error ? e.message : String(e);
        this.showError(`Cannot load the planet: ${message}`);
        if (!retry) {
          this.planetBusy = null;
          throw e instanceof Error ? e : new Error(message);
        }
        attempt++;
        await new Promise((r) => setTimeout(r, Math.min(10_000, 500 * 2 ** attempt)));
        if (request !== this.planetRequest) return;
      }
    }
  }

  private applyPlanet(info: PlanetInfo): void {
    this.params = planetParams(info);
    // An elevation-model planet has no preset: it is the server's own planet, asked for with
    // no preset parameter (the picker lists it under the empty value).
    if (info.preset === null) this.servedTerrain = info.terrain?.name ?? 'elevation model';
    this.choice = { ...(info.preset !== null ? { preset: info.preset } : {}), seed: info.seed };
    const lod = lodPlanetOf(info);
    this.lodPlanet = lod.planet;
    this.levelZeroOnly = lod.levelZeroOnly;
    this.streamer.setPlanet(this.choice, lod.planet);
    this.selector.setPlanet({ layout: info.layout, errors: lod.planet.errors, occluder: lod.planet.occluder });
    this.selectedView = null;
    this.lastView = null;
    this.editor.setPlanet(info);
    this.pathTool.setPlanet(this.params.shape.datum);
    this.navLoader.reset();
    this.navRevision = this.editor.revision ?? 0;
    this.scene.clearChunks();
    this.scene.setPlanet(this.params);
    const shape = this.params.shape;
    if (!Number.isFinite(this.state.alt)) this.state.alt = 1.6 * shape.outer;
    this.clampAltitude();
    const served = this.servedTerrain;
    const presets =
      served === null ? info.presets : [{ name: '', label: served, description: 'the real planet this server serves' }, ...info.presets];
    this.ui.setPresets(presets, info.preset ?? '');
    this.ui.setPlanet(info.preset ?? '', info.seed);
    this.planetBusy = null;
    this.settledFrames = 0;
    this.writeHash(true);
  }

  async setPlanet(preset: string, seed: string | number): Promise<void> {
    const s = String(seed);
    this.ui.setPlanet(preset, s);
    try {
      await this.loadPlanet({ preset, seed: s }, false);
    } catch (e) {
      // keep showing the planet that is still there
      if (this.choice.preset && this.choice.seed) this.ui.setPlanet(this.choice.preset, this.choice.seed);
      throw e;
    }
  }

  // ---- camera -------------------------------------------------------------------------------

  private clampAltitude(): void {
    if (!this.params) return;
    const shape = this.params.shape;
    const min = this.mode === 'orbit' ? minOrbitAltitude(shape) : -shape.datum + 1;
    this.state.alt = Math.min(maxAltitude(shape), Math.max(min, this.state.alt));
  }

  setMode(mode: CameraMode): void {
    if (mode === this.mode) return;
    this.mode = mode;
    if (mode === 'orbit') {
      this.walk = false;
      this.input.releasePointerLock();
      if (this.params) this.state = toOrbit(this.state, this.params.shape);
    } else {
      this.state = toFly(this.state);
    }
    this.clampAltitude();
    this.ui.setMode(this.mode, this.walk);
    this.writeHash(true);
  }

  setWalk(walk: boolean): void {
    if (walk && this.mode !== 'fly') this.setMode('fly');
    this.walk = walk;
    if (walk) this.state.pitch = Math.max(-60, Math.min(60, this.state.pitch));
    this.ui.setMode(this.mode, this.walk);
    this.writeHash(true);
  }

  setCamera(lat: number, lon: number, alt: number, heading?: number, pitch?: number): void {
    if (![lat, lon, alt].every(Number.isFinite)) throw new Error('setCamera: lat, lon and altitude must be finite numbers');
    const s: CameraState = {
      lat: Math.max(-90, Math.min(90, lat)),
      lon: wrapLon(lon),
      alt,
      heading: heading ?? this.state.heading,
      pitch: pitch ?? this.state.pitch,
    };
    // a view that is not straight down needs the fly mode
    if (pitch !== undefined && pitch > -89.5 && this.mode === 'orbit') {
      this.mode = 'fly';
      this.ui.setMode(this.mode, this.walk);
    }
    if (this.mode === 'orbit') s.pitch = -90;
    this.state = s;
    this.clampAltitude();
    this.settledFrames = 0;
    this.writeHash(true);
  }

  private applyUrlState(u: UrlState, fromUser: boolean): void {
    if (u.mode) this.mode = u.mode;
    if (u.walk !== undefined) this.walk = u.walk && this.mode === 'fly';
    const s = this.state;
    if (u.lat !== undefined) s.lat = u.lat;
    if (u.lon !== undefined) s.lon = wrapLon(u.lon);
    if (u.alt !== undefined) s.alt = u.alt;
    if (u.heading !== undefined) s.heading = u.heading;
    if (u.pitch !== undefined) s.pitch = Math.max(-90, Math.min(90, u.pitch));
    if (this.mode === 'orbit') s.pitch = -90;
    this.clampAltitude();
    if (fromUser) this.ui.setMode(this.mode, this.walk);
  }

  private onHashChange(): void {
    if (location.hash === this.writtenHash) return;
    const u = parseHash(location.hash);
    this.applyUrlState(u, true);
    const preset = u.preset ?? this.choice.preset;
    const seed = u.seed ?? this.choice.seed;
    if (preset !== this.choice.preset || seed !== this.choice.seed) {
      void this.loadPlanet({ ...(preset ? { preset } : {}), ...(seed ? { seed } : {}) }, false).catch(() => undefined);
    }
  }

  private writeHash(force: boolean): void {
    const now = performance.now();
    if (!force && now - this.lastHashWrite < 500) return;
    this.lastHashWrite = now;
    const s = this.state;
    const hash = formatHash({
      ...(this.choice.preset ? { preset: this.choice.preset } : {}),
      ...(this.choice.seed ? { seed: this.choice.seed } : {}),
      mode: this.mode,
      walk: this.walk,
      ...(Number.isFinite(s.alt) ? { lat: s.lat, lon: s.lon, alt: s.alt, heading: s.heading, pitch: s.pitch } : {}),
    });
    if (hash !== this.writtenHash && hash !== location.hash) {
      this.writtenHash = hash;
      history.replaceState(null, '', hash);
    }
  }

  // ---- editing ------------------------------------------------------------------------------

  /** Editing shortcuts (outside text fields); true when `e` was one. */
  private shortcut(e: KeyboardEvent): boolean {
    const mod = e.ctrlKey || e.metaKey;
    if (mod) {
      if (e.altKey || !this.editor.enabled) return false;
      if (e.code === 'KeyZ') {
        if (!e.repeat) void (e.shiftKey ? this.editor.redo() : this.editor.undo());
        return true;
      }
      if (e.code === 'KeyY' && !e.shiftKey) {
        if (!e.repeat) void this.editor.redo();
        return true;
      }
      return false;
    }
    if (e.altKey) return false;
    if (e.code === 'Escape' && this.pathTool.active) {
      // Esc clears the path first (the tool stays), then goes back to Look
      this.pathTool.clear();
      return true;
    }
    if (e.code === PATH_TOOL.code) {
      this.choosePathTool();
      return true;
    }
    if (e.code === 'KeyN' && !e.shiftKey) {
      if (!e.repeat) this.setNavGrid(!this.navLoader.enabled);
      return true;
    }
    const tool = toolForKey(e.code);
    if (tool) {
      if (tool === 'look' && this.editor.currentTool === 'look' && !this.pathActive) return false;
      this.chooseTool(tool);
      return true;
    }
    if ((e.code === 'BracketLeft' || e.code === 'BracketRight') && this.editor.enabled) {
      this.editor.stepRadius(e.code === 'BracketRight' ? 1 : -1);
      return true;
    }
    return false;
  }

  /** An editing tool (or Look) from the tool bar or its key; leaves the Path tool. */
  private chooseTool(tool: ToolName): void {
    this.editor.setTool(tool);
    // a tool editing is off for is refused (the editor says why): the Path tool stays then
    if (this.editor.currentTool === tool && this.pathActive) {
      this.pathActive = false;
      this.editChanged = true;
    }
  }

  /** The Path tool: the left button picks the start, then the goal. No world needed. */
  private choosePathTool(): void {
    this.editor.setTool('look');
    this.pathActive = true;
    this.editChanged = true;
  }

  setNavGrid(on: boolean): void {
    this.navLoader.setEnabled(on);
    this.navChanged = true;
  }

  private readonly ndc = new THREE.Vector2();

  /** The loaded terrain under canvas pixel (x, y), with the camera of the last frame. */
  private pick(x: number, y: number): (PickResult & { render: V3 }) | null {
    const w = this.canvas.clientWidth || window.innerWidth;
    const h = this.canvas.clientHeight || window.innerHeight;
    if (!(w > 0 && h > 0) || !this.params) return null;
    this.ndc.set((2 * x) / w - 1, 1 - (2 * y) / h);
    this.raycaster.setFromCamera(this.ndc, this.camera);
    this.raycaster.near = this.camera.near;
    this.raycaster.far = this.camera.far;
    const hits = this.raycaster.intersectObjects(this.scene.terrainMeshes(), false);
    const hit = hits[0];
    if (!hit) return null;
    const cam = this.cameraPos;
    // render space is relative to the camera (floating origin): add it back in f64
    const render: V3 = [hit.point.x, hit.point.y, hit.point.z];
    return {
      distance: hit.distance,
      point: [render[0] + cam[0], render[1] + cam[1], render[2] + cam[2]],
      key: hit.object.name,
      render,
    };
  }

  /** The brush under the mouse: cursor, press, drag and release. */
  private brushFrame(input: ReturnType<Input['take']>): void {
    if (this.pathActive) {
      this.scene.setBrushCursor(null);
      this.canvas.classList.add('brush');
      for (const at of input.brushPresses) this.pathTool.click(this.pick(at.x, at.y)?.point ?? null);
      return;
    }
    if (!this.editor.brushActive) {
      this.scene.setBrushCursor(null);
      if (input.brushRelease) this.editor.release();
      this.canvas.classList.remove('brush');
      return;
    }
    this.canvas.classList.add('brush');
    if (input.brushPress) this.editor.press(this.pick(input.brushPress.x, input.brushPress.y)?.point ?? null);
    const ptr = this.input.pointer();
    const hit = ptr ? this.pick(ptr.x, ptr.y) : null;
    this.editor.frame(hit ? hit.point : null);
    if (input.brushRelease) this.editor.release();
    if (hit) {
      this.scene.setBrushCursor(hit.render, this.editor.radius, normalize(hit.point), toolByName(this.editor.currentTool).colour);
    } else {
      this.scene.setBrushCursor(null);
    }
  }

  private editStatsText(s: EditStatus): { text: string; push: string } {
    if (!s.enabled) return { text: 'off', push: '–' };
    const push = s.push === 'open' ? 'live' : s.push === 'off' ? 'off' : s.push;
    const counts = s.active !== null ? ` · ${s.active} active${s.redo ? ` · ${s.redo} undone` : ''}` : '';
    return { text: `rev ${s.revision ?? '?'}${counts}`, push };
  }

  // ---- navigation -----------------------------------------------------------------------------

  /**
   * The path and the grid overlay: after an edit (a new world revision) ask for the path again
   * and refresh the grid; fetch the grid around the ground point as the camera moves; redraw what
   * changed; place it all around the camera.
   */
  private navFrame(pos: V3, params: PlanetParams): void {
    const revision = this.editor.revision ?? 0;
    if (revision !== this.navRevision) {
      this.navRevision = revision;
      this.pathTool.refresh();
    }
    if (this.navLoader.enabled) {
      const ground = groundPoint(pos, this.aboveGround, params.shape.datum);
      const height = length(pos) - length(ground);
      this.navLoader.update({
        planet: `${this.choice.preset ?? ''}/${this.choice.seed ?? ''}`,
        centre: ground,
        range: navRange(height),
        revision,
      });
    }
    if (this.pathDrawn !== this.pathTool.version) {
      this.pathDrawn = this.pathTool.version;
      const ps = this.pathTool.status();
      this.navScene.setPath(ps.waypoints.length >= 2 ? ps.waypoints : null);
      this.navScene.setMarkers(ps.from?.point ?? null, ps.to?.point ?? null);
    }
    if (this.gridDrawn !== this.navLoader.version) {
      this.gridDrawn = this.navLoader.version;
      this.navScene.setGrid(this.navLoader.overlay());
    }
    this.navScene.place(pos);
  }

  /** Canvas pixel (CSS) of a planet-frame point with the camera of the last frame; null behind it. */
  private toScreen(p: V3): [number, number] | null {
    const cam = this.cameraPos;
    const v = new THREE.Vector3(p[0] - cam[0], p[1] - cam[1], p[2] - cam[2]);
    v.applyMatrix4(this.camera.matrixWorldInverse);
    if (v.z >= 0) return null;
    v.applyMatrix4(this.camera.projectionMatrix);
    const w = this.canvas.clientWidth || window.innerWidth;
    const h = this.canvas.clientHeight || window.innerHeight;
    return [((v.x + 1) / 2) * w, ((1 - v.y) / 2) * h];
  }

  private pathHook(): PmcPathHook {
    const s = this.pathTool.status();
    const { waypoints: _w, from, to, ...rest } = s;
    return {
      ...rest,
      from: from?.query ?? null,
      to: to?.query ?? null,
      fromPoint: from?.point ?? null,
      toPoint: to?.point ?? null,
      waypoints: s.waypoints.length,
      screen: this.navScene.drawnPath().map((p) => this.toScreen(p)),
      active: this.pathActive,
    };
  }

  private navGridHook(): PmcNavGridHook {
    const st = this.navLoader.status();
    const onScreen: Record<number, number> = {};
    const d = this.navLoader.overlay();
    const w = this.canvas.clientWidth || window.innerWidth;
    const h = this.canvas.clientHeight || window.innerHeight;
    const visible: Record<number, number> = {};
    if (d) {
      const cam = this.cameraPos;
      for (let i = 0; i < d.count; i++) {
        const p: V3 = [d.origin[0] + d.positions[3 * i]!, d.origin[1] + d.positions[3 * i + 1]!, d.origin[2] + d.positions[3 * i + 2]!];
        const px = this.toScreen(p);
        if (!px || px[0] < 0 || px[0] >= w || px[1] < 0 || px[1] >= h) continue;
        const label = d.labels[i]!;
        onScreen[label] = (onScreen[label] ?? 0) + 1;
        if (label === d.main) continue;
        // not hidden by the terrain: nothing nearer along the ray through its pixel
        const hit = this.pick(px[0], px[1]);
        const dist = Math.hypot(p[0] - cam[0], p[1] - cam[1], p[2] - cam[2]);
        if (!hit || hit.distance > dist - 0.5) visible[label] = (visible[label] ?? 0) + 1;
      }
    }
    return { ...st, drawn: this.navScene.gridShown(), onScreen, visible };
  }

  // ---- level of detail ------------------------------------------------------------------------

  /** The selection's input for the camera of this frame (planet frame, f64). */
  private viewState(pos: V3, forward: V3, up: V3): ViewState {
    const planes: Plane[] = this.frustum.planes.map((p) => [p.normal.x, p.normal.y, p.normal.z, p.constant]);
    const size = this.renderer.getDrawingBufferSize(new THREE.Vector2());
    const lod = this.lodPlanet;
    const total = lod ? levelZeroCount(lod.layout) : 0;
    return {
      view: {
        eye: [pos[0], pos[1], pos[2]],
        frustum: planesToPlanetFrame(planes, pos),
        viewportHeightPx: Math.max(1, size.y),
        fovY: (this.camera.fov * Math.PI) / 180,
      },
      params: {
        maxPixelError: this.lodSettings.maxPixelError,
        finestLevel: 0,
        // a server without levels of detail: every level-0 chunk, however many the budget allows
        maxChunks: this.levelZeroOnly ? Math.max(this.lodSettings.maxChunks, total) : this.lodSettings.maxChunks,
      },
      forward,
      up,
      near: this.camera.near,
      far: this.camera.far,
    };
  }

  /**
   * Starts a selection when the view differs from the last one selected for and no selection is
   * running: at once when the camera has stopped (the same view as the frame before), else at most
   * every 150 ms while it moves.
   */
  private maybeSelect(view: ViewState, now: number): void {
    if (this.lodPlanet === null || this.planetBusy !== null || this.selector.busy) return;
    if (this.selectedView !== null && sameView(view, this.selectedView)) return;
    const still = this.lastView !== null && sameView(view, this.lastView);
    if (!still && now - this.lastSelectAt < 150) return;
    if (this.selector.request(view.view, view.params)) {
      this.selectedView = view;
      this.lastSelectAt = now;
    }
  }

  private onSelection(r: SelectionResult): void {
    this.selectMs = r.ms;
    this.streamer.setSelection(r.selection, r.view);
  }

  /** The last selection was asked for the view of the last frame and has arrived. */
  private selectionCurrent(): boolean {
    return (
      !this.selector.busy && this.selectedView !== null && this.lastView !== null && sameView(this.lastView, this.selectedView)
    );
  }

  /** New selection settings: the next frame selects again. */
  setLod(settings: Partial<LodSettings>): void {
    const px = settings.maxPixelError ?? this.lodSettings.maxPixelError;
    const budget = settings.maxChunks ?? this.lodSettings.maxChunks;
    if (!(Number.isFinite(px) && px > 0) || !(Number.isInteger(budget) && budget >= 1)) {
      throw new Error('the pixel error must be a number above 0 and the chunk budget a whole number of at least 1');
    }
    this.lodSettings = { maxPixelError: px, maxChunks: budget };
    this.ui.setLod(this.lodSettings);
    this.settledFrames = 0;
  }

  // ---- frame loop ---------------------------------------------------------------------------

  private resize(): void {
    const w = Math.max(1, this.canvas.clientWidth || window.innerWidth);
    const h = Math.max(1, this.canvas.clientHeight || window.innerHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  /** Distance down to the loaded terrain from `from` (render space), or null without a hit. */
  private groundDistance(from: V3, up: V3, maxDistance: number): number | null {
    this.raycaster.near = 0;
    this.raycaster.far = maxDistance;
    const origin = new THREE.Vector3(from[0], from[1], from[2]);
    const down = new THREE.Vector3(-up[0], -up[1], -up[2]);
    this.raycaster.set(origin, down);
    let hits = this.raycaster.intersectObjects(this.scene.terrainMeshes(), false);
    if (hits.length === 0) {
      // A ray exactly along a chunk border (a face's centre line: chunks of every level meet
      // there) can pass between the two chunks' triangles, whose float32 vertices are relative
      // to different origins: tilt it by a microradian and try once more.
      const side = Math.abs(up[1]) < 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0);
      down.addScaledVector(side.cross(down).normalize(), 1e-6).normalize();
      this.raycaster.set(origin, down);
      hits = this.raycaster.intersectObjects(this.scene.terrainMeshes(), false);
    }
    return hits.length > 0 ? hits[0]!.distance : null;
  }

  private frame(): void {
    const now = performance.now();
    const dt = Math.min(0.1, Math.max(0, (now - this.lastFrame) / 1000));
    this.lastFrame = now;
    this.frames++;
    this.fpsFrames++;
    if (now - this.fpsSince >= 500) {
      this.fps = (this.fpsFrames * 1000) / (now - this.fpsSince);
      this.fpsFrames = 0;
      this.fpsSince = now;
    }
    const params = this.params;
    const input = this.input.take();
    if (!params) {
      this.renderer.render(this.scene.scene, this.camera);
      this.ui.setLoading(0, 0, this.planetBusy ?? 'waiting for the server');
      if (this.editChanged) {
        this.editChanged = false;
        this.toolsUi.update(this.editor.status(), this.pathActive);
        this.toolsUi.setPath(this.pathTool.status(), this.pathActive);
      }
      return;
    }
    const shape = params.shape;
    const viewportHeight = this.canvas.clientHeight || window.innerHeight;
    let moved = false;
    if (this.mode === 'orbit') {
      if (input.dragX !== 0 || input.dragY !== 0) {
        this.state = orbitDrag(this.state, shape, input.dragX, input.dragY, viewportHeight, FOV);
        moved = true;
      }
      if (input.wheel !== 0) {
        this.state = orbitZoom(this.state, shape, input.wheel);
        moved = true;
      }
    } else {
      if (input.dragX !== 0 || input.dragY !== 0) {
        this.state = look(this.state, input.dragX * 0.15, -input.dragY * 0.15);
        if (this.walk) this.state.pitch = Math.max(-80, Math.min(80, this.state.pitch));
        moved = true;
      }
      if (input.wheel !== 0) {
        this.speedFactor = Math.min(100, Math.max(0.01, this.speedFactor * Math.exp(-input.wheel * 0.001)));
      }
      if (input.forward !== 0 || input.right !== 0 || input.up !== 0) {
        const r = length(cameraPosition(this.state, shape));
        const height = this.aboveGround ?? Math.max(1, r - shape.outer);
        const speed = flySpeed(this.walk ? 3 : height) * this.speedFactor * (input.fast ? 4 : 1);
        this.state = flyMove(this.state, shape, input, dt, speed, this.walk).state;
        moved = true;
      }
    }
    this.clampAltitude();
    let pos = cameraPosition(this.state, shape);
    this.scene.place(pos);
    this.scene.scene.updateMatrixWorld();

    // ground: walk snaps the eye above it; fly measures it (every few frames)
    const up = normalize(pos);
    if (this.walk) {
      const probe = STEP_CLIMB - EYE_HEIGHT; // ray origin relative to the eye, along up
      const d = this.groundDistance(addScaled([0, 0, 0], up, probe), up, 5000);
      if (d !== null) {
        const below = d - probe; // height of the eye above the ground now
        const want = EYE_HEIGHT - below;
        // climb at once, fall at most 25 m/s
        const adjust = want > 0 ? want : Math.max(want, -25 * Math.max(dt, 1 / 60));
        this.state.alt += adjust;
        this.aboveGround = below + adjust;
        pos = cameraPosition(this.state, shape);
        this.scene.place(pos);
        this.scene.scene.updateMatrixWorld();
        moved = true;
      }
    } else if (this.mode === 'fly' && (this.frames % 6 === 0 || moved)) {
      this.aboveGround = this.groundDistance([0, 0, 0], up, 4 * shape.outer);
    } else if (this.mode === 'orbit') {
      this.aboveGround = null;
    }

    // camera orientation and clip planes
    const basis = cameraBasis(pos, this.state.heading, this.state.pitch);
    const m = new THREE.Matrix4().makeBasis(
      new THREE.Vector3(...basis.right),
      new THREE.Vector3(...basis.up),
      new THREE.Vector3(-basis.forward[0], -basis.forward[1], -basis.forward[2]),
    );
    this.camera.matrix.copy(m);
    this.camera.matrixWorld.copy(m);
    this.camera.matrixWorldInverse.copy(m).invert();
    // clip planes: with the logarithmic depth buffer only the far plane's order of magnitude
    // matters for precision; near stays a few centimetres up to a tenth of the height above the
    // highest terrain (or the ground measured below), far reaches past the horizon
    const r = length(pos);
    const clearance = Math.max(r - shape.outer, this.aboveGround ?? 0);
    this.camera.near = Math.min(1e4, Math.max(0.05, 0.1 * clearance));
    this.range = loadRange(r, params.extent, Math.max(4 * params.chunkWidth, 100));
    this.camera.far = Math.max(this.camera.near * 10, this.range * 1.05 + params.chunkWidth);
    this.camera.updateProjectionMatrix();
    this.cameraPos = pos;
    this.brushFrame(input);
    this.navFrame(pos, params);

    // sky: blue near the ground, black from orbit
    const aboveSea = r - (params.seaRadius ?? shape.datum);
    const skyT = (aboveSea - 0.04 * shape.datum) / (0.5 * shape.datum);
    this.scene.setSky(1 - Math.max(0, Math.min(1, skyT)) ** 0.5);

    // sun: above the camera's side of the planet, from the south-east-ish
    const enu = enuAt(pos);
    this.scene.setSun(normalize(addScaled(addScaled(enu.up, enu.east, 0.55), enu.north, 0.35)));

    // streaming: select for this view (when it changed), fetch and show
    this.projView.multiplyMatrices(this.camera.projectionMatrix, this.camera.matrixWorldInverse);
    this.frustum.setFromProjectionMatrix(this.projView);
    const view = this.viewState(pos, basis.forward, basis.up);
    this.maybeSelect(view, now);
    this.lastView = view;
    this.streamer.update();

    this.renderer.render(this.scene.scene, this.camera);

    const st = this.streamer.stats();
    const settled = this.planetBusy === null && this.selectionCurrent() && this.streamer.settled();
    this.settledFrames = settled ? this.settledFrames + 1 : 0;
    if (this.settledFrames >= 2 && this.readyWaiters.length > 0) {
      const waiters = this.readyWaiters;
      this.readyWaiters = [];
      for (const w of waiters) {
        clearTimeout(w.timer);
        w.resolve();
      }
    }
    if (now - this.lastUiUpdate > 200) {
      this.lastUiUpdate = now;
      this.ui.setStats({
        planet: `${this.choice.preset ?? '?'} · seed ${this.choice.seed ?? '?'}`,
        chunks: st.shown,
        loaded: st.loaded,
        pending: st.pending,
        levels: formatLevels(st.levels),
        triangles: st.triangles,
        fps: this.fps,
        lat: this.state.lat,
        lon: this.state.lon,
        alt: this.state.alt,
        aboveGround: this.aboveGround,
        heading: this.state.heading,
      });
      this.ui.setLoading(st.pending, st.missing, this.planetBusy);
      const es = this.editor.status();
      const et = this.editStatsText(es);
      this.ui.setEditStats(et.text, et.push, es.error);
    }
    if (this.editChanged) {
      this.editChanged = false;
      this.toolsUi.update(this.editor.status(), this.pathActive);
      const ps = this.pathTool.status();
      this.toolsUi.setPath(ps, this.pathActive);
      this.ui.setPathStats(pathStatsText(ps));
    }
    if (this.navChanged) {
      this.navChanged = false;
      this.ui.setNavGrid(this.navLoader.status());
    }
    if (moved) this.writeHash(false);
  }

  // ---- errors and the test hook -------------------------------------------------------------

  private showError(message: string): void {
    this.error = message;
    this.ui.showError(message);
  }

  private clearError(): void {
    this.error = null;
    this.ui.clearError();
  }

  stats(): PmcStats {
    const st = this.streamer.stats();
    const {
      loaded: _l, pending: _p, missing: _m, triangles: _t, vertices: _v, requested: _r, failed: _f, stale: _s, reloading: _g, reloads: _d,
      ...lod
    } = st;
    return {
      preset: this.choice.preset ?? null,
      seed: this.choice.seed ?? null,
      shown: st.shown,
      loaded: st.loaded,
      pending: st.pending,
      missing: st.missing,
      triangles: st.triangles,
      vertices: st.vertices,
      requested: st.requested,
      failed: st.failed,
      fps: this.fps,
      frames: this.frames,
      lat: this.state.lat,
      lon: this.state.lon,
      alt: this.state.alt,
      heading: this.state.heading,
      pitch: this.state.pitch,
      aboveGround: this.aboveGround,
      mode: this.mode,
      walk: this.walk,
      range: this.range,
      drawCalls: this.renderer.info.render.calls,
      ready: this.settledFrames >= 2,
      error: this.error,
      loadedKeys: this.streamer.shownNames(),
      background: this.scene.backgroundRgb(),
      lod: {
        ...lod,
        levelsText: formatLevels(st.levels),
        ...this.lodSettings,
        selectMs: this.selectMs,
        selecting: this.selector.busy,
        current: this.selectionCurrent(),
        levelZeroOnly: this.levelZeroOnly,
      },
      stale: st.stale,
      reloading: st.reloading,
      reloads: st.reloads,
      cursor: this.scene.brushCursorVisible(),
      edit: this.editor.status(),
      pathTool: this.pathActive,
    };
  }

  private testHook(): PmcTestHook {
    return {
      stats: () => this.stats(),
      ready: (timeoutMs = 120_000) =>
        new Promise<void>((resolve, reject) => {
          this.settledFrames = Math.min(this.settledFrames, 1);
          const timer = window.setTimeout(() => {
            this.readyWaiters = this.readyWaiters.filter((w) => w.timer !== timer);
            const s = this.stats();
            reject(
              new Error(
                `__pmc.ready() timed out after ${timeoutMs} ms (loaded ${s.loaded}, pending ${s.pending}, ` +
                  `missing ${s.missing}, error ${String(s.error)})`,
              ),
            );
          }, timeoutMs);
          this.readyWaiters.push({ resolve, reject, timer });
        }),
      setCamera: (lat, lon, alt, heading, pitch) => this.setCamera(lat, lon, alt, heading, pitch),
      setPlanet: (preset, seed) => this.setPlanet(preset, String(seed)),
      mode: (name) => {
        if (name === 'walk') this.setWalk(true);
        else if (name === 'fly') {
          this.setMode('fly');
          this.setWalk(false);
        } else if (name === 'orbit') this.setMode('orbit');
        return this.walk ? 'walk' : this.mode;
      },
      debug: (flags) => {
        this.scene.setDebug(flags);
        this.ui.setDebug(this.scene.debug());
        return this.scene.debug();
      },
      pick: (x, y) => {
        const p = this.pick(x, y);
        return p ? { distance: p.distance, point: p.point, key: p.key } : null;
      },
      path: () => this.pathHook(),
      navgrid: (on) => {
        if (on !== undefined) this.setNavGrid(on);
        return this.navGridHook();
      },
      lod: (settings) => {
        if (settings) this.setLod(settings);
        return { ...this.lodSettings };
      },
    };
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

/** The path row of the stats panel. */
function pathStatsText(s: PathStatus): string {
  switch (s.phase) {
    case 'empty':
      return '–';
    case 'start':
      return 'start set';
    case 'loading':
      return 'finding…';
    case 'found':
      return `${formatDistance(s.length!)} · ${s.steps} step${s.steps === 1 ? '' : 's'}`;
    case 'none':
      return 'no path';
    case 'error':
      return 'error';
  }
}
