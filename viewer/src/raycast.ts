// Picking the terrain: a ray against a chunk's triangles through a bounding volume hierarchy
// (three-mesh-bvh) instead of every triangle in turn. The cursor, the brush, the path tool and the
// height under the camera cast rays every frame, and a chunk holds thousands of triangles: three's
// own test took about a millisecond a ray over a planet of 270 000 triangles, the hierarchy a few
// microseconds. A chunk's hierarchy is built the first time a ray meets its bounding sphere
// (chunks never aimed at cost nothing), beside the geometry (`indirect`: the triangles keep their
// order, the index drawn is not touched), and goes with the geometry when the chunk is replaced.

import * as THREE from 'three';
import { MeshBVH, acceleratedRaycast } from 'three-mesh-bvh';

const sphere = new THREE.Sphere();

/**
 * `Mesh.raycast` for terrain meshes: the bounding sphere first, then the mesh's hierarchy (made
 * on first use). Hits are those of three's own test (the material's side, the ray's near and far).
 */
export function bvhRaycast(this: THREE.Mesh, raycaster: THREE.Raycaster, intersects: THREE.Intersection[]): void {
  const g = this.geometry;
  if (g.boundsTree === undefined || g.boundsTree === null) {
    if (g.boundingSphere === null) g.computeBoundingSphere();
    sphere.copy(g.boundingSphere!).applyMatrix4(this.matrixWorld);
    if (!raycaster.ray.intersectsSphere(sphere)) return;
    g.boundsTree = new MeshBVH(g, { indirect: true });
  }
  acceleratedRaycast.call(this, raycaster, intersects);
}

/** Makes `mesh` picked through its hierarchy (`bvhRaycast`). */
export function useBvh(mesh: THREE.Mesh): void {
  mesh.raycast = bvhRaycast;
}
