import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { chunkKeyOf, decodeChunk, encodedLength, FACE_NAMES } from '../src/chunkDecode';
import { encodeChunk, type ChunkInput } from './encodeChunk';

const fixture = (name: string): string => fileURLToPath(new URL(`./fixtures/${name}`, import.meta.url));

interface FixtureJson {
  byte_length: number;
  magic: string;
  version: number;
  flags: number;
  face: string;
  face_index: number;
  level: number;
  i: number;
  j: number;
  k: number;
  origin: [number, number, number];
  vertex_count: number;
  index_count: number;
  index_type: 'u16' | 'u32';
  positions: number[][];
  normals_snorm: number[][];
  colors: number[][];
  heights: number[];
  water_depths: number[];
  materials: number[];
  indices: number[];
  section_offsets: Record<string, number>;
}

describe('the shared test vector (test/fixtures/chunk-v1.bin, written by the Rust encoder)', () => {
  const bin = readFileSync(fixture('chunk-v1.bin'));
  const expected = JSON.parse(readFileSync(fixture('chunk-v1.json'), 'utf8')) as FixtureJson;
  // copy into a fresh, 4-aligned ArrayBuffer (a Node Buffer may sit at any offset of its pool)
  const bytes = new Uint8Array(bin.byteLength);
  bytes.set(bin);
  const c = decodeChunk(bytes.buffer);

  it('has the expected header', () => {
    expect(bin.byteLength).toBe(expected.byte_length);
    expect(c.byteLength).toBe(expected.byte_length);
    expect(FACE_NAMES[c.face]).toBe(expected.face);
    expect(c.face).toBe(expected.face_index);
    expect([c.level, c.i, c.j, c.k]).toEqual([expected.level, expected.i, expected.j, expected.k]);
    expect(c.origin).toEqual(expected.origin); // f64, bit for bit
    expect(c.vertexCount).toBe(expected.vertex_count);
    expect(c.indexCount).toBe(expected.index_count);
    expect(c.indices).toBeInstanceOf(expected.index_type === 'u16' ? Uint16Array : Uint32Array);
    expect(chunkKeyOf(c)).toBe(`${expected.face}/${expected.level}/${expected.i}/${expected.j}/${expected.k}`);
  });

  it('decodes every section', () => {
    expect([...c.positions]).toEqual(expected.positions.flat());
    expect([...c.normals]).toEqual(expected.normals_snorm.flat());
    expect([...c.colors]).toEqual(expected.colors.flat());
    expect([...c.heights]).toEqual(expected.heights);
    expect([...c.waterDepths]).toEqual(expected.water_depths);
    expect([...c.materials]).toEqual(expected.materials);
    expect([...c.indices]).toEqual(expected.indices);
  });

  it('views the sections in place at the documented offsets (no copies)', () => {
    const off = expected.section_offsets;
    expect(c.positions.buffer).toBe(bytes.buffer);
    expect(c.positions.byteOffset).toBe(off['positions']);
    expect(c.normals.byteOffset).toBe(off['normals']);
    expect(c.colors.byteOffset).toBe(off['colors']);
    expect(c.heights.byteOffset).toBe(off['heights']);
    expect(c.waterDepths.byteOffset).toBe(off['water_depths']);
    expect(c.materials.byteOffset).toBe(off['materials']);
    expect(c.indices.byteOffset).toBe(off['indices']);
    expect(c.indices.buffer).toBe(bytes.buffer);
  });

  it('agrees with the independent test encoder byte for byte', () => {
    const again = encodeChunk({
      face: expected.face_index,
      level: expected.level,
      i: expected.i,
      j: expected.j,
      k: expected.k,
      origin: expected.origin,
      positions: expected.positions,
      normals: expected.normals_snorm.map((n) => n.map((x) => x / 127)),
      colors: expected.colors,
      heights: expected.heights,
      waterDepths: expected.water_depths,
      materials: expected.materials,
      indices: expected.indices,
    });
    expect([...again]).toEqual([...bytes]);
  });
});

const triangle: ChunkInput = {
  face: 2,
  level: 0,
  i: 3,
  j: 4,
  k: 1,
  origin: [12.5, 6371000.25, -40.125],
  positions: [
    [0, 0, 0],
    [1, 0, 0],
    [0, 1, 0],
  ],
  normals: [
    [0, 1, 0],
    [0, -1, 0],
    [1, 0, 0],
  ],
  colors: [
    [1, 2, 3, 4],
    [5, 6, 7, 8],
    [9, 10, 11, 12],
  ],
  heights: [1.5, -2.5, 3],
  waterDepths: [0, 2.5, 0],
  materials: [0, 3, 5],
  indices: [0, 1, 2],
};

describe('decodeChunk on synthetic buffers', () => {
  it('reads u16 indices', () => {
    const bytes = encodeChunk(triangle);
    expect(bytes.byteLength).toBe(encodedLength(3, 3, false));
    const c = decodeChunk(bytes.buffer);
    expect(c.indices).toBeInstanceOf(Uint16Array);
    expect([...c.indices]).toEqual([0, 1, 2]);
    expect(c.face).toBe(2);
    expect(chunkKeyOf(c)).toBe('north/0/3/4/1');
    expect(c.origin).toEqual([12.5, 6371000.25, -40.125]);
    expect([...c.normals]).toEqual([0, 127, 0, 0, -127, 0, 127, 0, 0]);
    expect([...c.colors]).toEqual([1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]);
    expect([...c.heights]).toEqual([1.5, -2.5, 3]);
    expect([...c.waterDepths]).toEqual([0, 2.5, 0]);
    expect([...c.materials]).toEqual([0, 3, 5]);
  });

  it('reads the positions\' low-order parts (flag bit 1), and none without the flag', () => {
    const lows = [
      [1e-8, -2e-8, 0],
      [0, 0, 3e-9],
      [-1e-9, 5e-9, 7e-9],
    ];
    const bytes = encodeChunk({ ...triangle, positionsLow: lows });
    expect(bytes.byteLength).toBe(encodedLength(3, 3, false, true));
    const c = decodeChunk(bytes);
    expect([...c.positions]).toEqual([...decodeChunk(encodeChunk(triangle)).positions]);
    expect([...c.positionsLow!]).toEqual(lows.flat().map(Math.fround));
    expect([...c.heights]).toEqual([1.5, -2.5, 3]);
    expect(decodeChunk(encodeChunk(triangle)).positionsLow).toBeNull();
    // the flag without the section is a length error
    const lying = encodeChunk(triangle);
    new DataView(lying.buffer).setUint16(6, 2, true);
    expect(() => decodeChunk(lying)).toThrow(/length/);
  });

  it('reads u32 indices (flag bit 0)', () => {
    const bytes = encodeChunk({ ...triangle, u32: true });
    expect(bytes.byteLength).toBe(encodedLength(3, 3, true));
    const c = decodeChunk(bytes);
    expect(c.indices).toBeInstanceOf(Uint32Array);
    expect([...c.indices]).toEqual([0, 1, 2]);
  });

  it('reads a big mesh whose indices need u32', () => {
    const V = 70_000;
    const positions = Array.from({ length: V }, (_, n) => [n, 0, 0]);
    const bytes = encodeChunk({ positions, indices: [0, 69_999, 65_536] });
    const c = decodeChunk(bytes);
    expect(c.indices).toBeInstanceOf(Uint32Array);
    expect([...c.indices]).toEqual([0, 69_999, 65_536]);
    expect(c.positions[3 * 69_999]).toBe(69_999);
  });

  it('reads an empty chunk (56 bytes)', () => {
    const bytes = encodeChunk({ positions: [], indices: [] });
    expect(bytes.byteLength).toBe(56);
    const c = decodeChunk(bytes);
    expect(c.vertexCount).toBe(0);
    expect(c.indexCount).toBe(0);
    expect(c.indices.length).toBe(0);
  });

  it('handles odd vertex counts (padded sections)', () => {
    for (const V of [1, 2, 3, 4, 5, 7]) {
      const positions = Array.from({ length: V }, (_, n) => [n, 2 * n, 3 * n]);
      const materials = Array.from({ length: V }, (_, n) => n);
      const bytes = encodeChunk({ positions, materials, indices: [0, 0, V - 1] });
      const c = decodeChunk(bytes);
      expect([...c.materials]).toEqual(materials);
      expect(c.positions[3 * (V - 1) + 2]).toBe(3 * (V - 1));
    }
  });

  it('copies when the buffer is not 4-aligned, with the same values', () => {
    const bytes = encodeChunk(triangle);
    const shifted = new Uint8Array(bytes.byteLength + 1);
    shifted.set(bytes, 1);
    const c = decodeChunk(shifted.subarray(1));
    expect([...c.positions]).toEqual([0, 0, 0, 1, 0, 0, 0, 1, 0]);
    expect([...c.heights]).toEqual([1.5, -2.5, 3]);
    expect([...c.indices]).toEqual([0, 1, 2]);
    expect(c.positions.buffer).not.toBe(shifted.buffer);
  });

  it('views in place at a 4-aligned offset into a larger buffer', () => {
    const bytes = encodeChunk(triangle);
    const big = new Uint8Array(bytes.byteLength + 8);
    big.set(bytes, 4);
    const c = decodeChunk(big.subarray(4, 4 + bytes.byteLength));
    expect(c.positions.buffer).toBe(big.buffer);
    expect(c.positions.byteOffset).toBe(4 + 56);
  });
});

describe('decodeChunk rejects invalid buffers with a descriptive error', () => {
  const good = (): Uint8Array<ArrayBuffer> => encodeChunk(triangle);

  it('bad magic', () => {
    const b = good();
    b[0] = 0x47; // 'G'
    expect(() => decodeChunk(b)).toThrow(/bad magic "GMCM"/);
  });

  it('bad version', () => {
    const b = good();
    new DataView(b.buffer).setUint16(4, 2, true);
    expect(() => decodeChunk(b)).toThrow(/unsupported version 2/);
  });

  it('unknown flags', () => {
    const b = good();
    new DataView(b.buffer).setUint16(6, 4, true);
    expect(() => decodeChunk(b)).toThrow(/unknown flags/);
  });

  it('shorter than the header', () => {
    expect(() => decodeChunk(good().slice(0, 40))).toThrow(/shorter than the 56-byte header/);
    expect(() => decodeChunk(new ArrayBuffer(0))).toThrow(/truncated/);
  });

  it('truncated body', () => {
    const b = good();
    expect(() => decodeChunk(b.slice(0, b.byteLength - 4))).toThrow(/length \d+ bytes differs/);
  });

  it('trailing bytes', () => {
    const b = good();
    const longer = new Uint8Array(b.byteLength + 4);
    longer.set(b);
    expect(() => decodeChunk(longer)).toThrow(/differs/);
  });

  it('a vertex count that does not match the length', () => {
    const b = good();
    new DataView(b.buffer).setUint32(48, 4, true);
    expect(() => decodeChunk(b)).toThrow(/differs/);
  });

  it('an index count that is not a multiple of 3', () => {
    const b = encodeChunk({ ...triangle, indices: [0, 1, 2, 0] });
    expect(() => decodeChunk(b)).toThrow(/not a multiple of 3/);
  });

  it('index out of range (u16)', () => {
    const b = encodeChunk({ ...triangle, indices: [0, 1, 3] });
    expect(() => decodeChunk(b)).toThrow(/index 3 at position 2 is out of range \(3 vertices\)/);
  });

  it('index out of range (u32)', () => {
    const b = encodeChunk({ ...triangle, indices: [0, 70000, 1], u32: true });
    expect(() => decodeChunk(b)).toThrow(/index 70000 .* out of range/);
  });

  it('a non-zero reserved field', () => {
    const b = good();
    new DataView(b.buffer).setUint16(10, 7, true);
    expect(() => decodeChunk(b)).toThrow(/reserved header field is 7/);
  });

  it('face index out of range', () => {
    const b = good();
    b[8] = 6;
    expect(() => decodeChunk(b)).toThrow(/face index 6/);
  });

  it('not a buffer at all', () => {
    expect(() => decodeChunk('PMCM' as unknown as ArrayBuffer)).toThrow(/expected an ArrayBuffer/);
  });
});
