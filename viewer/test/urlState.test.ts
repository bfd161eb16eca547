import { describe, expect, it } from 'vitest';
import { formatHash, parseHash } from '../src/urlState';

describe('URL hash state', () => {
  it('round-trips', () => {
    const s = { preset: 'earthlike', seed: '18446744073709551615', mode: 'fly' as const, walk: true, lat: -10.12345, lon: 8.5, alt: 250.25, heading: 12.5, pitch: -20 };
    const h = formatHash(s);
    expect(h.startsWith('#preset=earthlike&seed=18446744073709551615')).toBe(true);
    expect(parseHash(h)).toEqual({ ...s, alt: 250.3 });
  });

  it('ignores invalid values', () => {
    expect(parseHash('#preset=<script>&seed=-1&mode=warp&lat=abc&lon=&alt=1e3')).toEqual({ alt: 1000 });
    expect(parseHash('')).toEqual({});
  });

  it('clamps the latitude', () => {
    expect(parseHash('lat=95').lat).toBe(90);
  });
});

describe('the detail settings in the URL', () => {
  it('round-trip, and only sane values are read', () => {
    const h = formatHash({ preset: 'earth', seed: '7', lat: 1, lon: 2, alt: 3, px: 1.5, chunks: 4000 });
    expect(h).toContain('px=1.5');
    expect(h).toContain('chunks=4000');
    expect(parseHash(h)).toMatchObject({ px: 1.5, chunks: 4000 });
    expect(parseHash('#px=0&chunks=1.5')).toEqual({});
    expect(parseHash('#px=abc&chunks=-3')).toEqual({});
    expect(parseHash('#px=1000&chunks=1e9')).toEqual({});
  });
});

describe('antialiasing in the URL', () => {
  it('is kept in the link only when off, and read in a few spellings', () => {
    expect(formatHash({ preset: 'earth' })).not.toContain('aa=');
    expect(formatHash({ preset: 'earth', aa: true })).not.toContain('aa=');
    const off = formatHash({ preset: 'earth', aa: false });
    expect(off).toContain('aa=0');
    expect(parseHash(off).aa).toBe(false);
    for (const v of ['0', 'false', 'off']) expect(parseHash(`#aa=${v}`).aa).toBe(false);
    for (const v of ['1', 'true', 'on']) expect(parseHash(`#aa=${v}`).aa).toBe(true);
    expect(parseHash('#aa=maybe').aa).toBeUndefined();
    expect(parseHash('#lat=1').aa).toBeUndefined();
  });
});

describe('the 3D Tiles mode in the URL', () => {
  it('is kept in the link only when on, and read in a few spellings', () => {
    expect(formatHash({ preset: 'earth' })).not.toContain('tiles=');
    expect(formatHash({ preset: 'earth', tiles: false })).not.toContain('tiles=');
    const on = formatHash({ preset: 'earth', tiles: true });
    expect(on).toContain('tiles=1');
    expect(parseHash(on).tiles).toBe(true);
    for (const v of ['1', 'true', 'on']) expect(parseHash(`#tiles=${v}`).tiles).toBe(true);
    for (const v of ['0', 'false', 'off']) expect(parseHash(`#tiles=${v}`).tiles).toBe(false);
    expect(parseHash('#tiles=maybe').tiles).toBeUndefined();
  });
});
