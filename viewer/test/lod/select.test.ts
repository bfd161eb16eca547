import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { chunkSphere } from '../../src/lod/bounds';
import {
  compareKeys,
  faceUvToSphere,
  keyId,
  Layout,
  parentOf,
  type ChunkKey,
  type LayoutParams,
} from '../../src/lod/layout';
import { adjacent, levelHistogram, selectLod, type LodSelection, type Plane } from '../../src/lod/select';

// The vectors the Rust crate writes and checks (`PMC_BLESS=1 cargo test -p pmc-lod --test vectors`).
const vectorsPath = fileURLToPath(
  new URL('../../../crates/pmc-lod/tests/data/selection-vectors.json', import.meta.url),
);

interface VectorCase {
  name: string;
  layout: LayoutParams;
  errors: number[];
  occluder: number;
  view: { eye: [number, number, number]; frustum: Plane[] | null; viewport_height_px: number; fov_y: number };
  params: { max_pixel_error: number; finest_level: number; max_chunks: number };
  expected: { truncated: boolean; chunks: number[][] };
}

const doc = JSON.parse(readFileSync(vectorsPath, 'utf8')) as { format: string; version: number; cases: VectorCase[] };

const run = (c: VectorCase): LodSelection =>
  selectLod(
    new Layout(c.layout),
    c.errors,
    c.occluder,
    {
      eye: c.view.eye,
      frustum: c.view.frustum,
      viewportHeightPx: c.view.viewport_height_px,
      fovY: c.view.fov_y,
    },
    {
      maxPixelError: c.params.max_pixel_error,
      finestLevel: c.params.finest_level,
      maxChunks: c.params.max_chunks,
    },
  );

const rows = (s: LodSelection): number[][] =>
  s.chunks.map((c) => [c.key.face, c.key.level, c.key.i, c.key.j, c.key.k, c.coarser, c.drawn ? 1 : 0]);

describe('level-of-detail selection', () => {
  it('reads the shared vectors', () => {
    expect(doc.format).toBe('pmc-lod-selection-vectors');
    expect(doc.version).toBe(1);
    expect(doc.cases.length).toBeGreaterThanOrEqual(20);
  });

  for (const c of doc.cases) {
    it(`selects what the Rust crate selects: ${c.name}`, () => {
      const s = run(c);
      expect(rows(s)).toEqual(c.expected.chunks);
      expect(s.truncated).toBe(c.expected.truncated);
    });
  }

  it('covers every level-0 chunk exactly once', () => {
    for (const c of doc.cases) {
      const layout = new Layout(c.layout);
      const s = run(c);
      const ids = new Set(s.chunks.map((x) => keyId(x.key)));
      for (const cell of layout.chunks(0)) {
        let hits = 0;
        for (let k: ChunkKey = cell; ; k = parentOf(k)) {
          if (ids.has(keyId(k))) hits++;
          if (k.level >= layout.maxLevel()) break;
        }
        expect(hits).toBe(1);
      }
      const sorted = s.chunks.every((x, n) => n === 0 || compareKeys(s.chunks[n - 1].key, x.key) < 0);
      expect(sorted).toBe(true);
      expect(levelHistogram(s).reduce((a, b) => a + b, 0)).toBe(s.chunks.length);
    }
  });

  it('steps across face edges and back', () => {
    const layout = new Layout({ n_c: 4, n_t: 4, d_b: 100, l_d: 1, d_c: 4 });
    for (let level = 0; level <= layout.maxLevel(); level++) {
      for (const key of layout.chunks(level)) {
        for (const o of [
          [1, 0, 0],
          [1, 1, 0],
          [-1, 1, 1],
          [0, -1, -1],
        ] as [number, number, number][]) {
          const n = adjacent(layout, key, o);
          if (n === null) continue;
          const back = [-1, 0, 1].flatMap((a) => [-1, 0, 1].flatMap((b) => [-1, 0, 1].map((c) => [a, b, c])));
          const home = back.filter((p) => {
            const m = adjacent(layout, n, p as [number, number, number]);
            return m !== null && keyId(m) === keyId(key);
          });
          expect(home.length).toBe(1);
        }
      }
    }
  });

  it('bounding spheres hold every voxel of their chunk', () => {
    const layout = new Layout({ n_c: 4, n_t: 4, d_b: 100, l_d: 1, d_c: 3 });
    const n = layout.faceTiles();
    for (let level = 0; level <= layout.maxLevel(); level++) {
      const stride = 2 ** level;
      for (const key of layout.chunks(level)) {
        const s = chunkSphere(layout, key);
        const span = layout.chunkSpan(level);
        let far = 0;
        for (let a = 0; a <= layout.n_t; a++) {
          for (let b = 0; b <= layout.n_t; b++) {
            const u = (2 * (key.i * span + a * stride)) / n - 1;
            const v = (2 * (key.j * span + b * stride)) / n - 1;
            const d = faceUvToSphere(key.face, u, v);
            for (let c = 0; c <= layout.n_t; c++) {
              const r = layout.layerRadius(key.k * span + c * stride);
              far = Math.max(far, Math.hypot(d[0] * r - s.center[0], d[1] * r - s.center[1], d[2] * r - s.center[2]));
            }
          }
        }
        expect(far).toBeLessThanOrEqual(s.radius);
        expect(s.radius).toBeLessThanOrEqual(1.35 * far);
      }
    }
  });

  it('refuses malformed input', () => {
    const c = doc.cases[0];
    const layout = new Layout(c.layout);
    const view = { eye: c.view.eye, frustum: null, viewportHeightPx: 800, fovY: 1 };
    const params = { maxPixelError: 2, finestLevel: 0, maxChunks: 100 };
    expect(() => selectLod(layout, [0], 0, view, params)).toThrow();
    expect(() => selectLod(layout, c.errors, 0, { ...view, fovY: 4 }, params)).toThrow();
    expect(() => selectLod(layout, c.errors, 0, { ...view, eye: [NaN, 0, 0] }, params)).toThrow();
    expect(() => selectLod(layout, c.errors, 0, view, { ...params, maxPixelError: 0 })).toThrow();
  });
});
