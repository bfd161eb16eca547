// The chunk decoder over hostile bytes (fast-check): the shared test vector bit-flipped,
// overwritten, truncated, extended and spliced, random headers with random counts, and random
// bytes. Every buffer either decodes into a chunk whose parts are consistent (sections of the
// sizes its counts say, every index below the vertex count) or is refused with the decoder's own
// error (`chunk-mesh-v1: ...`): never another exception, never a hang.

import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import { decodeChunk, type DecodedChunk } from '../src/chunkDecode';

const vector = (() => {
  const bin = readFileSync(fileURLToPath(new URL('./fixtures/chunk-v1.bin', import.meta.url)));
  const bytes = new Uint8Array(bin.byteLength);
  bytes.set(bin);
  return bytes;
})();

/** Decodes `bytes` (at `offset` in a larger buffer: unaligned views too); checks the outcome. */
function decodeChecked(bytes: Uint8Array, offset = 0): 'ok' | 'refused' {
  const host = new Uint8Array(bytes.length + offset);
  host.set(bytes, offset);
  let c: DecodedChunk;
  try {
    c = decodeChunk(host.subarray(offset));
  } catch (e) {
    expect(e).toBeInstanceOf(Error);
    expect((e as Error).message).toMatch(/^chunk-mesh-v1: /);
    return 'refused';
  }
  const v = c.vertexCount;
  expect(c.positions.length).toBe(3 * v);
  expect(c.normals.length).toBe(3 * v);
  expect(c.colors.length).toBe(4 * v);
  expect([c.heights.length, c.waterDepths.length, c.materials.length]).toEqual([v, v, v]);
  if (c.positionsLow) expect(c.positionsLow.length).toBe(3 * v);
  expect(c.indices.length).toBe(c.indexCount);
  expect(c.indexCount % 3).toBe(0);
  for (const i of c.indices) expect(i).toBeLessThan(v);
  expect(c.face).toBeLessThan(6);
  expect(c.origin.every(Number.isFinite)).toBe(true);
  expect(c.byteLength).toBe(bytes.length);
  return 'ok';
}

/** One mutation of a buffer. */
const mutation = fc.oneof(
  fc.record({ kind: fc.constant('flip' as const), at: fc.nat(), bit: fc.integer({ min: 0, max: 7 }) }),
  fc.record({ kind: fc.constant('set' as const), at: fc.nat(), value: fc.integer({ min: 0, max: 255 }) }),
  fc.record({ kind: fc.constant('truncate' as const), at: fc.nat() }),
  fc.record({ kind: fc.constant('insert' as const), at: fc.nat(), bytes: fc.uint8Array({ maxLength: 16 }) }),
  // a header field overwritten by an extreme 32-bit value (counts, indices, the key)
  fc.record({ kind: fc.constant('word' as const), at: fc.nat({ max: 60 }), value: fc.constantFrom(0, 1, 3, 0xffff, 0x10000, 0x7fffffff, 0xffffffff) }),
);
type Mutation = typeof mutation extends fc.Arbitrary<infer M> ? M : never;

function mutate(src: Uint8Array, ms: readonly Mutation[]): Uint8Array {
  let b = src.slice();
  for (const m of ms) {
    if (b.length === 0) break;
    const at = m.at % b.length;
    switch (m.kind) {
      case 'flip':
        b[at] = b[at]! ^ (1 << m.bit);
        break;
      case 'set':
        b[at] = m.value;
        break;
      case 'truncate':
        b = b.slice(0, at);
        break;
      case 'insert': {
        const c = new Uint8Array(b.length + m.bytes.length);
        c.set(b.subarray(0, at));
        c.set(m.bytes, at);
        c.set(b.subarray(at), at + m.bytes.length);
        b = c;
        break;
      }
      case 'word':
        if (at + 4 <= b.length) new DataView(b.buffer, b.byteOffset).setUint32(at - (at % 4), m.value, true);
        break;
    }
  }
  return b;
}

describe('decodeChunk on hostile bytes', () => {
  it('decodes the shared test vector itself', () => {
    expect(decodeChecked(vector)).toBe('ok');
  });

  it('refuses or decodes consistently every mutation of the test vector, aligned or not', () => {
    const seen = { ok: 0, refused: 0 };
    fc.assert(
      fc.property(fc.array(mutation, { minLength: 1, maxLength: 6 }), fc.integer({ min: 0, max: 3 }), (ms, offset) => {
        seen[decodeChecked(mutate(vector, ms), offset)]++;
      }),
      { numRuns: 3000, seed: 20261127 },
    );
    // both outcomes happen: mutations in the vertex data decode, those in the header are refused
    expect(seen.ok).toBeGreaterThan(100);
    expect(seen.refused).toBeGreaterThan(100);
  });

  it('refuses a valid header over random bytes, and random bytes', () => {
    fc.assert(
      fc.property(fc.uint8Array({ maxLength: 2048 }), fc.integer({ min: 0, max: 3 }), (body, offset) => {
        const b = new Uint8Array(56 + body.length);
        b.set(vector.subarray(0, 56));
        b.set(body, 56);
        decodeChecked(b, offset);
        decodeChecked(body, offset);
      }),
      { numRuns: 2000, seed: 7 },
    );
  });
});
