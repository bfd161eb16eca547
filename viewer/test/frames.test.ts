import { describe, expect, it } from 'vitest';
import {
  cameraBasis,
  cross,
  directionFromLatLon,
  dot,
  enuAt,
  headingPitchOf,
  latLonFromPosition,
  length,
  modPositive,
  normalize,
  positionFromLatLon,
  relativeToCamera,
  splitHighLow,
  splitPositions,
  sub,
  wrapLon,
  type V3,
} from '../src/frames';

const close = (a: V3, b: V3, eps = 1e-12): void => {
  for (let n = 0; n < 3; n++) expect(Math.abs(a[n]! - b[n]!)).toBeLessThan(eps);
};

describe('lat/lon <-> planet frame', () => {
  it('puts the axes where the spec says', () => {
    close(directionFromLatLon(0, 0), [0, 0, 1]); // lon 0 on +Z
    close(directionFromLatLon(0, 90), [1, 0, 0]); // 90 E on +X
    close(directionFromLatLon(90, 0), [0, 1, 0]); // north pole +Y
    close(directionFromLatLon(-90, 0), [0, -1, 0]);
    close(directionFromLatLon(0, -90), [-1, 0, 0]);
    close(directionFromLatLon(0, 180), [0, 0, -1]);
  });

  it('round-trips lat/lon/radius on a grid, at Earth radius', () => {
    for (let lat = -89; lat <= 89; lat += 7.3) {
      for (let lon = -179; lon <= 180; lon += 11.1) {
        const p = positionFromLatLon(lat, lon, 6.4e6);
        const back = latLonFromPosition(p);
        expect(back.lat).toBeCloseTo(lat, 9);
        expect(back.lon).toBeCloseTo(lon, 9);
        expect(back.radius / 6.4e6).toBeCloseTo(1, 12);
      }
    }
  });

  it('handles the poles and the origin', () => {
    expect(latLonFromPosition([0, 5, 0])).toEqual({ lat: 90, lon: 0, radius: 5 });
    expect(latLonFromPosition([0, 0, 0])).toEqual({ lat: 0, lon: 0, radius: 0 });
  });

  it('wraps longitudes', () => {
    expect(wrapLon(190)).toBe(-170);
    expect(wrapLon(-190)).toBe(170);
    expect(wrapLon(180)).toBe(180);
    expect(wrapLon(-180)).toBe(180);
    expect(wrapLon(720 + 5)).toBe(5);
  });
});

describe('east/north/up', () => {
  it('is orthonormal and right-handed everywhere, up radial', () => {
    for (let lat = -90; lat <= 90; lat += 15) {
      for (let lon = -180; lon < 180; lon += 20) {
        const p = positionFromLatLon(lat, lon, 2000);
        const { east, north, up } = enuAt(p);
        for (const v of [east, north, up]) expect(length(v)).toBeCloseTo(1, 12);
        expect(dot(east, north)).toBeCloseTo(0, 12);
        expect(dot(east, up)).toBeCloseTo(0, 12);
        expect(dot(north, up)).toBeCloseTo(0, 12);
        close(cross(east, north), up, 1e-12);
        close(up, normalize(p), 1e-12);
        if (Math.abs(lat) < 90) {
          // north points toward increasing latitude, east toward increasing longitude
          const dNorth = sub(positionFromLatLon(lat + 1e-4, lon, 2000), p);
          const dEast = sub(positionFromLatLon(lat, lon + 1e-4, 2000), p);
          expect(dot(normalize(dNorth), north)).toBeGreaterThan(0.999999);
          expect(dot(normalize(dEast), east)).toBeGreaterThan(0.999999);
        }
      }
    }
  });

  it('at lat 0 lon 0: east +X, north +Y, up +Z', () => {
    const f = enuAt([0, 0, 6.4e6]);
    close(f.east, [1, 0, 0]);
    close(f.north, [0, 1, 0]);
    close(f.up, [0, 0, 1]);
  });
});

describe('camera basis', () => {
  it('is orthonormal with the radial direction as up at pitch 0', () => {
    const p = positionFromLatLon(-10, 8, 1872);
    for (const heading of [0, 37, 90, 200, 359]) {
      const b = cameraBasis(p, heading, 0);
      expect(dot(b.forward, b.right)).toBeCloseTo(0, 12);
      expect(dot(b.forward, b.up)).toBeCloseTo(0, 12);
      expect(dot(b.right, b.up)).toBeCloseTo(0, 12);
      close(b.up, normalize(p), 1e-12);
      close(cross(b.right, b.up), [-b.forward[0], -b.forward[1], -b.forward[2]], 1e-12);
    }
  });

  it('heading 0 looks north, 90 east; pitch -90 looks down with north on top', () => {
    const p = positionFromLatLon(30, 40, 1000);
    const enu = enuAt(p);
    close(cameraBasis(p, 0, 0).forward, enu.north, 1e-12);
    close(cameraBasis(p, 90, 0).forward, enu.east, 1e-12);
    const down = cameraBasis(p, 0, -90);
    close(down.forward, [-enu.up[0], -enu.up[1], -enu.up[2]], 1e-12);
    close(down.up, enu.north, 1e-12);
    close(down.right, enu.east, 1e-12);
  });

  it('heading and pitch round-trip through a view direction', () => {
    const p = positionFromLatLon(-10, 8, 6.4e6);
    for (const [h, pt] of [
      [0, 0],
      [45, -20],
      [180, 30],
      [300, -80],
    ] as const) {
      const b = cameraBasis(p, h, pt);
      const back = headingPitchOf(p, b.forward);
      expect(back.heading).toBeCloseTo(h, 9);
      expect(back.pitch).toBeCloseTo(pt, 9);
    }
  });
});

describe('floating origin', () => {
  it('gives exact small offsets for chunks near a camera at Earth radius', () => {
    const R = 6.4e6;
    const camera = positionFromLatLon(-10.123456, 8.654321, R + 1.75);
    // a chunk origin a few hundred metres away, as the server would send it (an f64)
    const origin: V3 = [camera[0] + 123.456, camera[1] - 78.9, camera[2] + 0.3];
    const rel = relativeToCamera(origin, camera);
    // the offsets are what they should be to within f64 rounding at planet scale (~1e-9 m) ...
    expect(Math.abs(rel[0] - 123.456)).toBeLessThan(1e-8);
    expect(Math.abs(rel[1] + 78.9)).toBeLessThan(1e-8);
    expect(Math.abs(rel[2] - 0.3)).toBeLessThan(1e-8);
    // ... and survive the f32 conversion of a mesh position to within f32 rounding of the offset,
    // a million times better than storing the planet-frame position as f32
    const f32 = Float32Array.from(rel);
    expect(Math.abs(f32[0]! - 123.456)).toBeLessThan(1e-5);
    expect(Math.abs(f32[2]! - 0.3)).toBeLessThan(1e-7);
    const naive = Float32Array.from(origin).map((x, n) => x - Math.fround(camera[n]!));
    expect(Math.abs(naive[2]! - 0.3)).toBeGreaterThan(0.1); // what a non-floating origin loses (f32 steps of 0.5 m)
  });

  it('moves every vertex by the camera motion exactly (no jitter between frames)', () => {
    const R = 6.4e6;
    const origin: V3 = [1234.5, -2345.25, R - 0.125];
    const vertex = Float32Array.from([10.5, -3.25, 7.125]);
    let prev: number[] | null = null;
    for (let step = 0; step < 50; step++) {
      const camera: V3 = [1200 + step * 0.01, -2300, R + 2];
      const rel = relativeToCamera(origin, camera);
      // the render-space vertex, as the GPU computes it (f32)
      const onScreen = [0, 1, 2].map((n) => Math.fround(Math.fround(rel[n]!) + vertex[n]!));
      if (prev) {
        // moving the camera 1 cm moves the vertex by 1 cm, to within f32 rounding at ~50 m
        expect(Math.abs(prev[0]! - onScreen[0]! - 0.01)).toBeLessThan(1e-5);
        expect(Math.abs(prev[1]! - onScreen[1]!)).toBeLessThan(1e-5);
      }
      prev = onScreen;
    }
  });

  it('takes origins modulo the noise period without losing precision', () => {
    const period = 289 / 0.01;
    const a = 6.4e6 + 12.5;
    const b = a + 45.25; // a neighbouring chunk 45.25 m further
    const ma = modPositive(a, period);
    const mb = modPositive(b, period);
    expect(ma).toBeGreaterThanOrEqual(0);
    expect(ma).toBeLessThan(period);
    expect(modPositive(-1, period)).toBeCloseTo(period - 1, 9);
    // the noise sees the same relative offset between the chunks (unless one wrapped)
    expect(mb - ma).toBeCloseTo(45.25, 9);
  });
});

describe('eye-relative positions from high and low parts', () => {
  // the server's way: a place p (f64) stored relative to a chunk origin as f32 high and low parts
  const store = (p: V3, o: V3): { pos: number[]; low: number[] } => {
    const pos = [0, 1, 2].map((n) => Math.fround(p[n]! - o[n]!));
    return { pos, low: [0, 1, 2].map((n) => Math.fround(p[n]! - o[n]! - pos[n]!)) };
  };
  /** The shader's sum, with every operation rounded to f32. */
  const eyeRelative = (high: number[], low: number[], eye: V3): number[] => {
    const e = splitHighLow(eye);
    const f = Math.fround;
    return [0, 1, 2].map((n) => f(f(high[n]! - e.high[n]!) + f(low[n]! - e.low[n]!)));
  };

  it('draws the copies of a vertex in chunks of other origins on the same bits, where the f32 offsets alone do not', () => {
    let seed = 7;
    const rand = (): number => {
      seed = (seed * 16807) % 2147483647;
      return seed / 2147483647;
    };
    let same = 0;
    let sameWithoutLow = 0;
    const trials = 2000;
    for (let t = 0; t < trials; t++) {
      // a place on the Earth's surface, two chunk origins up to 300 km away, the eye 10 km off
      const dir = normalize([rand() - 0.5, rand() - 0.5, rand() - 0.5]);
      const p: V3 = [dir[0] * 6371000.3, dir[1] * 6371000.3, dir[2] * 6371000.3];
      const o1: V3 = [p[0] + 3e5 * (rand() - 0.5), p[1] + 3e5 * (rand() - 0.5), p[2] + 3e5 * (rand() - 0.5)];
      const o2: V3 = [p[0] + 3e3 * (rand() - 0.5), p[1] + 3e3 * (rand() - 0.5), p[2] + 3e3 * (rand() - 0.5)];
      const eye: V3 = [p[0] + 1e4 * (rand() - 0.5), p[1] + 1e4 * (rand() - 0.5), p[2] + 1e4 * (rand() - 0.5)];
      const a = store(p, o1);
      const b = store(p, o2);
      const sa = splitPositions(o1, new Float32Array(a.pos), new Float32Array(a.low));
      const sb = splitPositions(o2, new Float32Array(b.pos), new Float32Array(b.low));
      expect([...sa.high]).toEqual([...sb.high]);
      const ra = eyeRelative([...sa.high], [...sa.low], eye);
      const rb = eyeRelative([...sb.high], [...sb.low], eye);
      if (ra.every((x, n) => x === rb[n])) same++;
      // without the low parts (as before): the chunks' f32 offsets alone
      const na = splitPositions(o1, new Float32Array(a.pos), null);
      const nb = splitPositions(o2, new Float32Array(b.pos), null);
      const qa = eyeRelative([...na.high], [...na.low], eye);
      const qb = eyeRelative([...nb.high], [...nb.low], eye);
      if (qa.every((x, n) => x === qb[n])) sameWithoutLow++;
      // and the eye-relative place is right to a fraction of a millimetre
      for (let n = 0; n < 3; n++) expect(Math.abs(ra[n]! - (p[n]! - eye[n]!))).toBeLessThan(1e-3);
    }
    expect(same).toBeGreaterThanOrEqual(trials - 2);
    expect(sameWithoutLow).toBeLessThan(trials / 2);
  });

  it('splits a point into an f32 and the f32 of the rest', () => {
    const { high, low } = splitHighLow([6371000.123456789, -1.5, 1e-12]);
    expect(high[0]).toBe(Math.fround(6371000.123456789));
    expect(low[0]).toBe(Math.fround(6371000.123456789 - high[0]));
    expect(Math.abs(high[0] + low[0] - 6371000.123456789)).toBeLessThan(1e-8);
    expect(high[1]).toBe(-1.5);
    expect(low[1]).toBe(0);
  });
});
