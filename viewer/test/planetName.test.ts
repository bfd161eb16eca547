import { describe, expect, it } from 'vitest';
import type { PlanetInfo } from '../src/api';
import { EARTHLIKE_INFO } from './fixtures';
import { bodyOfRadius, planetIdentity, planetName } from '../src/planetName';

const preset: PlanetInfo = EARTHLIKE_INFO;

describe('planet names', () => {
  it('names a preset by its name and seed', () => {
    expect(planetName(preset)).toBe('earthlike · seed 7');
  });

  it('names an elevation model by its file and the body of its radius', () => {
    const dem: PlanetInfo = {
      ...preset,
      preset: null,
      seed: '0',
      radius: 6_390_000,
      base_radius: 6_350_000,
      sea_radius: 6_371_000,
      terrain: { kind: 'dem', name: 'dem:earth.pmcdem', seed: '0', file: 'earth.pmcdem' },
    };
    expect(planetName(dem)).toBe('earth.pmcdem · the Earth');
    expect(planetName({ ...dem, sea_radius: null, radius: 3_400_000, base_radius: 3_380_000 })).toBe('earth.pmcdem · Mars');
  });

  it('puts the world first when the server edits one', () => {
    const edit = {
      enabled: true as const, world: 'my.pmcw', revision: 3, active: 3, redo: 0, min_brush_radius: 0.5,
      max_brush_radius: 64, rate_per_second: 5, burst: 10, brushes: ['add'],
    };
    expect(planetName({ ...preset, edit })).toBe('my.pmcw · earthlike · seed 7');
    expect(planetName({ ...preset, edit: { enabled: false, reason: 'no world' } })).toBe('earthlike · seed 7');
  });

  it('gives the radius when no body is that size', () => {
    expect(bodyOfRadius(6_371_000 * 1.005)).toBe('the Earth');
    expect(bodyOfRadius(6_371_000 * 1.05)).toBe('radius 6,690 km');
    expect(bodyOfRadius(1884.8)).toBe('radius 1,885 m');
    expect(bodyOfRadius(1_737_400)).toBe('the Moon');
  });

  it('tells another planet from the same one edited meanwhile (the viewer back online)', () => {
    const edit = {
      enabled: true as const, world: 'my.pmcw', revision: 3, active: 3, redo: 0, min_brush_radius: 0.5,
      max_brush_radius: 64, rate_per_second: 5, burst: 10, brushes: ['add'],
    };
    const before = planetIdentity({ ...preset, edit });
    // edits made meanwhile: the same planet (the edit stream brings them)
    expect(planetIdentity({ ...preset, edit: { ...edit, revision: 5, active: 4, redo: 1 } })).toBe(before);
    // another seed, another world's state (no editing), another layout: another planet
    expect(planetIdentity({ ...preset, seed: '8', edit })).not.toBe(before);
    expect(planetIdentity({ ...preset, edit: { enabled: false, reason: 'no world' } })).not.toBe(before);
    expect(planetIdentity({ ...preset, edit, radius: preset.radius + 1 })).not.toBe(before);
  });
});
