// The Path tool's click state machine against a fake fetch through the real API client: start,
// goal, the path found (waypoints in the planet frame), no path (an answer, not an error), errors
// with the server's message, starting over, Esc, and asking again after an edit.

import { describe, expect, it } from 'vitest';
import { PmcApi } from '../src/api';
import { positionFromLatLon, type V3 } from '../src/frames';
import { pathEndOf } from '../src/navOverlay';
import { PathTool, pathMessage } from '../src/pathTool';

const DATUM = 1884.8;
const json = (body: unknown, status = 200): Response =>
  new Response(JSON.stringify(body), { status, headers: { 'Content-Type': 'application/json' } });

const FOUND = {
  format: 'pmc-path', version: 1, found: true, revision: 0,
  length: 23.5, steps: 2, component: 0, expanded: 3,
  waypoints: [
    { lat: -10, lon: 8, alt: 52.5 },
    { lat: -10.3, lon: 8, alt: 50 },
    { lat: -10.6, lon: 8.1, alt: 48.25 },
  ],
};
/** FOUND with its smoothed form (spec 1.3): one straight leg, drawn through a point between. */
const SMOOTHED = {
  ...FOUND,
  smoothed: {
    length: 21.25, legs: 1,
    waypoints: [FOUND.waypoints[0], FOUND.waypoints[2]],
    line: [FOUND.waypoints[0], { lat: -10.3, lon: 8.05, alt: 50.4 }, FOUND.waypoints[2]],
  },
};
const NONE = {
  format: 'pmc-path', version: 1, found: false, revision: 0,
  reason: 'the two ends lie in different components of the grid (detached grids)', components: [0, 457], waypoints: [],
};

interface Pending {
  url: string;
  resolve: (r: Response) => void;
  reject: (e: unknown) => void;
  aborted: boolean;
}

/**
 * A fetch whose answers the test gives by hand, in any order. `honourAbort` false: an aborted
 * request still answers (as a slow server's answer may race the abort).
 */
function manualFetch(honourAbort = true) {
  const calls: Pending[] = [];
  const fetchFn = (url: string, init?: RequestInit): Promise<Response> =>
    new Promise((resolve, reject) => {
      const p: Pending = { url, resolve, reject, aborted: false };
      init?.signal?.addEventListener('abort', () => {
        p.aborted = true;
        if (honourAbort) reject(new DOMException('aborted', 'AbortError'));
      });
      calls.push(p);
    });
  return { calls, fetchFn };
}

const flush = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

function setup(honourAbort = true) {
  const f = manualFetch(honourAbort);
  const api = new PmcApi('api/v1', f.fetchFn);
  let changes = 0;
  const tool = new PathTool({
    fetchPath: (from, to, signal) => api.path({ preset: 'earthlike', seed: '7' }, from, to, signal),
    onChange: () => changes++,
  });
  tool.setPlanet(DATUM);
  return { tool, f, changes: () => changes };
}

const A: V3 = positionFromLatLon(-10, 8, DATUM + 52.5);
const B: V3 = positionFromLatLon(-10.6, 8.1, DATUM + 48.25);
const C: V3 = positionFromLatLon(-9, 7, DATUM - 20); // under the datum: a cave floor

describe('PathTool', () => {
  it('first click: the start; second: the goal, and the path is asked with LAT,LON,ALT of both', async () => {
    const { tool, f, changes } = setup();
    expect(tool.status().phase).toBe('empty');
    expect(tool.status().message).toBe('click the terrain to set the start of a path');
    tool.click(A);
    let s = tool.status();
    expect(s.phase).toBe('start');
    expect(s.from!.query).toBe('-10.000000000,8.000000000,52.500');
    expect(s.from!.point).toEqual(A);
    expect(s.to).toBeNull();
    expect(s.message).toBe('path start set (-10.0000°, 8.0000°): click the goal');
    expect(f.calls.length).toBe(0);
    tool.click(B);
    s = tool.status();
    expect(s.phase).toBe('loading');
    expect(s.message).toBe('finding the path…');
    expect(f.calls.map((c) => c.url)).toEqual([
      'api/v1/path?preset=earthlike&seed=7&from=-10.000000000%2C8.000000000%2C52.500&to=-10.600000000%2C8.100000000%2C48.250',
    ]);
    f.calls[0]!.resolve(json(FOUND));
    await flush();
    s = tool.status();
    expect(s.phase).toBe('found');
    expect([s.length, s.steps, s.reason, s.error, s.revision, s.requests]).toEqual([23.5, 2, null, null, 0, 1]);
    expect(s.message).toBe('path: 23.5 m, 2 steps');
    // waypoints in the planet frame: datum + alt along lat/lon
    expect(s.waypoints.length).toBe(3);
    const w0 = pathEndOf(s.waypoints[0]!, DATUM);
    expect([w0.lat, w0.lon]).toEqual([expect.closeTo(-10, 9), expect.closeTo(8, 9)]);
    expect(w0.alt).toBeCloseTo(52.5, 9);
    // without a smoothed form, the walk is what is drawn
    expect([s.smoothed, s.line]).toEqual([null, s.waypoints]);
    expect(changes()).toBeGreaterThanOrEqual(3);
  });

  it('a path with a smoothed form shows its length and legs and draws its line', async () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(B);
    f.calls[0]!.resolve(json(SMOOTHED));
    await flush();
    const s = tool.status();
    expect([s.phase, s.length, s.steps, s.smoothed]).toEqual(['found', 23.5, 2, { length: 21.25, legs: 1 }]);
    expect(s.message).toBe('path: 21.3 m in 1 straight leg (grid walk 23.5 m, 2 steps)');
    expect([s.waypoints.length, s.line.length]).toEqual([3, 3]);
    const mid = pathEndOf(s.line[1]!, DATUM);
    expect([mid.lat, mid.lon, mid.alt]).toEqual([expect.closeTo(-10.3, 9), expect.closeTo(8.05, 9), expect.closeTo(50.4, 9)]);
    // a 1.2 answer (no line) draws the corners
    tool.refresh();
    const { line: _l, ...older } = SMOOTHED.smoothed;
    f.calls[1]!.resolve(json({ ...SMOOTHED, smoothed: older }));
    await flush();
    expect(tool.status().line.length).toBe(2);
  });

  it('a smoothed form without a length or with a bad point is a malformed answer', async () => {
    for (const smoothed of [{ ...SMOOTHED.smoothed, length: null }, { ...SMOOTHED.smoothed, line: [{ lat: 1, lon: 2 }] }]) {
      const { tool, f } = setup();
      tool.click(A);
      tool.click(B);
      f.calls[0]!.resolve(json({ ...SMOOTHED, smoothed }));
      await flush();
      const s = tool.status();
      expect([s.phase, s.waypoints.length, s.line.length]).toEqual(['error', 0, 0]);
      expect(s.error).toMatch(/unexpected answer from api\/v1\/path/);
    }
  });

  it('a click in a cave sends the cave floor\'s altitude (below the datum)', () => {
    const { tool, f } = setup();
    tool.click(C);
    tool.click(A);
    expect(decodeURIComponent(f.calls[0]!.url)).toContain('from=-9.000000000,7.000000000,-20.000&');
  });

  it('no path is an answer: the reason is shown, no waypoints, no error', async () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(B);
    f.calls[0]!.resolve(json(NONE));
    await flush();
    const s = tool.status();
    expect([s.phase, s.reason, s.error, s.waypoints.length, s.length]).toEqual(['none', NONE.reason, null, 0, null]);
    expect(s.message).toBe(`no path: ${NONE.reason}`);
  });

  it('a 4xx or 5xx shows the server\'s message with the status', async () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(B);
    f.calls[0]!.resolve(json({ error: 'from=91,0: latitude must be within [-90, 90]; give LAT,LON or LAT,LON,ALT (degrees, metres)' }, 400));
    await flush();
    let s = tool.status();
    expect(s.phase).toBe('error');
    expect(s.error).toBe('the path request failed (400): from=91,0: latitude must be within [-90, 90]; give LAT,LON or LAT,LON,ALT (degrees, metres)');
    expect(s.message).toBe(s.error);
    expect(s.waypoints).toEqual([]);
    // a 500 without JSON, then a network failure
    tool.click(A);
    tool.click(B);
    f.calls[1]!.resolve(new Response('boom', { status: 500, statusText: 'Internal Server Error' }));
    await flush();
    expect(tool.status().error).toBe('the path request failed (500): 500 Internal Server Error');
    tool.click(A);
    tool.click(B);
    f.calls[2]!.reject(new TypeError('Failed to fetch'));
    await flush();
    expect(tool.status().error).toBe('the path request failed: cannot reach the PMC server (TypeError: Failed to fetch)');
  });

  it('a found path without waypoints is a malformed answer', async () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(B);
    f.calls[0]!.resolve(json({ ...FOUND, waypoints: [] }));
    await flush();
    expect(tool.status().phase).toBe('error');
    expect(tool.status().error).toMatch(/unexpected answer from api\/v1\/path.*without waypoints/);
  });

  it('a third click starts over: the old request is dropped, a late answer ignored', async () => {
    const { tool, f } = setup(false);
    tool.click(A);
    tool.click(B);
    tool.click(C); // while the path is asked
    expect(f.calls[0]!.aborted).toBe(true);
    f.calls[0]!.resolve(json(FOUND));
    await flush();
    let s = tool.status();
    expect(s.phase).toBe('start');
    expect(s.from!.point).toEqual(C);
    expect([s.to, s.waypoints.length]).toEqual([null, 0]);
    tool.click(A);
    f.calls[1]!.resolve(json(FOUND));
    await flush();
    expect(tool.status().phase).toBe('found');
    tool.click(B); // after an answer: the new start
    s = tool.status();
    expect([s.phase, s.from!.point, s.to, s.waypoints.length, s.length]).toEqual(['start', B, null, 0, null]);
  });

  it('a click on no terrain says so and changes nothing', () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(null);
    const s = tool.status();
    expect(s.phase).toBe('start');
    expect(s.notice).toBe('no terrain under the cursor (loaded chunks only)');
    expect(s.message).toMatch(/^no terrain under the cursor \(loaded chunks only\) · path start set/);
    tool.click([Number.NaN, 0, 0]);
    expect(tool.status().phase).toBe('start');
    expect(f.calls.length).toBe(0);
  });

  it('Esc clears everything and cancels the request; a new planet too', async () => {
    const { tool, f } = setup();
    tool.click(A);
    tool.click(B);
    expect(tool.clear()).toBe(true);
    expect(f.calls[0]!.aborted).toBe(true);
    const s = tool.status();
    expect([s.phase, s.from, s.to, s.waypoints.length, s.error]).toEqual(['empty', null, null, 0, null]);
    expect(tool.clear()).toBe(false); // nothing left
    tool.click(A);
    tool.setPlanet(1000);
    expect(tool.status().phase).toBe('empty');
    tool.click(positionFromLatLon(1, 2, 1010));
    expect(tool.status().from!.alt).toBeCloseTo(10, 9);
    await flush();
  });

  it('after an edit it asks again, showing the old path until the new answer', async () => {
    const { tool, f } = setup();
    expect(tool.refresh()).toBe(false); // no ends
    tool.click(A);
    expect(tool.refresh()).toBe(false); // no goal yet
    tool.click(B);
    f.calls[0]!.resolve(json(FOUND));
    await flush();
    const v = tool.version;
    expect(tool.refresh()).toBe(true);
    let s = tool.status();
    expect([s.phase, s.refreshing, s.waypoints.length]).toEqual(['found', true, 3]);
    expect(s.message).toBe('path: 23.5 m, 2 steps (updating)');
    expect(tool.version).toBe(v); // nothing to redraw yet
    expect(f.calls[1]!.url).toBe(f.calls[0]!.url);
    f.calls[1]!.resolve(json({ ...FOUND, revision: 4, length: 30, steps: 1, waypoints: FOUND.waypoints.slice(1) }));
    await flush();
    s = tool.status();
    expect([s.phase, s.refreshing, s.waypoints.length, s.length, s.revision]).toEqual(['found', false, 2, 30, 4]);
    expect(s.message).toBe('path: 30.0 m, 1 step');
    expect(tool.version).toBe(v + 1);
    // the edit cut the way
    tool.refresh();
    f.calls[2]!.resolve(json({ ...NONE, revision: 5 }));
    await flush();
    s = tool.status();
    expect([s.phase, s.waypoints.length, s.revision]).toEqual(['none', 0, 5]);
  });

  it('messages for every phase', () => {
    const base = { from: null, to: null, length: null, steps: null, smoothed: null, reason: null, error: null, waypoints: [], line: [], revision: null, refreshing: false, notice: null, requests: 0 };
    expect(pathMessage({ ...base, phase: 'found', length: 1234.5, steps: 100 })).toBe('path: 1.23 km, 100 steps');
    expect(pathMessage({ ...base, phase: 'found', length: 1234.5, steps: 100, smoothed: { length: 1100, legs: 3 } })).toBe(
      'path: 1.10 km in 3 straight legs (grid walk 1.23 km, 100 steps)',
    );
    expect(pathMessage({ ...base, phase: 'none', reason: null })).toBe('no path: no reason given');
    expect(pathMessage({ ...base, phase: 'error', error: null })).toBe('the path request failed');
  });
});
