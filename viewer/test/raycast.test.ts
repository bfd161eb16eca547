import { describe, expect, it } from 'vitest';
import fc from 'fast-check';
import * as THREE from 'three';
import { bvhRaycast, useBvh } from '../src/raycast';

/** A bumpy sheet of `n` x `n` quads, indexed, placed at `at`. */
function sheet(n: number, seed: number, at: THREE.Vector3): THREE.Mesh {
  const pos: number[] = [];
  const index: number[] = [];
  for (let j = 0; j <= n; j++) {
    for (let i = 0; i <= n; i++) pos.push(i, Math.sin(i * 0.7 + seed) * Math.cos(j * 0.9 - seed) * 2, j);
  }
  for (let j = 0; j < n; j++) {
    for (let i = 0; i < n; i++) {
      const a = j * (n + 1) + i;
      index.push(a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
  g.setIndex(index);
  const mesh = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ side: THREE.FrontSide }));
  mesh.position.copy(at);
  mesh.updateMatrixWorld(true);
  return mesh;
}

describe('picking through the hierarchy', () => {
  it('finds the first hit three finds, for any ray (the side, near and far kept)', () => {
    const plain = sheet(24, 1, new THREE.Vector3(-12, 0, -12));
    const fast = sheet(24, 1, new THREE.Vector3(-12, 0, -12));
    useBvh(fast);
    const order = fast.geometry.getIndex()!.array.slice();
    let hits = 0;
    fc.assert(
      fc.property(
        fc.tuple(fc.double({ min: -11, max: 11, noNaN: true }), fc.double({ min: -11, max: 11, noNaN: true })),
        fc.tuple(fc.double({ min: -0.5, max: 0.5, noNaN: true }), fc.double({ min: -0.5, max: 0.5, noNaN: true })),
        fc.boolean(),
        fc.double({ min: 5, max: 30, noNaN: true }),
        ([x, z], [dx, dz], fromBelow, far) => {
          const origin = new THREE.Vector3(x, fromBelow ? -10 : 10, z);
          const dir = new THREE.Vector3(dx, fromBelow ? 1 : -1, dz).normalize();
          const a = Object.assign(new THREE.Raycaster(origin, dir, 0, far), { firstHitOnly: true });
          const b = Object.assign(new THREE.Raycaster(origin, dir, 0, far), { firstHitOnly: true });
          const ha = a.intersectObject(plain, false)[0];
          const hb = b.intersectObject(fast, false)[0];
          expect(hb === undefined).toBe(ha === undefined);
          if (ha && hb) {
            hits++;
            expect(hb.distance).toBeCloseTo(ha.distance, 9);
            expect(hb.point.distanceTo(ha.point)).toBeLessThan(1e-9);
            expect(hb.object).toBe(fast);
          }
        },
      ),
      { numRuns: 300, seed: 7 },
    );
    // (most rays meet the sheet: the property is not about misses alone)
    expect(hits).toBeGreaterThan(60);
    // the triangles drawn keep their order
    expect(fast.geometry.getIndex()!.array).toEqual(order);
  });

  it('builds a mesh its hierarchy only when a ray meets its bounding sphere', () => {
    const mesh = sheet(8, 2, new THREE.Vector3(100, 0, 100));
    mesh.raycast = bvhRaycast;
    const away = new THREE.Raycaster(new THREE.Vector3(0, 10, 0), new THREE.Vector3(0, -1, 0));
    expect(away.intersectObject(mesh, false)).toEqual([]);
    expect(mesh.geometry.boundsTree).toBeUndefined();
    const onto = new THREE.Raycaster(new THREE.Vector3(104.3, 10, 104.6), new THREE.Vector3(0, -1, 0));
    expect(onto.intersectObject(mesh, false).length).toBe(1);
    expect(mesh.geometry.boundsTree).toBeDefined();
  });
});
