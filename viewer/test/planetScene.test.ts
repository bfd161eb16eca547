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
});
