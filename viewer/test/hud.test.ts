// The HUD's numbers: round scale bars, the ground's distance along the view's axis, the
// loading bar's share.

import { describe, expect, it } from 'vitest';
import { formatLat, formatLon, formatScale, loadingShare, metresPerPixel, rayToSphere, scaleBar } from '../src/hud';

describe('scaleBar', () => {
  it('is the longest round distance (1, 2, 5 x 10^k m) that fits', () => {
    expect(scaleBar(1, 110)).toMatchObject({ metres: 100, px: 100, label: '100 m' });
    expect(scaleBar(2.5, 110)).toMatchObject({ metres: 200, px: 80, label: '200 m' });
    expect(scaleBar(50, 110)).toMatchObject({ metres: 5000, px: 100, label: '5 km' });
    expect(scaleBar(0.004, 110)).toMatchObject({ metres: 0.2, label: '20 cm' });
    expect(scaleBar(1e5, 110)!.label).toBe('10,000 km');
    // exactly 1, 2 or 5 of a power at the full length is taken (no rounding off by one)
    expect(scaleBar(0.2 / 110, 110)!.metres).toBeCloseTo(0.2, 12);
  });

  it('always fits, never under 40 % of the room, for any scale', () => {
    for (let e = -4; e <= 7; e += 0.013) {
      const b = scaleBar(10 ** e, 110)!;
      expect(b.px).toBeLessThanOrEqual(110 * (1 + 1e-9));
      expect(b.px).toBeGreaterThanOrEqual(110 * 0.4 - 1e-9);
      expect(b.label).toBe(formatScale(b.metres));
    }
  });

  it('is null for a scale that is not a positive number', () => {
    for (const bad of [0, -1, Number.NaN, Number.POSITIVE_INFINITY]) expect(scaleBar(bad)).toBeNull();
  });
});

describe('rayToSphere', () => {
  it('meets the sphere in front, misses it beside, and exits it from inside', () => {
    expect(rayToSphere([0, 0, 10], [0, 0, -1], 6)).toBeCloseTo(4, 12);
    expect(rayToSphere([0, 0, 10], [0, 0, 1], 6)).toBeNull(); // looking away
    expect(rayToSphere([0, 0, 10], [1, 0, 0], 6)).toBeNull(); // beside it: the sky
    expect(rayToSphere([0, 0, 3], [0, 0, 1], 6)).toBeCloseTo(3, 12); // under the ground
  });

  it('keeps its digits 2 m over an Earth-sized sphere', () => {
    const R = 6_371_000;
    expect(rayToSphere([0, R + 2, 0], [0, -1, 0], R)).toBeCloseTo(2, 6);
    // 45° down from 2 m: 2√2 m (the curvature adds under a micrometre)
    const d = Math.SQRT1_2;
    expect(rayToSphere([0, R + 2, 0], [d, -d, 0], R)).toBeCloseTo(2 * Math.SQRT2, 5);
  });
});

describe('the HUD', () => {
  it('has a metre per pixel of height over the view for the field of view', () => {
    // 50° vertical field, 640 px: 2 tan(25°) d / 640
    expect(metresPerPixel(1000, 50, 640)).toBeCloseTo((2 * Math.tan((25 * Math.PI) / 180) * 1000) / 640, 12);
  });

  it('fills the loading bar with the chunks shown among those wanted, and hides it when none load', () => {
    expect(loadingShare(30, 5, 5)).toBeCloseTo(0.75, 12);
    expect(loadingShare(0, 3, 0)).toBe(0);
    expect(loadingShare(40, 0, 0)).toBeNull();
  });

  it('prints places with their hemispheres', () => {
    expect([formatLat(27.98806), formatLon(-86.925)]).toEqual(['27.9881° N', '86.9250° W']);
    expect([formatLat(-0.5), formatLon(0)]).toEqual(['0.5000° S', '0.0000° E']);
  });
});
