import { describe, expect, it } from 'vitest';
import {
  cameraPosition,
  flyMove,
  look,
  minOrbitAltitude,
  orbitDrag,
  orbitTilt,
  orbitZoom,
  pinchAsWheel,
  ORBIT_MAX_PITCH,
  toFly,
  toOrbit,
  type PlanetShape,
} from '../src/cameraModel';
import { cameraBasis, dot, enuAt, length, normalize, sub } from '../src/frames';

const shape: PlanetShape = { datum: 1884.8, outer: 1995.5, inner: 1810.6 };

describe('orbit', () => {
  it('drags the ground with the cursor', () => {
    const s = { lat: 0, lon: 0, alt: 2000, heading: 0, pitch: -90 };
    // dragging the mouse to the right moves the camera west (the planet turns east under it)
    const right = orbitDrag(s, shape, 100, 0, 600, 50);
    expect(right.lon).toBeLessThan(0);
    expect(right.lat).toBeCloseTo(0, 9);
    // dragging down moves the camera north
    const down = orbitDrag(s, shape, 0, 100, 600, 50);
    expect(down.lat).toBeGreaterThan(0);
    expect(down.alt).toBe(2000);
    expect(down.pitch).toBe(-90);
  });

  it('crosses the pole without flipping', () => {
    let s = { lat: 80, lon: 10, alt: 2000, heading: 0, pitch: -90 };
    for (let n = 0; n < 40; n++) s = orbitDrag(s, shape, 0, 20, 600, 50);
    // past the pole, going on in the same direction: now heading south on the other side
    expect(Math.abs(Math.abs(s.lon - 10) - 180)).toBeLessThan(1e-6);
    expect(Math.abs(s.heading - 180)).toBeLessThan(1e-6);
  });

  it('zooms multiplicatively and keeps above the terrain', () => {
    const s = { lat: 0, lon: 0, alt: 3000, heading: 0, pitch: -90 };
    expect(orbitZoom(s, shape, 100).alt).toBeGreaterThan(3000);
    expect(orbitZoom(s, shape, -100).alt).toBeLessThan(3000);
    let z = s;
    for (let n = 0; n < 100; n++) z = orbitZoom(z, shape, -500);
    expect(z.alt).toBe(minOrbitAltitude(shape));
    expect(shape.datum + z.alt).toBeGreaterThan(shape.outer);
  });

  it('tilts between straight down and 30° under the horizontal, and a drag keeps the tilt', () => {
    const s = { lat: 0, lon: 0, alt: 2000, heading: 0, pitch: -90 };
    expect(orbitTilt(s, 20).pitch).toBe(-70);
    expect(orbitTilt(s, 200).pitch).toBe(ORBIT_MAX_PITCH);
    expect(orbitTilt(orbitTilt(s, 30), -100).pitch).toBe(-90);
    const tilted = orbitTilt(s, 40);
    const moved = orbitDrag(tilted, shape, 0, 100, 600, 50);
    expect(moved.pitch).toBe(-50);
    // the drag moves the ground as seen from above: the same place as without the tilt
    const flat = orbitDrag(s, shape, 0, 100, 600, 50);
    expect([moved.lat, moved.lon, moved.heading]).toEqual([flat.lat, flat.lon, flat.heading]);
  });

  it('zooms with a pinch as the wheel does: spreading the fingers comes closer', () => {
    const s = { lat: 0, lon: 0, alt: 3000, heading: 0, pitch: -90 };
    const base = shape.outer - shape.datum;
    const closer = orbitZoom(s, shape, pinchAsWheel(Math.log(2)));
    // twice as far apart: half the height over the highest terrain
    expect(closer.alt - base).toBeCloseTo((s.alt - base) / 2, 9);
    expect(orbitZoom(s, shape, pinchAsWheel(-Math.log(2))).alt - base).toBeCloseTo(2 * (s.alt - base), 9);
  });

  it('switching modes keeps the place', () => {
    const fly = toFly({ lat: 5, lon: 6, alt: 20, heading: 30, pitch: -90 });
    expect(fly.pitch).toBeGreaterThan(-89);
    const orbit = toOrbit(fly, shape);
    expect([orbit.lat, orbit.lon, orbit.pitch]).toEqual([5, 6, -90]);
    expect(orbit.alt).toBe(minOrbitAltitude(shape));
  });
});

describe('fly', () => {
  it('moves along the view, up along the radial direction, and keeps the view direction', () => {
    const s = { lat: -10, lon: 8, alt: 100, heading: 45, pitch: -10 };
    const p0 = cameraPosition(s, shape);
    const f0 = cameraBasis(p0, s.heading, s.pitch).forward;
    const { state, position } = flyMove(s, shape, { forward: 1, right: 0, up: 0 }, 0.5, 10, false);
    const d = sub(position, p0);
    expect(length(d)).toBeCloseTo(5, 9);
    expect(dot(normalize(d), f0)).toBeCloseTo(1, 9);
    // the world view direction is unchanged (transported heading and pitch)
    const f1 = cameraBasis(position, state.heading, state.pitch).forward;
    expect(dot(f0, f1)).toBeCloseTo(1, 9);
    const climb = flyMove(s, shape, { forward: 0, right: 0, up: 1 }, 1, 3, false);
    expect(climb.state.alt).toBeCloseTo(103, 6);
    expect(climb.state.lat).toBeCloseTo(-10, 9);
  });

  it('walking stays horizontal', () => {
    const s = { lat: 0, lon: 0, alt: 2, heading: 90, pitch: -60 };
    const { position } = flyMove(s, shape, { forward: 1, right: 0, up: 1 }, 1, 2, true);
    const d = sub(position, cameraPosition(s, shape));
    expect(dot(d, enuAt(cameraPosition(s, shape)).up)).toBeCloseTo(0, 9);
    expect(dot(normalize(d), [1, 0, 0])).toBeCloseTo(1, 9); // heading 90 at lon 0 is +X
  });

  it('mouse look clamps the pitch', () => {
    const s = look({ lat: 0, lon: 0, alt: 2, heading: 350, pitch: 80 }, 20, 30);
    expect(s.heading).toBeCloseTo(10, 9);
    expect(s.pitch).toBe(89.5);
  });
});
