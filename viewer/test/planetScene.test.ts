import { describe, expect, it } from 'vitest';
import type { PlanetInfo } from '../src/api';
import { EARTHLIKE_INFO } from './fixtures';
import { decodeChunk } from '../src/chunkDecode';
import { planetParams } from '../src/planetParams';
import { PlanetScene } from '../src/planetScene';
import { encodeChunk } from './encodeChunk';

const info: PlanetInfo = EARTHLIKE_INFO;

describe('PlanetScene', () => {
  it('places a chunk added after the frame placed the scene at once (a chunk at the render origin was culled from the one frame that drew it: a hole with render on demand)', () => {
    const scene = new PlanetScene();
    scene.setPlanet(planetParams(info));
    const camera: [number, number, number] = [100, 1900, -50];
    scene.place(camera);
    const origin: [number, number, number] = [120.5, 1880.25, -40];
    const chunk = decodeChunk(
      encodeChunk({
        origin,
        positions: [[0, 0, 0], [1, 0, 0], [0, 0, 1]],
        positionsLow: [[0, 0, 0], [0, 0, 0], [0, 0, 0]],
        heights: [5, 5, 5],
        indices: [0, 1, 2],
      }),
    );
    scene.addChunk('top/0/0/0/0', 0, chunk);
    const mesh = scene.terrainMeshes().find((m) => m.name === 'top/0/0/0/0');
    expect(mesh).toBeDefined();
    expect(mesh!.position.toArray()).toEqual([20.5, -19.75, 10]);
    // (and its world matrix with it, which the frustum culling of the same frame reads)
    expect(mesh!.matrixWorld.elements.slice(12, 15)).toEqual([20.5, -19.75, 10]);
    scene.dispose();
  });

  it('samples vertices spread over every chunk shown, whatever order they arrived in ("only 68 land places in view": with fewer than twice as many vertices as asked for, the first ones in arrival order were taken)', () => {
    // 8 chunks of 30 vertices (10 triangles each), 240 vertices, 150 asked for
    const chunkAt = (c: number) =>
      decodeChunk(
        encodeChunk({
          origin: [1000 * c, 1900, 0],
          positions: Array.from({ length: 30 }, (_, i) => [i, (i % 3) * 2, 0] as [number, number, number]),
          positionsLow: Array.from({ length: 30 }, () => [0, 0, 0] as [number, number, number]),
          heights: Array.from({ length: 30 }, (_, i) => 10 * c + i),
          indices: Array.from({ length: 30 }, (_, i) => i),
        }),
      );
    const keys = Array.from({ length: 8 }, (_, c) => `top/2/${c}/0/0`);
    const sampled = (order: number[], count = 150) => {
      const scene = new PlanetScene();
      scene.setPlanet(planetParams(info));
      for (const c of order) scene.addChunk(keys[c]!, 0, chunkAt(c));
      const out = scene.sampleVertices(count);
      scene.dispose();
      return out;
    };
    const a = sampled([0, 1, 2, 3, 4, 5, 6, 7]);
    const b = sampled([5, 2, 7, 0, 3, 6, 1, 4]);
    expect(a.length).toBe(150);
    expect(b).toEqual(a);
    // every chunk gives 150 / 8 of them, give or take one
    for (const key of keys) {
      const n = a.filter((v) => v.key === key).length;
      expect(n).toBeGreaterThanOrEqual(18);
      expect(n).toBeLessThanOrEqual(19);
    }
    // every vertex, once, when more are asked for than there are
    const all = sampled([3, 1, 0, 2, 4, 5, 6, 7], 1000);
    expect(all.length).toBe(240);
    expect(new Set(all.map((v) => `${v.key} ${v.height}`)).size).toBe(240);
  });
});
