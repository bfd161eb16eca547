// Test helpers for level-of-detail streaming: a small layout, selections built by hand, a fake
// chunk server whose answers are held until the test releases them, and a streamer wired to a
// record of what is shown.

import { PmcApi } from '../src/api';
import { chunkName, parseChunkName } from '../src/chunkSelection';
import { ChunkStreamer, type StreamerOptions } from '../src/chunkStreamer';
import { childrenOf, compareKeys, Layout, parentOf, type ChunkKey } from '../src/lod/layout';
import type { LodSelection, LodView } from '../src/lod/select';
import { encodeChunk } from './encodeChunk';

/**
 * Three levels: six level-2 roots (one per face), each split into four level-1 chunks, each into
 * four level-0 chunks (one chunk along depth at every level). Radius 116 m.
 */
export const LAYOUT = new Layout({ n_c: 4, n_t: 4, d_b: 100, l_d: 1, d_c: 1 });
export const ERRORS = [0, 1, 2];
/** The radius of the inner shell (solid at every level): the occluder. */
export const OCCLUDER = 100;
/** Far above the east face, no frustum: everything is drawn. */
export const VIEW: LodView = { eye: [500, 40, 30], frustum: null, viewportHeightPx: 600, fovY: 1 };

export const tick = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

/**
 * A selection: the roots with the chunks named in `splits` split (in that order), the `seams`
 * given per leaf (default 0), the leaves in `hidden` not drawn.
 */
export function selection(splits: string[] = [], seams: Record<string, number> = {}, hidden: string[] = []): LodSelection {
  const leaves = new Map<string, ChunkKey>();
  for (const r of LAYOUT.chunks(LAYOUT.maxLevel())) leaves.set(chunkName(r), r);
  for (const name of splits) {
    const key = leaves.get(name);
    if (!key) throw new Error(`${name} is not a leaf`);
    leaves.delete(name);
    for (const c of childrenOf(key)) if (LAYOUT.containsChunk(c)) leaves.set(chunkName(c), c);
  }
  const chunks = [...leaves.values()].sort(compareKeys).map((key) => ({
    key,
    coarser: seams[chunkName(key)] ?? 0,
    drawn: !hidden.includes(chunkName(key)),
  }));
  return { chunks, truncated: false };
}

export interface HeldRequest {
  name: string;
  seams: number;
  priority: number;
  reload?: boolean;
}

/**
 * A chunk server. Every answer is held until `release`; a chunk's mesh has as many triangles as
 * its version (bumped by `edit`), or none for the names in `empty`. Records requests and aborts.
 */
export function chunkServer() {
  const version = new Map<string, number>();
  const empty = new Set<string>();
  const failing = new Map<string, number>();
  const waiting: { req: HeldRequest; version: number; resolve: (r: Response) => void }[] = [];
  const requests: HeldRequest[] = [];
  const aborted: string[] = [];
  const body = (name: string, v: number): Uint8Array<ArrayBuffer> => {
    const key = parseChunkName(name)!;
    const n = empty.has(name) ? 0 : v;
    const positions: number[][] = [];
    const indices: number[] = [];
    for (let t = 0; t < n; t++) {
      positions.push([t, 0, 0], [t + 1, 0, 0], [t, 1, 0]);
      indices.push(3 * t, 3 * t + 1, 3 * t + 2);
    }
    return encodeChunk({ ...key, positions, indices });
  };
  const fetchFn = (url: string, init?: RequestInit): Promise<Response> => {
    const u = new URL(url, 'http://host/');
    const name = u.pathname.slice('/api/v1/chunk/'.length);
    const req: HeldRequest = {
      name,
      seams: Number(u.searchParams.get('seams') ?? 0),
      priority: Number(u.searchParams.get('priority') ?? 0),
    };
    requests.push(req);
    const fails = failing.get(name) ?? 0;
    if (fails > 0) {
      failing.set(name, fails - 1);
      return Promise.resolve(new Response(JSON.stringify({ error: 'queue full' }), { status: 503, headers: { 'Retry-After': '1' } }));
    }
    const v = version.get(name) ?? 1;
    return new Promise((resolve, reject) => {
      init?.signal?.addEventListener('abort', () => {
        aborted.push(`${name}~${req.seams}`);
        const at = waiting.findIndex((w) => w.req === req);
        if (at >= 0) waiting.splice(at, 1);
        reject(new DOMException('aborted', 'AbortError'));
      });
      waiting.push({ req, version: v, resolve });
    });
  };
  const answer = async (pick: (r: HeldRequest) => boolean): Promise<void> => {
    for (const w of waiting.filter((x) => pick(x.req))) {
      waiting.splice(waiting.indexOf(w), 1);
      w.resolve(new Response(body(w.req.name, w.version)));
    }
    for (let n = 0; n < 4; n++) await tick();
  };
  return {
    fetchFn,
    requests,
    aborted,
    empty,
    /** The next `count` requests of `name` answer 503 (Retry-After: 1). */
    fail: (name: string, count: number) => failing.set(name, count),
    edit: (name: string) => version.set(name, (version.get(name) ?? 1) + 1),
    /** Answers every held request (with the version it was asked at). */
    releaseAll: () => answer(() => true),
    /** Answers the held requests of these chunk names. */
    release: (...names: string[]) => answer((r) => names.includes(r.name)),
    held: (): string[] => waiting.map((w) => `${w.req.name}~${w.req.seams}`),
  };
}

/** A streamer on `server`, the layout above, recording what it shows. */
export function streamerOn(server: ReturnType<typeof chunkServer>, opts: StreamerOptions = {}) {
  const shown = new Map<string, { seams: number; triangles: number }>();
  const log: string[] = [];
  const errors: string[] = [];
  const s = new ChunkStreamer(
    // one chunk a request: this server answers `GET /chunk/...` (the batches are tested in api.test.ts)
    new PmcApi('/api/v1', server.fetchFn, { batches: false }),
    {
      onShow: (name, seams, chunk) => {
        shown.set(name, { seams, triangles: chunk.indexCount / 3 });
        log.push(`show ${name}~${seams}`);
      },
      onHide: (name) => {
        shown.delete(name);
        log.push(`hide ${name}`);
      },
      onError: (m) => errors.push(m),
    },
    opts,
  );
  s.setPlanet({ preset: 'earthlike', seed: '7' }, { layout: LAYOUT, errors: ERRORS, occluder: OCCLUDER });
  /** `update` then let the fetches settle, `n` times. */
  const step = async (n = 1): Promise<void> => {
    for (let k = 0; k < n; k++) {
      s.update();
      await tick();
    }
  };
  return { s, shown, log, errors, step };
}

/** Chunks of `shown` that overlap (one above another): must be none. */
export function overlaps(shown: Iterable<string>): string[] {
  const names = new Set(shown);
  const out: string[] = [];
  for (const name of names) {
    for (let k = parseChunkName(name)!; k.level < LAYOUT.maxLevel(); ) {
      k = parentOf(k);
      if (names.has(chunkName(k))) out.push(`${name} under ${chunkName(k)}`);
    }
  }
  return out;
}

/** The drawn leaves of `sel` whose place nothing shown covers (neither it, above, nor all below). */
export function holes(sel: LodSelection, shown: Iterable<string>): string[] {
  const names = new Set(shown);
  const covered = (key: ChunkKey): boolean => {
    if (names.has(chunkName(key))) return true;
    const kids = childrenOf(key).filter((c) => LAYOUT.containsChunk(c));
    return kids.length > 0 && kids.every(covered);
  };
  return sel.chunks
    .filter((c) => c.drawn)
    .filter((c) => {
      for (let k = c.key; k.level < LAYOUT.maxLevel(); ) {
        k = parentOf(k);
        if (names.has(chunkName(k))) return false;
      }
      return !covered(c.key);
    })
    .map((c) => chunkName(c.key));
}
