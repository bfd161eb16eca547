import { describe, expect, it } from 'vitest';
import { chunkName } from '../src/chunkSelection';
import { pack, unpack } from '../src/lod/runner';
import { selectLod, sphereInFrustum, type LodSelection, type LodView, type Plane } from '../src/lod/select';
import { LodSelector, planesToPlanetFrame, sameView, type SelectionResult, type ViewState } from '../src/lodSelector';
import { chunkServer, ERRORS, holes, LAYOUT, overlaps, streamerOn, tick } from './lodFixture';

const PLANET = { layout: { n_c: 4, n_t: 4, d_b: 100, l_d: 1, d_c: 1 }, errors: ERRORS, occluder: 0 };
const PARAMS = { maxPixelError: 2, finestLevel: 0, maxChunks: 1000 };
const viewAt = (y: number): LodView => ({ eye: [0, y, 0], frustum: null, viewportHeightPx: 600, fovY: 1 });

function selector() {
  const results: SelectionResult[] = [];
  const errors: string[] = [];
  const sel = new LodSelector(null, (r) => results.push(r), (m) => errors.push(m));
  return { sel, results, errors };
}

describe('LodSelector', () => {
  it('selects one view at a time, off the calling stack, and answers with the rule\'s selection', async () => {
    const { sel, results } = selector();
    sel.setPlanet(PLANET);
    expect(sel.request(viewAt(150), PARAMS)).toBe(true);
    expect(sel.busy).toBe(true);
    expect(sel.request(viewAt(160), PARAMS)).toBe(false);
    expect(results).toEqual([]);
    await tick();
    expect(sel.busy).toBe(false);
    expect(results.length).toBe(1);
    const direct = selectLod(LAYOUT, ERRORS, 0, viewAt(150), PARAMS);
    expect(results[0]!.selection).toEqual(direct);
    expect(results[0]!.view.eye).toEqual([0, 150, 0]);
  });

  it('drops the answer of a selection made for the previous planet', async () => {
    const { sel, results } = selector();
    sel.setPlanet(PLANET);
    sel.request(viewAt(150), PARAMS);
    sel.setPlanet({ ...PLANET, errors: [0, 2, 4] });
    await tick();
    expect(results).toEqual([]);
    expect(sel.busy).toBe(false);
  });

  it('reports a view the rule refuses', async () => {
    const { sel, results, errors } = selector();
    sel.setPlanet(PLANET);
    sel.request({ ...viewAt(150), fovY: 4 }, PARAMS);
    await tick();
    expect(results).toEqual([]);
    expect(errors[0]).toMatch(/level-of-detail selection: bad field of view/);
  });

  it('packs a selection into seven numbers a chunk and back', () => {
    const s = selectLod(LAYOUT, ERRORS, 0, viewAt(130), PARAMS);
    const p = pack(s);
    expect(p.rows.length).toBe(7 * s.chunks.length);
    expect(unpack(p)).toEqual(s);
  });
});

describe('views', () => {
  const state = (eye: [number, number, number], forward: [number, number, number]): ViewState => ({
    view: { eye, frustum: null, viewportHeightPx: 600, fovY: 1 },
    params: PARAMS,
    forward,
    up: [0, 1, 0],
    near: 10,
    far: 1e7,
  });

  it('are the same within a millimetre and a hair of a turn', () => {
    const a = state([6.4e6, 0, 0], [0, 0, 1]);
    expect(sameView(a, state([6.4e6 + 5e-4, 0, 0], [0, 0, 1]))).toBe(true);
    expect(sameView(a, state([6.4e6 + 5e-3, 0, 0], [0, 0, 1]))).toBe(false);
    expect(sameView(a, state([6.4e6, 0, 0], [0, Math.sin(1e-3), Math.cos(1e-3)]))).toBe(false);
    expect(sameView(a, { ...a, params: { ...PARAMS, maxPixelError: 4 } })).toBe(false);
    expect(sameView(a, { ...a, view: { ...a.view, viewportHeightPx: 700 } })).toBe(false);
  });

  it('differ when the clip distances do (regression: the ground under a camera teleported down was never loaded)', () => {
    // After a teleport from 10 km to 100 m above the ground the first frames still clip at a
    // tenth of the old height; the selection made then left out every chunk nearer than 1 km,
    // and, the eye and directions unchanged, was taken as current once the near plane followed.
    const a = state([6.4e6, 0, 0], [0, 0, 1]);
    expect(sameView(a, { ...a, near: 1000 })).toBe(false);
    expect(sameView(a, { ...a, far: 2e7 })).toBe(false);
    expect(sameView(a, { ...a, near: 10 * (1 + 1e-9) })).toBe(true);
  });

  it('move frustum planes from the render frame to the planet frame exactly, at Earth radius', () => {
    // a camera at the render origin looking along -z, 90° wide: its four side planes and near/far
    const s = Math.SQRT1_2;
    const planes: Plane[] = [
      [s, 0, -s, 0],
      [-s, 0, -s, 0],
      [0, s, -s, 0],
      [0, -s, -s, 0],
      [0, 0, -1, -0.05],
      [0, 0, 1, 1e6],
    ];
    const eye: [number, number, number] = [6_371_000.25, -12.5, 3.75];
    const moved = planesToPlanetFrame(planes, eye);
    // a sphere 10 m ahead, 1 m across, is inside; 10 m behind, outside; a hair outside the side
    const at = (x: number, y: number, z: number) => ({ center: [eye[0] + x, eye[1] + y, eye[2] + z] as [number, number, number], radius: 0.5 });
    expect(sphereInFrustum(moved, at(0, 0, -10))).toBe(true);
    expect(sphereInFrustum(moved, at(0, 0, 10))).toBe(false);
    expect(sphereInFrustum(moved, at(10.72, 0, -10))).toBe(false);
    expect(sphereInFrustum(moved, at(10.7, 0, -10))).toBe(true);
  });
});

describe('streaming a descent', () => {
  it('converges at every stop to exactly the selection, finer as the eye comes down', async () => {
    const server = chunkServer();
    const { s, shown, step } = streamerOn(server, { maxConcurrent: 6 });
    const means: number[] = [];
    let last: LodSelection | null = null;
    for (const y of [116 + 5000, 116 + 400, 116 + 150, 116 + 20, 116 + 2]) {
      const view = viewAt(y);
      const sel = selectLod(LAYOUT, ERRORS, 0, view, PARAMS);
      s.setSelection(sel, view);
      for (let n = 0; n < 100 && !s.settled(); n++) {
        await step();
        // no overlap at any time; no hole once something was shown
        expect(overlaps(shown.keys())).toEqual([]);
        if (last !== null) expect(holes(sel, shown.keys())).toEqual([]);
        await server.releaseAll();
      }
      expect(s.settled()).toBe(true);
      const drawn = sel.chunks.filter((c) => c.drawn);
      expect(new Map([...shown].map(([n, v]) => [n, v.seams]))).toEqual(new Map(drawn.map((c) => [chunkName(c.key), c.coarser])));
      const levels = s.stats().levels;
      means.push(levels.reduce((a, n, l) => a + n * l, 0) / levels.reduce((a, n) => a + n, 0));
      last = sel;
    }
    // orbit: the coarsest level only; the ground: level 0 there
    expect(means[0]).toBe(2);
    expect(s.stats().levels[0]).toBeGreaterThan(0);
    for (let n = 1; n < means.length; n++) expect(means[n]).toBeLessThanOrEqual(means[n - 1]!);
    expect(means.at(-1)).toBeLessThan(means[0]!);
  });
});
