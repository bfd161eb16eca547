// Test helper: an independent writer of the chunk-mesh-v1 encoding (docs/specs/chunk-mesh-v1.md),
// used to build synthetic buffers for the decoder tests.

export interface ChunkInput {
  face?: number;
  level?: number;
  i?: number;
  j?: number;
  k?: number;
  origin?: [number, number, number];
  positions: number[][];
  /** The positions' low-order parts (flag bit 1), when given. */
  positionsLow?: number[][];
  normals?: number[][];
  colors?: number[][];
  heights?: number[];
  waterDepths?: number[];
  materials?: number[];
  indices: number[];
  /** Force u32 indices (the writer uses u16 for V <= 65536). */
  u32?: boolean;
}

const pad4 = (n: number): number => (n + 3) & ~3;

export function encodeChunk(c: ChunkInput): Uint8Array<ArrayBuffer> {
  const V = c.positions.length;
  const I = c.indices.length;
  const u32 = c.u32 ?? V > 65536;
  const low = c.positionsLow !== undefined;
  const size =
    56 + 12 * V + (low ? 12 * V : 0) + pad4(3 * V) + 4 * V + 4 * V + 4 * V + pad4(V) + pad4((u32 ? 4 : 2) * I);
  const bytes = new Uint8Array(size);
  const dv = new DataView(bytes.buffer);
  bytes.set([0x50, 0x4d, 0x43, 0x4d], 0);
  dv.setUint16(4, 1, true);
  dv.setUint16(6, (u32 ? 1 : 0) | (low ? 2 : 0), true);
  dv.setUint8(8, c.face ?? 0);
  dv.setUint8(9, c.level ?? 0);
  dv.setUint32(12, c.i ?? 0, true);
  dv.setUint32(16, c.j ?? 0, true);
  dv.setUint32(20, c.k ?? 0, true);
  const o = c.origin ?? [0, 0, 0];
  dv.setFloat64(24, o[0], true);
  dv.setFloat64(32, o[1], true);
  dv.setFloat64(40, o[2], true);
  dv.setUint32(48, V, true);
  dv.setUint32(52, I, true);
  let at = 56;
  for (const p of c.positions) for (const x of p) { dv.setFloat32(at, x, true); at += 4; }
  for (const p of c.positionsLow ?? []) for (const x of p) { dv.setFloat32(at, x, true); at += 4; }
  for (let v = 0; v < V; v++) {
    const n = c.normals?.[v] ?? [0, 1, 0];
    for (const x of n) { dv.setInt8(at, Math.round(x * 127)); at += 1; }
  }
  at = pad4(at);
  for (let v = 0; v < V; v++) {
    const col = c.colors?.[v] ?? [255, 255, 255, 255];
    for (const x of col) { dv.setUint8(at, x); at += 1; }
  }
  for (let v = 0; v < V; v++) { dv.setFloat32(at, c.heights?.[v] ?? 0, true); at += 4; }
  for (let v = 0; v < V; v++) { dv.setFloat32(at, c.waterDepths?.[v] ?? 0, true); at += 4; }
  for (let v = 0; v < V; v++) { dv.setUint8(at, c.materials?.[v] ?? 0); at += 1; }
  at = pad4(at);
  for (const x of c.indices) {
    if (u32) { dv.setUint32(at, x, true); at += 4; } else { dv.setUint16(at, x, true); at += 2; }
  }
  at = pad4(at);
  if (at !== size) throw new Error(`encoder bug: wrote ${at} of ${size} bytes`);
  return bytes;
}
