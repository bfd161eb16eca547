import { describe, expect, it } from 'vitest';
import { ApiError, PmcApi } from '../src/api';

interface Call {
  url: string;
  method: string;
  headers: Record<string, string>;
  body: string | null;
}

/** A fetch that records calls and answers with `reply(call)`. */
function fakeFetch(reply: (c: Call) => Response) {
  const calls: Call[] = [];
  const fetchFn = async (url: string, init?: RequestInit): Promise<Response> => {
    const c: Call = {
      url,
      method: init?.method ?? 'GET',
      headers: Object.fromEntries(new Headers(init?.headers).entries()),
      body: typeof init?.body === 'string' ? init.body : null,
    };
    calls.push(c);
    return reply(c);
  };
  return { calls, fetchFn };
}

const json = (body: unknown, status = 200, headers: Record<string, string> = {}): Response =>
  new Response(JSON.stringify(body), { status, headers: { 'Content-Type': 'application/json', ...headers } });

const ANSWER = { id: 11, revision: 13, active: 11, redo: 0, chunks: ['top/0/3/4/1', 'top/0/3/4/0'] };

describe('PmcApi editing', () => {
  it('POSTs an edit as JSON, naming the planet shown', async () => {
    const f = fakeFetch(() => json(ANSWER));
    const api = new PmcApi('api/v1', f.fetchFn);
    const a = await api.postEdit(
      { brush: 'remove', x: 812.5, y: 1650, z: 402.1, radius: 4, strength: 1 },
      { preset: 'earthlike', seed: '7' },
    );
    expect(a).toEqual(ANSWER);
    expect(f.calls).toEqual([
      {
        url: 'api/v1/edits?preset=earthlike&seed=7',
        method: 'POST',
        headers: { 'content-type': 'application/json' },
        body: '{"brush":"remove","x":812.5,"y":1650,"z":402.1,"radius":4,"strength":1}',
      },
    ]);
  });

  it('undoes, redoes and lists', async () => {
    const f = fakeFetch((c) => {
      if (c.url.startsWith('api/v1/edits/undo')) return json({ ...ANSWER, revision: 14, active: 10, redo: 1, chunks: ['top/0/3/4/1'] });
      if (c.url.startsWith('api/v1/edits/redo')) return json({ id: null, revision: 14, active: 10, redo: 0, chunks: [] });
      return json({
        revision: 14, active: 1, redo: 0,
        edits: [{ id: 1, brush: 'remove', center: [1, 2, 3], radius: 4, strength: 1, material: null, active: true }],
      });
    });
    const api = new PmcApi('api/v1', f.fetchFn);
    expect((await api.undo()).redo).toBe(1);
    expect(await api.redo()).toEqual({ id: null, revision: 14, active: 10, redo: 0, chunks: [] });
    const list = await api.listEdits();
    expect(list.edits[0]!.center).toEqual([1, 2, 3]);
    expect(f.calls.map((c) => `${c.method} ${c.url} ${c.body}`)).toEqual([
      'POST api/v1/edits/undo null',
      'POST api/v1/edits/redo null',
      'GET api/v1/edits null',
    ]);
    expect(api.eventsUrl()).toBe('api/v1/events');
  });

  it.each([
    [400, 'brush "explode" is not one of add, remove, smooth, flatten, paint', null],
    [403, 'editing needs a world: start pmc serve --world FILE', null],
    [409, 'the planet moon/7 is not the world\'s planet earthlike/7', null],
    [429, 'too many edits: at most 20 per second', '2'],
    [500, 'cannot write the world file: disk full', null],
  ])('surfaces a %i with the server message', async (status, message, retryAfter) => {
    const f = fakeFetch(() => json({ error: message }, status, retryAfter ? { 'Retry-After': retryAfter } : {}));
    const api = new PmcApi('api/v1', f.fetchFn);
    const e = await api.postEdit({ brush: 'add', x: 0, y: 0, z: 0, radius: 4 }).then(
      () => null,
      (err: unknown) => err,
    );
    expect(e).toBeInstanceOf(ApiError);
    const err = e as ApiError;
    expect(err.status).toBe(status);
    expect(err.serverMessage).toBe(message);
    expect(err.message).toContain(message);
    expect(err.message.startsWith(String(status))).toBe(true);
    expect(err.retryAfter).toBe(retryAfter === null ? null : Number(retryAfter));
    expect(err.rateLimited).toBe(status === 429);
    expect(err.transient).toBe(false);
  });

  it('keeps the status line of an error without JSON, and reports a network failure as status 0', async () => {
    const api = new PmcApi('api/v1', fakeFetch(() => new Response('oops', { status: 502, statusText: 'Bad Gateway' })).fetchFn);
    const e = (await api.undo().catch((x: unknown) => x)) as ApiError;
    expect(e.status).toBe(502);
    expect(e.message).toBe('502 Bad Gateway');
    expect(e.serverMessage).toBeNull();
    const down = new PmcApi('api/v1', async () => {
      throw new TypeError('Failed to fetch');
    });
    const e2 = (await down.redo().catch((x: unknown) => x)) as ApiError;
    expect(e2.status).toBe(0);
    expect(e2.message).toMatch(/cannot reach the PMC server/);
  });

  it('refuses an answer of the wrong shape', async () => {
    const api = new PmcApi('api/v1', fakeFetch(() => json({ ok: true })).fetchFn);
    await expect(api.postEdit({ brush: 'add', x: 0, y: 0, z: 0, radius: 4 })).rejects.toThrow(/unexpected answer/);
    await expect(api.listEdits()).rejects.toThrow(/no revision or edits/);
  });

  it('types the edit object of /planet', async () => {
    const planet = {
      format: 'pmc-planet', version: 1, preset: 'earthlike', seed: '7', presets: [],
      layout: { n_c: 8, n_t: 32, d_b: 1744, l_d: 4, d_c: 2 }, radius: 2000, base_radius: 1744,
      sea_radius: null, surface_bounds: null, chunk_count: 768, face_tiles: 256, depth_tiles: 64,
      faces: [], materials: ['sand'], palette: { a: [1, 1, 1], b: [0, 0, 0] },
      edit: { enabled: false, reason: 'no world', brushes: ['add'] },
    };
    const api = new PmcApi('api/v1', fakeFetch(() => json(planet)).fetchFn);
    const info = await api.planet();
    expect(info.edit?.enabled).toBe(false);
    if (info.edit && !info.edit.enabled) expect(info.edit.reason).toBe('no world');
  });
});
