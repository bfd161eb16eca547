// Decoder for the chunk-mesh-v1 binary encoding (docs/specs/chunk-mesh-v1.md).
//
// Pure: no DOM, no three.js. Every section of the encoding starts at a multiple of 4, so when the
// buffer itself is 4-aligned the returned arrays are views into it (no copies); otherwise (a
// `Uint8Array` at an odd offset into a larger buffer) the sections are copied into fresh arrays.

export const CHUNK_MAGIC = 'PMCM';
export const CHUNK_VERSION = 1;
export const HEADER_BYTES = 56;
/** Flag bit 0: indices are u32 (else u16). */
export const FLAG_U32_INDICES = 1;
/** Flag bit 1: the positions' low-order parts follow the positions. */
export const FLAG_POSITIONS_LOW = 2;

export const FACE_NAMES = ['top', 'bottom', 'north', 'south', 'east', 'west'] as const;
export type FaceName = (typeof FACE_NAMES)[number];

export interface DecodedChunk {
  /** Face index 0..5 (top, bottom, north, south, east, west). */
  face: number;
  level: number;
  i: number;
  j: number;
  k: number;
  /** World position (planet frame, metres, f64) that `positions` are relative to. */
  origin: [number, number, number];
  vertexCount: number;
  indexCount: number;
  /** f32 x 3 per vertex, relative to `origin`. */
  positions: Float32Array;
  /**
   * What f32 could not hold of each position (f32 x 3 per vertex, flag bit 1), or null: then
   * `origin + positions + positionsLow` (in f64) is the vertex's place to about 1e-14 of the
   * chunk's size, the same for every chunk's copy of a border vertex.
   */
  positionsLow: Float32Array | null;
  /** snorm i8 x 3 per vertex (component = round(n * 127)). */
  normals: Int8Array;
  /** Linear RGBA u8 x 4 per vertex. */
  colors: Uint8Array;
  /** Metres above the datum, one per vertex. */
  heights: Float32Array;
  /** Metres of sea water above the vertex, one per vertex. */
  waterDepths: Float32Array;
  /** Material id per vertex (index into the planet's `materials`). */
  materials: Uint8Array;
  /** Triangles, counter-clockwise from the air side. */
  indices: Uint16Array | Uint32Array;
  /** Total encoded length in bytes. */
  byteLength: number;
}

const pad4 = (n: number): number => (n + 3) & ~3;

/**
 * Byte length of an encoded chunk with `v` vertices and `i` indices (u32 when `u32Indices`), with
 * the positions' low-order parts when `low`.
 */
export function encodedLength(v: number, i: number, u32Indices: boolean, low = false): number {
  return (
    HEADER_BYTES +
    12 * v +
    (low ? 12 * v : 0) +
    pad4(3 * v) +
    4 * v +
    4 * v +
    4 * v +
    pad4(v) +
    pad4((u32Indices ? 4 : 2) * i)
  );
}

function fail(message: string): never {
  throw new Error(`chunk-mesh-v1: ${message}`);
}

/**
 * Decodes one chunk mesh. Throws an `Error` whose message says what is wrong when the buffer is
 * not a valid chunk-mesh-v1 encoding (magic, version, flags, length, index count or range).
 */
export function decodeChunk(input: ArrayBufferLike | ArrayBufferView): DecodedChunk {
  let buffer: ArrayBufferLike;
  let base: number;
  let length: number;
  if (ArrayBuffer.isView(input)) {
    buffer = input.buffer;
    base = input.byteOffset;
    length = input.byteLength;
  } else if (
    input instanceof ArrayBuffer ||
    (typeof SharedArrayBuffer !== 'undefined' && input instanceof SharedArrayBuffer)
  ) {
    buffer = input;
    base = 0;
    length = input.byteLength;
  } else {
    fail('expected an ArrayBuffer or a typed array');
  }
  if (length < HEADER_BYTES) {
    fail(`buffer of ${length} bytes is shorter than the ${HEADER_BYTES}-byte header (truncated?)`);
  }
  const view = new DataView(buffer, base, length);
  const magic = String.fromCharCode(
    view.getUint8(0),
    view.getUint8(1),
    view.getUint8(2),
    view.getUint8(3),
  );
  if (magic !== CHUNK_MAGIC) {
    fail(`bad magic ${JSON.stringify(magic)}, expected "${CHUNK_MAGIC}" (not a chunk mesh)`);
  }
  const version = view.getUint16(4, true);
  if (version !== CHUNK_VERSION) {
    fail(`unsupported version ${version}, this viewer reads version ${CHUNK_VERSION}`);
  }
  const flags = view.getUint16(6, true);
  if ((flags & ~(FLAG_U32_INDICES | FLAG_POSITIONS_LOW)) !== 0) {
    fail(`unknown flags 0x${flags.toString(16)} (only bits 0 and 1 are defined)`);
  }
  const u32 = (flags & FLAG_U32_INDICES) !== 0;
  const low = (flags & FLAG_POSITIONS_LOW) !== 0;
  const face = view.getUint8(8);
  if (face >= FACE_NAMES.length) fail(`face index ${face} out of range 0..5`);
  const level = view.getUint8(9);
  const reserved = view.getUint16(10, true);
  if (reserved !== 0) fail(`reserved header field is ${reserved}, expected 0`);
  const i = view.getUint32(12, true);
  const j = view.getUint32(16, true);
  const k = view.getUint32(20, true);
  const origin: [number, number, number] = [
    view.getFloat64(24, true),
    view.getFloat64(32, true),
    view.getFloat64(40, true),
  ];
  if (!origin.every(Number.isFinite)) fail(`origin ${origin.join(', ')} is not finite`);
  const vertexCount = view.getUint32(48, true);
  const indexCount = view.getUint32(52, true);
  if (indexCount % 3 !== 0) fail(`index count ${indexCount} is not a multiple of 3`);
  const expected = encodedLength(vertexCount, indexCount, u32, low);
  if (length !== expected) {
    fail(
      `length ${length} bytes differs from the ${expected} bytes that ${vertexCount} vertices and ` +
        `${indexCount} ${u32 ? 'u32' : 'u16'} indices need (truncated or trailing data)`,
    );
  }

  const aligned = (base & 3) === 0;
  let offset = HEADER_BYTES;
  // Takes the next section: a view in place when aligned, else a copy.
  function section<T>(
    make: (buf: ArrayBufferLike, byteOffset: number, count: number) => T,
    copyInto: (bytes: Uint8Array) => T,
    count: number,
    bytesPerItem: number,
  ): T {
    const bytes = count * bytesPerItem;
    const at = offset;
    offset += pad4(bytes);
    if (aligned) return make(buffer, base + at, count);
    return copyInto(new Uint8Array(buffer, base + at, bytes).slice());
  }
  const positions = section(
    (b, o, n) => new Float32Array(b, o, n),
    (c) => new Float32Array(c.buffer),
    3 * vertexCount,
    4,
  );
  const positionsLow = low
    ? section(
        (b, o, n) => new Float32Array(b, o, n),
        (c) => new Float32Array(c.buffer),
        3 * vertexCount,
        4,
      )
    : null;
  const normals = section(
    (b, o, n) => new Int8Array(b, o, n),
    (c) => new Int8Array(c.buffer),
    3 * vertexCount,
    1,
  );
  const colors = section(
    (b, o, n) => new Uint8Array(b, o, n),
    (c) => c,
    4 * vertexCount,
    1,
  );
  const heights = section(
    (b, o, n) => new Float32Array(b, o, n),
    (c) => new Float32Array(c.buffer),
    vertexCount,
    4,
  );
  const waterDepths = section(
    (b, o, n) => new Float32Array(b, o, n),
    (c) => new Float32Array(c.buffer),
    vertexCount,
    4,
  );
  const materials = section(
    (b, o, n) => new Uint8Array(b, o, n),
    (c) => c,
    vertexCount,
    1,
  );
  const indices: Uint16Array | Uint32Array = u32
    ? section(
        (b, o, n) => new Uint32Array(b, o, n),
        (c) => new Uint32Array(c.buffer),
        indexCount,
        4,
      )
    : section(
        (b, o, n) => new Uint16Array(b, o, n),
        (c) => new Uint16Array(c.buffer),
        indexCount,
        2,
      );

  for (let n = 0; n < indices.length; n++) {
    if (indices[n]! >= vertexCount) {
      fail(`index ${indices[n]} at position ${n} is out of range (${vertexCount} vertices)`);
    }
  }

  return {
    face,
    level,
    i,
    j,
    k,
    origin,
    vertexCount,
    indexCount,
    positions,
    positionsLow,
    normals,
    colors,
    heights,
    waterDepths,
    materials,
    indices,
    byteLength: length,
  };
}

/** The API key of a decoded chunk, e.g. `top/0/3/4/1`. */
export function chunkKeyOf(c: Pick<DecodedChunk, 'face' | 'level' | 'i' | 'j' | 'k'>): string {
  return `${FACE_NAMES[c.face]}/${c.level}/${c.i}/${c.j}/${c.k}`;
}
