// Streams chunks around the camera: keeps the chunk list from `/chunks` fresh, requests what
// `selectChunks` asks for, hands decoded chunks to the renderer and tells it what to drop.
// No three.js: the renderer plugs in through callbacks, so this can be tested with a fake API.

import { ApiError, isAbort, type ChunkEntry, type PlanetChoice, type PmcApi } from './api';
import type { DecodedChunk } from './chunkDecode';
import {
  needsRequery,
  selectChunks,
  type ChunkBounds,
  DEFAULT_MAX_CONCURRENT,
} from './chunkSelection';
import type { V3 } from './frames';

export interface StreamerCallbacks {
  /** A chunk arrived: build and show it. */
  onLoad(key: string, chunk: DecodedChunk, bounds: ChunkBounds): void;
  /** A chunk went out of range: remove and dispose it. */
  onUnload(key: string): void;
  /** A request failed for a reason that is not transient, or repeatedly. */
  onError(message: string): void;
  /** A request succeeded after errors: the error message may be cleared. */
  onRecovered?(): void;
}

export interface StreamerOptions {
  maxConcurrent?: number;
  /** Re-query `/chunks` when the camera moved more than this fraction of the range. */
  requeryFraction?: number;
  /** `limit` for `/chunks`. */
  listLimit?: number;
  now?: () => number;
}

interface Pending {
  bounds: ChunkBounds;
  abort: AbortController;
  /** A refetch of a chunk that stays on screen until the new data arrives. */
  reload: boolean;
}

interface Loaded {
  bounds: ChunkBounds;
  triangles: number;
  vertices: number;
  bytes: number;
}

export interface StreamerStats {
  loaded: number;
  pending: number;
  /** Wanted in range but neither loaded nor pending. */
  missing: number;
  triangles: number;
  vertices: number;
  bytes: number;
  /** Chunk requests made since the planet was chosen. */
  requested: number;
  failed: number;
  listInFlight: boolean;
  /** Loaded chunks waiting to be fetched again (edited), and refetches under way. */
  stale: number;
  reloading: number;
  /** Chunk refetches made since the planet was chosen. */
  reloads: number;
}

export class ChunkStreamer {
  private planet: PlanetChoice = {};
  private generation = 0;
  private candidates: ChunkBounds[] = [];
  private lastQuery: { camera: V3; range: number } | null = null;
  private listAbort: AbortController | null = null;
  private listRetryAt = 0;
  private readonly loaded = new Map<string, Loaded>();
  private readonly pending = new Map<string, Pending>();
  private readonly failures = new Map<string, { count: number; retryAt: number }>();
  /** Loaded chunks whose data is out of date (an edit named them): fetch again, keep showing. */
  private readonly stale = new Set<string>();
  /** Pending chunks an edit named while their fetch was in flight: fetch again after it answers. */
  private readonly refetch = new Set<string>();
  private reloads = 0;
  private missing = 0;
  private requested = 0;
  private failed = 0;
  private hadError = false;
  private readonly maxConcurrent: number;
  private readonly requeryFraction: number;
  private readonly listLimit: number;
  private readonly now: () => number;

  constructor(
    private readonly api: PmcApi,
    private readonly callbacks: StreamerCallbacks,
    opts: StreamerOptions = {},
  ) {
    this.maxConcurrent = opts.maxConcurrent ?? DEFAULT_MAX_CONCURRENT;
    this.requeryFraction = opts.requeryFraction ?? 0.25;
    this.listLimit = opts.listLimit ?? 4096;
    this.now = opts.now ?? (() => performance.now());
  }

  /** Drops every chunk and request, and streams `planet` from now on. */
  setPlanet(planet: PlanetChoice): void {
    this.generation++;
    this.listAbort?.abort();
    this.listAbort = null;
    for (const p of this.pending.values()) p.abort.abort();
    this.pending.clear();
    for (const key of [...this.loaded.keys()]) this.callbacks.onUnload(key);
    this.loaded.clear();
    this.failures.clear();
    this.stale.clear();
    this.refetch.clear();
    this.reloads = 0;
    this.candidates = [];
    this.lastQuery = null;
    this.listRetryAt = 0;
    this.missing = 0;
    this.requested = 0;
    this.failed = 0;
    this.planet = { ...planet };
  }

  /** Stops everything (the planet is being replaced or the page closed). */
  clear(): void {
    this.setPlanet(this.planet);
  }

  /**
   * The data of `keys` changed on the server (an edit): every one that is loaded is fetched again
   * and its mesh replaced only when the new data arrives (no hole meanwhile); every one whose
   * fetch is in flight is fetched once more after that answer (which may predate the change).
   * Keys neither loaded nor pending are ignored: they will be fetched fresh when wanted. The chunk
   * list is queried again too (an edit can make chunks hold surface that did not).
   * Returns how many chunks were marked.
   */
  reload(keys: Iterable<string>): number {
    let n = 0;
    for (const key of keys) {
      if (this.pending.has(key)) {
        this.refetch.add(key);
        n++;
      } else if (this.loaded.has(key)) {
        this.stale.add(key);
        // an edit is a new reason to try: forget the back-off of an earlier failure
        this.failures.delete(key);
        n++;
      }
    }
    if (n > 0) this.lastQuery = null;
    return n;
  }

  /** Every chunk's data changed (a `resync`): fetch all the loaded and pending ones again. */
  reloadAll(): number {
    return this.reload([...this.loaded.keys(), ...this.pending.keys()]);
  }

  /**
   * One streaming step: call it every frame (it is cheap). `range` is the load range,
   * `inFrustum` tests a bounding sphere in planet coordinates.
   */
  update(camera: V3, range: number, inFrustum: (center: V3, radius: number) => boolean): void {
    const now = this.now();
    if (
      !this.listAbort &&
      now >= this.listRetryAt &&
      needsRequery(this.lastQuery, camera, range, this.requeryFraction)
    ) {
      this.queryList(camera, range);
    }
    const blocked = new Set<string>();
    for (const [key, f] of this.failures) if (now < f.retryAt) blocked.add(key);
    // refetches of edited chunks come first: the user is looking at them
    if (this.stale.size > 0) {
      for (const key of this.stale) {
        if (this.pending.size >= this.maxConcurrent) break;
        if (blocked.has(key) || this.pending.has(key)) continue;
        const l = this.loaded.get(key);
        if (!l) {
          this.stale.delete(key);
          continue;
        }
        this.stale.delete(key);
        this.request(key, l.bounds, true);
      }
    }
    const sel = selectChunks({
      camera,
      range,
      candidates: this.candidates,
      inFrustum,
      loaded: new Map([...this.loaded].map(([k, v]) => [k, v.bounds])),
      pending: new Map([...this.pending].map(([k, v]) => [k, v.bounds])),
      blocked,
      maxConcurrent: this.maxConcurrent,
    });
    this.missing = sel.missing;
    for (const key of sel.cancel) {
      this.pending.get(key)?.abort.abort();
      this.pending.delete(key);
      this.refetch.delete(key);
      // a cancelled refetch of a chunk still shown must be tried again
      if (this.loaded.has(key)) this.stale.add(key);
    }
    for (const key of sel.unload) {
      this.loaded.delete(key);
      this.stale.delete(key);
      this.callbacks.onUnload(key);
    }
    const byKey = new Map(this.candidates.map((c) => [c.key, c]));
    for (const key of sel.request) {
      const bounds = byKey.get(key);
      if (bounds) this.request(key, bounds);
    }
  }

  private queryList(camera: V3, range: number): void {
    const generation = this.generation;
    const abort = new AbortController();
    this.listAbort = abort;
    const at: V3 = [camera[0], camera[1], camera[2]];
    // ask a little beyond the range: until the next query (after moving `requeryFraction` of
    // the range) every chunk that comes within range is already in the list
    const queryRange = range * (1 + this.requeryFraction);
    this.api
      .chunks(this.planet, at, queryRange, this.listLimit, abort.signal)
      .then((list) => {
        if (generation !== this.generation) return;
        this.candidates = list.chunks.map(toBounds);
        this.lastQuery = { camera: at, range };
        this.recovered();
      })
      .catch((e: unknown) => {
        if (generation !== this.generation || isAbort(e)) return;
        this.listRetryAt = this.now() + retryDelay(e, 1);
        this.reportError(`chunk list: ${errorMessage(e)}`);
      })
      .finally(() => {
        if (this.listAbort === abort) this.listAbort = null;
      });
  }

  private request(key: string, bounds: ChunkBounds, reload = false): void {
    const generation = this.generation;
    const abort = new AbortController();
    this.pending.set(key, { bounds, abort, reload });
    this.requested++;
    if (reload) this.reloads++;
    this.api
      .chunk(this.planet, key, abort.signal)
      .then((chunk) => {
        if (generation !== this.generation || this.pending.get(key)?.abort !== abort) return;
        this.pending.delete(key);
        this.failures.delete(key);
        this.loaded.set(key, {
          bounds,
          triangles: chunk.indexCount / 3,
          vertices: chunk.vertexCount,
          bytes: chunk.byteLength,
        });
        // named by an edit while in flight: this answer may predate it, so fetch once more
        if (this.refetch.delete(key)) this.stale.add(key);
        this.callbacks.onLoad(key, chunk, bounds);
        this.recovered();
      })
      .catch((e: unknown) => {
        if (generation !== this.generation || this.pending.get(key)?.abort !== abort) return;
        this.pending.delete(key);
        // a chunk still shown keeps its old mesh and is tried again (after the back-off)
        if (this.refetch.delete(key) || reload) {
          if (this.loaded.has(key)) this.stale.add(key);
        }
        if (isAbort(e)) return;
        this.failed++;
        const prev = this.failures.get(key)?.count ?? 0;
        const count = prev + 1;
        this.failures.set(key, { count, retryAt: this.now() + retryDelay(e, count) });
        // a busy server is normal under load: report only what keeps failing
        if (!(e instanceof ApiError && e.transient && count < 3)) {
          this.reportError(`chunk ${key}: ${errorMessage(e)}`);
        }
      });
  }

  private reportError(message: string): void {
    this.hadError = true;
    this.callbacks.onError(message);
  }

  private recovered(): void {
    if (this.hadError) {
      this.hadError = false;
      this.callbacks.onRecovered?.();
    }
  }

  /**
   * True when nothing is pending, missing or stale, the chunk list is current and a chunk is
   * loaded.
   */
  settled(camera: V3, range: number): boolean {
    return (
      this.loaded.size > 0 &&
      this.pending.size === 0 &&
      this.stale.size === 0 &&
      this.missing === 0 &&
      this.listAbort === null &&
      !needsRequery(this.lastQuery, camera, range, this.requeryFraction)
    );
  }

  stats(): StreamerStats {
    let triangles = 0;
    let vertices = 0;
    let bytes = 0;
    for (const l of this.loaded.values()) {
      triangles += l.triangles;
      vertices += l.vertices;
      bytes += l.bytes;
    }
    let reloading = 0;
    for (const p of this.pending.values()) if (p.reload) reloading++;
    return {
      loaded: this.loaded.size,
      pending: this.pending.size,
      missing: this.missing,
      triangles,
      vertices,
      bytes,
      requested: this.requested,
      failed: this.failed,
      listInFlight: this.listAbort !== null,
      stale: this.stale.size,
      reloading,
      reloads: this.reloads,
    };
  }

  loadedKeys(): string[] {
    return [...this.loaded.keys()];
  }
}

function toBounds(c: ChunkEntry): ChunkBounds {
  return { key: c.key, center: [c.center[0], c.center[1], c.center[2]], radius: c.radius };
}

function errorMessage(e: unknown): string {
  return e instanceof Error ? e.message : String(e);
}

/** Milliseconds before retrying after `count` failures: Retry-After when given, else backoff. */
export function retryDelay(e: unknown, count: number): number {
  if (e instanceof ApiError && e.retryAfter !== null) return Math.max(250, e.retryAfter * 1000);
  return Math.min(30_000, 500 * 2 ** Math.min(6, count - 1));
}
