// Editing the world: the chosen tool and brush settings, sending edits (paced by BrushThrottle,
// one at a time, respecting 429), undo and redo, the server push, and which chunks to reload.
// No DOM (the EventSource constructor is injected) and no three.js: the app feeds it the point
// under the cursor each frame, and the chunks plug in through `reload`/`reloadAll`.

import { ApiError, type EditAnswer, type EditEnabled, type PlanetChoice, type PlanetInfo, type PmcApi } from './api';
import {
  BrushThrottle,
  DEFAULT_RADIUS,
  DEFAULT_STRENGTH,
  clampRadius,
  clampStrength,
  editRequest,
  resolveMaterial,
  stepRadius,
  toolByName,
  type BrushSettings,
  type ToolName,
} from './editTools';
import { EditFeed, RevisionTracker, type EditEvent, type EventSourceFactory, type FeedState } from './editEvents';
import type { V3 } from './frames';

/** What the edits do to the chunks shown. */
export interface ChunkReloader {
  reload(keys: Iterable<string>): number;
  reloadAll(): number;
}

export interface EditSessionOptions {
  api: PmcApi;
  chunks: ChunkReloader;
  /** Opens the push stream; null: no push (edits of other clients show after a reload only). */
  eventSource: EventSourceFactory | null;
  now?: () => number;
  /** Something the UI shows changed. */
  onChange?: () => void;
  feedRetryMs?: number;
}

export interface EditStatus {
  enabled: boolean;
  /** Why editing is off (when it is). */
  reason: string | null;
  tool: ToolName;
  settings: BrushSettings;
  /** The server's limits and offer (when enabled). */
  minRadius: number;
  maxRadius: number;
  materials: string[];
  revision: number | null;
  active: number | null;
  redo: number | null;
  /** The last edit, undo or redo that failed, with the server's reason; cleared by a success. */
  error: string | null;
  /** A note that is not an error (nothing to undo, waiting for the rate limit). */
  notice: string | null;
  push: FeedState | 'off';
  inFlight: boolean;
  /** Edits, undos and redos answered since the page loaded. */
  sent: number;
}

/** A message for the user about a failed edit request. */
export function editErrorMessage(what: string, e: unknown): string {
  if (e instanceof ApiError) {
    const reason = e.serverMessage ?? e.message;
    switch (e.status) {
      case 0:
        return `${what} failed: ${e.message}`;
      case 429:
        return `${what} refused: too many edits (429)${e.retryAfter !== null ? `, wait ${e.retryAfter} s` : ''}: ${reason}`;
      case 403:
        return `${what} refused: editing is off on this server (403): ${reason}`;
      case 409:
        return `${what} refused: this planet is not the world's (409): ${reason}`;
      case 500:
        return `${what} failed: the server could not save it, nothing changed (500): ${reason}`;
      default:
        return `${what} refused (${e.status}): ${reason}`;
    }
  }
  return `${what} failed: ${e instanceof Error ? e.message : String(e)}`;
}

export class EditSession {
  private readonly api: PmcApi;
  private readonly chunks: ChunkReloader;
  private readonly eventSource: EventSourceFactory | null;
  private readonly now: () => number;
  private readonly onChange: () => void;
  private readonly feedRetryMs: number;

  private info: EditEnabled | null = null;
  private reason: string | null = 'waiting for the planet';
  private planet: PlanetChoice = {};
  private materials: string[] = [];
  private generation = 0;
  private tracker: RevisionTracker | null = null;
  private feed: EditFeed | null = null;
  private pushState: FeedState | 'off' = 'off';
  private throttle = new BrushThrottle();

  private tool: ToolName = 'look';
  private settings: BrushSettings = { radius: DEFAULT_RADIUS, strength: DEFAULT_STRENGTH, material: null };
  private active: number | null = null;
  private redoCount: number | null = null;
  private error: string | null = null;
  private notice: string | null = null;
  private inFlight = false;
  private queue: Promise<void> = Promise.resolve();
  private sent = 0;

  constructor(opts: EditSessionOptions) {
    this.api = opts.api;
    this.chunks = opts.chunks;
    this.eventSource = opts.eventSource;
    this.now = opts.now ?? (() => performance.now());
    this.onChange = opts.onChange ?? (() => undefined);
    this.feedRetryMs = opts.feedRetryMs ?? 1000;
  }

  /** The planet shown changed (its `/planet` answer): turns editing and the push on or off. */
  setPlanet(info: PlanetInfo): void {
    this.generation++;
    this.feed?.close();
    this.feed = null;
    this.pushState = 'off';
    this.planet = { ...(info.preset !== null ? { preset: info.preset } : {}), seed: info.seed };
    this.materials = [...(info.materials ?? [])];
    this.settings.material = resolveMaterial(this.materials, this.settings.material);
    this.throttle.release();
    this.inFlight = false;
    this.queue = Promise.resolve();
    const edit = info.edit;
    if (edit && edit.enabled) {
      this.info = edit;
      this.reason = null;
      this.active = edit.active;
      this.redoCount = edit.redo;
      this.tracker = new RevisionTracker(edit.revision);
      this.throttle = new BrushThrottle({ ratePerSecond: edit.rate_per_second });
      this.settings.radius = clampRadius(this.settings.radius, edit);
      if (this.eventSource) {
        const generation = this.generation;
        this.feed = new EditFeed(
          this.api.eventsUrl(),
          this.eventSource,
          {
            onEvent: (e) => {
              if (generation === this.generation) this.onEvent(e);
            },
            onState: (state, detail) => {
              if (generation !== this.generation) return;
              this.pushState = state;
              if (detail) this.notice = detail;
              else if (state === 'open' && this.notice?.startsWith('the edit stream')) this.notice = null;
              this.onChange();
            },
            onBadEvent: (message) => {
              if (generation !== this.generation) return;
              // cannot tell what changed: reload everything
              this.error = message;
              this.chunks.reloadAll();
              this.onChange();
            },
          },
          { retryMs: this.feedRetryMs },
        );
        this.feed.open();
      }
    } else {
      this.info = null;
      this.reason = edit
        ? edit.reason
        : 'this server has no editing API (an older pmc; start a newer `pmc serve --world FILE`)';
      this.active = null;
      this.redoCount = null;
      this.tracker = null;
      this.tool = 'look';
    }
    this.error = null;
    this.notice = null;
    this.onChange();
  }

  /** The server is back: the edit stream reconnects now (its `hello` tells what was missed). */
  reconnectNow(): void {
    this.feed?.reconnectNow();
  }

  get enabled(): boolean {
    return this.info !== null;
  }

  /** Whether a brush tool is chosen (the left button edits). */
  get brushActive(): boolean {
    return this.enabled && this.tool !== 'look';
  }

  /** The last world revision seen (answers and push), null when editing is off. */
  get revision(): number | null {
    return this.tracker?.revision ?? null;
  }

  get currentTool(): ToolName {
    return this.tool;
  }

  get radius(): number {
    return this.settings.radius;
  }

  setTool(tool: ToolName): void {
    toolByName(tool);
    if (tool !== 'look' && !this.info) {
      this.notice = `editing is off: ${this.reason ?? 'unknown reason'}`;
      this.onChange();
      return;
    }
    this.tool = tool;
    if (tool === 'look') this.throttle.release();
    this.onChange();
  }

  setRadius(r: number): void {
    this.settings.radius = this.info ? clampRadius(r, this.info) : Number.isFinite(r) && r > 0 ? r : DEFAULT_RADIUS;
    this.onChange();
  }

  stepRadius(dir: 1 | -1): void {
    if (!this.info) return;
    this.setRadius(stepRadius(this.settings.radius, dir, this.info));
  }

  setStrength(s: number): void {
    this.settings.strength = clampStrength(s);
    this.onChange();
  }

  setMaterial(m: string): void {
    this.settings.material = resolveMaterial(this.materials, m);
    this.onChange();
  }

  /** The left button went down with `hit` (planet frame, metres) under the cursor. */
  press(hit: V3 | null): void {
    if (!this.brushActive) return;
    const now = this.now();
    if (!this.throttle.press(now, hit)) {
      this.notice = `too many edits: wait ${Math.ceil(this.throttle.blockedFor(now) / 1000)} s`;
      this.onChange();
    } else if (!hit) {
      this.notice = 'no terrain under the cursor (loaded chunks only)';
      this.onChange();
    }
  }

  release(): void {
    this.throttle.release();
  }

  /** Every frame: `hit` is the point under the cursor (null: none). Sends an edit when due. */
  frame(hit: V3 | null): void {
    if (!this.info || this.tool === 'look') return;
    const center = this.throttle.poll(this.now(), hit, this.settings.radius, this.inFlight);
    if (center) this.apply(center);
  }

  /** Sends one brush at `center` (planet frame, metres). */
  apply(center: V3): Promise<void> {
    const info = this.info;
    if (!info) return Promise.resolve();
    const label = toolByName(this.tool).label;
    let body;
    try {
      body = editRequest(this.tool, center, this.settings, info);
    } catch (e) {
      this.error = `${label}: ${e instanceof Error ? e.message : String(e)}`;
      this.onChange();
      return Promise.resolve();
    }
    return this.send(label, 'edit', () => this.api.postEdit(body, this.planet));
  }

  undo(): Promise<void> {
    if (!this.info) return Promise.resolve();
    return this.send('Undo', 'undo', () => this.api.undo(this.planet));
  }

  redo(): Promise<void> {
    if (!this.info) return Promise.resolve();
    return this.send('Redo', 'redo', () => this.api.redo(this.planet));
  }

  /** Runs edit requests one after the other; applies their answers. */
  private send(what: string, action: 'edit' | 'undo' | 'redo', call: () => Promise<EditAnswer>): Promise<void> {
    const generation = this.generation;
    this.inFlight = true;
    this.onChange();
    const run = async (): Promise<void> => {
      if (generation !== this.generation) return;
      const now = this.now();
      if (this.throttle.blockedFor(now) > 0) {
        this.notice = `${what} not sent: too many edits, wait ${Math.ceil(this.throttle.blockedFor(now) / 1000)} s`;
        return;
      }
      try {
        const answer = await call();
        if (generation !== this.generation) return;
        this.sent++;
        this.error = null;
        this.active = answer.active;
        this.redoCount = answer.redo;
        if (answer.id === null && action !== 'edit') this.notice = `nothing to ${action}`;
        else this.notice = null;
        if (this.tracker?.change(answer.revision) && answer.chunks.length > 0) this.chunks.reload(answer.chunks);
      } catch (e) {
        if (generation !== this.generation) return;
        if (e instanceof ApiError && e.rateLimited) {
          this.throttle.block(this.now() + 1000 * Math.max(1, e.retryAfter ?? 1));
        }
        this.error = editErrorMessage(what, e);
      }
    };
    const p = this.queue.then(run).finally(() => {
      if (generation !== this.generation) return;
      if (this.queue === p) this.inFlight = false;
      this.onChange();
    });
    this.queue = p;
    return p;
  }

  private onEvent(e: EditEvent): void {
    const tracker = this.tracker;
    if (!tracker) return;
    switch (e.type) {
      case 'hello':
        if (tracker.hello(e.revision)) this.chunks.reloadAll();
        break;
      case 'edit':
        if (tracker.change(e.revision)) this.chunks.reload(e.chunks);
        break;
      case 'resync':
        tracker.reset(e.revision);
        this.chunks.reloadAll();
        break;
    }
    this.onChange();
  }

  status(): EditStatus {
    return {
      enabled: this.info !== null,
      reason: this.reason,
      tool: this.tool,
      settings: { ...this.settings },
      minRadius: this.info?.min_brush_radius ?? 0,
      maxRadius: this.info?.max_brush_radius ?? 0,
      materials: [...this.materials],
      revision: this.tracker?.revision ?? null,
      active: this.active,
      redo: this.redoCount,
      error: this.error,
      notice: this.notice,
      push: this.pushState,
      inFlight: this.inFlight,
      sent: this.sent,
    };
  }
}
