import { describe, expect, it } from 'vitest';
import { Flight, parseGoTo } from '../src/goTo';

describe('the go-to box', () => {
  it('reads decimal degrees, with or without an altitude', () => {
    expect(parseGoTo('27.98, 86.92')).toEqual({ lat: 27.98, lon: 86.92, alt: null });
    expect(parseGoTo(' -33.9 18.4 2 km ')).toEqual({ lat: -33.9, lon: 18.4, alt: 2000 });
    expect(parseGoTo('40.85,14.3,5000')).toEqual({ lat: 40.85, lon: 14.3, alt: 5000 });
    expect(parseGoTo('10 S, 200 E, 30 m')).toEqual({ lat: -10, lon: -160, alt: 30 });
  });

  it('reads degrees, minutes and seconds with hemispheres', () => {
    const everest = parseGoTo("27°59'N 86°55'E");
    expect(everest).toMatchObject({ alt: null });
    if ('error' in everest) throw new Error(everest.error);
    expect(everest.lat).toBeCloseTo(27 + 59 / 60, 12);
    expect(everest.lon).toBeCloseTo(86 + 55 / 60, 12);
    const south = parseGoTo('33°55′30″S, 18°25′E, 1 km');
    if ('error' in south) throw new Error(south.error);
    expect(south.lat).toBeCloseTo(-(33 + 55 / 60 + 30 / 3600), 12);
    expect(south.lon).toBeCloseTo(18 + 25 / 60, 12);
    expect(south.alt).toBe(1000);
  });

  it('says what is wrong', () => {
    for (const bad of ['', 'Paris', '91, 0', '12', '1, 2, 3, 4', '10 E, 20 N', '-10 S, 20', "10°75'N 20E", '10, 20, high', 'NaN, 3']) {
      const r = parseGoTo(bad);
      expect('error' in r, bad).toBe(true);
    }
  });
});

describe('the flight', () => {
  const datum = 6_371_000;
  it('starts and ends where asked, along the great circle, climbing between', () => {
    const f = new Flight({ lat: 0, lon: 0, alt: 1000 }, { lat: 0, lon: 90, alt: 500 }, datum);
    expect(f.at(0)).toEqual({ lat: 0, lon: 0, alt: 1000 });
    expect(f.at(f.duration)).toEqual({ lat: 0, lon: 90, alt: 500 });
    expect(f.at(f.duration + 5)).toEqual({ lat: 0, lon: 90, alt: 500 });
    const mid = f.at(f.duration / 2);
    expect(mid.lat).toBeCloseTo(0, 9);
    expect(mid.lon).toBeCloseTo(45, 6);
    // a third of the way (10 000 km): the middle of the way is the peak
    expect(f.peak).toBeCloseTo((Math.PI / 2) * datum / 3, 3);
    expect(mid.alt).toBeCloseTo(f.peak, 0);
    // across the planet, never higher than its radius
    expect(new Flight({ lat: 0, lon: 0, alt: 0 }, { lat: 0, lon: 179, alt: 0 }, datum).peak).toBe(datum);
    expect(f.duration).toBeGreaterThan(2);
    expect(f.duration).toBeLessThanOrEqual(9);
    // the longitude goes one way only, the altitude up then down
    let lon = -1;
    let alt = 0;
    let climbing = true;
    for (let t = 0; t <= f.duration; t += f.duration / 50) {
      const p = f.at(t);
      expect(p.lon).toBeGreaterThanOrEqual(lon - 1e-9);
      lon = p.lon;
      if (p.alt < alt) climbing = false;
      else if (!climbing) expect(p.alt).toBeLessThanOrEqual(alt + 1e-6);
      alt = p.alt;
    }
  });

  it('takes the short way across the antimeridian and over a pole', () => {
    const f = new Flight({ lat: 10, lon: 170, alt: 100 }, { lat: 10, lon: -170, alt: 100 }, datum);
    const mid = f.at(f.duration / 2);
    expect(Math.abs(mid.lon)).toBeGreaterThan(175);
    const polar = new Flight({ lat: 80, lon: 0, alt: 100 }, { lat: 80, lon: 180, alt: 100 }, datum);
    expect(polar.at(polar.duration / 2).lat).toBeCloseTo(90, 3);
  });

  it('hops without a climb, also from under the sea', () => {
    const hop = new Flight({ lat: 1, lon: 1, alt: 100 }, { lat: 1, lon: 1, alt: 2000 }, datum);
    expect(hop.peak).toBe(2000);
    expect(hop.at(hop.duration / 2).lat).toBeCloseTo(1, 9);
    const floor = new Flight({ lat: 27.9, lon: 86.9, alt: -3448 }, { lat: 27.91, lon: 86.9, alt: -3440 }, datum);
    for (let t = 0; t <= floor.duration; t += 0.1) expect(floor.at(t).alt).toBeLessThan(0);
    expect(() => new Flight({ lat: NaN, lon: 0, alt: 0 }, { lat: 0, lon: 0, alt: 0 }, datum)).toThrow();
  });
});

describe('the go-to box, mixed forms', () => {
  it('reads hemispheres with a comma-separated altitude', () => {
    const r = parseGoTo("27°59'N 86°55'E, 300");
    if ('error' in r) throw new Error(r.error);
    expect(r.lat).toBeCloseTo(27 + 59 / 60, 12);
    expect(r.lon).toBeCloseTo(86 + 55 / 60, 12);
    expect(r.alt).toBe(300);
    const s = parseGoTo('10 S, 20 W');
    expect(s).toEqual({ lat: -10, lon: -20, alt: null });
  });
});
