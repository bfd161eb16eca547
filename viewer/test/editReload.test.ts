import { describe, expect, it } from 'vitest';
import { ApiError, PmcApi, type PlanetInfo } from '../src/api';
import { EditSession, editErrorMessage } from '../src/editSession';
import type { EventSourceLike } from '../src/editEvents';
import { chunkServer, selection, streamerOn, tick, VIEW } from './lodFixture';

const TOP = 'top/2/0/0/0';

/** A streamer showing five roots and the four level-1 chunks of the top face, all loaded. */
async function loadedStreamer(opts: { now?: () => number } = {}) {
  const server = chunkServer();
  const t = streamerOn(server, { maxConcurrent: 20, ...opts });
  t.s.setSelection(selection([TOP]), VIEW);
  await t.step();
  await server.releaseAll();
  await t.step();
  expect(t.s.settled()).toBe(true);
  return { server, ...t };
}

describe('reloading edited chunks', () => {
  it('refetches a chunk shown and swaps the mesh only when the new data arrives', async () => {
    const { server, s, shown, log, step } = await loadedStreamer();
    server.edit('top/1/0/0/0');
    // an edit names chunks of every level: those not shown are ignored
    expect(s.reload(['top/1/0/0/0', 'top/0/0/0/0', 'bottom/1/0/0/0'])).toBe(1);
    expect(s.settled()).toBe(false);
    expect(s.stats().stale).toBe(1);
    await step();
    expect(server.held()).toEqual(['top/1/0/0/0~0']);
    expect(s.stats().reloading).toBe(1);
    // meanwhile the old mesh stays
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(1);
    expect(log.filter((l) => l.startsWith('hide'))).toEqual([]);
    await server.releaseAll();
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(2);
    await step();
    expect(s.settled()).toBe(true);
    expect(s.stats()).toMatchObject({ shown: 9, stale: 0, reloading: 0, reloads: 1, triangles: 10 });
  });

  it('drops a loaded chunk not shown that an edit names, so that it is fetched fresh', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20 });
    for (const sel of [selection(), selection([TOP])]) {
      s.setSelection(sel, VIEW);
      await step();
      await server.releaseAll();
      await step();
    }
    // the top root is in the cache, not shown (its children are)
    expect(shown.has(TOP)).toBe(false);
    expect(s.stats().loaded).toBe(10);
    server.edit(TOP);
    expect(s.reload([TOP])).toBe(0);
    expect(s.stats().loaded).toBe(9);
    s.setSelection(selection(), VIEW);
    await step();
    // not shown from the stale cache: fetched again, the children stay meanwhile
    expect(server.held()).toEqual([`${TOP}~0`]);
    expect(shown.get(TOP)).toBeUndefined();
    expect(shown.has('top/1/0/0/0')).toBe(true);
    await server.releaseAll();
    await step();
    expect(shown.get(TOP)!.triangles).toBe(2);
    expect(shown.has('top/1/0/0/0')).toBe(false);
  });

  it('reloads every seams variant of a chunk shown', async () => {
    const { server, s, shown, step } = await loadedStreamer();
    s.setSelection(selection([TOP], { 'top/1/0/0/0': 3 }), VIEW);
    await step();
    await server.releaseAll();
    await step();
    expect(shown.get('top/1/0/0/0')!.seams).toBe(3);
    server.edit('top/1/0/0/0');
    expect(s.reload(['top/1/0/0/0'])).toBe(1);
    await step();
    expect(server.held()).toEqual(['top/1/0/0/0~3']);
    expect(s.stats().loaded).toBe(9); // the old variant (seams 0), not shown, was dropped
    await server.releaseAll();
    expect(shown.get('top/1/0/0/0')).toEqual({ seams: 3, triangles: 2 });
  });

  it('fetches again a chunk whose fetch was in flight when the edit named it', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 20 });
    s.setSelection(selection(), VIEW);
    await step();
    expect(server.held()).toContain(`${TOP}~0`); // asked before the edit
    server.edit(TOP);
    expect(s.reload([TOP])).toBe(1);
    await server.releaseAll(); // the old answer arrives: shown (better than a hole)...
    await step();
    expect(shown.get(TOP)!.triangles).toBe(1);
    expect(s.settled()).toBe(false); // ...but not final
    expect(server.held()).toEqual([`${TOP}~0`]);
    await server.releaseAll();
    expect(shown.get(TOP)!.triangles).toBe(2);
    await step();
    expect(s.settled()).toBe(true);
    expect(server.requests.filter((r) => r.name === TOP).length).toBe(2);
  });

  it('fetches again a chunk named while its reload was in flight', async () => {
    const { server, s, shown, step } = await loadedStreamer();
    server.edit('top/1/0/0/0');
    s.reload(['top/1/0/0/0']);
    await step(); // the reload is asked (version 2)
    server.edit('top/1/0/0/0'); // a second edit while it is in flight
    s.reload(['top/1/0/0/0']);
    await server.releaseAll();
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(2);
    await step();
    await server.releaseAll();
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(3);
    expect(server.requests.filter((r) => r.name === 'top/1/0/0/0').length).toBe(3);
  });

  it('keeps the old mesh when a reload fails and tries again', async () => {
    let clock = 0;
    const { server, s, shown, step } = await loadedStreamer({ now: () => clock });
    server.edit(TOP.replace('top', 'north'));
    server.fail('north/2/0/0/0', 1);
    s.reload(['north/2/0/0/0']);
    await step(3);
    expect(shown.get('north/2/0/0/0')!.triangles).toBe(1);
    expect(s.stats()).toMatchObject({ stale: 1, failed: 1 });
    clock += 1000;
    await step(2);
    await server.releaseAll();
    expect(shown.get('north/2/0/0/0')!.triangles).toBe(2);
    expect(s.stats().stale).toBe(0);
  });

  it('refetches once resumed the chunks an edit named while paused, and keeps the others', async () => {
    // the order of the step 17 flake: the edit stream reached the restarted server before the
    // page did, so the page heard of the edit by its event (named chunks) and not by the hello
    const { server, s, shown, step } = await loadedStreamer();
    s.setPaused(true);
    server.edit('top/1/0/0/0');
    expect(s.reload(['top/1/0/0/0', 'top/0/0/0/0'])).toBe(1);
    await step();
    // nothing is asked of a server the page thinks is gone; the old mesh stays
    expect(server.held()).toEqual([]);
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(1);
    s.retryFailed();
    await step();
    expect(server.held()).toEqual(['top/1/0/0/0~0']);
    await server.releaseAll();
    await step();
    expect(shown.get('top/1/0/0/0')!.triangles).toBe(2);
    expect(s.stats()).toMatchObject({ shown: 9, stale: 0, reloading: 0, reloads: 1 });
  });

  it('reloads everything shown or loading on reloadAll', async () => {
    const { server, s, step } = await loadedStreamer();
    s.setSelection(selection([TOP, 'top/1/0/0/0']), VIEW);
    await step();
    expect(server.held().length).toBe(4);
    expect(s.reloadAll()).toBe(9 + 4);
    await step();
    // the four in flight are fetched again once they answer; the nine shown now
    expect(server.held().length).toBe(4 + 9);
  });

  it('forgets reloads when the planet changes', async () => {
    const { s } = await loadedStreamer();
    s.reload(['top/1/0/0/0']);
    s.setPlanet({ preset: 'moon' }, null);
    expect(s.stats()).toMatchObject({ stale: 0, reloading: 0, reloads: 0, loaded: 0 });
  });
});

// ---- the edit session: answers, events, errors ---------------------------------------------

const PLANET: PlanetInfo = {
  format: 'pmc-planet', version: 1, preset: 'earthlike', seed: '7', presets: [],
  layout: { n_c: 8, n_t: 32, d_b: 1744, l_d: 4, d_c: 2 }, radius: 2000, base_radius: 1744,
  sea_radius: 1884.8, surface_bounds: [1810, 1995], chunk_count: 768, face_tiles: 256, depth_tiles: 64,
  faces: [], materials: ['sand', 'grass', 'rock', 'cave'], palette: { a: [1, 1, 1], b: [0, 0, 0] },
  edit: {
    enabled: true, world: 'e2e.pmcw', revision: 5, active: 5, redo: 0, min_brush_radius: 0.5,
    max_brush_radius: 64, rate_per_second: 20, burst: 40, brushes: ['add', 'remove', 'smooth', 'flatten', 'paint'],
  },
};

class FakeSource implements EventSourceLike {
  readyState = 1;
  onopen: ((e: Event) => void) | null = null;
  onerror: ((e: Event) => void) | null = null;
  closed = false;
  private readonly listeners = new Map<string, ((e: MessageEvent) => void)[]>();
  addEventListener(type: string, fn: (e: MessageEvent) => void): void {
    this.listeners.set(type, [...(this.listeners.get(type) ?? []), fn]);
  }
  close(): void {
    this.closed = true;
  }
  emit(type: string, data: unknown): void {
    for (const fn of this.listeners.get(type) ?? []) fn({ data: JSON.stringify(data) } as MessageEvent);
  }
}

function session(reply: (url: string, body: string | null) => Response) {
  const reloaded: string[][] = [];
  let reloadAlls = 0;
  const sources: FakeSource[] = [];
  const posted: string[] = [];
  let clock = 1000;
  const api = new PmcApi('api/v1', async (url, init) => {
    const body = typeof init?.body === 'string' ? init.body : null;
    posted.push(`${init?.method ?? 'GET'} ${url}${body ? ` ${body}` : ''}`);
    return reply(url, body);
  });
  const ed = new EditSession({
    api,
    chunks: {
      reload: (keys) => {
        reloaded.push([...keys]);
        return 1;
      },
      reloadAll: () => {
        reloadAlls++;
        return 1;
      },
    },
    eventSource: () => {
      const s = new FakeSource();
      sources.push(s);
      return s;
    },
    now: () => clock,
  });
  return {
    ed, reloaded, sources, posted,
    reloadAlls: () => reloadAlls,
    advance: (ms: number) => (clock += ms),
  };
}

const answer = (revision: number, chunks: string[], id: number | null = revision) =>
  new Response(JSON.stringify({ id, revision, active: 1, redo: 0, chunks }), { status: 200 });

describe('EditSession', () => {
  it('is off with the reason when the planet is not editable, and closes the push', () => {
    const t = session(() => answer(1, []));
    t.ed.setPlanet(PLANET);
    expect(t.sources.length).toBe(1);
    t.ed.setTool('dig');
    expect(t.ed.brushActive).toBe(true);
    t.ed.setPlanet({ ...PLANET, preset: 'moon', edit: { enabled: false, reason: 'the world is earthlike/7' } });
    expect(t.sources[0]!.closed).toBe(true);
    expect(t.ed.status()).toMatchObject({ enabled: false, reason: 'the world is earthlike/7', tool: 'look', push: 'off' });
    t.ed.setTool('dig');
    expect(t.ed.brushActive).toBe(false);
    expect(t.ed.status().notice).toMatch(/editing is off: the world is earthlike/);
    // an older server without the editing API
    const { edit: _unused, ...old } = PLANET;
    t.ed.setPlanet(old);
    expect(t.ed.status().reason).toMatch(/no editing API/);
    expect(t.sources.length).toBe(1);
    // back on the world: a new stream
    t.ed.setPlanet(PLANET);
    expect(t.sources.length).toBe(2);
  });

  it('sends a click as one edit, reloads the answer\'s chunks once even when the event repeats them', async () => {
    const t = session(() => answer(6, ['top/0/1/0/0']));
    t.ed.setPlanet(PLANET);
    t.ed.setTool('dig');
    t.ed.setRadius(14);
    t.ed.press([1, 1900, 2]);
    t.ed.release();
    t.ed.frame([5, 5, 5]);
    expect(t.ed.status().inFlight).toBe(true);
    t.ed.frame([5, 5, 5]); // nothing more while in flight
    await tick();
    await tick();
    expect(t.posted).toEqual([
      'POST api/v1/edits?preset=earthlike&seed=7 {"brush":"remove","x":1,"y":1900,"z":2,"radius":14,"strength":1}',
    ]);
    expect(t.reloaded).toEqual([['top/0/1/0/0']]);
    t.sources[0]!.emit('edit', { revision: 6, action: 'apply', id: 6, chunks: ['top/0/1/0/0'] });
    expect(t.reloaded.length).toBe(1);
    // another client's edit
    t.sources[0]!.emit('edit', { revision: 7, action: 'apply', id: 7, chunks: ['top/0/2/0/0'] });
    expect(t.reloaded).toEqual([['top/0/1/0/0'], ['top/0/2/0/0']]);
    expect(t.ed.status()).toMatchObject({ revision: 7, inFlight: false, error: null, sent: 1 });
  });

  it('reloads everything on a hello that shows missed changes, and on resync', () => {
    const t = session(() => answer(1, []));
    t.ed.setPlanet(PLANET);
    t.sources[0]!.emit('hello', { revision: 5 });
    expect(t.reloadAlls()).toBe(0);
    t.sources[0]!.emit('hello', { revision: 7 }); // reconnected after missing two changes
    expect(t.reloadAlls()).toBe(1);
    t.sources[0]!.emit('resync', { revision: 9 });
    expect(t.reloadAlls()).toBe(2);
    expect(t.ed.status().revision).toBe(9);
    t.sources[0]!.emit('edit', { revision: 'nine' });
    expect(t.reloadAlls()).toBe(3);
    expect(t.ed.status().error).toMatch(/revision/);
  });

  it('stops sending after a 429 until Retry-After has passed, and says so', async () => {
    let status = 429;
    const t = session(() =>
      status === 429
        ? new Response(JSON.stringify({ error: 'too many edits' }), { status: 429, headers: { 'Retry-After': '2' } })
        : answer(6, ['top/0/0/0/0']),
    );
    t.ed.setPlanet(PLANET);
    t.ed.setTool('build');
    t.ed.press([0, 1900, 0]);
    t.ed.frame([0, 1900, 0]);
    await tick();
    await tick();
    expect(t.ed.status().error).toBe('Build refused: too many edits (429), wait 2 s: too many edits');
    // held and dragged: nothing is sent while blocked
    t.advance(500);
    t.ed.frame([0, 1900, 50]);
    t.ed.release();
    t.ed.press([0, 1900, 60]);
    expect(t.ed.status().notice).toMatch(/wait 2 s/);
    expect(t.posted.length).toBe(1);
    status = 200;
    t.advance(2000);
    t.ed.press([0, 1900, 70]);
    t.ed.frame([0, 1900, 70]);
    await tick();
    await tick();
    expect(t.posted.length).toBe(2);
    expect(t.ed.status().error).toBeNull();
  });

  it('undoes and redoes in order, noting when there is nothing to undo', async () => {
    const answers = [answer(6, ['a/0/0/0/0']), answer(6, [], null)];
    const t = session(() => answers.shift()!);
    t.ed.setPlanet(PLANET);
    const a = t.ed.undo();
    const b = t.ed.redo();
    await Promise.all([a, b]);
    expect(t.posted).toEqual(['POST api/v1/edits/undo?preset=earthlike&seed=7', 'POST api/v1/edits/redo?preset=earthlike&seed=7']);
    expect(t.reloaded).toEqual([['a/0/0/0/0']]);
    expect(t.ed.status()).toMatchObject({ notice: 'nothing to redo', inFlight: false, revision: 6 });
  });

  it('paints with the chosen material and clamps the radius to the server limits', async () => {
    const t = session(() => answer(6, []));
    t.ed.setPlanet(PLANET);
    t.ed.setTool('paint');
    t.ed.setMaterial('rock');
    t.ed.setRadius(500);
    t.ed.setStrength(0.25);
    await t.ed.apply([1, 2, 3]);
    expect(t.posted[0]).toBe(
      'POST api/v1/edits?preset=earthlike&seed=7 {"brush":"paint","x":1,"y":2,"z":3,"radius":64,"strength":0.25,"material":"rock"}',
    );
    t.ed.setMaterial('lava');
    expect(t.ed.status().settings.material).toBe('sand');
  });

  it('words each failure for the user', () => {
    const e = (status: number, msg: string | null, retry: number | null = null) =>
      new ApiError(`${status} X${msg ? `: ${msg}` : ''}`, status, 'api/v1/edits', retry, msg);
    expect(editErrorMessage('Dig', e(400, 'radius 99 is above 64'))).toBe('Dig refused (400): radius 99 is above 64');
    expect(editErrorMessage('Dig', e(403, 'no world'))).toBe('Dig refused: editing is off on this server (403): no world');
    expect(editErrorMessage('Dig', e(409, 'not the world'))).toBe("Dig refused: this planet is not the world's (409): not the world");
    expect(editErrorMessage('Undo', e(429, 'slow down', 3))).toBe('Undo refused: too many edits (429), wait 3 s: slow down');
    expect(editErrorMessage('Dig', e(500, 'disk full'))).toBe('Dig failed: the server could not save it, nothing changed (500): disk full');
    expect(editErrorMessage('Dig', e(502, null))).toBe('Dig refused (502): 502 X');
    expect(editErrorMessage('Dig', new ApiError('cannot reach the PMC server (TypeError)', 0, 'u'))).toBe(
      'Dig failed: cannot reach the PMC server (TypeError)',
    );
    expect(editErrorMessage('Redo', new Error('boom'))).toBe('Redo failed: boom');
  });
});
