// Chunk batches (`POST /chunk-batch`, docs/specs/http-api-v1.md): the answer's reader over any
// split of its bytes and over foreign bytes, and the API client's batching: chunks asked for
// together go out together, each settles as its record arrives, errors and aborts are per chunk,
// and a server without batches is asked one chunk a request.

import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import { ApiError, BatchReader, MAX_BATCH_CHUNKS, MAX_OPEN_BATCHES, PmcApi, type BatchRecord } from '../src/api';
import { encodeChunk } from './encodeChunk';

/** The answer's header: magic, version, records to follow. */
function header(count: number, version = 1): Uint8Array {
  const b = new Uint8Array(10);
  b.set([0x50, 0x4d, 0x43, 0x42]);
  const v = new DataView(b.buffer);
  v.setUint16(4, version, true);
  v.setUint32(6, count, true);
  return b;
}

/** One record: its length after the length field, the chunk's index, the status, the payload. */
function record(index: number, status: number, payload: Uint8Array): Uint8Array {
  const b = new Uint8Array(8 + payload.byteLength);
  const v = new DataView(b.buffer);
  v.setUint32(0, 4 + payload.byteLength, true);
  v.setUint16(4, index, true);
  v.setUint16(6, status, true);
  b.set(payload, 8);
  return b;
}

function concat(parts: Uint8Array[]): Uint8Array {
  const out = new Uint8Array(parts.reduce((n, p) => n + p.byteLength, 0));
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.byteLength;
  }
  return out;
}

/** A chunk of `n` triangles keyed by `name` (`face/level/i/j/k`, faces by index). */
function chunkBytes(name: string, n: number): Uint8Array<ArrayBuffer> {
  const [, level, i, j, k] = name.split('/').map(Number);
  const positions: number[][] = [];
  const indices: number[] = [];
  for (let t = 0; t < n; t++) {
    positions.push([t, 0, 0], [t + 1, 0, 0], [t, 1, 0]);
    indices.push(3 * t, 3 * t + 1, 3 * t + 2);
  }
  return encodeChunk({ face: 0, level, i, j, k, positions, indices });
}

const text = (s: string): Uint8Array => new TextEncoder().encode(s);

describe('BatchReader', () => {
  it('reads the records of an answer split anywhere, in the order they come', () => {
    const records = fc.array(
      fc.record({ status: fc.constantFrom(200, 404, 503), payload: fc.uint8Array({ maxLength: 40 }) }),
      { minLength: 1, maxLength: 12 },
    );
    fc.assert(
      fc.property(records, fc.array(fc.nat(), { maxLength: 20 }), fc.nat(), (rs, cuts, seed) => {
        // the records in a shuffled order of their indices
        const order = rs.map((_, i) => i).sort((a, b) => ((a * 7919 + seed) % 101) - ((b * 7919 + seed) % 101));
        const bytes = concat([header(rs.length), ...order.map((i) => record(i, rs[i]!.status, rs[i]!.payload))]);
        const at = [...new Set(cuts.map((c) => c % (bytes.byteLength + 1)))].sort((a, b) => a - b);
        const reader = new BatchReader();
        const got: BatchRecord[] = [];
        let from = 0;
        for (const to of [...at, bytes.byteLength]) {
          got.push(...reader.push(bytes.subarray(from, to)));
          from = to;
        }
        expect(reader.complete).toBe(true);
        expect(got.map((r) => r.index)).toEqual(order);
        for (const r of got) {
          expect(r.status).toBe(rs[r.index]!.status);
          expect([...r.payload]).toEqual([...rs[r.index]!.payload]);
        }
      }),
    );
  });

  it('is not complete until every record announced has come', () => {
    const reader = new BatchReader();
    reader.push(concat([header(2), record(1, 200, text('x'))]));
    expect(reader.complete).toBe(false);
    expect(reader.received).toBe(1);
  });

  it('refuses bytes that are not a batch answer', () => {
    const bad = (bytes: Uint8Array): unknown => {
      try {
        new BatchReader().push(bytes);
        return null;
      } catch (e) {
        return e;
      }
    };
    expect(String(bad(text('<html>not found</html>')))).toMatch(/not a chunk batch/);
    expect(String(bad(header(1, 2)))).toMatch(/version 2/);
    expect(String(bad(concat([header(1), record(1, 200, text('x'))])))).toMatch(/chunk 1 of 1/);
    expect(String(bad(concat([header(1), record(0, 200, text('x')), record(0, 200, text('y'))])))).toMatch(/more than the 1/);
    const short = new Uint8Array(4);
    new DataView(short.buffer).setUint32(0, 2, true);
    expect(String(bad(concat([header(1), short])))).toMatch(/record of 2 bytes/);
  });
});

/** A request the fake server holds: the batch's chunks, and how to answer them. */
interface Held {
  url: string;
  keys: string[];
  seams: number[];
  priorities: number[];
  aborted: boolean;
  /** Sends records (and ends the answer when `end`). */
  send: (records: Uint8Array[], end?: boolean) => void;
}

/** A server of chunk batches that holds each batch until the test answers it. */
function batchServer(opts: { batches?: boolean } = {}) {
  const held: Held[] = [];
  const gets: string[] = [];
  const fetchFn = async (url: string, init?: RequestInit): Promise<Response> => {
    if (init?.method !== 'POST') {
      gets.push(url);
      const name = new URL(url, 'http://host/').pathname.slice('/api/v1/chunk/'.length);
      return new Response(chunkBytes(name, 1));
    }
    if (opts.batches === false) return new Response(JSON.stringify({ error: 'no such endpoint' }), { status: 404 });
    const body = JSON.parse(String(init.body)) as { chunks: { key: string; seams: number; priority: number }[] };
    let controller!: ReadableStreamDefaultController<Uint8Array>;
    const stream = new ReadableStream<Uint8Array>({ start: (c) => void (controller = c) });
    const h: Held = {
      url,
      keys: body.chunks.map((c) => c.key),
      seams: body.chunks.map((c) => c.seams),
      priorities: body.chunks.map((c) => c.priority),
      aborted: false,
      send: (records, end = false) => {
        for (const r of records) controller.enqueue(r);
        if (end) controller.close();
      },
    };
    init.signal?.addEventListener('abort', () => {
      h.aborted = true;
      controller.error(new DOMException('aborted', 'AbortError'));
    });
    h.send([header(body.chunks.length)]);
    held.push(h);
    return new Response(stream, { status: 200 });
  };
  return { fetchFn, held, gets };
}

const settle = async (): Promise<void> => {
  for (let n = 0; n < 10; n++) await new Promise((r) => setTimeout(r, 0));
};

describe('PmcApi: chunk batches', () => {
  it('sends the chunks asked for in one task in one batch, and settles each as its record comes', async () => {
    const server = batchServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const keys = ['top/0/1/2/3', 'top/0/1/2/4', 'top/1/0/0/1'];
    const results = keys.map((k, n) => api.chunk({ preset: 'earth' }, k, undefined, { seams: n, priority: 10 - n }));
    await settle();
    expect(server.held).toHaveLength(1);
    const b = server.held[0]!;
    expect(b.url).toBe('/api/v1/chunk-batch?preset=earth');
    expect(b.keys).toEqual(keys);
    expect(b.seams).toEqual([0, 1, 2]);
    expect(b.priorities).toEqual([10, 9, 8]);
    // out of order, one at a time: the second is settled before the others come
    b.send([record(1, 200, chunkBytes(keys[1]!, 2))]);
    const second = await results[1]!;
    expect(second.indexCount).toBe(6);
    b.send([record(2, 200, chunkBytes(keys[2]!, 3)), record(0, 200, chunkBytes(keys[0]!, 1))], true);
    expect((await results[0]!).indexCount).toBe(3);
    expect((await results[2]!).indexCount).toBe(9);
    expect(server.gets).toEqual([]);
  });

  it('rejects each chunk with its own error: 503 is transient with a retry after a second, 404 is not', async () => {
    const server = batchServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const [busy, gone, fine] = ['top/0/0/0/0', 'top/0/0/0/9', 'top/0/0/0/1'].map((k) => api.chunk({}, k).catch((e: unknown) => e));
    await settle();
    server.held[0]!.send(
      [record(0, 503, text('the server is busy')), record(1, 404, text('not part of this planet')), record(2, 200, chunkBytes('top/0/0/0/1', 1))],
      true,
    );
    const e503 = (await busy) as ApiError;
    expect(e503).toBeInstanceOf(ApiError);
    expect(e503.transient).toBe(true);
    expect(e503.retryAfter).toBe(1);
    expect(e503.message).toMatch(/top\/0\/0\/0\/0: 503: the server is busy/);
    const e404 = (await gone) as ApiError;
    expect(e404.status).toBe(404);
    expect(e404.transient).toBe(false);
    expect(((await fine) as { indexCount: number }).indexCount).toBe(3);
  });

  it('rejects an aborted chunk at once, and aborts the batch when none of its chunks is wanted any more', async () => {
    const server = batchServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const a = new AbortController();
    const b = new AbortController();
    const first = api.chunk({}, 'top/0/0/0/0', a.signal).catch((e: unknown) => e);
    const second = api.chunk({}, 'top/0/0/0/1', b.signal).catch((e: unknown) => e);
    await settle();
    a.abort();
    expect(((await first) as Error).name).toBe('AbortError');
    expect(server.held[0]!.aborted).toBe(false);
    b.abort();
    expect(((await second) as Error).name).toBe('AbortError');
    await settle();
    expect(server.held[0]!.aborted).toBe(true);
    // a chunk aborted before its batch went out is never sent
    const c = new AbortController();
    const third = api.chunk({}, 'top/0/0/0/2', c.signal).catch((e: unknown) => e);
    const fourth = api.chunk({}, 'top/0/0/0/3');
    c.abort();
    await settle();
    expect(((await third) as Error).name).toBe('AbortError');
    expect(server.held[1]!.keys).toEqual(['top/0/0/0/3']);
    server.held[1]!.send([record(0, 200, chunkBytes('top/0/0/0/3', 1))], true);
    expect((await fourth).indexCount).toBe(3);
  });

  it('rejects the chunks an answer cut short never gave, as a transient failure', async () => {
    const server = batchServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const got = ['top/0/0/0/0', 'top/0/0/0/1'].map((k) => api.chunk({}, k).catch((e: unknown) => e));
    await settle();
    server.held[0]!.send([record(0, 200, chunkBytes('top/0/0/0/0', 1))], true);
    expect(((await got[0]) as { indexCount: number }).indexCount).toBe(3);
    const e = (await got[1]) as ApiError;
    expect(e).toBeInstanceOf(ApiError);
    expect(e.transient).toBe(true);
    expect(e.message).toMatch(/ended after 1 of 2 chunks/);
  });

  it('keeps at most MAX_OPEN_BATCHES batches open, and sends what waits when one closes', async () => {
    const server = batchServer();
    const api = new PmcApi('/api/v1', server.fetchFn);
    const n = MAX_OPEN_BATCHES * MAX_BATCH_CHUNKS + 5;
    const all = Array.from({ length: n }, (_, i) => api.chunk({}, `top/0/0/0/${i}`));
    await settle();
    expect(server.held).toHaveLength(MAX_OPEN_BATCHES);
    expect(server.held.every((h) => h.keys.length === MAX_BATCH_CHUNKS)).toBe(true);
    const first = server.held[0]!;
    first.send(first.keys.map((k, i) => record(i, 200, chunkBytes(k, 1))), true);
    await settle();
    expect(server.held).toHaveLength(MAX_OPEN_BATCHES + 1);
    expect(server.held[MAX_OPEN_BATCHES]!.keys).toEqual(Array.from({ length: 5 }, (_, i) => `top/0/0/0/${MAX_OPEN_BATCHES * MAX_BATCH_CHUNKS + i}`));
    for (const h of server.held.slice(1)) h.send(h.keys.map((k, i) => record(i, 200, chunkBytes(k, 1))), true);
    expect((await Promise.all(all)).length).toBe(n);
  });

  it('asks a server without batches (404) for one chunk a request, from then on', async () => {
    const server = batchServer({ batches: false });
    const api = new PmcApi('/api/v1', server.fetchFn);
    const got = await Promise.all(['top/0/0/0/0', 'top/0/0/0/1'].map((k) => api.chunk({ seed: '7' }, k, undefined, { seams: 3 })));
    expect(got.map((c) => c.indexCount)).toEqual([3, 3]);
    expect(server.gets).toEqual(['/api/v1/chunk/top/0/0/0/0?seed=7&seams=3', '/api/v1/chunk/top/0/0/0/1?seed=7&seams=3']);
    await api.chunk({}, 'top/0/0/0/2');
    expect(server.gets).toHaveLength(3);
  });
});
