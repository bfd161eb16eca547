import { describe, expect, it } from 'vitest';
import type { PlanetInfo } from '../src/api';
import { EARTHLIKE_INFO } from './fixtures';
import { MACRO_CELL_SHARE, planetParams } from '../src/planetParams';
import { JITTER_SCALE, NOISE_PERIOD_CELLS } from '../src/shaders';

const base: PlanetInfo = EARTHLIKE_INFO;

describe('planetParams', () => {
  it('measures altitude from sea level and streams above the sea floor that the sea hides', () => {
    const p = planetParams(base);
    expect(p.shape).toEqual({ datum: 1884.8, outer: 1995.5, inner: 1810.6 });
    expect(p.extent).toEqual({ innerRadius: 1884.8, outerRadius: 1995.5 });
    expect(p.bandHeight).toBeCloseTo(110.7, 9);
    expect(p.snowHeight).toBeGreaterThan(0);
    expect(p.snowHeight).toBeLessThan(p.bandHeight);
    expect(p.waterScale).toBeCloseTo((1884.8 - 1810.6) / 3, 9);
    // a whole number of periods of every octave's lattice, the jitter's (a quarter of the
    // frequency) included: chunk origins taken modulo it keep the noise continuous
    expect(p.noisePeriod * p.noiseFreq * JITTER_SCALE).toBeCloseTo(NOISE_PERIOD_CELLS, 9);
  });

  it('makes the cells of the large-scale noise at least a fiftieth of the radius', () => {
    // the default planet: 40 tiles (8 chunks of 32 tiles over a quarter of a 1.9 km radius)
    const small = planetParams(base);
    expect(small.macroFreq).toBeCloseTo(1884.8 / (40 * ((Math.PI / 2) * 1884.8) / 8 / 32), 9);
    // at the Earth's size with tiles of a metre: a fiftieth of the radius, not 40 m
    const earth = planetParams({ ...base, radius: 6.38e6, base_radius: 6.36e6, sea_radius: 6.371e6, surface_bounds: [6.36e6, 6.38e6], layout: { ...base.layout, n_c: 2 ** 20, n_t: 16 } });
    expect(earth.macroFreq).toBeCloseTo(1 / MACRO_CELL_SHARE, 9);
  });

  it('uses the middle of the shell without a sea and the shell without surface bounds', () => {
    const p = planetParams({ ...base, sea_radius: null, surface_bounds: null });
    expect(p.shape.datum).toBe(1872);
    expect(p.extent).toEqual({ innerRadius: 1744, outerRadius: 2000 });
    expect(p.seaRadius).toBeNull();
    expect(p.snowAmount).toBeLessThan(1);
  });

  it('normalises the palette to a mean luminance of 1', () => {
    const p = planetParams(base);
    const lum = (c: number[]): number => 0.2126 * c[0]! + 0.7152 * c[1]! + 0.0722 * c[2]!;
    expect((lum(p.paletteA) + lum(p.paletteB)) / 2).toBeCloseTo(1, 9);
  });
});
