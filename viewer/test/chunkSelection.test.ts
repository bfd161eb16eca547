import { describe, expect, it } from 'vitest';
import {
  loadRange,
  needsRequery,
  selectChunks,
  sphereDistance,
  type ChunkBounds,
} from '../src/chunkSelection';
import type { V3 } from '../src/frames';

// a row of chunks along +X, 10 m apart, radius 2: chunk n is at x = 10 n
const row = (count: number): ChunkBounds[] =>
  Array.from({ length: count }, (_, n) => ({ key: `c${n}`, center: [10 * n, 0, 0] as V3, radius: 2 }));

const everywhere = (): boolean => true;
const none = new Map<string, ChunkBounds>();
const noneSet = new Set<string>();

describe('selectChunks', () => {
  it('requests nearest first, within range', () => {
    const sel = selectChunks({
      camera: [25, 0, 0],
      range: 100,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: none,
      pending: noneSet,
      maxConcurrent: 20,
    });
    // distances to sphere: |10n - 25| - 2
    expect(sel.request.slice(0, 4)).toEqual(['c2', 'c3', 'c1', 'c4']);
    expect(sel.request).toHaveLength(10);
    expect(sel.missing).toBe(10);
  });

  it('leaves out chunks beyond the range', () => {
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 35,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: none,
      pending: noneSet,
      maxConcurrent: 20,
    });
    // c3 at 30 - 2 = 28 is in, c4 at 38 is out
    expect(sel.request).toEqual(['c0', 'c1', 'c2', 'c3']);
  });

  it('puts chunks in the view frustum first, nearest first among them', () => {
    const inFrustum = (c: V3): boolean => c[0] >= 50; // looking toward +X far away
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 1000,
      candidates: row(10),
      inFrustum,
      loaded: none,
      pending: noneSet,
      maxConcurrent: 6,
    });
    expect(sel.request).toEqual(['c5', 'c6', 'c7', 'c8', 'c9', 'c0']);
  });

  it('caps the requests in flight', () => {
    const pending = new Set(['c0', 'c1', 'c2', 'c3']);
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 1000,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: none,
      pending,
      maxConcurrent: 6,
    });
    expect(sel.request).toEqual(['c4', 'c5']); // 6 - 4 free slots, pending ones skipped
    const full = selectChunks({
      camera: [0, 0, 0],
      range: 1000,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: none,
      pending: new Set(['c0', 'c1', 'c2', 'c3', 'c4', 'c5']),
    });
    expect(full.request).toEqual([]); // default cap is 6
    expect(full.missing).toBe(4);
  });

  it('skips loaded and blocked chunks', () => {
    const loaded = new Map(row(3).map((c) => [c.key, c]));
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 1000,
      candidates: row(6),
      inFrustum: everywhere,
      loaded,
      pending: noneSet,
      blocked: new Set(['c3']),
    });
    expect(sel.request).toEqual(['c4', 'c5']);
    expect(sel.missing).toBe(3); // c3 is still missing
  });

  it('unloads only beyond range x 1.25 (hysteresis)', () => {
    const loaded = new Map(row(10).map((c) => [c.key, c]));
    // range 40: loaded while within 40, unloaded beyond 50 (to the sphere)
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 40,
      candidates: row(10),
      inFrustum: everywhere,
      loaded,
      pending: noneSet,
    });
    // c5: 48 (kept, inside 50), c6: 58 (unloaded)
    expect(sel.unload).toEqual(['c6', 'c7', 'c8', 'c9']);
    expect(sel.request).toEqual([]);
    // a chunk that has just left the load range is not dropped
    const sel2 = selectChunks({
      camera: [-5, 0, 0],
      range: 40,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: new Map([['c4', row(10)[4]!]]),
      pending: noneSet,
      unloadFactor: 1.25,
    });
    expect(sel2.unload).toEqual([]);
  });

  it('cancels pending requests beyond the unload distance', () => {
    const pending = new Map(row(10).map((c) => [c.key, c]));
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 40,
      candidates: row(10),
      inFrustum: everywhere,
      loaded: none,
      pending,
    });
    expect(sel.cancel).toEqual(['c6', 'c7', 'c8', 'c9']);
  });

  it('ordering is deterministic for equal distances', () => {
    const cands: ChunkBounds[] = [
      { key: 'b', center: [10, 0, 0], radius: 1 },
      { key: 'a', center: [-10, 0, 0], radius: 1 },
      { key: 'c', center: [0, 10, 0], radius: 1 },
    ];
    const sel = selectChunks({
      camera: [0, 0, 0],
      range: 100,
      candidates: cands,
      inFrustum: everywhere,
      loaded: none,
      pending: noneSet,
    });
    expect(sel.request).toEqual(['a', 'b', 'c']);
  });
});

describe('sphereDistance', () => {
  it('is 0 inside the sphere', () => {
    expect(sphereDistance([0, 0, 0], [1, 0, 0], 2)).toBe(0);
    expect(sphereDistance([0, 0, 0], [5, 0, 0], 2)).toBe(3);
  });
});

describe('needsRequery', () => {
  it('re-queries the first time and after moving a fraction of the range', () => {
    expect(needsRequery(null, [0, 0, 0], 100)).toBe(true);
    const last = { camera: [0, 0, 0] as V3, range: 100 };
    expect(needsRequery(last, [24, 0, 0], 100)).toBe(false);
    expect(needsRequery(last, [26, 0, 0], 100)).toBe(true);
    expect(needsRequery(last, [0, 0, 10], 100, 0.05)).toBe(true);
  });

  it('re-queries when the range changes a lot', () => {
    const last = { camera: [0, 0, 0] as V3, range: 100 };
    expect(needsRequery(last, [0, 0, 0], 120)).toBe(false);
    expect(needsRequery(last, [0, 0, 0], 130)).toBe(true);
    expect(needsRequery(last, [0, 0, 0], 70)).toBe(true);
  });
});

describe('loadRange', () => {
  const extent = { innerRadius: 1814, outerRadius: 1870 };
  it('reaches the horizon plus what sticks out behind it', () => {
    const r = 3 * 1870;
    const expected = Math.sqrt(r * r - 1814 ** 2) + Math.sqrt(1870 ** 2 - 1814 ** 2);
    expect(loadRange(r, extent, 100)).toBeCloseTo(expected, 9);
  });
  it('is at least the minimum near the ground and at most the maximum', () => {
    expect(loadRange(1814, extent, 500)).toBe(500);
    expect(loadRange(1e6, extent, 100, 5000)).toBe(5000);
  });
  it('grows with altitude', () => {
    expect(loadRange(2500, extent, 1)).toBeGreaterThan(loadRange(2000, extent, 1));
  });
});
