import { describe, expect, it } from 'vitest';
import { buildSeaDisk, seaDiskStale } from '../src/seaGeometry';
import { positionFromLatLon, type V3 } from '../src/frames';

describe('sea disk', () => {
  it('puts every vertex on the sea sphere, even at Earth radius', () => {
    const R = 6.371e6;
    const camera = positionFromLatLon(-10, 8, R + 250);
    const disk = buildSeaDisk(camera, R);
    let worst = 0;
    for (let v = 0; v < disk.positions.length / 3; v++) {
      // planet-frame position in f64 from the f32 offset
      const p: V3 = [0, 1, 2].map((c) => disk.origin[c]! + disk.positions[3 * v + c]!) as V3;
      worst = Math.max(worst, Math.abs(Math.hypot(...p) - R));
    }
    // f32 offsets up to the horizon (~56 km) keep a few millimetres
    expect(worst).toBeLessThan(0.01);
    // the inner ring is a few metres from the nadir, the disk reaches the horizon
    expect(disk.innerAngle * R).toBeLessThan(10);
    expect(disk.outerAngle).toBeGreaterThanOrEqual(Math.acos(R / (R + 250)));
  });

  it('has outward normals and triangles wound counter-clockwise from above', () => {
    const disk = buildSeaDisk([0, 3000, 0], 1884.8, { rings: 8, segments: 12 });
    const pos = disk.positions;
    for (let t = 0; t < disk.indices.length; t += 3) {
      const [a, b, c] = [disk.indices[t]!, disk.indices[t + 1]!, disk.indices[t + 2]!];
      const e1 = [0, 1, 2].map((k) => pos[3 * b + k]! - pos[3 * a + k]!);
      const e2 = [0, 1, 2].map((k) => pos[3 * c + k]! - pos[3 * a + k]!);
      const ny = e1[2]! * e2[0]! - e1[0]! * e2[2]!; // y component of e1 x e2
      expect(ny).toBeGreaterThan(0); // faces +Y (up at the north pole)
    }
    for (let v = 0; v < disk.normals.length / 3; v++) {
      expect(Math.hypot(disk.normals[3 * v]!, disk.normals[3 * v + 1]!, disk.normals[3 * v + 2]!)).toBeCloseTo(1, 5);
    }
    expect(Math.max(...disk.indices)).toBe(disk.positions.length / 3 - 1);
  });

  it('is rebuilt when the camera moves or climbs', () => {
    const R = 2000;
    const at: V3 = [0, 0, R + 100];
    const disk = buildSeaDisk(at, R);
    expect(seaDiskStale(disk, at, at, R)).toBe(false);
    expect(seaDiskStale(disk, at, [0, 0, R + 105], R)).toBe(false);
    expect(seaDiskStale(disk, at, [0, 0, R + 120], R)).toBe(true);
    expect(seaDiskStale(disk, at, [5, 0, R + 100], R)).toBe(true);
    expect(seaDiskStale(disk, at, [0, 0, R - 1], R)).toBe(true); // dived under the surface
  });
});
