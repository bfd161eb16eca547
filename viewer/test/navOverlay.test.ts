// The navigation overlay's pure side: component colours, the typed arrays built from a
// `/navgrid` answer, path ends <-> planet frame, what to fetch and when, and the loader against a
// fake fetch (through the real API client).

import { describe, expect, it } from 'vitest';
import { PmcApi, type NavGridAnswer } from '../src/api';
import { TOOLS } from '../src/editTools';
import { length, positionFromLatLon, type V3 } from '../src/frames';
import { BOUND_KEYS } from '../src/input';
import {
  MAIN_COLOUR,
  NavGridLoader,
  PATH_COLOUR,
  buildNavOverlay,
  colourDistance,
  colourHex,
  componentColour,
  formatPathEnd,
  groundPoint,
  mainComponent,
  navRange,
  needsRefetch,
  pathEndOf,
  pointOfEnd,
  srgbToLinear,
  type NavQuery,
} from '../src/navOverlay';
import { PATH_TOOL } from '../src/pathTool';

const json = (body: unknown, status = 200): Response =>
  new Response(JSON.stringify(body), { status, headers: { 'Content-Type': 'application/json' } });

/** A small answer: main component 0 (3 nodes of a 10-node planet, 6 in component 0), a detached pair (label 5). */
function answer(over: Partial<NavGridAnswer> = {}): NavGridAnswer {
  return {
    revision: 3,
    origin: [0, 2000, 0],
    positions: [0, 0, 0, 10, 0, 0, 0, 0, 10, 5, 1, 5, 6, 1, 5],
    components: [0, 0, 0, 5, 5],
    component_sizes: [8, 8, 8, 2, 2],
    edges: [0, 1, 0, 2, 3, 4],
    truncated: false,
    total_nodes: 10,
    total_components: 2,
    ...over,
  };
}

describe('component colours', () => {
  it('are deterministic per label and bright', () => {
    for (const label of [0, 1, 7, 123, 4_000_000_000]) {
      expect(componentColour(label)).toEqual(componentColour(label));
      const c = componentColour(label);
      expect(Math.max(...c)).toBeCloseTo(1, 9); // full value
      expect(Math.max(...c) - Math.min(...c)).toBeGreaterThan(0.75); // saturated
    }
  });

  it('differ between neighbouring labels, and from the main grid and the path', () => {
    for (let start = 0; start < 500; start++) {
      const cs = Array.from({ length: 8 }, (_, k) => componentColour(start + k));
      for (let i = 0; i < cs.length; i++) {
        expect(colourDistance(cs[i]!, MAIN_COLOUR)).toBeGreaterThan(0.35);
        expect(colourDistance(cs[i]!, PATH_COLOUR)).toBeGreaterThan(0.2);
        for (let j = i + 1; j < cs.length; j++) expect(colourDistance(cs[i]!, cs[j]!)).toBeGreaterThan(0.2);
      }
    }
    // many labels: many different colours
    expect(new Set(Array.from({ length: 64 }, (_, k) => colourHex(componentColour(k)))).size).toBe(64);
  });

  it('the main grid is calm (little saturation) and hex-formatted', () => {
    expect(Math.max(...MAIN_COLOUR) - Math.min(...MAIN_COLOUR)).toBeLessThan(0.35);
    expect(colourHex(MAIN_COLOUR)).toBe('#8fbddb');
    expect(colourHex([1, 0, 0.5])).toBe('#ff0080');
    expect(srgbToLinear(1)).toBeCloseTo(1, 12);
    expect(srgbToLinear(0.5)).toBeCloseTo(0.214, 3);
    expect(srgbToLinear(0.02)).toBeCloseTo(0.02 / 12.92, 12);
  });

  it('the main component is the one with at least half the planet, else none', () => {
    expect(mainComponent(answer())).toBe(0);
    expect(mainComponent(answer({ total_nodes: 100 }))).toBeNull();
    expect(mainComponent(answer({ components: [4, 4, 4, 9, 9], component_sizes: [2, 2, 2, 5, 5] }))).toBe(9);
    expect(mainComponent(answer({ positions: [], components: [], component_sizes: [], edges: [] }))).toBeNull();
  });
});

describe('buildNavOverlay', () => {
  it('lifts every node along its local up, relative to the origin, coloured by component', () => {
    const a = answer();
    const d = buildNavOverlay(a, 0.5);
    expect(d.count).toBe(5);
    expect(d.origin).toEqual([0, 2000, 0]);
    for (let i = 0; i < 5; i++) {
      const p: V3 = [a.origin[0] + a.positions[3 * i]!, a.origin[1] + a.positions[3 * i + 1]!, a.origin[2] + a.positions[3 * i + 2]!];
      const q: V3 = [d.origin[0] + d.positions[3 * i]!, d.origin[1] + d.positions[3 * i + 1]!, d.origin[2] + d.positions[3 * i + 2]!];
      expect(length(q) - length(p)).toBeCloseTo(0.5, 3); // 0.5 m further from the centre
      const dir = (v: V3): V3 => v.map((x) => x / length(v)) as V3;
      for (let k = 0; k < 3; k++) expect(dir(q)[k]).toBeCloseTo(dir(p)[k]!, 6); // straight up
    }
    expect(Array.from(d.positions.slice(0, 3))).toEqual([0, 0.5, 0]);
    // colours: linear RGB of the main colour and of component 5's
    const lin = (c: number[]): number[] => c.map(srgbToLinear);
    for (let k = 0; k < 3; k++) {
      expect(d.colours[3 * 0 + k]).toBeCloseTo(lin(MAIN_COLOUR)[k]!, 6);
      expect(d.colours[3 * 3 + k]).toBeCloseTo(lin(componentColour(5))[k]!, 6);
      expect(d.colours[3 * 4 + k]).toBeCloseTo(lin(componentColour(5))[k]!, 6);
    }
    expect(Array.from(d.labels)).toEqual([0, 0, 0, 5, 5]);
    expect(Array.from(d.edges)).toEqual([0, 1, 0, 2, 3, 4]);
    expect(Array.from(d.mainNodes)).toEqual([0, 1, 2]);
    expect(Array.from(d.otherNodes)).toEqual([3, 4]);
    expect(d.main).toBe(0);
    expect(d.components).toEqual([
      { label: 0, size: 8, nodes: 3, main: true, colour: MAIN_COLOUR, hex: '#8fbddb' },
      { label: 5, size: 2, nodes: 2, main: false, colour: componentColour(5), hex: colourHex(componentColour(5)) },
    ]);
    expect([d.revision, d.totalNodes, d.totalComponents, d.truncated]).toEqual([3, 10, 2, false]);
  });

  it('without a main component every component is bright, biggest in view first', () => {
    const d = buildNavOverlay(answer({ total_nodes: 1000 }));
    expect(d.main).toBeNull();
    expect(d.mainNodes.length).toBe(0);
    expect(Array.from(d.otherNodes)).toEqual([0, 1, 2, 3, 4]);
    expect(d.components.map((c) => [c.label, c.nodes, c.main])).toEqual([[0, 3, false], [5, 2, false]]);
    expect(d.components[0]!.colour).toEqual(componentColour(0));
  });

  it('keeps f32 offsets small at Earth radius (floating origin)', () => {
    const R = 6.371e6;
    const d = buildNavOverlay(answer({ origin: [0, R, 0] }), 0.25);
    expect(Array.from(d.positions.slice(0, 3))).toEqual([0, 0.25, 0]);
    expect(d.positions[3]).toBeCloseTo(10, 4);
  });

  it('rejects an edge naming no node of the answer, and mismatched lists', () => {
    expect(() => buildNavOverlay(answer({ edges: [0, 5] }))).toThrow(/edge end 5/);
    expect(() => buildNavOverlay(answer({ edges: [0, 1, 2] }))).toThrow(/odd/);
    expect(() => buildNavOverlay(answer({ components: [0, 0, 0, 5] }))).toThrow(/positions/);
  });
});

describe('path ends', () => {
  it('round-trip between the planet frame and lat, lon, alt above the datum', () => {
    const datum = 1884.8;
    for (const [lat, lon, alt] of [[-10, 8, 52.5], [89.9, -170, -30], [0, 180, 0.001], [-45.123456789, 0, 115]] as const) {
      const p = positionFromLatLon(lat, lon, datum + alt);
      const e = pathEndOf(p, datum);
      expect(e.lat).toBeCloseTo(lat, 9);
      expect(e.lon).toBeCloseTo(lon, 9);
      expect(e.alt).toBeCloseTo(alt, 6);
      const q = pointOfEnd(e, datum);
      for (let k = 0; k < 3; k++) expect(q[k]).toBeCloseTo(p[k]!, 6);
    }
    // longitude 0 on +Z, 90 E on +X, latitude from +Y
    expect(pathEndOf([0, 0, 2000], 1900)).toEqual({ lat: 0, lon: 0, alt: 100 });
    const east = pathEndOf([2000, 0, 0], 2000);
    expect([east.lat, east.lon, east.alt]).toEqual([0, 90, 0]);
    expect(pathEndOf([0, 1950, 0], 2000).lat).toBe(90);
  });

  it('are formatted as LAT,LON[,ALT] for /path', () => {
    expect(formatPathEnd({ lat: -10.116438786, lon: 7.9795, alt: 52.50729 })).toBe('-10.116438786,7.979500000,52.507');
    expect(formatPathEnd({ lat: 12, lon: 40, alt: null })).toBe('12.000000000,40.000000000');
    expect(formatPathEnd({ lat: -1e-12, lon: -0, alt: -0.0001 })).toBe('0.000000000,0.000000000,0.000');
  });
});

describe('what to fetch', () => {
  it('the range grows with the height, within a few hundred metres to 3 km', () => {
    expect(navRange(0)).toBe(250);
    expect(navRange(2)).toBe(250);
    expect(navRange(120)).toBe(450);
    expect(navRange(1e6)).toBe(3000);
    expect(navRange(Number.NaN)).toBe(250);
  });

  it('the ground point is under the camera: measured, else on the datum', () => {
    const cam: V3 = [0, 0, 2100];
    expect(groundPoint(cam, 80, 1900)).toEqual([0, 0, 2020]);
    expect(groundPoint(cam, null, 1900)).toEqual([0, 0, 1900]);
  });

  it('refetches for another planet or revision, a move of a third of the range, a range changed by half', () => {
    const shown: NavQuery = { planet: 'earthlike/7', centre: [0, 0, 2000], range: 300, revision: 2 };
    const want = (o: Partial<NavQuery>): NavQuery => ({ ...shown, ...o });
    expect(needsRefetch(null, shown)).toBe(true);
    expect(needsRefetch(shown, want({}))).toBe(false);
    expect(needsRefetch(shown, want({ centre: [99, 0, 2000] }))).toBe(false);
    expect(needsRefetch(shown, want({ centre: [101, 0, 2000] }))).toBe(true);
    expect(needsRefetch(shown, want({ revision: 3 }))).toBe(true);
    expect(needsRefetch(shown, want({ planet: 'moon/7' }))).toBe(true);
    expect(needsRefetch(shown, want({ range: 440 }))).toBe(false);
    expect(needsRefetch(shown, want({ range: 460 }))).toBe(true);
    expect(needsRefetch(shown, want({ range: 190 }))).toBe(true);
  });

  it('the Path tool key (7) and the nav grid key (N) clash with no other key', () => {
    for (const code of [PATH_TOOL.code, 'KeyN']) {
      expect(BOUND_KEYS.has(code)).toBe(false);
      expect(TOOLS.some((t) => t.code === code)).toBe(false);
    }
  });
});

/** A fetch answering /navgrid with `reply`, recording the URLs; `hold` keeps answers until released. */
function fakeServer(reply: (url: string) => Response) {
  const urls: string[] = [];
  const pending: (() => void)[] = [];
  let hold = false;
  const fetchFn = (url: string, init?: RequestInit): Promise<Response> => {
    urls.push(url);
    return new Promise((resolve, reject) => {
      const go = (): void => resolve(reply(url));
      init?.signal?.addEventListener('abort', () => reject(new DOMException('aborted', 'AbortError')));
      if (hold) pending.push(go);
      else go();
    });
  };
  return {
    urls,
    fetchFn,
    hold(on: boolean) {
      hold = on;
    },
    release() {
      for (const p of pending.splice(0)) p();
    },
  };
}

const flush = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

function loaderWith(server: ReturnType<typeof fakeServer>, clock = { t: 0 }) {
  const api = new PmcApi('api/v1', server.fetchFn);
  let changes = 0;
  const loader = new NavGridLoader({
    fetchGrid: (at, range, signal) => api.navgrid({ preset: 'earthlike', seed: '7' }, at, range, 20_000, signal),
    now: () => clock.t,
    onChange: () => changes++,
    retryMs: 5000,
  });
  return { loader, clock, changes: () => changes };
}

describe('NavGridLoader', () => {
  const q = (o: Partial<NavQuery> = {}): NavQuery => ({ planet: 'earthlike/7', centre: [0, 0, 2000], range: 300, revision: 0, ...o });

  it('fetches when on, around the ground point, and again only when due', async () => {
    const server = fakeServer(() => json(answer()));
    const { loader } = loaderWith(server);
    loader.update(q());
    expect(server.urls).toEqual([]); // off: nothing
    loader.setEnabled(true);
    loader.update(q());
    await flush();
    expect(server.urls).toEqual(['api/v1/navgrid?preset=earthlike&seed=7&x=0&y=0&z=2000&range=300&limit=20000']);
    const st = loader.status();
    expect([st.enabled, st.loading, st.nodes, st.edges, st.main, st.error, st.fetches]).toEqual([true, false, 5, 3, 0, null, 1]);
    expect(loader.overlay()!.count).toBe(5);
    const v = loader.version;
    loader.update(q({ centre: [50, 0, 2000] })); // less than a third of the range
    await flush();
    expect(server.urls.length).toBe(1);
    loader.update(q({ centre: [150, 0, 2000] }));
    await flush();
    expect(server.urls.length).toBe(2);
    expect(loader.version).toBe(v + 1);
    loader.update(q({ centre: [150, 0, 2000], revision: 1 })); // an edit landed
    await flush();
    expect(server.urls.length).toBe(3);
  });

  it('one request at a time; off cancels it and drops the overlay', async () => {
    const server = fakeServer(() => json(answer()));
    const { loader } = loaderWith(server);
    loader.setEnabled(true);
    server.hold(true);
    loader.update(q());
    loader.update(q({ centre: [500, 0, 2000] }));
    expect(server.urls.length).toBe(1);
    expect(loader.status().loading).toBe(true);
    loader.setEnabled(false);
    server.release();
    await flush();
    const st = loader.status();
    expect([st.enabled, st.loading, st.nodes, st.error]).toEqual([false, false, 0, null]);
    expect(loader.overlay()).toBeNull();
  });

  it('shows the server error, and asks again after a move or the retry time', async () => {
    let fail = true;
    const server = fakeServer(() => (fail ? json({ error: 'range must be above 0 metres, got 0' }, 400) : json(answer())));
    const { loader, clock } = loaderWith(server);
    loader.setEnabled(true);
    loader.update(q());
    await flush();
    expect(loader.status().error).toBe('the navigation grid request failed (400): range must be above 0 metres, got 0');
    expect(loader.overlay()).toBeNull();
    clock.t = 1000;
    loader.update(q());
    await flush();
    expect(server.urls.length).toBe(1); // same place, too soon
    loader.update(q({ centre: [200, 0, 2000] }));
    await flush();
    expect(server.urls.length).toBe(2); // moved
    clock.t = 7000;
    fail = false;
    loader.update(q({ centre: [200, 0, 2000] }));
    await flush();
    expect(server.urls.length).toBe(3); // retry time passed
    expect(loader.status().error).toBeNull();
    expect(loader.status().nodes).toBe(5);
  });

  it('a malformed answer is an error, not a crash', async () => {
    const server = fakeServer(() => json({ ...answer(), edges: [0, 9] }));
    const { loader } = loaderWith(server);
    loader.setEnabled(true);
    loader.update(q());
    await flush();
    expect(loader.status().error).toMatch(/^the navigation grid request failed: unexpected answer from api\/v1\/navgrid.*edge end 9/);
  });

  it('reset (another planet) drops the overlay and fetches anew', async () => {
    const server = fakeServer(() => json(answer()));
    const { loader } = loaderWith(server);
    loader.setEnabled(true);
    loader.update(q());
    await flush();
    loader.reset();
    expect(loader.overlay()).toBeNull();
    expect(loader.enabled).toBe(true);
    loader.update(q());
    await flush();
    expect(server.urls.length).toBe(2);
  });
});
