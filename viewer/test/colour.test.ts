import { describe, expect, it } from 'vitest';
import { deltaE76, linearToSrgb, srgb8ToLab, srgbToLinear } from '../src/colour';

describe('colour', () => {
  it('round-trips the sRGB transfer function', () => {
    for (let i = 0; i <= 255; i++) expect(linearToSrgb(srgbToLinear(i / 255)) * 255).toBeCloseTo(i, 6);
    expect(srgbToLinear(128 / 255)).toBeCloseTo(0.2158, 3);
  });

  it('gives CIELAB of white, black and a known red (D65)', () => {
    const white = srgb8ToLab([255, 255, 255]);
    expect(white[0]).toBeCloseTo(100, 2);
    expect(Math.abs(white[1])).toBeLessThan(0.01);
    expect(Math.abs(white[2])).toBeLessThan(0.01);
    expect(srgb8ToLab([0, 0, 0])).toEqual([0, 0, 0]);
    const red = srgb8ToLab([255, 0, 0]);
    expect(red[0]).toBeCloseTo(53.24, 1);
    expect(red[1]).toBeCloseTo(80.09, 1);
    expect(red[2]).toBeCloseTo(67.2, 1);
  });

  it('measures CIE76 differences: zero for equal colours, about 100 from black to white', () => {
    expect(deltaE76([10, 20, 30], [10, 20, 30])).toBe(0);
    expect(deltaE76([0, 0, 0], [255, 255, 255])).toBeCloseTo(100, 2);
    expect(deltaE76([120, 130, 140], [121, 130, 140])).toBeLessThan(1);
  });
});
