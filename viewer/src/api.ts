// Typed client for the PMC HTTP API, version 1 (docs/specs/http-api-v1.md).

import { decodeChunk, type DecodedChunk } from './chunkDecode';

export type Vec3Tuple = [number, number, number];

export interface PresetInfo {
  name: string;
  description: string;
}

export interface Layout {
  n_c: number;
  n_t: number;
  d_b: number;
  l_d: number;
  d_c: number;
}

export interface FaceInfo {
  name: string;
  index: number;
  normal: Vec3Tuple;
  u: Vec3Tuple;
  v: Vec3Tuple;
}

/** `terrain` of `GET /api/v1/planet`: a preset, or an elevation model served by this server. */
export interface TerrainInfo {
  kind: 'preset' | 'dem';
  /** The preset's name, or `dem` and the elevation file's name. */
  name: string;
  seed: string;
  file?: string;
  interpolation?: string;
}

export interface PlanetInfo {
  format: string;
  version: number;
  /** The preset, or null when the planet is made from an elevation model (see `terrain`). */
  preset: string | null;
  /** A decimal u64, kept as a string. */
  seed: string;
  /** What the planet is made of. */
  terrain?: TerrainInfo;
  presets: PresetInfo[];
  layout: Layout;
  radius: number;
  base_radius: number;
  sea_radius: number | null;
  surface_bounds: [number, number] | null;
  chunk_count: number;
  face_tiles: number;
  depth_tiles: number;
  /** Highest level of detail of the layout (absent from older servers). */
  max_level?: number;
  /** What a level-of-detail selection needs (absent from servers without levels of detail). */
  lod?: LodInfo;
  faces: FaceInfo[];
  materials: string[];
  palette: { a: Vec3Tuple; b: Vec3Tuple };
  /** Editing (absent from servers older than the editing API: treated as disabled). */
  edit?: EditInfo;
}

/** `/planet`'s `lod` block. */
export interface LodInfo {
  max_level: number;
  /** `errors[L]`: the measured geometric error of level `L`, metres (`errors[0] = 0`). */
  errors: number[];
  /** A ball solid at every level: what lies behind it is hidden (horizon culling). */
  occluder_radius: number;
  /** The side names in the bit order of a chunk's `seams` mask. */
  seam_sides: string[];
}

/** The brushes of `POST /edits`. */
export type BrushName = 'add' | 'remove' | 'smooth' | 'flatten' | 'paint';
export const BRUSH_NAMES: readonly BrushName[] = ['add', 'remove', 'smooth', 'flatten', 'paint'];

/** `/planet`'s `edit` object when the planet shown can be edited. */
export interface EditEnabled {
  enabled: true;
  /** The world file's name. */
  world: string;
  revision: number;
  active: number;
  redo: number;
  min_brush_radius: number;
  max_brush_radius: number;
  rate_per_second: number;
  burst: number;
  brushes: string[];
}

/** `/planet`'s `edit` object when editing is off, with the reason. */
export interface EditDisabled {
  enabled: false;
  reason: string;
  brushes?: string[];
}

export type EditInfo = EditEnabled | EditDisabled;

/** The body of `POST /api/v1/edits`. */
export interface EditRequest {
  brush: BrushName;
  /** Brush centre, planet frame, metres. */
  x: number;
  y: number;
  z: number;
  radius: number;
  /** In (0, 1]; the server's default is 1. */
  strength?: number;
  /** Paint only (required there): a name of `/planet`'s `materials` or its index. */
  material?: string | number;
}

/** The answer of `POST /edits`, `/edits/undo` and `/edits/redo`. */
export interface EditAnswer {
  /** The edit applied, undone or redone; null when there was nothing to undo or redo. */
  id: number | null;
  revision: number;
  active: number;
  redo: number;
  /** Names of every chunk, of every level, whose mesh (any seams variant) may have changed. */
  chunks: string[];
}

export interface EditRecord {
  id: number;
  brush: BrushName;
  center: Vec3Tuple;
  radius: number;
  strength: number;
  /** The paint material's index, else null. */
  material: number | null;
  active: boolean;
}

export interface EditList {
  revision: number;
  active: number;
  redo: number;
  edits: EditRecord[];
}

/** One end of a path, as `/path` takes it: degrees, and metres above the datum (null: none given). */
export interface PathEnd {
  lat: number;
  lon: number;
  alt: number | null;
}

/** A waypoint of a path: degrees, metres above the planet's datum. */
export interface PathWaypoint {
  lat: number;
  lon: number;
  alt: number;
}

/** The answer of `GET /path` (docs/specs/path-v1.md, JSON), the members the viewer reads. */
export interface PathAnswer {
  found: boolean;
  /** Metres walked and steps (when found). */
  length: number | null;
  steps: number | null;
  /** The surface points walked, start and goal included (empty when not found). */
  waypoints: PathWaypoint[];
  /** The walk pulled into straight legs (when found on a whole-planet grid). */
  smoothed: SmoothedPath | null;
  /** Why there is no path (when not found). */
  reason: string | null;
  /** The components of the two ends when they differ (when not found). */
  components: [number, number] | null;
  /** The world revision the grid reflects. */
  revision: number;
}

/** A path's smoothed form (`smoothed` of docs/specs/path-v1.md). */
export interface SmoothedPath {
  /** Metres walked along the legs. */
  length: number;
  legs: number;
  /** The ground the legs walk, a point for every column they cross (`line`, 1.3; the corners from older servers). */
  line: PathWaypoint[];
}

/** The answer of `GET /navgrid`: nodes near a point, their components and the steps between them. */
export interface NavGridAnswer {
  revision: number;
  /** The point asked for, planet frame. */
  origin: Vec3Tuple;
  /** Three per node, metres, relative to `origin`. */
  positions: number[];
  /** Component label per node. */
  components: number[];
  /** Node count of each node's component over the whole planet. */
  component_sizes: number[];
  /** Pairs of node indices joined by a step. */
  edges: number[];
  truncated: boolean;
  total_nodes: number;
  total_components: number;
}

/** How a chunk is asked for: its seams mask (0 to 63) and the priority of its job. */
export interface ChunkOptions {
  seams?: number;
  priority?: number;
}

export interface PlanetChoice {
  preset?: string | undefined;
  seed?: string | undefined;
}

/** An error from the API: the HTTP status (0 for a network failure) and the server's message. */
export class ApiError extends Error {
  constructor(
    message: string,
    readonly status: number,
    readonly url: string,
    /** Seconds from a `Retry-After` header (503, 429), when given. */
    readonly retryAfter: number | null = null,
    /** The server's own message (the JSON `error` member), when it sent one. */
    readonly serverMessage: string | null = null,
  ) {
    super(message);
    this.name = 'ApiError';
  }
  /** True when retrying later may succeed (busy server, network trouble). */
  get transient(): boolean {
    return this.status === 0 || this.status === 503 || this.status === 502 || this.status === 504;
  }
  /** True for 429: too many edits from this client; wait `retryAfter` seconds. */
  get rateLimited(): boolean {
    return this.status === 429;
  }
}

/** Whether an error is the result of an `AbortSignal`. */
export function isAbort(e: unknown): boolean {
  return (
    (e instanceof DOMException && e.name === 'AbortError') ||
    (e instanceof Error && e.name === 'AbortError')
  );
}

export type FetchFn = (input: string, init?: RequestInit) => Promise<Response>;

/** Told of each request's fate: answered (any HTTP status), or the server could not be reached. */
export interface ReachObserver {
  reached(): void;
  unreachable(): void;
}

/** The first bytes of a chunk batch's answer (`POST /chunk-batch`, docs/specs/http-api-v1.md). */
const BATCH_MAGIC = [0x50, 0x4d, 0x43, 0x42]; // "PMCB"
/** The layout version of a chunk batch's answer this client reads. */
const BATCH_VERSION = 1;
/** Bytes of a batch answer's header: magic, version (u16), records to follow (u32). */
const BATCH_HEADER = 10;
/** Most chunks one batch asks for (the server takes up to 256). */
export const MAX_BATCH_CHUNKS = 64;
/**
 * Batch requests open at once. A browser opens six connections to a server; two are left to the
 * other requests (the planet, the edit events' stream, paths).
 */
export const MAX_OPEN_BATCHES = 4;

/** One record of a chunk batch's answer: the chunk's index in the request, a status, the payload. */
export interface BatchRecord {
  index: number;
  /** 200: the payload is the chunk (chunk-mesh-v1); else an HTTP status and the UTF-8 message. */
  status: number;
  payload: Uint8Array;
}

/**
 * Reads a chunk batch's answer as its bytes arrive, in pieces split anywhere: `push` each piece,
 * get back the records it completed. Throws on bytes that are not a batch answer (a wrong magic or
 * version, a record out of range, more records than announced).
 */
export class BatchReader {
  private pieces: Uint8Array[] = [];
  private buffered = 0;
  /** Records the header announced (-1 until it is read). */
  count = -1;
  /** Records read so far. */
  received = 0;

  /** Whether every record the header announced has been read. */
  get complete(): boolean {
    return this.count >= 0 && this.received === this.count && this.buffered === 0;
  }

  push(piece: Uint8Array): BatchRecord[] {
    if (piece.byteLength > 0) {
      this.pieces.push(piece);
      this.buffered += piece.byteLength;
    }
    const out: BatchRecord[] = [];
    for (;;) {
      if (this.count < 0) {
        if (this.buffered < BATCH_HEADER) return out;
        const h = this.take(BATCH_HEADER);
        if (BATCH_MAGIC.some((b, i) => h[i] !== b)) throw new Error('not a chunk batch (wrong magic)');
        const v = new DataView(h.buffer, h.byteOffset, h.byteLength);
        const version = v.getUint16(4, true);
        if (version !== BATCH_VERSION) throw new Error(`chunk batch version ${version}, this viewer reads ${BATCH_VERSION}`);
        this.count = v.getUint32(6, true);
        continue;
      }
      if (this.buffered < 4) return out;
      const len = new DataView(this.peek(4).buffer).getUint32(0, true);
      if (len < 4) throw new Error(`chunk batch record of ${len} bytes (at least 4)`);
      if (this.buffered < 4 + len) return out;
      if (this.received >= this.count) throw new Error(`chunk batch: more than the ${this.count} records announced`);
      const r = this.take(4 + len);
      const v = new DataView(r.buffer, r.byteOffset, r.byteLength);
      const index = v.getUint16(4, true);
      if (index >= this.count) throw new Error(`chunk batch record for chunk ${index} of ${this.count}`);
      out.push({ index, status: v.getUint16(6, true), payload: r.slice(8) });
      this.received++;
    }
  }

  /** The first `n` buffered bytes, copied. */
  private peek(n: number): Uint8Array {
    const out = new Uint8Array(n);
    let at = 0;
    for (const p of this.pieces) {
      const k = Math.min(p.byteLength, n - at);
      out.set(p.subarray(0, k), at);
      at += k;
      if (at === n) break;
    }
    return out;
  }

  /** Removes and returns the first `n` buffered bytes (a fresh buffer). */
  private take(n: number): Uint8Array {
    const out = this.peek(n);
    let left = n;
    while (left > 0) {
      const p = this.pieces[0]!;
      if (p.byteLength <= left) {
        this.pieces.shift();
        left -= p.byteLength;
      } else {
        this.pieces[0] = p.subarray(left);
        left = 0;
      }
    }
    this.buffered -= n;
    return out;
  }
}

/** A chunk asked for through `PmcApi.chunk`, waiting for its batch's answer. */
interface BatchWaiter {
  key: string;
  opts: ChunkOptions;
  signal: AbortSignal | undefined;
  resolve: (chunk: DecodedChunk) => void;
  reject: (e: unknown) => void;
  settled: boolean;
  /** The batch request it went out in (none while queued). */
  batch: { waiters: BatchWaiter[]; abort: AbortController } | null;
}

function abortError(): Error {
  return new DOMException('the chunk was no longer wanted', 'AbortError');
}

export class PmcApi {
  private readonly fetchFn: FetchFn;
  /** Told whether requests reach the server (the connection monitor). */
  observer: ReachObserver | null = null;
  /** Whether the server answers chunk batches (null: not known yet; false: one chunk a request). */
  private batches: boolean | null = null;
  /** Chunks waiting for a batch, by the planet's query. */
  private queued = new Map<string, { planet: PlanetChoice; waiters: BatchWaiter[] }>();
  private openBatches = 0;
  private flushScheduled = false;

  constructor(
    /** Prefix of the API, e.g. `api/v1` (relative to the page) or `http://host:8080/api/v1`. */
    readonly base = 'api/v1',
    fetchFn?: FetchFn,
    /** `batches: false` asks for each chunk with a request of its own (`chunkAlone`). */
    opts: { batches?: boolean } = {},
  ) {
    this.fetchFn = fetchFn ?? ((input, init) => fetch(input, init));
    if (opts.batches === false) this.batches = false;
  }

  /** The URL of `path` with the planet choice and extra parameters as query string. */
  url(path: string, planet: PlanetChoice = {}, params: Record<string, string | number> = {}): string {
    const q = new URLSearchParams();
    if (planet.preset) q.set('preset', planet.preset);
    if (planet.seed !== undefined && planet.seed !== '') q.set('seed', planet.seed);
    for (const [k, v] of Object.entries(params)) q.set(k, String(v));
    const qs = q.toString();
    return `${this.base}/${path}${qs ? `?${qs}` : ''}`;
  }

  private async request(url: string, signal?: AbortSignal, init: RequestInit = {}): Promise<Response> {
    let res: Response;
    try {
      res = await this.fetchFn(url, signal ? { ...init, signal } : init);
    } catch (e) {
      if (isAbort(e)) throw e;
      this.observer?.unreachable();
      throw new ApiError(`cannot reach the PMC server (${String(e)})`, 0, url);
    }
    // a proxy's 502 or 504: the PMC server behind it does not answer
    if (res.status === 502 || res.status === 504) this.observer?.unreachable();
    else this.observer?.reached();
    if (!res.ok) {
      let message = `${res.status} ${res.statusText}`.trim();
      let serverMessage: string | null = null;
      try {
        const body: unknown = await res.json();
        if (body && typeof body === 'object' && 'error' in body) {
          serverMessage = String((body as { error: unknown }).error);
          message = `${message}: ${serverMessage}`;
        }
      } catch {
        // not JSON: keep the status line
      }
      const ra = res.headers.get('Retry-After');
      const retryAfter = ra !== null && ra.trim() !== '' && Number.isFinite(Number(ra)) ? Number(ra) : null;
      throw new ApiError(message, res.status, url, retryAfter, serverMessage);
    }
    return res;
  }

  private async json<T>(url: string, signal?: AbortSignal, init?: RequestInit): Promise<T> {
    const res = await this.request(url, signal, init);
    try {
      return (await res.json()) as T;
    } catch (e) {
      throw new ApiError(`invalid JSON from ${url}: ${String(e)}`, res.status, url);
    }
  }

  health(signal?: AbortSignal): Promise<{ ok: boolean; version: string }> {
    return this.json(this.url('health'), signal);
  }

  async planet(planet: PlanetChoice = {}, signal?: AbortSignal): Promise<PlanetInfo> {
    const info = await this.json<PlanetInfo>(this.url('planet', planet), signal);
    if (!info || info.format !== 'pmc-planet' || info.version !== 1) {
      throw new ApiError(
        `unexpected /planet response (format ${String(info?.format)}, version ${String(info?.version)})`,
        200,
        this.url('planet', planet),
      );
    }
    return info;
  }

  /**
   * The URL of one chunk mesh (`chunk/<face>/<level>/<i>/<j>/<k>`), with its `seams` mask (sides
   * toward a coarser neighbour) and the `priority` of its job on the server when given.
   */
  chunkUrl(planet: PlanetChoice, key: string, opts: ChunkOptions = {}): string {
    const params: Record<string, number> = {};
    if (opts.seams !== undefined) params['seams'] = opts.seams;
    if (opts.priority !== undefined) params['priority'] = opts.priority;
    return this.url(`chunk/${key}`, planet, params);
  }

  /**
   * One chunk, decoded. Chunks asked for together (in one task) and while batches are open go
   * out together in one `POST /chunk-batch` (up to MAX_BATCH_CHUNKS a batch, MAX_OPEN_BATCHES
   * batches at once), each settled as its record arrives; a server without batches (404 or 405 to
   * the first) is asked one chunk a request (`chunkAlone`) from then on. Aborting `signal` rejects
   * the chunk at once; when every chunk of a batch sent is settled, the batch is aborted (the
   * server drops the jobs nobody waits for).
   */
  chunk(planet: PlanetChoice, key: string, signal?: AbortSignal, opts: ChunkOptions = {}): Promise<DecodedChunk> {
    if (this.batches === false) return this.chunkAlone(planet, key, signal, opts);
    if (signal?.aborted) return Promise.reject(abortError());
    return new Promise<DecodedChunk>((resolve, reject) => {
      const w: BatchWaiter = { key, opts, signal, resolve, reject, settled: false, batch: null };
      const q = this.url('chunk-batch', planet);
      const group = this.queued.get(q) ?? { planet, waiters: [] };
      group.waiters.push(w);
      this.queued.set(q, group);
      signal?.addEventListener(
        'abort',
        () => {
          if (w.settled) return;
          w.settled = true;
          reject(abortError());
          if (w.batch && w.batch.waiters.every((x) => x.settled)) w.batch.abort.abort();
        },
        { once: true },
      );
      this.scheduleFlush();
    });
  }

  /** Sends the queued chunks once the current task has asked for all it will. */
  private scheduleFlush(): void {
    if (this.flushScheduled || this.openBatches >= MAX_OPEN_BATCHES) return;
    this.flushScheduled = true;
    queueMicrotask(() => {
      this.flushScheduled = false;
      this.flush();
    });
  }

  private flush(): void {
    for (const [q, group] of this.queued) {
      group.waiters = group.waiters.filter((w) => !w.settled);
      while (group.waiters.length > 0 && this.openBatches < MAX_OPEN_BATCHES) {
        void this.sendBatch(group.planet, group.waiters.splice(0, MAX_BATCH_CHUNKS));
      }
      if (group.waiters.length === 0) this.queued.delete(q);
    }
  }

  private async sendBatch(planet: PlanetChoice, waiters: BatchWaiter[]): Promise<void> {
    this.openBatches++;
    const abort = new AbortController();
    const batch = { waiters, abort };
    for (const w of waiters) w.batch = batch;
    const url = this.url('chunk-batch', planet);
    try {
      const body = JSON.stringify({
        chunks: waiters.map((w) => ({ key: w.key, seams: w.opts.seams ?? 0, priority: w.opts.priority ?? 0 })),
      });
      const res = await this.request(url, abort.signal, {
        method: 'POST',
        headers: { 'Content-Type': 'application/json' },
        body,
      });
      if (res.body === null) throw new ApiError('the chunk batch came without a body', res.status, url);
      const reader = res.body.getReader();
      const records = new BatchReader();
      try {
        for (;;) {
          const { done, value } = await reader.read();
          if (done) break;
          let got: BatchRecord[];
          try {
            got = records.push(value);
          } catch (e) {
            throw new ApiError(`${(e as Error).message} (${url})`, res.status, url);
          }
          this.batches = true;
          for (const r of got) this.settle(waiters[r.index], r, url);
        }
      } finally {
        reader.releaseLock();
      }
      if (!records.complete) throw new ApiError(`the chunk batch ended after ${records.received} of ${waiters.length} chunks`, 0, url);
    } catch (e) {
      const unsupported = this.batches === null && e instanceof ApiError && (e.status === 404 || e.status === 405);
      if (unsupported) this.batches = false;
      for (const w of waiters) {
        if (w.settled) continue;
        if (unsupported) {
          // an older server: each chunk on its own
          w.batch = null;
          this.chunkAlone(planet, w.key, w.signal, w.opts).then(
            (c) => this.settleWith(w, () => w.resolve(c)),
            (err: unknown) => this.settleWith(w, () => w.reject(err)),
          );
        } else {
          this.settleWith(w, () => w.reject(isAbort(e) ? e : e instanceof ApiError ? e : new ApiError(String(e), 0, url)));
        }
      }
    } finally {
      this.openBatches--;
      this.scheduleFlush();
    }
  }

  private settleWith(w: BatchWaiter, settle: () => void): void {
    if (w.settled) return;
    w.settled = true;
    settle();
  }

  /** Settles `w` with its record of the batch answered at `url`. */
  private settle(w: BatchWaiter | undefined, r: BatchRecord, url: string): void {
    if (w === undefined) return;
    this.settleWith(w, () => {
      if (r.status !== 200) {
        const message = new TextDecoder().decode(r.payload);
        w.reject(new ApiError(`chunk ${w.key}: ${r.status}: ${message}`, r.status, url, r.status === 503 ? 1 : null, message));
        return;
      }
      try {
        w.resolve(decodeChunk(r.payload));
      } catch (e) {
        w.reject(new ApiError(`chunk ${w.key}: ${(e as Error).message}`, 200, url));
      }
    });
  }

  /** One chunk in a request of its own (`GET /chunk/...`). */
  async chunkAlone(planet: PlanetChoice, key: string, signal?: AbortSignal, opts: ChunkOptions = {}): Promise<DecodedChunk> {
    const url = this.chunkUrl(planet, key, opts);
    const res = await this.request(url, signal);
    const bytes = await res.arrayBuffer();
    try {
      return decodeChunk(bytes);
    } catch (e) {
      throw new ApiError(`chunk ${key}: ${(e as Error).message}`, res.status, url);
    }
  }

  stats(signal?: AbortSignal): Promise<Record<string, number>> {
    return this.json(this.url('stats'), signal);
  }

  // ---- navigation ------------------------------------------------------------------------------

  /**
   * The walking path between two ends (`GET /path`), each `LAT,LON[,ALT]` (see `formatPathEnd`).
   * "No path" is an answer (`found` false, with the reason), not an error.
   */
  async path(planet: PlanetChoice, from: string, to: string, signal?: AbortSignal): Promise<PathAnswer> {
    const url = this.url('path', planet, { from, to });
    return checkPathAnswer(await this.json<unknown>(url, signal), url);
  }

  /** The grid's nodes within `range` metres of `at` (planet frame), at most `limit` (`GET /navgrid`). */
  async navgrid(planet: PlanetChoice, at: Vec3Tuple, range: number, limit = 20_000, signal?: AbortSignal): Promise<NavGridAnswer> {
    const url = this.url('navgrid', planet, { x: at[0], y: at[1], z: at[2], range, limit });
    return checkNavGrid(await this.json<unknown>(url, signal), url);
  }

  // ---- editing (a server started with `--world`) ---------------------------------------------

  /**
   * Applies a brush (`POST /edits`). `planet` names the planet the viewer shows: the server
   * refuses (409) an edit of any planet but the world's.
   */
  async postEdit(edit: EditRequest, planet: PlanetChoice = {}, signal?: AbortSignal): Promise<EditAnswer> {
    const url = this.url('edits', planet);
    return checkEditAnswer(
      await this.json<unknown>(url, signal, {
        method: 'POST',
        headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify(edit),
      }),
      url,
    );
  }

  /** Takes back the last active edit (`POST /edits/undo`); `id` null when there was none. */
  async undo(planet: PlanetChoice = {}, signal?: AbortSignal): Promise<EditAnswer> {
    const url = this.url('edits/undo', planet);
    return checkEditAnswer(await this.json<unknown>(url, signal, { method: 'POST' }), url);
  }

  /** Re-applies the most recently undone edit (`POST /edits/redo`); `id` null when there was none. */
  async redo(planet: PlanetChoice = {}, signal?: AbortSignal): Promise<EditAnswer> {
    const url = this.url('edits/redo', planet);
    return checkEditAnswer(await this.json<unknown>(url, signal, { method: 'POST' }), url);
  }

  /** The edit list (`GET /edits`), oldest first, active ones before undone ones. */
  async listEdits(planet: PlanetChoice = {}, signal?: AbortSignal): Promise<EditList> {
    const url = this.url('edits', planet);
    const list = await this.json<EditList>(url, signal);
    if (!list || typeof list.revision !== 'number' || !Array.isArray(list.edits)) {
      throw new ApiError(`unexpected answer from ${url}: no revision or edits`, 200, url);
    }
    return list;
  }

  /** The URL of the server push (`GET /events`, Server-Sent Events). */
  eventsUrl(): string {
    return this.url('events');
  }
}

/** Checks the shape of an edit, undo or redo answer. */
function checkEditAnswer(body: unknown, url: string): EditAnswer {
  const a = body as Partial<EditAnswer> | null;
  if (
    !a ||
    typeof a !== 'object' ||
    typeof a.revision !== 'number' ||
    !(a.id === null || typeof a.id === 'number') ||
    !Array.isArray(a.chunks) ||
    !a.chunks.every((k) => typeof k === 'string')
  ) {
    throw new ApiError(`unexpected answer from ${url}: ${JSON.stringify(body)?.slice(0, 200)}`, 200, url);
  }
  return {
    id: a.id,
    revision: a.revision,
    active: typeof a.active === 'number' ? a.active : 0,
    redo: typeof a.redo === 'number' ? a.redo : 0,
    chunks: a.chunks,
  };
}

const finite = (x: unknown): x is number => typeof x === 'number' && Number.isFinite(x);

/** Checks the members of a `/path` answer the viewer reads. */
function checkPathAnswer(body: unknown, url: string): PathAnswer {
  const bad = (why: string): ApiError => new ApiError(`unexpected answer from ${url}: ${why}`, 200, url);
  const a = body as Record<string, unknown> | null;
  if (!a || typeof a !== 'object' || typeof a['found'] !== 'boolean') throw bad('no "found"');
  const found = a['found'];
  const revision = finite(a['revision']) ? a['revision'] : 0;
  if (!found) {
    const c = a['components'];
    return {
      found: false,
      length: null,
      steps: null,
      waypoints: [],
      smoothed: null,
      reason: typeof a['reason'] === 'string' ? a['reason'] : 'no reason given',
      components: Array.isArray(c) && c.length === 2 && c.every(finite) ? [c[0], c[1]] : null,
      revision,
    };
  }
  const points = (w: unknown, what: string): PathWaypoint[] => {
    if (!Array.isArray(w) || w.length === 0) throw bad(`a path found without ${what}`);
    return w.map((p: unknown, i) => {
      const q = p as Record<string, unknown> | null;
      if (!q || !finite(q['lat']) || !finite(q['lon']) || !finite(q['alt'])) throw bad(`${what}: point ${i} is not {lat, lon, alt}`);
      return { lat: q['lat'], lon: q['lon'], alt: q['alt'] };
    });
  };
  const waypoints = points(a['waypoints'], 'waypoints');
  if (!finite(a['length'])) throw bad('a path found without a length');
  let smoothed: SmoothedPath | null = null;
  const sm = a['smoothed'] as Record<string, unknown> | null | undefined;
  if (sm !== undefined && sm !== null) {
    if (typeof sm !== 'object' || !finite(sm['length']) || !finite(sm['legs'])) throw bad('"smoothed" without a length and legs');
    const line = sm['line'] !== undefined ? points(sm['line'], 'smoothed.line') : points(sm['waypoints'], 'smoothed.waypoints');
    smoothed = { length: sm['length'], legs: sm['legs'], line };
  }
  return {
    found: true,
    length: a['length'],
    steps: finite(a['steps']) ? a['steps'] : waypoints.length - 1,
    waypoints,
    smoothed,
    reason: null,
    components: null,
    revision,
  };
}

/** Checks a `/navgrid` answer: array lengths agree and every edge names nodes of the answer. */
function checkNavGrid(body: unknown, url: string): NavGridAnswer {
  const bad = (why: string): ApiError => new ApiError(`unexpected answer from ${url}: ${why}`, 200, url);
  const a = body as Partial<NavGridAnswer> | null;
  if (!a || typeof a !== 'object') throw bad('not an object');
  const { origin, positions, components, component_sizes: sizes, edges } = a;
  if (!Array.isArray(origin) || origin.length !== 3 || !origin.every(finite)) throw bad('no origin [x, y, z]');
  if (!Array.isArray(positions) || positions.length % 3 !== 0) throw bad('positions is not a list of triples');
  if (!positions.every(finite)) throw bad('a position is not a finite number');
  const n = positions.length / 3;
  if (!Array.isArray(components) || components.length !== n) throw bad(`${String(components?.length)} components for ${n} nodes`);
  if (!Array.isArray(sizes) || sizes.length !== n) throw bad(`${String(sizes?.length)} component sizes for ${n} nodes`);
  if (!Array.isArray(edges) || edges.length % 2 !== 0) throw bad('edges is not a list of pairs');
  for (const e of edges) {
    if (!Number.isInteger(e) || e < 0 || e >= n) throw bad(`edge end ${String(e)} is not a node index below ${n}`);
  }
  return {
    revision: finite(a.revision) ? a.revision : 0,
    origin: [origin[0], origin[1], origin[2]],
    positions,
    components,
    component_sizes: sizes,
    edges,
    truncated: a.truncated === true,
    total_nodes: finite(a.total_nodes) ? a.total_nodes : n,
    total_components: finite(a.total_components) ? a.total_components : new Set(components).size,
  };
}
