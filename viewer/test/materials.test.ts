import { describe, expect, it } from 'vitest';
import type { PlanetInfo } from '../src/api';
import { directionFromLatLon, latLonFromPosition } from '../src/frames';
import { EARTH_RADIUS, MATERIAL_SLOTS, latLonOfDirection, materialModel, materialUniforms, snowLineAt } from '../src/materials';
import { planetParams } from '../src/planetParams';

const earthlike: PlanetInfo = {
  format: 'pmc-planet', version: 1, preset: 'earthlike', seed: '7', presets: [],
  layout: { n_c: 8, n_t: 32, d_b: 1744, l_d: 4, d_c: 2 },
  radius: 2000, base_radius: 1744, sea_radius: 1884.8, surface_bounds: [1810.6, 1995.5],
  chunk_count: 768, face_tiles: 256, depth_tiles: 64, faces: [], materials: [],
  palette: { a: [0.42, 0.5, 0.26], b: [0.56, 0.47, 0.32] },
};
const dem: PlanetInfo = {
  ...earthlike, preset: null, terrain: { kind: 'dem', name: 'dem', seed: '0', file: 'earth.pmcdem' },
  radius: EARTH_RADIUS + 20_000, base_radius: EARTH_RADIUS - 20_000, sea_radius: EARTH_RADIUS,
};

describe('materialModel', () => {
  it('reproduces the earthlike preset: bands in fractions of the shell, snow falling toward the poles', () => {
    const m = materialModel(earthlike, 1884.8);
    const t = 256;
    expect(m.family).toBe('earthlike');
    expect(m.shoreHeight).toBeCloseTo(0.012 * t, 9);
    expect(m.forestFrom).toBeCloseTo(0.1 * t, 9);
    expect(snowLineAt(m, 0)).toBeCloseTo(0.25 * t, 9);
    // presets/earthlike.rs: t (0.25 - 0.32 sin^2 lat), at least 0.004 t
    expect(snowLineAt(m, Math.sin(Math.PI / 6))).toBeCloseTo(t * (0.25 - 0.32 * 0.25), 9);
    expect(snowLineAt(m, 1)).toBeCloseTo(0.004 * t, 9);
    expect(m.rockSlope).toBe(0.62);
  });

  it('gives elevation models true-scale lines: snow at 5500 m (1 - sin^4 lat), a 200 m shelf', () => {
    const m = materialModel(dem, EARTH_RADIUS);
    expect(m.family).toBe('dem');
    expect(m.shelfDepth).toBeCloseTo(200, 9);
    expect(snowLineAt(m, 0)).toBeCloseTo(5500, 9);
    expect(snowLineAt(m, Math.sin(Math.PI / 4))).toBeCloseTo(5500 * (1 - 0.25), 6);
    // a planet shrunk onto a smaller layout: every line scaled with it
    const small = materialModel(dem, EARTH_RADIUS / 10);
    expect(snowLineAt(small, 0)).toBeCloseTo(550, 6);
  });

  it('has a model for every preset, with their own colours, and a generic one from the blend colours', () => {
    const families = ['earthlike', 'earth', 'mars', 'moon'].map((p) => materialModel({ ...earthlike, preset: p }, 1884.8));
    expect(families.map((m) => m.family)).toEqual(['earthlike', 'earth', 'mars', 'moon']);
    const lows = new Set(families.map((m) => m.colours.low[0].map((c) => c.toFixed(3)).join()));
    expect(lows.size).toBeGreaterThanOrEqual(3);
    expect(materialModel({ ...earthlike, preset: 'mars' }, 1884.8).iceFrom).toBeLessThan(1);
    expect(materialModel({ ...earthlike, preset: 'moon' }, 1884.8).darkHeight).toBeLessThan(0);
    const generic = materialModel({ ...earthlike, preset: 'sphere' }, 1884.8);
    expect(generic.family).toBe('generic');
    expect(generic.colours.low[0]).toEqual([0.42, 0.5, 0.26]);
  });

  it('packs the model into uniforms the shader can hold (no infinities, one colour pair per slot)', () => {
    for (const preset of ['earthlike', 'earth', 'mars', 'moon', 'sphere']) {
      const u = materialUniforms(materialModel({ ...earthlike, preset }, 1884.8));
      expect(u.colourA.length).toBe(3 * MATERIAL_SLOTS.length);
      for (const x of [...u.colourA, ...u.colourB, ...u.heights, ...u.snow, ...u.shares, ...u.slopes, ...u.extra]) {
        expect(Number.isFinite(x)).toBe(true);
        expect(Math.abs(x)).toBeLessThanOrEqual(1e30);
      }
      expect(u.extra[1]).toBeGreaterThan(0);
    }
  });

  it('is part of the planet parameters, with noise frequencies of the place alone', () => {
    const p = planetParams(earthlike);
    expect(p.materials.family).toBe('earthlike');
    // two tiles per cycle of the place noise, 4 m per cycle of the detail noise
    const tile = ((Math.PI / 2) * 1884.8) / 8 / 32;
    expect(1 / p.noiseFreq).toBeCloseTo(2 * tile, 9);
    expect(p.detailFreq).toBeCloseTo(0.25, 12);
    expect(p.detailPeriod * p.detailFreq).toBeCloseTo(289, 9);
    expect(p.macroFreq).toBeGreaterThan(0);
  });
});

describe('latLonOfDirection', () => {
  it('inverts frames.directionFromLatLon everywhere, including across the antimeridian', () => {
    for (const lat of [-89.5, -45, -1e-6, 0, 30, 89.9]) {
      for (const lon of [-179.99, -120, -0.5, 0, 45, 90, 179.99, 180]) {
        const d = directionFromLatLon(lat, lon);
        const ll = latLonOfDirection(d);
        expect(ll.lat).toBeCloseTo(lat, 9);
        const dl = ((((ll.lon - lon) % 360) + 540) % 360) - 180;
        expect(Math.abs(dl)).toBeLessThan(1e-8);
        const f = latLonFromPosition(d);
        expect(ll.lat).toBeCloseTo(f.lat, 9);
      }
    }
  });

  it('puts longitude 0 on +Z and +90 on +X, the poles on Y', () => {
    expect(latLonOfDirection([0, 0, 1])).toEqual({ lat: 0, lon: 0 });
    expect(latLonOfDirection([1, 0, 0]).lon).toBeCloseTo(90, 12);
    expect(latLonOfDirection([0, 5, 0]).lat).toBeCloseTo(90, 12);
    expect(latLonOfDirection([0, 0, 0])).toEqual({ lat: 0, lon: 0 });
  });
});
