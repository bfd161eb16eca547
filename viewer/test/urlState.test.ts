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
