import { describe, expect, it } from 'vitest';
import { ReliefError, gridAtStride, parseRelief, reliefCellMetres, reliefHeightAt, reliefStride } from '../src/relief';

// the planet description's block, as the server writes it (ETOPO5's axes)
const block = {
  url: '/api/v1/relief',
  width: 4320,
  height: 2160,
  lon_first: -180,
  lon_step: 1 / 12,
  lat_first: -90 + 1 / 24,
  lat_step: 1 / 12,
  wraps: true,
  scale: 1,
  digest: 'ab12',
  encoding: 'f32le',
};

describe('parseRelief', () => {
  it('reads the relief block, and none when absent or null', () => {
    const r = parseRelief({ relief: block })!;
    expect(r).toEqual({ url: '/api/v1/relief', width: 4320, height: 2160, lonFirst: -180, lonStep: 1 / 12, latFirst: -90 + 1 / 24, latStep: 1 / 12, wraps: true, scale: 1, digest: 'ab12' });
    expect(parseRelief({})).toBeNull();
    expect(parseRelief({ relief: null })).toBeNull();
  });

  it.each([
    ['not an object', { relief: 'earth' }, /expected an object or null/],
    ['no url', { relief: { ...block, url: '' } }, /url/],
    ['another encoding', { relief: { ...block, encoding: 'i16be' } }, /encoding/],
    ['a fractional width', { relief: { ...block, width: 20.5 } }, /width/],
    ['one row', { relief: { ...block, height: 1 } }, /height/],
    ['a NaN first longitude', { relief: { ...block, lon_first: Number.NaN } }, /lon_first/],
    ['a zero step', { relief: { ...block, lat_step: 0 } }, /lat_step/],
    ['a negative step', { relief: { ...block, lon_step: -1 } }, /lon_step/],
    ['a string scale', { relief: { ...block, scale: '1' } }, /scale/],
    ['wraps as a number', { relief: { ...block, wraps: 1 } }, /wraps/],
    ['a numeric digest', { relief: { ...block, digest: 3 } }, /digest/],
  ])('refuses %s with an error that says so', (_what, planet, message) => {
    expect(() => parseRelief(planet)).toThrow(ReliefError);
    expect(() => parseRelief(planet)).toThrow(message);
  });

  it('refuses a planet description that is not an object', () => {
    expect(() => parseRelief(null)).toThrow(/not an object/);
  });
});

describe('reliefStride and gridAtStride', () => {
  const info = parseRelief({ relief: block })!;

  it('reads the whole grid where it fits, every 2^k-th sample where it does not', () => {
    expect(reliefStride(info, 8192)).toBe(1);
    expect(reliefStride(info, 4096)).toBe(2);
    expect(reliefStride(info, 1000)).toBe(8);
    // ETOPO1 (21600 x 10800): its sample count bounds it too
    expect(reliefStride({ width: 21600, height: 10800 }, 8192)).toBe(4);
  });

  it('keeps the axes of the samples it reads, and the wrap only where the stride divides the width', () => {
    const g = gridAtStride(info, 2);
    expect([g.width, g.height, g.lonStep, g.latStep, g.wraps]).toEqual([2160, 1080, 1 / 6, 1 / 6, true]);
    expect([g.clampSouth, g.clampNorth]).toEqual([true, true]);
    const odd = gridAtStride({ ...info, width: 4321 }, 2);
    expect([odd.width, odd.wraps, odd.clampSouth]).toEqual([2161, false, false]);
    expect(reliefCellMetres(g, 6_371_000)).toBeCloseTo(18_532.2, 0);
  });
});

describe('reliefHeightAt', () => {
  // a 4 x 3 global grid every 90 degrees of longitude, rows at -60, 0 and 60 degrees: the value at
  // (c, r) is 10 c + 100 r
  const grid = gridAtStride(
    { url: 'x', width: 4, height: 3, lonFirst: -180, lonStep: 90, latFirst: -60, latStep: 60, wraps: true, scale: 2, digest: '' },
    1,
  );
  const values = [0, 10, 20, 30, 100, 110, 120, 130, 200, 210, 220, 230];

  it('is exact at the samples and bilinear in column and row between them (times the scale)', () => {
    expect(reliefHeightAt(grid, values, 0, -90)).toBe(2 * 110);
    expect(reliefHeightAt(grid, values, 30, -135)).toBe(2 * 155);
    expect(reliefHeightAt(grid, values, -60, 0)).toBe(2 * 20);
  });

  it('wraps across the antimeridian from the last column to the first', () => {
    // half way between column 3 (90 E) and column 0 (180 W = 180 E)
    expect(reliefHeightAt(grid, values, 0, 135)).toBe(2 * 115);
    expect(reliefHeightAt(grid, values, 0, -225)).toBe(2 * 115);
  });

  it('takes the edge row beyond a global grid, and nothing beyond a regional one', () => {
    expect(grid.clampSouth && grid.clampNorth).toBe(true);
    expect(reliefHeightAt(grid, values, -89, -180)).toBe(0);
    expect(reliefHeightAt(grid, values, 89, 90)).toBe(2 * 230);
    const regional = { ...grid, wraps: false, clampSouth: false, clampNorth: false };
    expect(reliefHeightAt(regional, values, -61, -180)).toBeNull();
    expect(reliefHeightAt(regional, values, 0, 135)).toBeNull();
    expect(reliefHeightAt(regional, values, 0, 90)).toBe(2 * 130);
  });
});
