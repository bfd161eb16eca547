import { describe, expect, it } from 'vitest';
import { ApiError, PmcApi, type ChunkEntry } from '../src/api';
import { ChunkStreamer, retryDelay } from '../src/chunkStreamer';
import type { V3 } from '../src/frames';
import { encodeChunk } from './encodeChunk';

/** A fake server: chunks along +X, 10 m apart; records requests; can fail some. */
function fakeServer(opts: { fail?: Map<string, number> } = {}) {
  const requests: string[] = [];
  const chunks: ChunkEntry[] = Array.from({ length: 20 }, (_, n) => ({
    key: `top/0/${n}/0/0`, face: 'top', level: 0, i: n, j: 0, k: 0,
    center: [10 * n, 0, 0], radius: 2, distance: 0,
  }));
  const fetchFn = async (url: string): Promise<Response> => {
    requests.push(url);
    const u = new URL(url, 'http://host/');
    if (u.pathname === '/api/v1/chunks') {
      const at = ['x', 'y', 'z'].map((k) => Number(u.searchParams.get(k)));
      const range = Number(u.searchParams.get('range'));
      const list = chunks
        .map((c) => ({ ...c, distance: Math.max(0, Math.hypot(c.center[0] - at[0]!, c.center[1] - at[1]!, c.center[2] - at[2]!) - c.radius) }))
        .filter((c) => c.distance <= range);
      return new Response(JSON.stringify({ chunks: list, total_in_range: list.length }), { status: 200 });
    }
    const m = /^\/api\/v1\/chunk\/(.+)$/.exec(u.pathname);
    if (m) {
      const key = m[1]!;
      const left = opts.fail?.get(key) ?? 0;
      if (left > 0) {
        opts.fail!.set(key, left - 1);
        return new Response(JSON.stringify({ error: 'queue full' }), { status: 503, headers: { 'Retry-After': '0' } });
      }
      const i = Number(key.split('/')[2]);
      const bytes = encodeChunk({ i, origin: [10 * i, 0, 0], positions: [[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices: [0, 1, 2] });
      return new Response(bytes, { status: 200 });
    }
    return new Response(JSON.stringify({ error: `no ${u.pathname}` }), { status: 404 });
  };
  return { requests, fetchFn };
}

const tick = (): Promise<void> => new Promise((r) => setTimeout(r, 0));
const all = (): boolean => true;

describe('ChunkStreamer', () => {
  it('loads what is in range, 6 at a time, then unloads what the camera left', async () => {
    const server = fakeServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const loaded = new Set<string>();
    let clock = 0;
    const s = new ChunkStreamer(api, {
      onLoad: (key) => loaded.add(key),
      onUnload: (key) => loaded.delete(key),
      onError: (m) => { throw new Error(m); },
    }, { now: () => clock });
    s.setPlanet({ preset: 'earthlike', seed: '7' });
    const cam: V3 = [0, 0, 0];
    s.update(cam, 45, all);
    await tick();
    expect(server.requests[0]).toBe('/api/v1/chunks?preset=earthlike&seed=7&x=0&y=0&z=0&range=56.25&limit=4096');
    s.update(cam, 45, all);
    expect(s.stats().pending).toBe(5); // chunks 0..4 are within 45 m
    for (let n = 0; n < 10; n++) { await tick(); s.update(cam, 45, all); }
    expect([...loaded].sort()).toEqual(['top/0/0/0/0', 'top/0/1/0/0', 'top/0/2/0/0', 'top/0/3/0/0', 'top/0/4/0/0']);
    expect(s.settled(cam, 45)).toBe(true);
    expect(s.stats().triangles).toBe(5);

    // move 100 m along the row: re-query, load the new ones, drop the old ones
    const far: V3 = [100, 0, 0];
    for (let n = 0; n < 20; n++) { s.update(far, 45, all); await tick(); clock += 16; }
    expect(loaded.has('top/0/10/0/0')).toBe(true);
    expect(loaded.has('top/0/0/0/0')).toBe(false);
    expect(s.stats().pending).toBe(0);
    expect(server.requests.filter((r) => r.includes('/chunks?')).length).toBe(2);
  });

  it('never has more than 6 requests in flight', async () => {
    const server = fakeServer();
    const s = new ChunkStreamer(new PmcApi('/api/v1', server.fetchFn), {
      onLoad: () => undefined, onUnload: () => undefined, onError: () => undefined,
    });
    s.setPlanet({});
    s.update([0, 0, 0], 1000, all);
    await tick();
    s.update([0, 0, 0], 1000, all);
    expect(s.stats().pending).toBe(6);
    s.update([0, 0, 0], 1000, all);
    expect(s.stats().pending).toBe(6);
  });

  it('retries a busy chunk later and reports nothing for a transient failure', async () => {
    const server = fakeServer({ fail: new Map([['top/0/0/0/0', 1]]) });
    const errors: string[] = [];
    let clock = 0;
    const loaded = new Set<string>();
    const s = new ChunkStreamer(new PmcApi('/api/v1', server.fetchFn), {
      onLoad: (k) => loaded.add(k), onUnload: (k) => loaded.delete(k), onError: (m) => errors.push(m),
    }, { now: () => clock });
    s.setPlanet({});
    for (let n = 0; n < 10; n++) { s.update([0, 0, 0], 5, all); await tick(); }
    expect(loaded.size).toBe(0);
    expect(s.stats().failed).toBe(1);
    expect(s.settled([0, 0, 0], 5)).toBe(false);
    clock += 1000; // past Retry-After
    for (let n = 0; n < 10; n++) { s.update([0, 0, 0], 5, all); await tick(); }
    expect([...loaded]).toEqual(['top/0/0/0/0']);
    expect(errors).toEqual([]);
  });

  it('drops everything when the planet changes', async () => {
    const server = fakeServer();
    const unloaded: string[] = [];
    const s = new ChunkStreamer(new PmcApi('/api/v1', server.fetchFn), {
      onLoad: () => undefined, onUnload: (k) => unloaded.push(k), onError: () => undefined,
    });
    s.setPlanet({ preset: 'moon' });
    for (let n = 0; n < 10; n++) { s.update([0, 0, 0], 15, all); await tick(); }
    expect(s.stats().loaded).toBe(2);
    s.setPlanet({ preset: 'mars', seed: '3' });
    expect(unloaded.sort()).toEqual(['top/0/0/0/0', 'top/0/1/0/0']);
    expect(s.stats()).toMatchObject({ loaded: 0, pending: 0, requested: 0 });
    s.update([0, 0, 0], 15, all);
    await tick();
    expect(server.requests.at(-1)).toContain('preset=mars&seed=3');
  });
});

describe('PmcApi', () => {
  it('surfaces the server error message and status', async () => {
    const api = new PmcApi('/api/v1', async () => new Response(JSON.stringify({ error: 'unknown preset "venus"' }), { status: 400, statusText: 'Bad Request' }));
    await expect(api.planet({ preset: 'venus' })).rejects.toThrow(/400 Bad Request: unknown preset "venus"/);
    const err = await api.planet().catch((e: unknown) => e);
    expect(err).toBeInstanceOf(ApiError);
    expect((err as ApiError).status).toBe(400);
    expect((err as ApiError).transient).toBe(false);
  });

  it('turns a network failure into a transient ApiError', async () => {
    const api = new PmcApi('/api/v1', async () => { throw new TypeError('fetch failed'); });
    const err = await api.health().catch((e: unknown) => e);
    expect(err).toBeInstanceOf(ApiError);
    expect((err as ApiError).transient).toBe(true);
    expect((err as Error).message).toMatch(/cannot reach the PMC server/);
  });

  it('rejects a chunk that does not decode, naming it', async () => {
    const api = new PmcApi('/api/v1', async () => new Response(new Uint8Array([1, 2, 3]), { status: 200 }));
    await expect(api.chunk({}, 'top/0/1/2/3')).rejects.toThrow(/chunk top\/0\/1\/2\/3: chunk-mesh-v1: buffer of 3 bytes/);
  });

  it('rejects an unexpected planet document', async () => {
    const api = new PmcApi('/api/v1', async () => new Response(JSON.stringify({ format: 'x' }), { status: 200 }));
    await expect(api.planet()).rejects.toThrow(/unexpected \/planet response/);
  });

  it('backs off', () => {
    expect(retryDelay(new ApiError('busy', 503, 'u', 2), 1)).toBe(2000);
    expect(retryDelay(new Error('x'), 1)).toBe(500);
    expect(retryDelay(new Error('x'), 3)).toBe(2000);
    expect(retryDelay(new Error('x'), 30)).toBe(30_000);
  });
});
