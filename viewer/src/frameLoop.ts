// The frame loop: every animation frame moves the camera by the input and places the scene around
// it (the floating origin), runs the brush and the navigation overlay, sets the sky and the sun,
// asks for the level-of-detail selection of the view and streams its chunks (or, in the 3D Tiles
// mode, lets the tiles pick and load theirs), renders, counts the settled frames `__pmc.ready()`
// waits for and refreshes the panels.

import * as THREE from 'three';
import { FOV, type CameraController } from './cameraController';
import { metresPerPixel, rayToSphere, scaleBar } from './hud';
import { formatLevels } from './chunkSelection';
import type { ChunkStreamer } from './chunkStreamer';
import { length, type V3 } from './frames';
import type { Input, InputFrame } from './input';
import type { PlanetParams } from './planetParams';
import { PictureKey } from './pictureKey';
import type { PlanetScene } from './planetScene';
import type { Readiness } from './readiness';
import { noTiles } from './tiles';
import type { TilesView } from './tilesMode';
import type { Ui } from './ui';
import type { ViewSelection } from './viewSelection';

/** What a frame works with. */
export interface FrameParts {
  renderer: THREE.WebGLRenderer;
  scene: PlanetScene;
  cameras: CameraController;
  input: Input;
  streamer: ChunkStreamer;
  selection: ViewSelection;
  readiness: Readiness;
  ui: Ui;
}

/** The application's part of a frame. */
export interface FrameSteps {
  /** The planet shown; null until one is loaded. */
  params(): PlanetParams | null;
  /** What the planet is busy with (e.g. 'loading planet'), null when nothing. */
  busy(): string | null;
  /** The stats panel's planet line. */
  planetLabel(): string;
  /** Moves the camera along a flight under way (before the camera's own step); true while one is. */
  travel(now: number): boolean;
  /** The brush (or the Path tool) under the mouse, with the camera of this frame. */
  brush(input: InputFrame): void;
  /** The path and the nav grid overlay around the camera at `pos`. */
  navigation(pos: V3, params: PlanetParams): void;
  /** The stats panel's editing line. */
  editStats(): void;
  /** The tools panel (and, with `planetShown`, the path and nav grid lines) where they changed. */
  panels(planetShown: boolean): void;
  /** The camera moved this frame. */
  moved(): void;
  /** Changes to the objects the application draws besides the scene's (the navigation overlay, the tiles). */
  pictureChanges(): number;
  /**
   * The 3D Tiles mode: null when off; on, its tiles (`view`), drawn instead of the chunks (null
   * for the moment its renderer's code loads).
   */
  tiles(): { view: TilesView | null } | null;
}

export class FrameLoop {
  /** Frames drawn, and frames per second over the last half second or so. */
  frames = 0;
  fps = 0;
  private lastFrame = performance.now();
  private fpsFrames = 0;
  private fpsSince = performance.now();
  private lastUiUpdate = 0;
  /** Frames that drew. */
  draws = 0;
  private readonly redraw = new RedrawPolicy();
  /** When the GPU finished the frames drawn (a fence after a drawn frame). */
  private readonly gpu: GpuTimer;
  /** The key of the last picture drawn (render on demand: see pictureKey.ts). */
  private readonly pictureKey = new PictureKey();
  private readonly key: number[] = [];
  private readonly bufferSize = new THREE.Vector2();

  constructor(
    private readonly parts: FrameParts,
    private readonly steps: FrameSteps,
  ) {
    const gl = parts.renderer.getContext();
    this.gpu = new GpuTimer('fenceSync' in gl ? gl : null);
  }

  /** Milliseconds a drawn frame costs (the redraw policy's measure: see `RedrawPolicy.costMs`). */
  get drawMs(): number {
    return this.redraw.costMs;
  }

  start(): void {
    this.parts.renderer.setAnimationLoop(() => this.frame());
  }

  /** The next frame draws, whether or not the picture's key changed. */
  invalidate(): void {
    this.pictureKey.invalidate();
  }

  /** Draws the scene, remembering the key of the picture drawn. */
  /**
   * The picture as a PNG data URL: drawn anew and read back at once (before the browser
   * composites the frame and clears the drawing buffer). The canvas alone: no panel is in it.
   */
  snapshot(): string {
    this.draw(performance.now());
    return this.parts.renderer.domElement.toDataURL('image/png');
  }

  private draw(now: number): void {
    const { renderer, scene, cameras } = this.parts;
    renderer.render(scene.scene, cameras.camera);
    this.gpu.drew(now);
    this.redraw.drew(now);
    this.pictureKey.drew(this.key);
    this.draws++;
  }

  /**
   * The key of the picture this frame would draw with the camera at `pos` (planet frame): the
   * camera, the drawing buffer, the scene's key and the application's changes.
   */
  private frameKey(pos: readonly number[]): readonly number[] {
    const { renderer, scene, cameras } = this.parts;
    const key = this.key;
    key.length = 0;
    cameras.camera.updateMatrixWorld();
    renderer.getDrawingBufferSize(this.bufferSize);
    key.push(pos[0]!, pos[1]!, pos[2]!, this.bufferSize.x, this.bufferSize.y, this.steps.pictureChanges());
    key.push(...cameras.camera.matrixWorld.elements, ...cameras.camera.projectionMatrix.elements);
    scene.pushPictureKey(key);
    return key;
  }

  private frame(): void {
    const { renderer, scene, cameras, input: inputs, streamer, selection, readiness, ui } = this.parts;
    const steps = this.steps;
    const now = performance.now();
    const dt = Math.min(0.1, Math.max(0, (now - this.lastFrame) / 1000));
    this.redraw.frameStarted(now - this.lastFrame);
    const gpuMs = this.gpu.poll(now);
    if (gpuMs !== null) this.redraw.gpuFinished(gpuMs);
    this.lastFrame = now;
    this.frames++;
    this.fpsFrames++;
    if (now - this.fpsSince >= 500) {
      this.fps = (this.fpsFrames * 1000) / (now - this.fpsSince);
      this.fpsFrames = 0;
      this.fpsSince = now;
    }
    const params = steps.params();
    const input = inputs.take();
    if (!params) {
      if (this.pictureKey.changed(this.frameKey([0, 0, 0]))) this.draw(now);
      ui.setLoading(0, 0, 0, steps.busy() ?? 'waiting for the server');
      steps.panels(false);
      return;
    }
    const shape = params.shape;
    const flying = steps.travel(now);
    const tilesMode = steps.tiles();
    const tiles = tilesMode?.view ?? null;
    const { pos, basis, moved } = cameras.frame(input, params, dt, this.frames, (p) => {
      scene.place(p);
      tiles?.place(p);
      scene.scene.updateMatrixWorld();
    });
    steps.brush(input);
    steps.navigation(pos, params);

    // the background where nothing is drawn (the sky covers it where the atmosphere is drawn):
    // on a planet with air a flat blue near the ground, black from orbit; black without air
    const r = length(pos);
    const aboveSea = r - (params.seaRadius ?? shape.datum);
    const skyT = (aboveSea - 0.04 * shape.datum) / (0.5 * shape.datum);
    scene.setSky(scene.atmosphere.kind() === null ? 0 : 1 - Math.max(0, Math.min(1, skyT)) ** 0.5);

    // sun: at the azimuth and elevation of the sky settings over the horizon under the camera
    // (by default south-east-ish and well up); the atmosphere's place of the camera
    scene.setSun(scene.atmosphere.frame(pos));

    // streaming: select for this view (when it changed), fetch and show; in the 3D Tiles mode no
    // chunk is asked for (those loaded stay, hidden), the tiles select theirs at the same
    // screen-space error and load them
    if (tilesMode) {
      tiles?.update(cameras.camera, renderer, selection.settings.maxPixelError, now);
    } else {
      const viewportHeightPx = renderer.getDrawingBufferSize(new THREE.Vector2()).y;
      selection.frame(cameras.camera, viewportHeightPx, pos, basis.forward, basis.up, now, steps.busy() !== null);
      streamer.update();
    }

    const settled = tilesMode ? (tiles?.settled(now) ?? false) : streamer.settled();
    const changed = this.pictureKey.changed(this.frameKey(pos));
    if (this.redraw.shouldDraw(now, moved || inputActive(input), settled, changed, this.gpu.busy)) this.draw(now);

    const st = streamer.stats();
    const wasReady = readiness.ready;
    readiness.frame(!flying && steps.busy() === null && (tilesMode !== null || selection.current()) && settled);
    // the panels every 200 ms, and in the frame the view becomes ready: what they say then is
    // what is shown (a waiter of `__pmc.ready()` reads them after this frame)
    if (now - this.lastUiUpdate > 200 || (readiness.ready && !wasReady)) {
      this.lastUiUpdate = now;
      const s = cameras.state;
      // the scale bar: the ground's scale where the view's axis meets the sphere of the ground
      // under the camera (of the datum where that is not known yet)
      const groundR = cameras.aboveGround !== null ? r - cameras.aboveGround : shape.datum;
      const hit = rayToSphere(pos, basis.forward, groundR);
      const scale = hit === null ? null : scaleBar(metresPerPixel(hit, FOV, renderer.domElement.clientHeight));
      ui.setStats({
        planet: steps.planetLabel(),
        chunks: st.shown,
        loaded: st.loaded,
        pending: st.pending,
        levels: formatLevels(st.levels),
        triangles: st.triangles,
        fps: this.fps,
        lat: s.lat,
        lon: s.lon,
        alt: s.alt,
        aboveGround: cameras.aboveGround,
        heading: s.heading,
        scale,
      });
      const ts = tilesMode ? (tiles?.stats(now) ?? noTiles(true)) : null;
      ui.setTiles(ts);
      if (ts) ui.setLoading(ts.visible, ts.queued + ts.downloading + ts.parsing, 0, steps.busy());
      else ui.setLoading(st.shown, st.pending, st.missing, steps.busy());
      steps.editStats();
    }
    steps.panels(true);
    if (moved) steps.moved();
  }
}

/** Whether `input` asks for anything this frame (a drag, the wheel, keys, a brush press). */
function inputActive(input: InputFrame): boolean {
  return (
    input.dragX !== 0 ||
    input.dragY !== 0 ||
    input.wheel !== 0 ||
    input.tilt !== 0 ||
    input.pinch !== 0 ||
    input.forward !== 0 ||
    input.right !== 0 ||
    input.up !== 0 ||
    input.brushPresses.length > 0 ||
    input.brushRelease
  );
}

/**
 * Which frames draw. A frame whose picture would be the one drawn last (same camera, same objects,
 * same uniforms: `changed` false) does not draw. Otherwise every frame draws, except on a slow
 * renderer (software WebGL, an old GPU: over SLOW_FRAME_MS a drawn frame) while chunks stream in
 * under a still camera: then the picture is redrawn every STREAMING_REDRAW_MS, or once in
 * STREAMING_DRAW_SHARE frame times when drawing takes longer, and never while the GPU is still
 * drawing the last one. A busy GPU holds up what the page sends it (chunk uploads, the
 * compositor's read back of the canvas) until the frame before is done, so redrawing a picture
 * that changes by a few chunks at a time would starve the streaming (by 20 times with software
 * WebGL on two cores). A camera that moves, or input, draws at once; a settled view draws as soon
 * as it changed.
 *
 * A frame's cost is the longer of two measures: the interval from a frame that drew to the next
 * (what drawing held up the page's own thread), and the time from a draw to the GPU having
 * finished it (a fence, `GpuTimer`). The second is the one that counts under a software
 * renderer: three.js hands the frame over at once and the GPU process then draws it on every
 * core for seconds (12 s for a 2 m view of the Earth at 1024 x 640 on two cores), while the
 * interval after the draw said a second.
 */
export class RedrawPolicy {
  /** Milliseconds a frame that draws takes (a running mean of the intervals after drawing). */
  renderMs = 0;
  /** Milliseconds from a draw to the GPU having finished it (a running mean; 0: not measured). */
  gpuMs = 0;
  private lastDraw = Number.NEGATIVE_INFINITY;
  private drewLast = false;

  /** A frame starts, `sinceLast` ms after the one before. */
  frameStarted(sinceLast: number): void {
    if (this.drewLast) this.renderMs = this.renderMs === 0 ? sinceLast : 0.8 * this.renderMs + 0.2 * sinceLast;
    this.drewLast = false;
  }

  /** A drawn frame was finished by the GPU `ms` after it was drawn. */
  gpuFinished(ms: number): void {
    this.gpuMs = this.gpuMs === 0 ? ms : 0.8 * this.gpuMs + 0.2 * ms;
  }

  /** What a drawn frame costs, milliseconds: the longer of the two measures. */
  get costMs(): number {
    return Math.max(this.renderMs, this.gpuMs);
  }

  /**
   * Whether the renderer is slow: a frame interval after drawing over SLOW_FRAME_MS, or a draw
   * the GPU finished over SLOW_GPU_MS later (the fence is read once a frame, so on a fast GPU
   * the second measure is a frame or two of the display's, 33 ms at 60 Hz, 66 ms at 30 Hz).
   */
  get slow(): boolean {
    return this.renderMs >= SLOW_FRAME_MS || this.gpuMs >= SLOW_GPU_MS;
  }

  /**
   * Whether the frame starting at `now` draws (`active`: the camera moved or input came;
   * `changed`: its picture differs from the last drawn; `gpuBusy`: the GPU has not finished
   * the last frame drawn).
   */
  shouldDraw(now: number, active: boolean, settled: boolean, changed = true, gpuBusy = false): boolean {
    if (active) return true;
    if (!changed) return false;
    if (settled || !this.slow) return true;
    if (gpuBusy) return false;
    return now - this.lastDraw >= Math.max(STREAMING_REDRAW_MS, STREAMING_DRAW_SHARE * this.costMs);
  }

  /** The frame starting at `now` drew. */
  drew(now: number): void {
    this.lastDraw = now;
    this.drewLast = true;
  }
}

/** The parts of a WebGL 2 context `GpuTimer` uses. */
export type FenceContext = Pick<
  WebGL2RenderingContext,
  'fenceSync' | 'getSyncParameter' | 'deleteSync' | 'SYNC_GPU_COMMANDS_COMPLETE' | 'SYNC_STATUS' | 'SIGNALED'
>;

/**
 * When the GPU finished a drawn frame: a fence follows a draw (one at a time: a draw while one is
 * out is not timed), and each frame asks whether it has signalled, which never blocks. Without
 * WebGL 2 (or with a lost context) nothing is measured and the GPU is never busy.
 */
export class GpuTimer {
  private sync: WebGLSync | null = null;
  private since = 0;

  constructor(private readonly gl: FenceContext | null) {}

  /** A frame was drawn at `now`. */
  drew(now: number): void {
    if (this.gl === null || this.sync !== null) return;
    this.sync = this.gl.fenceSync(this.gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
    this.since = now;
  }

  /** Whether the GPU is still drawing the frame timed. */
  get busy(): boolean {
    return this.sync !== null;
  }

  /** At `now`: the milliseconds the timed frame took if the GPU finished it since, else null. */
  poll(now: number): number | null {
    if (this.gl === null || this.sync === null) return null;
    if (this.gl.getSyncParameter(this.sync, this.gl.SYNC_STATUS) !== this.gl.SIGNALED) return null;
    this.gl.deleteSync(this.sync);
    this.sync = null;
    return now - this.since;
  }
}

/** A drawn frame slower than this (ms) makes a slow renderer (see `RedrawPolicy`). */
export const SLOW_FRAME_MS = 50;
/** ...and so does a draw the GPU finishes this much later (ms; see `RedrawPolicy.slow`). */
export const SLOW_GPU_MS = 200;
/** How often a slow renderer redraws a still view while chunks stream in (ms)... */
export const STREAMING_REDRAW_MS = 400;
/** ...or at most once in this many frame times (drawing takes at most a quarter of the time). */
export const STREAMING_DRAW_SHARE = 4;
