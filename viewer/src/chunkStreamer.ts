// Streams the chunks of a level-of-detail selection: fetches the wanted chunks (the selection's
// drawn leaves, each with its seams mask) most urgent first, aborts what is no longer wanted, keeps
// a bounded cache of loaded chunks, and tells the renderer what to show so that the picture never
// has a hole while levels change (`chooseDisplay`). Edited chunks are fetched again while their
// old meshes stay. No three.js: the renderer plugs in through callbacks, so this is tested with a
// fake API.

import { ApiError, isAbort, type PlanetChoice, type PmcApi } from './api';
import type { DecodedChunk } from './chunkDecode';
import {
  chooseDisplay,
  chunkName,
  fetchPriority,
  HOLE_PRIORITY,
  levelHistogram,
  parseChunkName,
  pixelScale,
  splitChunks,
  variantId,
  type SelectedLeaf,
} from './chunkSelection';
import { chunkSphere, type BoundingSphere } from './lod/bounds';
import { parentOf, type ChunkKey, type Layout, type Vec3 } from './lod/layout';
import { sphereBelowHorizon, sphereInFrustum, type LodSelection, type LodView } from './lod/select';

export interface StreamerCallbacks {
  /** Show `chunk` (variant `seams` of chunk `name`), replacing whatever of `name` is shown. */
  onShow(name: string, seams: number, chunk: DecodedChunk): void;
  /** Stop showing chunk `name`. */
  onHide(name: string): void;
  /** A request failed for a reason that is not transient, or repeatedly. */
  onError(message: string): void;
  /** A request succeeded after errors: the error message may be cleared. */
  onRecovered?(): void;
}

export interface StreamerOptions {
  /** At most this many chunks in flight (default DEFAULT_MAX_CONCURRENT). */
  maxConcurrent?: number;
  /** Loaded chunks kept at most (shown and wanted ones are never dropped; default 6000). */
  maxLoaded?: number;
  /** Bytes of loaded chunks kept at most (same rule; default 256 MiB). */
  maxBytes?: number;
  /**
   * A request unanswered for this long (milliseconds; default 60 000) is aborted and tried again
   * after the back-off: a request the server or the network never answers must not hold one of
   * the few slots for good, or the chunks behind it are never asked for (a stalled view).
   */
  requestTimeoutMs?: number;
  now?: () => number;
}

/** The planet's level-of-detail description (`/planet`'s `lod` block and layout). */
export interface LodPlanet {
  layout: Layout;
  errors: number[];
  occluder: number;
}

interface Pending {
  name: string;
  seams: number;
  abort: AbortController;
  /** A refetch of an edited chunk that stays on screen until the new data arrives. */
  reload: boolean;
  priority: number;
  /** When it was sent (`now()`). */
  sent: number;
}

interface Loaded {
  name: string;
  seams: number;
  chunk: DecodedChunk;
  triangles: number;
  bytes: number;
  /** The selection (serial) that last wanted or showed it: eviction drops the oldest first. */
  lastWanted: number;
}

export interface StreamerStats {
  /** Chunks in the cache (shown or not). */
  loaded: number;
  pending: number;
  /** Wanted chunks neither loaded nor pending. */
  missing: number;
  /** Chunks shown, and their triangles and vertices. */
  shown: number;
  triangles: number;
  vertices: number;
  /** Bytes of the chunks in the cache. */
  bytes: number;
  /** Chunks the selection wants (its drawn leaves) and all its leaves. */
  wanted: number;
  selected: number;
  /** Chunks shown per level (index = level). */
  levels: number[];
  /** What is shown is exactly the wanted set. */
  exact: boolean;
  /** Every part of the view is covered. */
  complete: boolean;
  /** The selection hit the chunk budget. */
  truncated: boolean;
  /** Chunk requests made, aborted because they were no longer wanted, failed; chunks evicted. */
  requested: number;
  aborted: number;
  failed: number;
  evicted: number;
  /** Requests given up after `requestTimeoutMs` without an answer (counted in `failed` too). */
  timedOut: number;
  /** Wanted chunks neither loaded nor pending that wait for the back-off of a failure. */
  blocked: number;
  /** No chunk is requested: the server does not answer (connection.ts probes it). */
  paused: boolean;
  /** Shown chunks waiting to be fetched again (edited), and refetches under way. */
  stale: number;
  reloading: number;
  /** Chunk refetches made since the planet was chosen. */
  reloads: number;
  /** Selections received since the planet was chosen. */
  selections: number;
  /** Chunks between a chunk shown and wanted chunks far below it, still to load. */
  bridges: number;
}

/**
 * Chunks in flight at once by default. The API client sends them in batches (`PmcApi.chunk`), so
 * this is not the browser's six connections: enough to keep the server's workers busy while each
 * chunk waits for its round trip (on two cores about 25 ms), few enough that a view that changes
 * drops little work.
 */
export const DEFAULT_MAX_CONCURRENT = 32;

export class ChunkStreamer {
  private planet: PlanetChoice = {};
  private lod: LodPlanet | null = null;
  private generation = 0;
  private serial = 0;
  private leaves = new Map<string, SelectedLeaf>();
  private split = new Set<string>();
  private view: LodView | null = null;
  private truncated = false;
  /** The wanted variants (drawn leaves) and their priorities, most urgent first. */
  private wanted: { id: string; name: string; seams: number; key: ChunkKey; priority: number }[] = [];
  private wantedIds = new Set<string>();
  /**
   * Chunks between a chunk shown and the wanted chunks far below it (seams 0), fetched too so that
   * a region refines level by level instead of waiting for all its finest chunks; and the loaded
   * chunks on those paths, kept from eviction.
   */
  private bridges: { id: string; name: string; seams: number; key: ChunkKey; priority: number }[] = [];
  private bridgeIds = new Set<string>();
  private onPaths = new Set<string>();
  private readonly cache = new Map<string, Loaded>();
  /** Loaded variants per chunk name. */
  private readonly variants = new Map<string, Set<number>>();
  /** Per chunk name: how many chunks strictly below it have a loaded variant. */
  private readonly below = new Map<string, number>();
  private readonly shown = new Map<string, number>();
  private readonly pending = new Map<string, Pending>();
  private readonly failures = new Map<string, { count: number; retryAt: number }>();
  /** Loaded variants an edit named: fetched again while they stay shown. */
  private readonly stale = new Set<string>();
  /** Pending variants an edit named while their fetch was in flight: fetch again after it answers. */
  private readonly refetch = new Set<string>();
  private readonly spheres = new Map<string, BoundingSphere>();
  private dirty = false;
  private exact = false;
  private complete = false;
  private holes = new Set<string>();
  private bytes = 0;
  private counts = { requested: 0, aborted: 0, failed: 0, evicted: 0, reloads: 0, selections: 0, timedOut: 0 };
  private hadError = false;
  private readonly maxConcurrent: number;
  private readonly maxLoaded: number;
  private readonly maxBytes: number;
  private readonly requestTimeoutMs: number;
  private readonly now: () => number;

  constructor(
    private readonly api: PmcApi,
    private readonly callbacks: StreamerCallbacks,
    opts: StreamerOptions = {},
  ) {
    this.maxConcurrent = opts.maxConcurrent ?? DEFAULT_MAX_CONCURRENT;
    this.maxLoaded = opts.maxLoaded ?? 6000;
    this.maxBytes = opts.maxBytes ?? 256 * 1024 * 1024;
    this.requestTimeoutMs = opts.requestTimeoutMs ?? 60_000;
    this.now = opts.now ?? (() => performance.now());
  }

  /**
   * While the server does not answer (connection.ts), no chunk is requested: the connection's
   * probe finds out when it is back, rather than every missing chunk on its own back-off.
   */
  private paused = false;

  /** Stops requesting chunks (the server is gone), or starts again. */
  setPaused(paused: boolean): void {
    this.paused = paused;
    if (!paused) this.pump();
  }

  /** Forgets the failures' back-off and requests what is missing now (the server is back). */
  retryFailed(): void {
    this.failures.clear();
    this.paused = false;
    this.pump();
  }

  /** Drops every chunk and request, and streams `planet` (with its level-of-detail data) from now on. */
  setPlanet(planet: PlanetChoice, lod: LodPlanet | null): void {
    this.generation++;
    for (const p of this.pending.values()) p.abort.abort();
    this.pending.clear();
    for (const name of [...this.shown.keys()]) this.callbacks.onHide(name);
    this.shown.clear();
    this.cache.clear();
    this.variants.clear();
    this.below.clear();
    this.failures.clear();
    this.stale.clear();
    this.refetch.clear();
    this.spheres.clear();
    this.leaves = new Map();
    this.split = new Set();
    this.wanted = [];
    this.wantedIds = new Set();
    this.bridges = [];
    this.bridgeIds = new Set();
    this.onPaths = new Set();
    this.view = null;
    this.truncated = false;
    this.dirty = false;
    this.exact = false;
    this.complete = false;
    this.holes = new Set();
    this.bytes = 0;
    this.serial = 0;
    this.counts = { requested: 0, aborted: 0, failed: 0, evicted: 0, reloads: 0, selections: 0, timedOut: 0 };
    this.planet = { ...planet };
    this.lod = lod;
  }

  /** Stops everything (the planet is being replaced or the page closed). */
  clear(): void {
    this.setPlanet(this.planet, this.lod);
  }

  private sphere(key: ChunkKey, name: string): BoundingSphere {
    let s = this.spheres.get(name);
    if (s === undefined) {
      s = chunkSphere(this.lod!.layout, key);
      if (this.spheres.size > 50_000) this.spheres.clear();
      this.spheres.set(name, s);
    }
    return s;
  }

  /**
   * A new selection for `view`: its drawn leaves become the wanted set. Requests for chunks no
   * longer wanted are aborted (the server then drops their queued jobs).
   */
  setSelection(selection: LodSelection, view: LodView): void {
    if (this.lod === null) return;
    this.serial++;
    this.counts.selections++;
    this.view = view;
    this.truncated = selection.truncated;
    this.leaves = new Map();
    const eye = view.eye;
    const r = Math.hypot(eye[0], eye[1], eye[2]);
    for (const c of selection.chunks) {
      const name = chunkName(c.key);
      // the ground under the camera is wanted too, in the view or not: walking, the fly speed,
      // the clip planes and the nav grid measure the height above it
      const drawn = c.drawn || (r > 0 && this.underEye(c.key, name, eye, r));
      this.leaves.set(name, { key: c.key, name, seams: c.coarser, drawn });
    }
    this.split = splitChunks(this.leaves.values(), this.lod.layout.maxLevel());
    const wanted: typeof this.wanted = [];
    for (const leaf of this.leaves.values()) {
      if (!leaf.drawn) continue;
      wanted.push({ id: variantId(leaf.name, leaf.seams), name: leaf.name, seams: leaf.seams, key: leaf.key, priority: 0 });
    }
    this.wanted = wanted;
    this.wantedIds = new Set(wanted.map((w) => w.id));
    for (const w of wanted) {
      const l = this.cache.get(w.id);
      if (l) l.lastWanted = this.serial;
    }
    this.dirty = true;
    this.redisplay();
  }

  /**
   * Whether the chunk's sphere meets the vertical below the eye, from the eye down to the
   * occluder (or the planet's centre): where the ground under the camera is.
   */
  private underEye(key: ChunkKey, name: string, eye: Vec3, r: number): boolean {
    const s = this.sphere(key, name);
    const down: Vec3 = [-eye[0] / r, -eye[1] / r, -eye[2] / r];
    const length = Math.max(0, r - (this.lod?.occluder ?? 0));
    const to: Vec3 = [s.center[0] - eye[0], s.center[1] - eye[1], s.center[2] - eye[2]];
    const t = Math.max(0, Math.min(length, to[0] * down[0] + to[1] * down[1] + to[2] * down[2]));
    const d = Math.hypot(to[0] - t * down[0], to[1] - t * down[1], to[2] - t * down[2]);
    return d <= s.radius;
  }

  /**
   * The data of the chunks named changed on the server (an edit; names of any level): every
   * variant shown is fetched again and its mesh replaced only when the new data arrives (no hole
   * meanwhile); every one whose fetch is in flight is fetched once more after that answer (which
   * may predate the change); loaded variants not shown are dropped. Returns how many were marked.
   */
  reload(names: Iterable<string>): number {
    let n = 0;
    for (const name of new Set(names)) {
      for (const [id, p] of this.pending) {
        if (p.name !== name) continue;
        this.refetch.add(id);
        n++;
      }
      for (const seams of [...(this.variants.get(name) ?? [])]) {
        const id = variantId(name, seams);
        if (this.shown.get(name) === seams) {
          this.stale.add(id);
          // an edit is a new reason to try: forget the back-off of an earlier failure
          this.failures.delete(id);
          n++;
        } else if (!this.pending.has(id)) {
          this.drop(id);
        }
      }
    }
    if (n > 0) this.dirty = true;
    return n;
  }

  /** Every chunk's data changed (a `resync`): fetch again everything shown or loading. */
  reloadAll(): number {
    return this.reload([...this.variants.keys(), ...[...this.pending.values()].map((p) => p.name)]);
  }

  /** One streaming step: call it every frame (it is cheap when nothing changed). */
  update(): void {
    if (this.lod === null) return;
    if (this.dirty) this.redisplay();
    this.pump();
  }

  /** Asks for the most urgent chunks not loaded yet, up to the limit of requests in flight. */
  private pump(): void {
    if (this.lod === null || this.paused) return;
    const now = this.now();
    this.expire(now);
    const free = (): boolean => this.pending.size < this.maxConcurrent;
    // refetches of edited chunks come first: the user is looking at them
    for (const id of [...this.stale]) {
      if (!free()) return;
      if (this.pending.has(id) || this.blocked(id, now)) continue;
      const l = this.cache.get(id);
      // (one not shown is dropped by the next redisplay)
      if (!l || this.shown.get(l.name) !== l.seams) continue;
      this.stale.delete(id);
      this.request(id, l.name, l.seams, HOLE_PRIORITY * 3, true);
    }
    // the wanted chunks and the bridges, both sorted, most urgent first
    let a = 0;
    let b = 0;
    while (free() && (a < this.wanted.length || b < this.bridges.length)) {
      const w = this.wanted[a];
      const g = this.bridges[b];
      const next = g === undefined || (w !== undefined && byPriority(w, g) <= 0) ? (a++, w!) : (b++, g);
      if (this.cache.has(next.id) || this.pending.has(next.id) || this.blocked(next.id, now)) continue;
      this.request(next.id, next.name, next.seams, next.priority, false);
    }
  }

  /**
   * Gives up the requests unanswered for `requestTimeoutMs`: each is aborted and counted as a
   * failure (retried after the back-off), so its slot goes to the next chunk.
   */
  private expire(now: number): void {
    for (const [id, p] of this.pending) {
      if (now - p.sent < this.requestTimeoutMs) continue;
      this.pending.delete(id);
      p.abort.abort();
      this.counts.failed++;
      this.counts.timedOut++;
      const count = (this.failures.get(id)?.count ?? 0) + 1;
      this.failures.set(id, { count, retryAt: now + retryDelay(null, count) });
      // a refetch of a chunk still shown is tried again (after the back-off)
      if ((this.refetch.delete(id) || p.reload) && this.shown.get(p.name) === p.seams) this.stale.add(id);
      if (count >= 3) this.reportError(`chunk ${p.name}: no answer within ${Math.round(this.requestTimeoutMs / 1000)} s, ${count} times`);
    }
  }

  private blocked(id: string, now: number): boolean {
    const f = this.failures.get(id);
    return f !== undefined && now < f.retryAt;
  }

  /** Recomputes what to show and hands the changes to the renderer; then the priorities. */
  private redisplay(): void {
    this.dirty = false;
    const lod = this.lod;
    const view = this.view;
    if (lod === null || view === null) return;
    const choice = chooseDisplay({
      layout: lod.layout,
      leaves: this.leaves,
      split: this.split,
      loaded: this.variants,
      loadedBelow: (name) => (this.below.get(name) ?? 0) > 0,
      shown: this.shown,
      visible: (key) => {
        const s = this.sphere(key, chunkName(key));
        return (view.frustum === null || sphereInFrustum(view.frustum, s)) && !sphereBelowHorizon(view.eye, lod.occluder, s);
      },
    });
    for (const name of [...this.shown.keys()]) {
      if (!choice.show.has(name)) {
        this.shown.delete(name);
        this.callbacks.onHide(name);
      }
    }
    for (const [name, seams] of choice.show) {
      if (this.shown.get(name) === seams) continue;
      const l = this.cache.get(variantId(name, seams));
      if (!l) continue;
      this.shown.set(name, seams);
      this.callbacks.onShow(name, seams, l.chunk);
    }
    for (const [name, seams] of this.shown) {
      const l = this.cache.get(variantId(name, seams));
      if (l) l.lastWanted = this.serial;
    }
    // edited chunks not shown are out of date: dropped (fetched fresh when wanted)
    for (const id of [...this.stale]) {
      const l = this.cache.get(id);
      if (this.pending.has(id) || (l && this.shown.get(l.name) === l.seams)) continue;
      this.stale.delete(id);
      this.drop(id);
    }
    this.exact = choice.exact;
    this.complete = choice.complete;
    // holes: wanted chunks with nothing shown at, above or below them
    this.holes = new Set();
    const shownBelow = new Set<string>();
    for (const name of this.shown.keys()) {
      const key = parseChunkName(name);
      for (let k = key; k !== null && k.level < lod.layout.maxLevel(); ) {
        k = parentOf(k);
        const n = chunkName(k);
        if (shownBelow.has(n)) break;
        shownBelow.add(n);
      }
    }
    for (const w of this.wanted) {
      let covered = this.shown.has(w.name) || shownBelow.has(w.name);
      for (let k = w.key; !covered && k.level < lod.layout.maxLevel(); ) {
        k = parentOf(k);
        covered = this.shown.has(chunkName(k));
      }
      if (!covered) this.holes.add(w.name);
    }
    const scale = pixelScale(view.viewportHeightPx, view.fovY);
    for (const w of this.wanted) {
      w.priority = fetchPriority(w.key.level, lod.errors, this.sphere(w.key, w.name), view.eye, scale, this.holes.has(w.name));
    }
    this.wanted.sort(byPriority);
    this.findBridges(lod.layout.maxLevel());
    // what is no longer wanted is not fetched any more (refetches of shown chunks go on)
    for (const [id, p] of this.pending) {
      if (p.reload || this.wantedIds.has(id) || this.bridgeIds.has(id)) continue;
      p.abort.abort();
      this.pending.delete(id);
      this.refetch.delete(id);
      this.counts.aborted++;
    }
    this.evict();
  }

  /**
   * For every wanted chunk with nothing loaded of it, whose place shows a chunk two or more levels
   * up: that chunk's child toward it is a bridge (asked before the wanted chunks below it). Loaded
   * chunks on such paths are kept from eviction.
   */
  private findBridges(maxLevel: number): void {
    const bridges = new Map<string, (typeof this.bridges)[number]>();
    this.onPaths = new Set();
    for (const w of this.wanted) {
      if (this.variants.has(w.name)) continue;
      let child = w.key;
      let k = w.key;
      let found = false;
      while (k.level < maxLevel) {
        k = parentOf(k);
        const name = chunkName(k);
        if (this.shown.has(name)) {
          found = true;
          break;
        }
        if (this.variants.has(name)) this.onPaths.add(name);
        child = k;
      }
      if (!found || child.level === w.key.level) continue;
      const name = chunkName(child);
      if (this.variants.has(name)) continue;
      const id = variantId(name, 0);
      const priority = Math.round(100 * Math.max(2 * w.priority, bridges.get(id)?.priority ?? 0)) / 100;
      bridges.set(id, { id, name, seams: 0, key: child, priority });
    }
    this.bridges = [...bridges.values()].sort(byPriority);
    this.bridgeIds = new Set(bridges.keys());
  }

  private request(id: string, name: string, seams: number, priority: number, reload: boolean): void {
    const generation = this.generation;
    const abort = new AbortController();
    this.pending.set(id, { name, seams, abort, reload, priority, sent: this.now() });
    this.counts.requested++;
    if (reload) this.counts.reloads++;
    this.api
      .chunk(this.planet, name, abort.signal, { seams, priority })
      .then((chunk) => {
        if (generation !== this.generation || this.pending.get(id)?.abort !== abort) return;
        this.pending.delete(id);
        this.failures.delete(id);
        this.store(id, name, seams, chunk);
        // named by an edit while in flight: this answer may predate it, so fetch once more
        if (this.refetch.delete(id)) this.stale.add(id);
        if (this.shown.get(name) === seams) {
          // new data of a chunk on screen (a refetch): swap the mesh now
          this.callbacks.onShow(name, seams, chunk);
        }
        this.dirty = true;
        this.recovered();
        // the next request goes now, not at the next frame (frames may be slow)
        this.pump();
      })
      .catch((e: unknown) => {
        if (generation !== this.generation || this.pending.get(id)?.abort !== abort) return;
        this.pending.delete(id);
        // a chunk still shown keeps its old mesh and is tried again (after the back-off)
        if ((this.refetch.delete(id) || reload) && this.shown.get(name) === seams) this.stale.add(id);
        if (isAbort(e)) return;
        this.counts.failed++;
        const count = (this.failures.get(id)?.count ?? 0) + 1;
        this.failures.set(id, { count, retryAt: this.now() + retryDelay(e, count) });
        // a busy server is normal under load: report only what keeps failing; a server that
        // cannot be reached is the connection notice's (connection.ts), not one chunk's
        if (e instanceof ApiError && (e.status === 0 || e.status === 502 || e.status === 504)) return;
        if (!(e instanceof ApiError && e.transient && count < 3)) {
          this.reportError(`chunk ${name}: ${errorMessage(e)}`);
        }
      });
  }

  private store(id: string, name: string, seams: number, chunk: DecodedChunk): void {
    const old = this.cache.get(id);
    if (old) this.bytes -= old.bytes;
    this.cache.set(id, {
      name,
      seams,
      chunk,
      triangles: chunk.indexCount / 3,
      bytes: chunk.byteLength,
      lastWanted: this.wantedIds.has(id) || this.shown.get(name) === seams ? this.serial : (old?.lastWanted ?? 0),
    });
    this.bytes += chunk.byteLength;
    let set = this.variants.get(name);
    if (set === undefined) {
      set = new Set();
      this.variants.set(name, set);
      this.countBelow(name, 1);
    }
    set.add(seams);
  }

  /** Forgets a loaded variant that is not shown. */
  private drop(id: string): void {
    const l = this.cache.get(id);
    if (!l) return;
    this.cache.delete(id);
    this.bytes -= l.bytes;
    const set = this.variants.get(l.name);
    if (set) {
      set.delete(l.seams);
      if (set.size === 0) {
        this.variants.delete(l.name);
        this.countBelow(l.name, -1);
      }
    }
    this.dirty = true;
  }

  private countBelow(name: string, delta: number): void {
    const key = parseChunkName(name);
    if (key === null || this.lod === null) return;
    const top = this.lod.layout.maxLevel();
    for (let k = key; k.level < top; ) {
      k = parentOf(k);
      const n = chunkName(k);
      const v = (this.below.get(n) ?? 0) + delta;
      if (v > 0) this.below.set(n, v);
      else this.below.delete(n);
    }
  }

  /**
   * Over the caps, drops the loaded chunks neither shown nor wanted nor between the two, least
   * recently wanted first.
   */
  private evict(): void {
    if (this.cache.size <= this.maxLoaded && this.bytes <= this.maxBytes) return;
    const candidates = [...this.cache.entries()]
      .filter(([id, l]) => this.shown.get(l.name) !== l.seams && !this.wantedIds.has(id) && !this.onPaths.has(l.name))
      .sort((a, b) => a[1].lastWanted - b[1].lastWanted || (a[0] < b[0] ? -1 : 1));
    for (const [id] of candidates) {
      if (this.cache.size <= this.maxLoaded && this.bytes <= this.maxBytes) break;
      this.drop(id);
      this.stale.delete(id);
      this.counts.evicted++;
    }
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
   * True when a selection has been received and what is shown is exactly its wanted set, with
   * nothing pending or waiting for a refetch.
   */
  settled(): boolean {
    if (this.dirty) this.redisplay();
    return (
      this.view !== null &&
      this.exact &&
      this.pending.size === 0 &&
      this.stale.size === 0 &&
      this.refetch.size === 0
    );
  }

  stats(): StreamerStats {
    let triangles = 0;
    let vertices = 0;
    for (const [name, seams] of this.shown) {
      const l = this.cache.get(variantId(name, seams));
      if (!l) continue;
      triangles += l.triangles;
      vertices += l.chunk.vertexCount;
    }
    let reloading = 0;
    for (const p of this.pending.values()) if (p.reload) reloading++;
    let missing = 0;
    let blocked = 0;
    const now = this.now();
    for (const w of this.wanted) {
      if (this.cache.has(w.id) || this.pending.has(w.id)) continue;
      missing++;
      if (this.blocked(w.id, now)) blocked++;
    }
    return {
      loaded: this.cache.size,
      pending: this.pending.size,
      missing,
      shown: this.shown.size,
      triangles,
      vertices,
      bytes: this.bytes,
      wanted: this.wanted.length,
      selected: this.leaves.size,
      levels: levelHistogram(this.shown.keys()),
      exact: this.exact,
      complete: this.complete,
      truncated: this.truncated,
      requested: this.counts.requested,
      aborted: this.counts.aborted,
      failed: this.counts.failed,
      evicted: this.counts.evicted,
      timedOut: this.counts.timedOut,
      blocked,
      paused: this.paused,
      stale: this.stale.size,
      reloading,
      reloads: this.counts.reloads,
      selections: this.counts.selections,
      bridges: this.bridges.length,
    };
  }

  /** The chunks shown, by name. */
  shownNames(): string[] {
    return [...this.shown.keys()];
  }

  /** The variant shown of chunk `name`, or undefined. */
  shownSeams(name: string): number | undefined {
    return this.shown.get(name);
  }

  /** The priorities of the requests in flight, by variant (`name~seams`). */
  pendingRequests(): { id: string; priority: number; reload: boolean }[] {
    return [...this.pending].map(([id, p]) => ({ id, priority: p.priority, reload: p.reload }));
  }
}

/** Larger priority first, then by variant id. */
function byPriority(a: { id: string; priority: number }, b: { id: string; priority: number }): number {
  return b.priority - a.priority || (a.id < b.id ? -1 : a.id > b.id ? 1 : 0);
}

function errorMessage(e: unknown): string {
  return e instanceof Error ? e.message : String(e);
}

/** Milliseconds before retrying after `count` failures: Retry-After when given, else backoff. */
export function retryDelay(e: unknown, count: number): number {
  if (e instanceof ApiError && e.retryAfter !== null) return Math.max(250, e.retryAfter * 1000);
  return Math.min(30_000, 500 * 2 ** Math.min(6, count - 1));
}
