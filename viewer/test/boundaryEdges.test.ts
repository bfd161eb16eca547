import { describe, expect, it } from 'vitest';
import { boundaryEdges } from '../src/boundaryEdges';

const pairs = (e: Uint32Array): string[] => {
  const out: string[] = [];
  for (let n = 0; n < e.length; n += 2) out.push(`${e[n]}-${e[n + 1]}`);
  return out.sort();
};

describe('boundaryEdges', () => {
  it('finds the outline of a quad made of two triangles', () => {
    // 0-1
    // |/|
    // 2-3
    expect(pairs(boundaryEdges([0, 2, 1, 1, 2, 3], 4))).toEqual(['0-1', '0-2', '1-3', '2-3']);
  });

  it('a closed mesh (tetrahedron) has no border', () => {
    expect(boundaryEdges([0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0], 4).length).toBe(0);
  });

  it('skips degenerate triangles', () => {
    expect(pairs(boundaryEdges([0, 1, 2, 2, 2, 1], 3))).toEqual(['0-1', '0-2', '1-2']);
  });
});
