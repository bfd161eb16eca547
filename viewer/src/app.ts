// The viewer application: wires the API, the streamer, the scene, the camera controller, the
// input, the UI, the URL hash and the test hook together, and starts the frame loop. The planet,
// editing and navigation state lives here; the work of a frame is frameLoop.ts's.

import * as THREE from 'three';
import { PmcApi, type PlanetInfo, type TerrainInfo } from './api';
import { storeAtmosphere, type SkySettings, type SkyState } from './atmosphere';
import { atmosphereOf } from './atmosphereModel';
import type { CameraMode } from './cameraModel';
import { CameraController, type PickResult } from './cameraController';
import { ChunkStreamer } from './chunkStreamer';
import { ConnectionMonitor, offlineMessage } from './connection';
import { formatLevels } from './chunkSelection';
import { EditSession, type EditStatus } from './editSession';
import { toolByName, type ToolName } from './editTools';
import { bookmarkName, loadBookmarks, saveBookmarks, withBookmark, withoutBookmark, type Bookmark } from './bookmarks';
import { Flight, parseGoTo, type GoToTarget } from './goTo';
import { planetIdentity, planetName } from './planetName';
import { shortcutOf } from './shortcuts';
import { length, normalize, type V3 } from './frames';
import { FrameLoop } from './frameLoop';
import { Input, type InputFrame } from './input';
import { LodSelector } from './lodSelector';
import { NavGridLoader, groundPoint, navRange } from './navOverlay';
import { NavScene } from './navScene';
import { PathTool, type PathStatus } from './pathTool';
import { planetParams, type PlanetParams } from './planetParams';
import { parseImagery, loadImageryTexture, type ImageryInfo } from './imagery';
import { parseRelief, type ReliefGrid } from './relief';
import { loadReliefTexture } from './reliefTexture';
import { PlanetScene, type DebugFlags } from './planetScene';
import { Readiness } from './readiness';
import {
  createTestHook,
  navGridHookOf,
  pathHookOf,
  type ModeName,
  type PmcNavGridHook,
  type PmcPathHook,
  type PmcPlace,
  type PmcStats,
  type TestHookTarget,
} from './testHook';
import { TILESET_PATH, noTiles, otherPlanet, type TilesStats } from './tiles';
import type { TilesView } from './tilesMode';
import { ToolsUi } from './toolsUi';
import { Ui, formatDistance } from './ui';
import { formatHash, parseHash, type UrlState } from './urlState';
import { DEFAULT_LOD, ViewSelection, lodPlanetOf, type LodSettings } from './viewSelection';

export class App implements TestHookTarget {
  private readonly api = new PmcApi('api/v1');
  private readonly renderer: THREE.WebGLRenderer;
  private readonly cameras: CameraController;
  private readonly scene = new PlanetScene();
  private readonly navScene = new NavScene();
  private readonly pathTool: PathTool;
  private readonly navLoader: NavGridLoader;
  /** The Path tool is chosen (the editor's tool is Look meanwhile). */
  private pathActive = false;
  /** The imagery draped on the planet shown, if any. */
  private imageryTexture: THREE.Texture | null = null;
  /** The relief of the planet shown (an elevation model's), if any. */
  private reliefTexture: THREE.Texture | null = null;
  private pathDrawn = -1;
  private gridDrawn = -1;
  private navChanged = true;
  /** The world revision the path and the grid were last asked for. */
  private navRevision = 0;
  private readonly streamer: ChunkStreamer;
  private readonly selection: ViewSelection;
  readonly readiness = new Readiness();
  private readonly loop: FrameLoop;
  private readonly ui: Ui;
  private readonly toolsUi: ToolsUi;
  private readonly editor: EditSession;
  private editChanged = true;
  private readonly input: Input;
  /** The 3D Tiles mode is on. */
  private tilesOn = false;
  /** Its tiles, drawn instead of the chunks; null when the mode is off or its renderer's code loads. */
  private tiles: TilesView | null = null;
  /** Changes to what the 3D Tiles mode draws (turned on or off, tiles shown or hidden), for the picture's key. */
  private tilesPicture = 0;
  /** What the planet shown is made of (`/planet`'s `terrain`), to tell whether the tiles show it. */
  private terrain: TerrainInfo | null = null;

  private params: PlanetParams | null = null;
  private choice: { preset?: string; seed?: string } = {};
  /** The name of the elevation-model planet the server serves, once seen. */
  private servedTerrain: string | null = null;
  /** The planet's name as the panel and the title show it (planetName.ts). */
  private planetTitle = '–';
  /** The bookmarks of views (bookmarks.ts), as kept in local storage. */
  private bookmarks: Bookmark[] = loadBookmarks(globalThis.localStorage);
  /** A flight of `goTo` under way. */
  private flight: { plan: Flight; start: number } | null = null;
  private planetRequest = 0;
  private planetBusy: string | null = null;

  private lastHashWrite = 0;
  private writtenHash = '';
  private error: string | null = null;
  /** Whether the renderer multisamples (`#aa=0` in the link at load turns it off). */
  private readonly antialias: boolean;
  /** The planet shown, as `planetIdentity` writes it (to tell, back online, whether the server serves another). */
  private planetJson = '';
  /** Whether the server answers (the notice and the retry when it does not). */
  readonly connection: ConnectionMonitor;
  private offlineTicker: ReturnType<typeof setInterval> | null = null;

  constructor(private readonly canvas: HTMLCanvasElement) {
    // a logarithmic depth buffer: the same relative depth precision from 5 cm to the far side of
    // an Earth-sized planet, with no near/far juggling
    // multisampling unless the link turns it off (`#aa=0`): under a software renderer it about
    // doubles a frame's cost (SwiftShader: 7.4 s against 4.1 s for the Earth 2 m above a range)
    this.antialias = parseHash(location.hash).aa ?? true;
    this.renderer = new THREE.WebGLRenderer({
      canvas,
      antialias: this.antialias,
      powerPreference: 'high-performance',
      logarithmicDepthBuffer: true,
      // the terrain marks its pixels: the sea disk is drawn only where no terrain is
      stencil: true,
    });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.connection = new ConnectionMonitor({
      probe: (signal) => this.api.health(signal).then(() => undefined),
      onChange: (s) => {
        this.streamer.setPaused(!s.online);
        this.showConnection();
      },
      onOnline: () => this.resume(),
    });
    this.api.observer = this.connection;
    this.renderer.outputColorSpace = THREE.SRGBColorSpace;
    // the ground the camera measures and picks: the chunks, or the tiles in the 3D Tiles mode
    this.cameras = new CameraController(canvas, () => (this.tiles ? this.tiles.meshes() : this.scene.terrainMeshes()));

    this.streamer = new ChunkStreamer(this.api, {
      onShow: (name, seams, chunk) => {
        this.scene.addChunk(name, seams, chunk);
        this.cameras.groundChanged();
      },
      onHide: (name) => {
        this.scene.removeChunk(name);
        this.cameras.groundChanged();
      },
      onError: (message) => this.showError(message),
      onRecovered: () => this.clearError(),
    });
    this.selection = new ViewSelection(
      new LodSelector(
        typeof Worker === 'function'
          ? () => new Worker(new URL('./lod/worker.ts', import.meta.url), { type: 'module', name: 'pmc-lod' })
          : null,
        (r) => {
          this.selection.onSelection(r);
          this.streamer.setSelection(r.selection, r.view);
        },
        (message) => this.showError(message),
      ),
    );
    this.ui = new Ui({
      onPlanet: (preset, seed) => void this.setPlanet(preset, seed).catch(() => undefined),
      onMode: (mode) => this.setMode(mode),
      onWalk: (walk) => this.setWalk(walk),
      onDebug: (flags) => this.setDebug(flags),
      onNavGrid: (on) => this.setNavGrid(on),
      onTiles: (on) => this.setTilesMode(on),
      onLod: (settings) => this.setLod(settings),
      onSky: (settings) => void this.setSky(settings),
      onBookmarkAdd: () => this.addBookmark(),
      onScreenshot: () => this.screenshot(),
      onNorth: () => this.faceNorth(),
      onRetry: () => this.connection.retryNow(),
      onBookmarkOpen: (name) => this.openBookmark(name),
      onBookmarkRemove: (name) => {
        this.bookmarks = withoutBookmark(this.bookmarks, name);
        saveBookmarks(globalThis.localStorage, this.bookmarks);
        this.ui.setBookmarks(this.bookmarks);
      },
      onGoTo: (text) => {
        try {
          this.goTo(text);
        } catch (e) {
          this.showError(e instanceof Error ? e.message : String(e));
        }
      },
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
      onToggleMode: () => this.setMode(this.cameras.mode === 'orbit' ? 'fly' : 'orbit'),
      onToggleWalk: () => {
        if (this.cameras.mode === 'fly') this.setWalk(!this.cameras.walk);
      },
      brushActive: () => this.editor.brushActive || this.pathActive,
      onShortcut: (e) => this.shortcut(e),
    });
    canvas.addEventListener('dblclick', () => {
      if (this.cameras.mode === 'fly' && !this.editor.brushActive && !this.pathActive) this.input.requestPointerLock();
    });
    window.addEventListener('resize', () => this.resize());
    window.addEventListener('hashchange', () => this.onHashChange());
    this.resize();
    this.loop = new FrameLoop(
      {
        renderer: this.renderer,
        scene: this.scene,
        cameras: this.cameras,
        input: this.input,
        streamer: this.streamer,
        selection: this.selection,
        readiness: this.readiness,
        ui: this.ui,
      },
      {
        params: () => this.params,
        busy: () => this.planetBusy,
        planetLabel: () => this.planetTitle,
        travel: (now) => this.travel(now),
        brush: (input) => this.brushFrame(input),
        navigation: (pos, params) => this.navFrame(pos, params),
        editStats: () => {
          const es = this.editor.status();
          const et = this.editStatsText(es);
          this.ui.setEditStats(et.text, et.push, es.error);
        },
        panels: (planetShown) => this.panels(planetShown),
        moved: () => this.writeHash(false),
        pictureChanges: () => this.navScene.pictureChanges() + this.tilesPicture,
        tiles: () => (this.tilesOn ? { view: this.tiles } : null),
      },
    );

    const fromHash = parseHash(location.hash);
    this.applyUrlState(fromHash, false);
    this.choice = { ...(fromHash.preset ? { preset: fromHash.preset } : {}), ...(fromHash.seed ? { seed: fromHash.seed } : {}) };
    this.ui.setMode(this.cameras.mode, this.cameras.walk);
    this.ui.setDebug(this.scene.debug());
    this.ui.setBookmarks(this.bookmarks);
    this.ui.setLod(this.selection.settings);
    this.ui.setSky(this.scene.atmosphere.state());
    window.__pmc = createTestHook(this);
    this.loop.start();
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
        const [imagery, relief] = await Promise.all([this.loadImagery(info), this.loadRelief(info)]);
        if (request !== this.planetRequest) {
          imagery.texture?.dispose();
          relief.texture?.dispose();
          return;
        }
        this.applyPlanet(info);
        this.setImagery(imagery.texture, imagery.info);
        this.setRelief(relief.texture, relief.grid);
        this.clearError();
        if (imagery.error) this.showError(`The planet's imagery is not shown: ${imagery.error}`);
        else if (relief.error) this.showError(`The planet's relief is not used for its materials: ${relief.error}`);
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

  /** The planet's imagery (`/planet`'s `imagery` block and its picture), or why there is none. */
  private async loadImagery(info: PlanetInfo): Promise<{ texture: THREE.Texture | null; info: ImageryInfo | null; error: string | null }> {
    try {
      const imagery = parseImagery(info);
      if (!imagery) return { texture: null, info: null, error: null };
      const max = this.renderer.capabilities.maxTextureSize;
      return { texture: await loadImageryTexture(imagery, document.baseURI, max), info: imagery, error: null };
    } catch (e) {
      return { texture: null, info: null, error: e instanceof Error ? e.message : String(e) };
    }
  }

  /** The planet's relief (`/planet`'s `relief` block and its grid), or why there is none. */
  private async loadRelief(info: PlanetInfo): Promise<{ texture: THREE.Texture | null; grid: ReliefGrid | null; error: string | null }> {
    try {
      const relief = parseRelief(info);
      if (!relief) return { texture: null, grid: null, error: null };
      const max = this.renderer.capabilities.maxTextureSize;
      const { texture, grid } = await loadReliefTexture(relief, document.baseURI, max);
      return { texture, grid, error: null };
    } catch (e) {
      return { texture: null, grid: null, error: e instanceof Error ? e.message : String(e) };
    }
  }

  private setRelief(texture: THREE.Texture | null, grid: ReliefGrid | null): void {
    if (this.reliefTexture && this.reliefTexture !== texture) this.reliefTexture.dispose();
    this.reliefTexture = texture;
    this.scene.setRelief(texture, grid);
  }

  private setImagery(texture: THREE.Texture | null, info: ImageryInfo | null): void {
    if (this.imageryTexture && this.imageryTexture !== texture) this.imageryTexture.dispose();
    this.imageryTexture = texture;
    this.scene.setImagery(texture, info);
  }

  private applyPlanet(info: PlanetInfo): void {
    this.planetJson = planetIdentity(info);
    this.params = planetParams(info);
    this.planetTitle = planetName(info);
    this.terrain = info.terrain ?? null;
    if (this.tiles) this.checkTilesPlanet(this.tiles.stats(performance.now()).terrain);
    document.title = `${this.planetTitle} — PMC`;
    // An elevation-model planet has no preset: it is the server's own planet, asked for with
    // no preset parameter (the picker lists it under the empty value).
    if (info.preset === null) this.servedTerrain = info.terrain?.name ?? 'elevation model';
    this.choice = { ...(info.preset !== null ? { preset: info.preset } : {}), seed: info.seed };
    const lod = lodPlanetOf(info);
    this.streamer.setPlanet(this.choice, lod.planet);
    this.selection.setPlanet(info, lod);
    this.editor.setPlanet(info);
    this.pathTool.setPlanet(this.params.shape.datum);
    this.navLoader.reset();
    this.navRevision = this.editor.revision ?? 0;
    this.scene.clearChunks();
    this.scene.setPlanet(this.params);
    this.scene.setAtmosphere(atmosphereOf(info, this.params.shape));
    this.ui.setSky(this.scene.atmosphere.state());
    const shape = this.params.shape;
    if (!Number.isFinite(this.cameras.state.alt)) this.cameras.state.alt = 1.6 * shape.outer;
    this.cameras.clampAltitude(shape);
    const served = this.servedTerrain;
    const presets =
      served === null ? info.presets : [{ name: '', label: served, description: 'the real planet this server serves' }, ...info.presets];
    this.ui.setPresets(presets, info.preset ?? '');
    this.ui.setPlanet(info.preset ?? '', info.seed);
    this.planetBusy = null;
    this.readiness.reset();
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

  setMode(mode: CameraMode): void {
    if (!this.cameras.setMode(mode, this.params?.shape ?? null)) return;
    if (mode === 'orbit') this.input.releasePointerLock();
    this.ui.setMode(this.cameras.mode, this.cameras.walk);
    this.writeHash(true);
  }

  setWalk(walk: boolean): void {
    if (walk && this.cameras.mode !== 'fly') this.setMode('fly');
    this.cameras.setWalk(walk);
    this.ui.setMode(this.cameras.mode, this.cameras.walk);
    this.writeHash(true);
  }

  modeName(): ModeName {
    return this.cameras.walk ? 'walk' : this.cameras.mode;
  }

  setCamera(lat: number, lon: number, alt: number, heading?: number, pitch?: number): void {
    if (this.cameras.setCamera(lat, lon, alt, heading, pitch, this.params?.shape ?? null)) {
      this.ui.setMode(this.cameras.mode, this.cameras.walk);
    }
    this.readiness.reset();
    this.writeHash(true);
  }

  /**
   * Flies to the place the go-to box's `text` names (`LAT, LON[, ALT]`; the altitude kept when
   * none is given): along the great circle, climbing and descending on the way. Returns the place;
   * throws with what is wrong with the text.
   */
  goTo(text: string): GoToTarget {
    const target = parseGoTo(text);
    if ('error' in target) throw new Error(target.error);
    this.flyTo(target);
    return target;
  }

  /** Flies to `target` (the altitude kept when it has none), as `goTo` does. */
  private flyTo(target: GoToTarget): void {
    if (!this.params) throw new Error('no planet yet to go to a place on');
    // (walking would hold the camera to the ground on the way)
    if (this.cameras.walk) this.setWalk(false);
    const s = this.cameras.state;
    const from = { lat: s.lat, lon: s.lon, alt: Number.isFinite(s.alt) ? s.alt : 0 };
    const to = { lat: target.lat, lon: target.lon, alt: target.alt ?? from.alt };
    this.flight = { plan: new Flight(from, to, this.params.shape.datum), start: performance.now() };
    this.readiness.reset();
  }

  /** Turns the camera to face north, where it is (the compass, `R`). */
  faceNorth(): void {
    this.cameras.state = { ...this.cameras.state, heading: 0 };
    this.writeHash(true);
  }

  /** The server-gone notice, kept up to date each second while the server does not answer. */
  private showConnection(): void {
    const s = this.connection.state();
    this.ui.setOffline(offlineMessage(s, Date.now()));
    if (!s.online && this.offlineTicker === null) {
      this.offlineTicker = setInterval(() => this.ui.setOffline(offlineMessage(this.connection.state(), Date.now())), 1000);
    } else if (s.online && this.offlineTicker !== null) {
      clearInterval(this.offlineTicker);
      this.offlineTicker = null;
    }
  }

  /**
   * The server answers again: what failed meanwhile is fetched now, the edit stream reconnects
   * (its `hello` tells what was missed), and a server that now serves another planet (restarted
   * with other options) has it loaded.
   */
  private resume(): void {
    this.streamer.retryFailed();
    this.editor.reconnectNow();
    if (this.params === null) return;
    const choice = this.choice;
    void this.api
      .planet(choice)
      .then((info) => {
        if (choice === this.choice && planetIdentity(info) !== this.planetJson) void this.loadPlanet(choice, true);
      })
      .catch(() => undefined);
  }

  /**
   * Saves the picture as a PNG (the canvas: the planet without the panels), named by the planet
   * and the place: `pmc-earthlike-seed-7-27.983N-86.917E.png`.
   */
  screenshot(): string {
    const s = this.cameras.state;
    const slug = this.planetTitle.replace(/[^A-Za-z0-9.]+/g, '-').replace(/^-+|-+$/g, '');
    const place = `${Math.abs(s.lat).toFixed(3)}${s.lat >= 0 ? 'N' : 'S'}-${Math.abs(s.lon).toFixed(3)}${s.lon >= 0 ? 'E' : 'W'}`;
    const name = `pmc-${slug}-${place}.png`;
    const a = document.createElement('a');
    a.href = this.loop.snapshot();
    a.download = name;
    a.click();
    return name;
  }

  /** Keeps the current view as a bookmark named by its place. */
  addBookmark(): Bookmark {
    const s = this.cameras.state;
    const b: Bookmark = { name: bookmarkName(s.lat, s.lon, Number.isFinite(s.alt) ? s.alt : 0), planet: this.planetTitle, hash: this.viewHash() };
    this.bookmarks = withBookmark(this.bookmarks, b);
    if (!saveBookmarks(globalThis.localStorage, this.bookmarks)) this.showError('The bookmark is kept for this page only: the browser refuses to store it');
    this.ui.setBookmarks(this.bookmarks, b.name);
    return b;
  }

  /** Goes to the bookmark named `name`: a flight on the same planet, else the view's link. */
  openBookmark(name: string): void {
    const b = this.bookmarks.find((x) => x.name === name);
    if (!b) return;
    const u = parseHash(b.hash);
    if (b.planet === this.planetTitle && u.lat !== undefined && u.lon !== undefined) {
      this.flyTo({ lat: u.lat, lon: u.lon, alt: u.alt ?? null });
    } else {
      location.hash = b.hash;
    }
  }

  /** The camera along a flight of `goTo`, this frame (before the camera's own step). */
  private travel(now: number): boolean {
    if (this.flight === null) return false;
    const t = (now - this.flight.start) / 1000;
    const p = this.flight.plan.at(t);
    this.cameras.setCamera(p.lat, p.lon, p.alt, undefined, undefined, this.params?.shape ?? null);
    if (t >= this.flight.plan.duration) {
      this.flight = null;
      this.readiness.reset();
      this.writeHash(true);
    }
    return true;
  }

  private applyUrlState(u: UrlState, fromUser: boolean): void {
    this.cameras.applyUrlState(u, this.params?.shape ?? null);
    if (u.px !== undefined || u.chunks !== undefined) {
      this.selection.setSettings({ ...(u.px !== undefined ? { maxPixelError: u.px } : {}), ...(u.chunks !== undefined ? { maxChunks: u.chunks } : {}) });
      this.ui.setLod(this.selection.settings);
      this.readiness.reset();
    }
    if (u.tiles !== undefined) this.setTilesMode(u.tiles, false);
    if (fromUser) this.ui.setMode(this.cameras.mode, this.cameras.walk);
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

  /** The URL hash of the view now: the planet, the mode and the camera. */
  private viewHash(): string {
    const s = this.cameras.state;
    const lod = this.selection.settings;
    return formatHash({
      ...(this.choice.preset ? { preset: this.choice.preset } : {}),
      ...(this.choice.seed ? { seed: this.choice.seed } : {}),
      mode: this.cameras.mode,
      walk: this.cameras.walk,
      ...(Number.isFinite(s.alt) ? { lat: s.lat, lon: s.lon, alt: s.alt, heading: s.heading, pitch: s.pitch } : {}),
      // the detail settings, where they are not the defaults
      ...(lod.maxPixelError !== DEFAULT_LOD.maxPixelError ? { px: lod.maxPixelError } : {}),
      ...(lod.maxChunks !== DEFAULT_LOD.maxChunks ? { chunks: lod.maxChunks } : {}),
      ...(this.antialias ? {} : { aa: false }),
      ...(this.tilesOn ? { tiles: true } : {}),
    });
  }

  private writeHash(force: boolean): void {
    const now = performance.now();
    if (!force && now - this.lastHashWrite < 500) return;
    this.lastHashWrite = now;
    const hash = this.viewHash();
    if (hash !== this.writtenHash && hash !== location.hash) {
      this.writtenHash = hash;
      history.replaceState(null, '', hash);
    }
  }

  // ---- editing ------------------------------------------------------------------------------

  /** Editing shortcuts (outside text fields); true when `e` was one. */
  private shortcut(e: KeyboardEvent): boolean {
    const s = shortcutOf(e);
    if (s === null) return false;
    switch (s.action) {
      case 'undo':
      case 'redo':
        if (!this.editor.enabled) return false;
        if (!e.repeat) void (s.action === 'redo' ? this.editor.redo() : this.editor.undo());
        return true;
      case 'escape':
        // Esc closes the help, clears the path (the tool stays), then goes back to Look
        if (this.ui.helpShown) {
          this.ui.toggleHelp(false);
          return true;
        }
        if (this.pathTool.active) {
          this.pathTool.clear();
          return true;
        }
        if (this.editor.currentTool === 'look' && !this.pathActive) return false;
        this.chooseTool('look');
        return true;
      case 'path':
        this.choosePathTool();
        return true;
      case 'navgrid':
        if (!e.repeat) this.setNavGrid(!this.navLoader.enabled);
        return true;
      case 'tool':
        if (s.tool === 'look' && this.editor.currentTool === 'look' && !this.pathActive) return false;
        this.chooseTool(s.tool!);
        return true;
      case 'radius-down':
      case 'radius-up':
        if (!this.editor.enabled) return false;
        this.editor.stepRadius(s.action === 'radius-up' ? 1 : -1);
        return true;
      case 'overlays':
        if (!e.repeat) this.ui.toggleOverlays();
        return true;
      case 'help':
        if (!e.repeat) this.ui.toggleHelp();
        return true;
      case 'panel':
        if (!e.repeat) this.ui.togglePanel();
        return true;
      case 'goto':
        this.ui.focusGoTo();
        return true;
      case 'north':
        if (!e.repeat) this.faceNorth();
        return true;
      case 'tiles':
        if (!e.repeat) this.setTilesMode(!this.tilesOn);
        return true;
      default:
        // the camera's keys (input.ts)
        return false;
    }
  }

  /** An editing tool (or Look) from the tool bar or its key; leaves the Path tool. */
  private chooseTool(tool: ToolName): void {
    this.editor.setTool(tool);
    // a tool editing is off for is refused (the editor says why): the Path tool stays then
    if (this.editor.currentTool === tool && this.pathActive) {
      this.pathActive = false;
      this.editChanged = true;
    }
    // the tool bar shows the choice at once, not at the next animation frame
    this.panels(this.params !== null);
  }

  /** The Path tool: the left button picks the start, then the goal. No world needed. */
  private choosePathTool(): void {
    this.editor.setTool('look');
    this.pathActive = true;
    this.editChanged = true;
    this.panels(this.params !== null);
  }

  setNavGrid(on: boolean): void {
    this.navLoader.setEnabled(on);
    this.navChanged = true;
  }

  /** Up to `count` vertices of the chunks shown and where they show on the canvas (test hook). */
  places(count: number): PmcPlace[] {
    const cam = this.cameras.position;
    return this.scene.sampleVertices(count).map((v) => {
      const d: V3 = [cam[0] - v.point[0], cam[1] - v.point[1], cam[2] - v.point[2]];
      const len = Math.hypot(d[0], d[1], d[2]) || 1;
      const facing = (v.normal[0] * d[0] + v.normal[1] * d[1] + v.normal[2] * d[2]) / len;
      const r = Math.hypot(v.point[0], v.point[1], v.point[2]) || 1;
      const upFacing = (v.point[0] * d[0] + v.point[1] * d[1] + v.point[2] * d[2]) / (r * len);
      return { ...v, screen: this.cameras.toScreen(v.point), facing, upFacing };
    });
  }

  /** The loaded terrain under canvas pixel (x, y), with the camera of the last frame. */
  pick(x: number, y: number): (PickResult & { render: V3 }) | null {
    if (!this.params) return null;
    return this.cameras.pick(x, y);
  }

  /** The brush under the mouse: cursor, press, drag and release. */
  private brushFrame(input: InputFrame): void {
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
      const ground = groundPoint(pos, this.cameras.aboveGround, params.shape.datum);
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
      this.navScene.setPath(ps.line.length >= 2 ? ps.line : null);
      this.navScene.setMarkers(ps.from?.point ?? null, ps.to?.point ?? null);
    }
    if (this.gridDrawn !== this.navLoader.version) {
      this.gridDrawn = this.navLoader.version;
      this.navScene.setGrid(this.navLoader.overlay());
    }
    this.navScene.place(pos);
  }

  pathHook(): PmcPathHook {
    return pathHookOf(this.pathTool.status(), this.navScene.drawnPath(), (p) => this.cameras.toScreen(p), this.pathActive);
  }

  navGridHook(): PmcNavGridHook {
    const { width, height } = this.cameras.viewport();
    return navGridHookOf(this.navLoader.status(), this.navLoader.overlay(), this.navScene.gridShown(), {
      width,
      height,
      camera: this.cameras.position,
      toScreen: (p) => this.cameras.toScreen(p),
      pick: (x, y) => this.pick(x, y),
    });
  }

  // ---- level of detail ------------------------------------------------------------------------

  /** New selection settings: the next frame selects again. */
  setLod(settings: Partial<LodSettings>): void {
    this.selection.setSettings(settings);
    this.ui.setLod(this.selection.settings);
    this.readiness.reset();
    this.writeHash(true);
  }

  lodSettings(): LodSettings {
    return this.selection.settings;
  }

  /** The next frame draws, whatever its picture's key (the test hook's `redraw()`). */
  invalidate(): void {
    this.loop.invalidate();
  }

  // ---- 3D Tiles mode ----------------------------------------------------------------------------

  /**
   * The 3D Tiles mode on or off (the panel's button, `T`, `#tiles=1`, the test hook). On: the
   * chunks are hidden and no chunk is asked for; a TilesRenderer (tilesMode.ts, its code loaded
   * the first time) loads the server's tileset in the sphere frame and draws it in their place.
   * Off: the tiles are disposed and the chunks show again (those loaded before at once; the view's
   * selection resumes).
   */
  setTilesMode(on: boolean, writeHash = true): void {
    if (on === this.tilesOn) return;
    this.tilesOn = on;
    if (on) {
      import('./tilesMode')
        .then(({ TilesView }) => {
          if (!this.tilesOn || this.tiles) return;
          this.tiles = new TilesView(new URL(TILESET_PATH, document.baseURI).href, this.scene.scene, this.scene, {
            onChange: () => {
              this.tilesPicture++;
              this.cameras.groundChanged();
            },
            onError: (message) => this.showError(message),
            onTileset: (frame, terrain) => {
              if (frame !== 'sphere') this.showError(`3D Tiles: the tileset is in the ${String(frame)} frame, not on the planet's sphere as drawn here`);
              else this.checkTilesPlanet(terrain);
            },
          });
          this.tilesPicture++;
          this.cameras.groundChanged();
        })
        .catch((e: unknown) => this.showError(`3D Tiles: cannot load the tiles' renderer: ${e instanceof Error ? e.message : String(e)}`));
    } else {
      this.tiles?.dispose();
      this.tiles = null;
    }
    this.tilesPicture++;
    this.scene.setChunksVisible(!on);
    this.cameras.groundChanged();
    this.readiness.reset();
    this.ui.setTilesMode(on);
    if (writeHash) this.writeHash(true);
  }

  tilesStats(): TilesStats {
    return this.tiles?.stats(performance.now()) ?? noTiles(this.tilesOn);
  }

  /** The tiles are of the planet the server serves: say so when another one is shown here. */
  private checkTilesPlanet(terrain: string | null): void {
    if (otherPlanet(terrain, this.terrain)) {
      this.showError(`3D Tiles show the planet the server serves (${String(terrain)}), not the one chosen here`);
    }
  }

  // ---- panels -------------------------------------------------------------------------------

  private resize(): void {
    const w = Math.max(1, this.canvas.clientWidth || window.innerWidth);
    const h = Math.max(1, this.canvas.clientHeight || window.innerHeight);
    this.renderer.setSize(w, h, false);
    this.cameras.setAspect(w / h);
  }

  /** The sky panel's and the test hook's settings: atmosphere on or off, the sun's place. */
  setSky(settings: Partial<SkySettings>): SkyState {
    if (settings.atmosphere !== undefined) storeAtmosphere(settings.atmosphere);
    this.scene.setSkySettings(settings);
    const state = this.scene.atmosphere.state();
    this.ui.setSky(state);
    return state;
  }

  setDebug(flags: Partial<DebugFlags>): DebugFlags {
    this.scene.setDebug(flags);
    this.ui.setSky(this.scene.atmosphere.state());
    this.ui.setDebug(this.scene.debug());
    return this.scene.debug();
  }

  /** The tools panel (and, with a planet shown, the path and nav grid lines) where they changed. */
  private panels(planetShown: boolean): void {
    if (this.editChanged) {
      this.editChanged = false;
      this.toolsUi.update(this.editor.status(), this.pathActive);
      const ps = this.pathTool.status();
      this.toolsUi.setPath(ps, this.pathActive);
      if (planetShown) this.ui.setPathStats(pathStatsText(ps));
    }
    if (planetShown && this.navChanged) {
      this.navChanged = false;
      this.ui.setNavGrid(this.navLoader.status());
    }
  }

  // ---- errors and stats ---------------------------------------------------------------------

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
    const cam = this.cameras;
    return {
      preset: this.choice.preset ?? null,
      flying: this.flight !== null,
      seed: this.choice.seed ?? null,
      shown: st.shown,
      loaded: st.loaded,
      pending: st.pending,
      missing: st.missing,
      triangles: st.triangles,
      vertices: st.vertices,
      requested: st.requested,
      failed: st.failed,
      fps: this.loop.fps,
      frames: this.loop.frames,
      draws: this.loop.draws,
      drawMs: this.loop.drawMs,
      lat: cam.state.lat,
      lon: cam.state.lon,
      alt: cam.state.alt,
      heading: cam.state.heading,
      pitch: cam.state.pitch,
      aboveGround: cam.aboveGround,
      mode: cam.mode,
      walk: cam.walk,
      range: cam.range,
      drawCalls: this.renderer.info.render.calls,
      ready: this.readiness.ready,
      error: this.error,
      online: this.connection.state().online,
      loadedKeys: this.streamer.shownNames(),
      background: this.scene.backgroundRgb(),
      lod: {
        ...lod,
        levelsText: formatLevels(st.levels),
        ...this.selection.settings,
        selectMs: this.selection.selectMs,
        selecting: this.selection.busy,
        current: this.selection.current(),
        levelZeroOnly: this.selection.levelZeroOnly,
      },
      stale: st.stale,
      reloading: st.reloading,
      reloads: st.reloads,
      cursor: this.scene.brushCursorVisible(),
      edit: this.editor.status(),
      pathTool: this.pathActive,
      tiles: this.tilesStats(),
    };
  }
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
      return s.smoothed
        ? `${formatDistance(s.smoothed.length)} · ${s.smoothed.legs} leg${s.smoothed.legs === 1 ? '' : 's'}`
        : `${formatDistance(s.length!)} · ${s.steps} step${s.steps === 1 ? '' : 's'}`;
    case 'none':
      return 'no path';
    case 'error':
      return 'error';
  }
}
