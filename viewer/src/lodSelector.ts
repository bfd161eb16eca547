// Runs the level-of-detail selection for the camera, one at a time, in a Web Worker when the page
// has workers (otherwise on the calling thread, e.g. in the unit tests), and says when the view
// has changed enough to run it again. No three.js, no DOM.

import { SelectionRunner, unpack, type RunnerPlanet } from './lod/runner';
import type { LodParams, LodSelection, LodView, Plane } from './lod/select';
import type { WorkerAnswer, WorkerRequest } from './lod/worker';
import type { V3 } from './frames';

/** What starts a worker (the app: Vite's worker URL); null: select on this thread. */
export type WorkerFactory = (() => Worker) | null;

export interface SelectionResult {
  selection: LodSelection;
  view: LodView;
  params: LodParams;
  ms: number;
}

/**
 * Selects for one planet at a time. `request` starts a selection unless one is running; the answer
 * comes through `onResult` (or `onError`). Answers for an earlier planet are dropped.
 */
export class LodSelector {
  private worker: Worker | null = null;
  private runner: SelectionRunner | null = null;
  private planetId = 0;
  private nextId = 0;
  private running: { id: number; planetId: number; view: LodView; params: LodParams } | null = null;

  constructor(
    private readonly factory: WorkerFactory,
    private readonly onResult: (r: SelectionResult) => void,
    private readonly onError: (message: string) => void,
  ) {}

  /** The planet to select for from now on (a running selection's answer will be dropped). */
  setPlanet(planet: RunnerPlanet): void {
    this.planetId++;
    this.running = null;
    if (this.factory !== null) {
      if (this.worker === null) {
        this.worker = this.factory();
        this.worker.onmessage = (e: MessageEvent<WorkerAnswer>) => this.answer(e.data);
        this.worker.onerror = (e) => {
          this.running = null;
          this.onError(`the level-of-detail worker failed: ${e.message}`);
        };
      }
      const m: WorkerRequest = { type: 'planet', id: ++this.nextId, planet };
      this.worker.postMessage(m);
    } else {
      this.runner = new SelectionRunner(planet);
    }
  }

  /** A selection is running. */
  get busy(): boolean {
    return this.running !== null;
  }

  /** Starts a selection for `view`; false when one is running already. */
  request(view: LodView, params: LodParams): boolean {
    if (this.running !== null) return false;
    const id = ++this.nextId;
    this.running = { id, planetId: this.planetId, view, params };
    if (this.worker !== null) {
      const m: WorkerRequest = { type: 'select', id, view, params };
      this.worker.postMessage(m);
    } else {
      const runner = this.runner;
      queueMicrotask(() => {
        if (runner === null) {
          this.answer({ id, error: 'no planet to select for' });
          return;
        }
        try {
          const s = runner.select(view, params);
          this.answer({ id, rows: s.rows, truncated: s.truncated, ms: s.ms });
        } catch (e) {
          this.answer({ id, error: e instanceof Error ? e.message : String(e) });
        }
      });
    }
    return true;
  }

  private answer(a: WorkerAnswer): void {
    const run = this.running;
    if (run === null || run.id !== a.id) return;
    this.running = null;
    if (run.planetId !== this.planetId) return;
    if ('error' in a) {
      this.onError(`level-of-detail selection: ${a.error}`);
      return;
    }
    this.onResult({ selection: unpack(a), view: run.view, params: run.params, ms: a.ms });
  }

  dispose(): void {
    this.worker?.terminate();
    this.worker = null;
  }
}

/** The camera as a selection sees it, with what decides whether to select again. */
export interface ViewState {
  view: LodView;
  params: LodParams;
  /** The camera's forward and up directions (planet frame, unit). */
  forward: V3;
  up: V3;
  /** The clip distances the frustum was built with (metres). */
  near: number;
  far: number;
}

/**
 * Whether two views select the same chunks for all practical purposes: the eye within `epsilon`
 * metres, the directions within 1e-9 (cosine), the clip distances within a millionth, the same
 * viewport, field of view and parameters. The clip distances matter: the near plane follows the
 * height above the ground, measured a few frames after a teleport, and a selection made with the
 * old one leaves out every chunk closer than it.
 */
export function sameView(a: ViewState, b: ViewState, epsilon = 1e-3): boolean {
  const d = Math.hypot(a.view.eye[0] - b.view.eye[0], a.view.eye[1] - b.view.eye[1], a.view.eye[2] - b.view.eye[2]);
  const dot = (p: V3, q: V3): number => p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
  return (
    d <= epsilon &&
    dot(a.forward, b.forward) >= 1 - 1e-9 &&
    dot(a.up, b.up) >= 1 - 1e-9 &&
    Math.abs(a.near - b.near) <= 1e-6 * Math.max(a.near, b.near) &&
    Math.abs(a.far - b.far) <= 1e-6 * Math.max(a.far, b.far) &&
    a.view.viewportHeightPx === b.view.viewportHeightPx &&
    a.view.fovY === b.view.fovY &&
    a.params.maxPixelError === b.params.maxPixelError &&
    a.params.maxChunks === b.params.maxChunks &&
    a.params.finestLevel === b.params.finestLevel
  );
}

/**
 * The six frustum planes of a camera at the render origin (`[nx, ny, nz, d]`, inside where
 * `n . p + d >= 0`, as three.js's `Frustum` gives them) moved to the planet frame, where the
 * camera is at `eye`: `d' = d - n . eye` (in f64).
 */
export function planesToPlanetFrame(planes: readonly Plane[], eye: V3): Plane[] {
  return planes.map((p) => [p[0], p[1], p[2], p[3] - (p[0] * eye[0] + p[1] * eye[1] + p[2] * eye[2])]);
}
