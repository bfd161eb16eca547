import { describe, expect, it } from 'vitest';
import { ApiError, PmcApi } from '../src/api';
import { chunkName, HOLE_PRIORITY } from '../src/chunkSelection';
import { retryDelay } from '../src/chunkStreamer';
import { chunkServer, holes, overlaps, selection, streamerOn, VIEW } from './lodFixture';

const TOP = 'top/2/0/0/0';
const TOP_CHILDREN = ['top/1/0/0/0', 'top/1/0/1/0', 'top/1/1/0/0', 'top/1/1/1/0'];
const ROOTS = ['top', 'bottom', 'north', 'south', 'east', 'west'].map((f) => `${f}/2/0/0/0`);

describe('ChunkStreamer: what is fetched', () => {
  it('fetches the drawn leaves with their seams, most urgent first, a few at a time, until exactly they are shown', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 3 });
    const sel = selection([TOP, 'top/1/0/0/0'], { 'top/0/1/0/0': 2, 'top/0/1/1/0': 2, 'top/1/0/1/0': 0 }, ['west/2/0/0/0']);
    s.setSelection(sel, VIEW);
    await step();
    expect(s.stats().pending).toBe(3);
    expect(s.stats()).toMatchObject({ wanted: 11, selected: 12, exact: false, complete: false });
    // every answer lets the next requests go, never more than three at a time
    for (let n = 0; n < 10 && !s.settled(); n++) {
      await server.releaseAll();
      await step();
      expect(s.stats().pending).toBeLessThanOrEqual(3);
    }
    expect(s.settled()).toBe(true);
    const wanted = sel.chunks.filter((c) => c.drawn);
    expect(server.requests.length).toBe(wanted.length);
    expect(server.requests.find((r) => r.name === 'top/0/1/0/0')!.seams).toBe(2);
    expect(server.requests.some((r) => r.name === 'west/2/0/0/0')).toBe(false); // not drawn
    expect(new Map([...shown].map(([n, v]) => [n, v.seams]))).toEqual(new Map(wanted.map((c) => [chunkName(c.key), c.coarser])));
    // nothing was shown at first: the first three carry the hole bonus and are the most urgent
    const first = server.requests.slice(0, 3).map((r) => r.priority);
    const rest = server.requests.slice(3).map((r) => r.priority);
    expect(Math.min(...first)).toBeGreaterThanOrEqual(HOLE_PRIORITY);
    expect(Math.min(...first)).toBeGreaterThanOrEqual(Math.max(...rest));
    expect(s.stats()).toMatchObject({ shown: 11, pending: 0, missing: 0, exact: true, complete: true, levels: [4, 3, 4] });
  });

  it('aborts the requests of chunks no longer wanted, and does not ask them again', async () => {
    const server = chunkServer();
    const { s, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection([TOP]), VIEW);
    await step();
    expect(server.held().sort()).toEqual([...ROOTS.slice(1), ...TOP_CHILDREN].map((n) => `${n}~0`).sort());
    // the camera moved: the top face is coarse again and the bottom one finer
    s.setSelection(selection(['bottom/2/0/0/0']), VIEW);
    expect(server.aborted.sort()).toEqual([...TOP_CHILDREN, 'bottom/2/0/0/0'].map((n) => `${n}~0`).sort());
    expect(s.stats().aborted).toBe(5);
    await step(3);
    expect(server.held().filter((h) => h.startsWith('top/1/'))).toEqual([]);
    expect(server.held()).toContain(`${TOP}~0`);
    await server.releaseAll();
    await step(3);
    expect(s.settled()).toBe(true);
    expect(server.requests.filter((r) => r.name.startsWith('top/1/')).length).toBe(4);
  });

  it('wants the ground under the camera even out of the view', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server);
    // nothing drawn (the camera looks at the sky): the chunk under it is fetched all the same
    s.setSelection(selection([], {}, ROOTS), VIEW);
    await step();
    expect(server.held()).toEqual(['east/2/0/0/0~0']);
    await server.releaseAll();
    await step();
    expect([...shown.keys()]).toEqual(['east/2/0/0/0']);
    expect(s.settled()).toBe(true);
  });

  it('fetches the chunks between a chunk shown and wanted chunks two levels below it, and shows them meanwhile', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection(), VIEW);
    await step();
    await server.releaseAll();
    await step();
    // the top root is shown; now four level-0 chunks under top/1/0/0/0 are wanted
    s.setSelection(selection([TOP, 'top/1/0/0/0']), VIEW);
    await step();
    expect(s.stats()).toMatchObject({ wanted: 12, bridges: 1 });
    expect(server.held()).toContain('top/1/0/0/0~0');
    expect(server.requests.find((r) => r.name === 'top/1/0/0/0')!.priority).toBeGreaterThan(
      Math.max(...server.requests.filter((r) => r.name.startsWith('top/0/')).map((r) => r.priority)),
    );
    // the bridge and its siblings come first: the top face refines one level
    await server.release(...TOP_CHILDREN);
    await step();
    expect(shown.has(TOP)).toBe(false);
    expect([...shown.keys()].filter((n) => n.startsWith('top/')).sort()).toEqual(TOP_CHILDREN);
    expect(s.settled()).toBe(false);
    await server.releaseAll();
    await step();
    expect(shown.has('top/1/0/0/0')).toBe(false);
    expect(shown.has('top/0/0/0/0')).toBe(true);
    expect(s.settled()).toBe(true);
    expect(s.stats().bridges).toBe(0);
  });

  it('drops a bridge that is no longer needed', async () => {
    const server = chunkServer();
    const { s, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection(), VIEW);
    await step();
    await server.releaseAll();
    await step();
    s.setSelection(selection([TOP, 'top/1/0/0/0']), VIEW);
    await step();
    // everything wanted arrives before the bridge
    await server.release(...TOP_CHILDREN.slice(1), 'top/0/0/0/0', 'top/0/0/1/0', 'top/0/1/0/0', 'top/0/1/1/0');
    await step();
    expect(server.aborted).toEqual(['top/1/0/0/0~0']);
    expect(s.settled()).toBe(true);
  });

  it('retries a busy chunk after its Retry-After without reporting it', async () => {
    const server = chunkServer();
    let clock = 0;
    const { s, shown, errors, step } = streamerOn(server, { now: () => clock });
    server.fail(TOP, 1);
    s.setSelection(selection(), VIEW);
    await step(2);
    await server.releaseAll();
    await step(2);
    expect(shown.has(TOP)).toBe(false);
    expect(s.stats().failed).toBe(1);
    expect(s.settled()).toBe(false);
    clock += 1000; // past Retry-After
    await step(2);
    await server.releaseAll();
    await step();
    expect(shown.has(TOP)).toBe(true);
    expect(s.settled()).toBe(true);
    expect(errors).toEqual([]);
  });

  it('requests nothing while the server is gone (paused), and what is missing at once when it is back', async () => {
    const server = chunkServer();
    let clock = 0;
    const { s, shown, errors, step } = streamerOn(server, { now: () => clock });
    server.fail(TOP, 1);
    s.setSelection(selection(), VIEW);
    await step(2);
    await server.releaseAll();
    await step(2);
    expect(s.stats().failed).toBe(1);
    const asked = server.requests.length;
    s.setPaused(true);
    clock += 60_000; // long past any back-off
    await step(3);
    expect(server.requests.length).toBe(asked);
    // back: the failed chunk goes now, not after its back-off
    clock -= 59_999;
    s.retryFailed();
    await step(2);
    await server.releaseAll();
    await step();
    expect(server.requests.length).toBe(asked + 1);
    expect(shown.has(TOP)).toBe(true);
    expect(errors).toEqual([]);
  });

  it('gives up a request the server never answers, so the chunks behind it are asked for (a stalled view)', async () => {
    // A slot held for good by a request that is never answered (a server or connection that
    // hangs) stopped every chunk behind it: with one slot, nothing else was ever asked.
    const server = chunkServer();
    let clock = 0;
    const { s, shown, errors, step } = streamerOn(server, { maxConcurrent: 1, requestTimeoutMs: 60_000, now: () => clock });
    s.setSelection(selection(), VIEW);
    await step();
    const first = server.held();
    expect(first.length).toBe(1);
    clock = 59_999;
    await step();
    expect(server.held()).toEqual(first);
    clock = 60_000;
    await step();
    // the hung request is aborted and the next chunk asked for
    expect(server.aborted).toEqual(first);
    expect(server.held().length).toBe(1);
    expect(server.held()).not.toEqual(first);
    expect(s.stats()).toMatchObject({ timedOut: 1, failed: 1, blocked: 1 });
    // the others answer; the given-up one is asked again after its back-off, and the view settles
    for (let n = 0; n < 20 && !s.settled(); n++) {
      clock += 1000;
      await server.releaseAll();
      await step();
    }
    expect(s.settled()).toBe(true);
    expect(server.requests.filter((r) => `${r.name}~${r.seams}` === first[0]).length).toBe(2);
    expect(shown.size).toBe(6);
    expect(errors).toEqual([]);
    expect(s.stats()).toMatchObject({ timedOut: 1, blocked: 0, missing: 0 });
  });

  it('reports a chunk whose requests go unanswered three times', async () => {
    const server = chunkServer();
    let clock = 0;
    const { s, errors, step } = streamerOn(server, { maxConcurrent: 6, requestTimeoutMs: 1000, now: () => clock });
    s.setSelection(selection(), VIEW);
    await step();
    for (let n = 0; n < 3; n++) {
      // nothing answers; each round gives every request up and, after the back-off, asks again
      clock += 1000;
      await step();
      clock += 5000;
      await step();
    }
    expect(s.stats().timedOut).toBeGreaterThanOrEqual(18);
    expect(errors.length).toBeGreaterThan(0);
    expect(errors[0]).toMatch(/^chunk \S+: no answer within 1 s, 3 times$/);
  });

  it('counts an empty chunk as loaded', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server);
    for (const r of ROOTS.slice(1)) server.empty.add(r);
    s.setSelection(selection(), VIEW);
    await step(2);
    await server.releaseAll();
    await step(2);
    expect(s.settled()).toBe(true);
    expect(shown.size).toBe(6);
    expect(s.stats()).toMatchObject({ shown: 6, triangles: 1, exact: true });
  });

  it('drops everything when the planet changes', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 3 });
    s.setSelection(selection(), VIEW);
    await step();
    await server.release(...server.held().map((h) => h.split('~')[0]!));
    await step();
    expect(shown.size).toBe(3);
    s.setPlanet({ preset: 'moon' }, null);
    expect(shown.size).toBe(0);
    expect(server.aborted.length).toBe(3);
    expect(s.stats()).toMatchObject({ loaded: 0, pending: 0, requested: 0, shown: 0 });
  });
});

describe('ChunkStreamer: no hole, no flicker', () => {
  it('keeps a chunk being refined until all its wanted children are there', async () => {
    const server = chunkServer();
    const { s, shown, log, step } = streamerOn(server, { maxConcurrent: 8 });
    s.setSelection(selection(), VIEW);
    await step(2);
    await server.releaseAll();
    await step();
    expect([...shown.keys()].sort()).toEqual([...ROOTS].sort());
    const fine = selection([TOP], {}, ['top/1/1/0/0']); // one child out of the view
    s.setSelection(fine, VIEW);
    await step();
    expect(server.held().sort()).toEqual(['top/1/0/0/0~0', 'top/1/0/1/0~0', 'top/1/1/1/0~0']);
    await server.release('top/1/0/0/0', 'top/1/0/1/0');
    await step();
    expect(shown.has(TOP)).toBe(true);
    expect(shown.has('top/1/0/0/0')).toBe(false);
    expect(holes(fine, shown.keys())).toEqual([]);
    await server.release('top/1/1/1/0');
    await step();
    // the child out of the view is not needed
    expect(shown.has(TOP)).toBe(false);
    expect([...shown.keys()].filter((n) => n.startsWith('top/')).sort()).toEqual(['top/1/0/0/0', 'top/1/0/1/0', 'top/1/1/1/0']);
    expect(s.settled()).toBe(true);
    // the parent went in the same step as its children came
    const swap = log.slice(log.indexOf('hide top/2/0/0/0'));
    expect(swap.slice(0, 4).sort()).toEqual(['hide top/2/0/0/0', 'show top/1/0/0/0~0', 'show top/1/0/1/0~0', 'show top/1/1/1/0~0']);
  });

  it('keeps the children of a chunk being coarsened until the chunk is there', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection([TOP, 'top/1/0/0/0']), VIEW);
    await step();
    await server.releaseAll();
    await step();
    expect(s.settled()).toBe(true);
    expect(shown.has(TOP)).toBe(false);
    const coarse = selection();
    s.setSelection(coarse, VIEW);
    await step();
    expect(server.held()).toEqual([`${TOP}~0`]);
    // meanwhile the finer chunks stay, without overlap or hole
    for (const c of [...TOP_CHILDREN.slice(1), 'top/0/0/0/0', 'top/0/1/1/0']) expect(shown.has(c)).toBe(true);
    expect(overlaps(shown.keys())).toEqual([]);
    expect(holes(coarse, shown.keys())).toEqual([]);
    expect(s.settled()).toBe(false);
    await server.release(TOP);
    await step();
    expect([...shown.keys()].sort()).toEqual([...ROOTS].sort());
    expect(s.settled()).toBe(true);
    // the finer chunks stay in the cache for a while
    expect(s.stats().loaded).toBe(6 + 3 + 4);
  });

  it('keeps showing the old seams variant until the new one arrives', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection([TOP]), VIEW);
    await step();
    await server.releaseAll();
    await step();
    expect(shown.get('top/1/0/0/0')!.seams).toBe(0);
    // a neighbour became coarser: the same chunk, now with two seams
    s.setSelection(selection([TOP], { 'top/1/0/0/0': 5 }), VIEW);
    await step();
    expect(server.held()).toEqual(['top/1/0/0/0~5']);
    expect(shown.get('top/1/0/0/0')!.seams).toBe(0);
    expect(s.settled()).toBe(false);
    await server.releaseAll();
    await step();
    expect(shown.get('top/1/0/0/0')!.seams).toBe(5);
    expect(s.settled()).toBe(true);
    expect(s.stats().loaded).toBe(5 + 4 + 1); // both variants kept
    // and back: the old variant is still loaded, shown at once, nothing fetched
    const before = server.requests.length;
    s.setSelection(selection([TOP]), VIEW);
    await step();
    expect(shown.get('top/1/0/0/0')!.seams).toBe(0);
    expect(server.requests.length).toBe(before);
    expect(s.settled()).toBe(true);
  });

  it('shows no two overlapping chunks and leaves no hole through a series of selections', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 2 });
    const sequence = [
      selection(),
      selection([TOP, 'top/1/0/0/0']),
      selection([TOP, 'top/1/1/1/0'], { 'top/0/2/2/0': 3 }),
      selection(['north/2/0/0/0']),
      selection([TOP]),
    ];
    let first = true;
    for (const sel of sequence) {
      s.setSelection(sel, VIEW);
      for (let n = 0; n < 40 && !s.settled(); n++) {
        // answer one request at a time, oldest first
        const next = server.held()[0];
        if (next) await server.release(next.split('~')[0]!);
        await step();
        expect(overlaps(shown.keys())).toEqual([]);
        if (!first) expect(holes(sel, shown.keys())).toEqual([]);
      }
      expect(s.settled()).toBe(true);
      first = false;
    }
  });
});

describe('ChunkStreamer: memory', () => {
  it('drops the least recently wanted chunks that are neither shown nor wanted, over the cap', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20, maxLoaded: 13 });
    const load = async (splits: string[]): Promise<void> => {
      s.setSelection(selection(splits), VIEW);
      await step();
      await server.releaseAll();
      await step();
      expect(s.settled()).toBe(true);
    };
    await load([]); // 6 roots
    await load([TOP]); // + 4: the top root stays in the cache, not shown
    expect(s.stats()).toMatchObject({ loaded: 10, evicted: 0 });
    // + 4 bottom children: 14 > 13. The top root is wanted again (and shown from the cache), the
    // bottom root was shown until its children came: the top children, wanted by the previous
    // selection only, are the least recently wanted; one of them goes
    await load(['bottom/2/0/0/0']);
    expect(s.stats()).toMatchObject({ loaded: 13, evicted: 1 });
    const before = server.requests.length;
    await load([TOP]);
    // three top children came back from the cache, the evicted one is fetched again
    expect(server.requests.slice(before).map((r) => r.name)).toEqual(['top/1/0/0/0']);
    // over the cap again: a bottom child goes (wanted two selections ago), nothing shown
    expect(s.stats()).toMatchObject({ loaded: 13, evicted: 2 });
    expect([...shown.keys()].filter((n) => n.startsWith('bottom/1/'))).toEqual([]);
    const again = server.requests.length;
    await load(['bottom/2/0/0/0']);
    expect(server.requests.slice(again).map((r) => r.name)).toEqual(['bottom/1/0/0/0']);
  });

  it('keeps everything shown or wanted even past the cap', async () => {
    const server = chunkServer();
    const { s, step } = streamerOn(server, { maxConcurrent: 20, maxLoaded: 2, maxBytes: 100 });
    s.setSelection(selection([TOP]), VIEW);
    await step();
    await server.releaseAll();
    await step();
    expect(s.settled()).toBe(true);
    expect(s.stats()).toMatchObject({ loaded: 9, shown: 9, evicted: 0 });
  });
});

describe('retryDelay and the chunk URL', () => {
  it('backs off', () => {
    expect(retryDelay(new ApiError('busy', 503, 'u', 2), 1)).toBe(2000);
    expect(retryDelay(new Error('x'), 1)).toBe(500);
    expect(retryDelay(new Error('x'), 3)).toBe(2000);
    expect(retryDelay(new Error('x'), 30)).toBe(30_000);
  });

  it('asks for a chunk with its seams and priority', () => {
    const api = new PmcApi('api/v1');
    expect(api.chunkUrl({ preset: 'earthlike', seed: '7' }, 'top/0/3/4/1', { seams: 5, priority: 12.5 })).toBe(
      'api/v1/chunk/top/0/3/4/1?preset=earthlike&seed=7&seams=5&priority=12.5',
    );
    expect(api.chunkUrl({}, 'top/0/3/4/1')).toBe('api/v1/chunk/top/0/3/4/1');
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

  it('tells its observer whether requests reach the server: a network failure or a proxy 502/504 no, any other answer yes', async () => {
    const seen: string[] = [];
    let answer: () => Promise<Response> = async () => { throw new TypeError('fetch failed'); };
    const api = new PmcApi('/api/v1', () => answer());
    api.observer = { reached: () => seen.push('reached'), unreachable: () => seen.push('unreachable') };
    await api.health().catch(() => undefined);
    answer = async () => new Response('', { status: 502 });
    await api.health().catch(() => undefined);
    answer = async () => new Response(JSON.stringify({ error: 'busy' }), { status: 503 });
    await api.health().catch(() => undefined);
    answer = async () => new Response(JSON.stringify({ ok: true, version: '1' }), { status: 200 });
    await api.health();
    expect(seen).toEqual(['unreachable', 'unreachable', 'reached', 'reached']);
  });

  it('rejects a chunk that does not decode, naming it', async () => {
    const api = new PmcApi('/api/v1', async () => new Response(new Uint8Array([1, 2, 3]), { status: 200 }));
    await expect(api.chunkAlone({}, 'top/0/1/2/3')).rejects.toThrow(/chunk top\/0\/1\/2\/3: chunk-mesh-v1: buffer of 3 bytes/);
  });

  it('rejects an unexpected planet document', async () => {
    const api = new PmcApi('/api/v1', async () => new Response(JSON.stringify({ format: 'x' }), { status: 200 }));
    await expect(api.planet()).rejects.toThrow(/unexpected \/planet response/);
  });
});

