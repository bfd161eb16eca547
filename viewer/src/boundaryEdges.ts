// The border of a chunk mesh: edges used by exactly one of its triangles. Inside a chunk the
// mesher shares one vertex per cut grid edge, so these are exactly the edges where the chunk meets
// its neighbours (the "chunk borders" debug view). Pure.

/** Pairs of vertex indices (flattened) of the edges used by exactly one triangle. */
export function boundaryEdges(indices: ArrayLike<number>, vertexCount: number): Uint32Array {
  const counts = new Map<number, number>();
  const key = (a: number, b: number): number => (a < b ? a * vertexCount + b : b * vertexCount + a);
  for (let t = 0; t + 2 < indices.length; t += 3) {
    const a = indices[t]!;
    const b = indices[t + 1]!;
    const c = indices[t + 2]!;
    if (a === b || b === c || a === c) continue; // degenerate: no real edges
    for (const k of [key(a, b), key(b, c), key(c, a)]) counts.set(k, (counts.get(k) ?? 0) + 1);
  }
  const out: number[] = [];
  for (const [k, n] of counts) {
    if (n !== 1) continue;
    out.push(Math.floor(k / vertexCount), k % vertexCount);
  }
  return Uint32Array.from(out);
}
