// The camera's state and its motion in the two modes, in f64. Pure: no three.js, no DOM.
//
// The camera is described by latitude, longitude, altitude (metres above the planet's datum: sea
// level, or the middle of the shell without sea), heading (degrees clockwise from north) and pitch
// (degrees above the horizon). ORBIT looks down at the planet (pitch -90, or tilted up to
// ORBIT_MAX_PITCH by a middle drag or two fingers) and moves around it;
// FLY moves freely with the local radial direction as "up"; WALK is FLY glued a few metres above
// the ground.

import {
  add,
  addScaled,
  cameraBasis,
  cross,
  dot,
  enuAt,
  headingPitchOf,
  latLonFromPosition,
  length,
  normalize,
  positionFromLatLon,
  scale,
  wrapHeading,
  type V3,
} from './frames';

export type CameraMode = 'orbit' | 'fly';

export interface CameraState {
  lat: number;
  lon: number;
  /** Metres above the datum radius. */
  alt: number;
  heading: number;
  pitch: number;
}

export interface PlanetShape {
  /** Radius that altitude 0 refers to (sea level, or the middle of the shell). */
  datum: number;
  /** Highest radius the surface can reach. */
  outer: number;
  /** Lowest radius the surface can reach. */
  inner: number;
}

export const MAX_PITCH = 89.5;

/** Orbit's tilt: the highest pitch it looks at (30° under the horizontal); -90 looks straight down. */
export const ORBIT_MAX_PITCH = -30;

/** Orbit: tilted by `deg` (positive: toward the horizon), between straight down and ORBIT_MAX_PITCH. */
export function orbitTilt(s: CameraState, deg: number): CameraState {
  return { ...s, pitch: Math.max(-90, Math.min(ORBIT_MAX_PITCH, s.pitch + deg)) };
}

/** Planet-frame position of a camera state. */
export function cameraPosition(s: CameraState, shape: PlanetShape): V3 {
  return positionFromLatLon(s.lat, s.lon, shape.datum + s.alt);
}

/** Camera state at planet-frame `p` looking along `forward`. */
export function stateFrom(p: V3, forward: V3, shape: PlanetShape): CameraState {
  const { lat, lon, radius } = latLonFromPosition(p);
  const { heading, pitch } = headingPitchOf(p, forward);
  return { lat, lon, alt: radius - shape.datum, heading, pitch };
}

/** Lowest orbit altitude (above the datum): a little above the highest possible terrain. */
export function minOrbitAltitude(shape: PlanetShape): number {
  const margin = Math.max(10, 0.01 * shape.datum);
  return shape.outer - shape.datum + margin;
}

/** Highest altitude allowed in any mode: 50 planet radii. */
export function maxAltitude(shape: PlanetShape): number {
  return 50 * shape.outer;
}

/** The state put into orbit mode: looking at the centre, above the highest terrain. */
export function toOrbit(s: CameraState, shape: PlanetShape): CameraState {
  return {
    ...s,
    alt: Math.min(maxAltitude(shape), Math.max(minOrbitAltitude(shape), s.alt)),
    // looking straight down: the heading becomes the direction at the top of the screen
    heading: s.heading,
    pitch: -90,
  };
}

/** The state put into fly mode from orbit: tilt up to look toward the horizon. */
export function toFly(s: CameraState): CameraState {
  return { ...s, pitch: s.pitch <= -89 ? -35 : s.pitch };
}

/**
 * Orbit: drag by (dx, dy) pixels in a viewport `viewportHeight` pixels tall with vertical field
 * of view `fovDeg`. The ground under the cursor follows it (grab and drag); north is kept where
 * the heading puts it.
 */
export function orbitDrag(
  s: CameraState,
  shape: PlanetShape,
  dx: number,
  dy: number,
  viewportHeight: number,
  fovDeg: number,
): CameraState {
  const p = cameraPosition(s, shape);
  const basis = cameraBasis(p, s.heading, -90);
  const radius = length(p);
  // metres per pixel on the highest surface under the camera
  const above = Math.max(1, radius - shape.outer);
  const mpp = (2 * above * Math.tan((fovDeg * Math.PI) / 360)) / Math.max(1, viewportHeight);
  // angular step on the sphere of the surface, at most a quarter turn per event
  const surfaceR = Math.max(1, Math.min(shape.outer, radius));
  const move = addScaled(scale(basis.right, -dx * mpp), basis.up, dy * mpp);
  const dist = length(move);
  if (dist === 0) return s;
  const angle = Math.min(Math.PI / 2, dist / surfaceR);
  const axis = normalize(cross(normalize(p), normalize(move)));
  const np = rotate(p, axis, angle);
  const nUp = rotate(basis.up, axis, angle);
  const { lat, lon } = latLonFromPosition(np);
  const enu = enuAt(np);
  const heading = wrapHeading((Math.atan2(dot(nUp, enu.east), dot(nUp, enu.north)) * 180) / Math.PI);
  // the tilt stays (the drag moves the ground along the heading, as if seen from straight above)
  return { lat, lon, alt: s.alt, heading, pitch: Math.max(-90, Math.min(ORBIT_MAX_PITCH, s.pitch)) };
}

/** The wheel delta (pixels) that zooms as a pinch of `pinch` (the log of the fingers' distance ratio) does. */
export function pinchAsWheel(pinch: number): number {
  return -pinch / WHEEL_ZOOM;
}

/** Zoom per wheel pixel: the height over the terrain is multiplied by exp(delta * WHEEL_ZOOM). */
const WHEEL_ZOOM = 0.0015;

/** Orbit: zoom by a wheel delta (pixels; positive zooms out), multiplicative in height above the terrain. */
export function orbitZoom(s: CameraState, shape: PlanetShape, wheelDelta: number): CameraState {
  const base = shape.outer - shape.datum; // altitude of the highest terrain
  const above = Math.max(1e-3, s.alt - base);
  const factor = Math.exp(Math.max(-2, Math.min(2, wheelDelta * WHEEL_ZOOM)));
  const alt = Math.min(maxAltitude(shape), Math.max(minOrbitAltitude(shape), base + above * factor));
  return { ...s, alt };
}

/** Rodrigues rotation of `v` about unit `axis` by `angle` radians. */
export function rotate(v: V3, axis: V3, angle: number): V3 {
  const c = Math.cos(angle);
  const sn = Math.sin(angle);
  const kv = cross(axis, v);
  const kd = dot(axis, v) * (1 - c);
  return [
    v[0] * c + kv[0] * sn + axis[0] * kd,
    v[1] * c + kv[1] * sn + axis[1] * kd,
    v[2] * c + kv[2] * sn + axis[2] * kd,
  ];
}

/** Turn the view by mouse-look deltas in degrees (yaw to the right, pitch up). */
export function look(s: CameraState, yawDeg: number, pitchDeg: number): CameraState {
  return {
    ...s,
    heading: wrapHeading(s.heading + yawDeg),
    pitch: Math.max(-MAX_PITCH, Math.min(MAX_PITCH, s.pitch + pitchDeg)),
  };
}

export interface MoveInput {
  /** +1 forward, -1 back */
  forward: number;
  /** +1 right, -1 left */
  right: number;
  /** +1 up (radially), -1 down */
  up: number;
}

/**
 * Fly speed in metres per second: proportional to the height above the ground (or above the
 * highest terrain when the ground is unknown), at least 2 m/s.
 */
export function flySpeed(heightAboveGround: number): number {
  return Math.max(2, 0.8 * Math.abs(heightAboveGround));
}

/**
 * Fly: move by `input` for `dt` seconds at `speed`; `walk` keeps the motion horizontal (the
 * ground snap is done separately). The view direction is kept as a world direction, so heading
 * and pitch are transported to the new position.
 */
export function flyMove(
  s: CameraState,
  shape: PlanetShape,
  input: MoveInput,
  dt: number,
  speed: number,
  walk: boolean,
): { state: CameraState; position: V3 } {
  const p = cameraPosition(s, shape);
  if (input.forward === 0 && input.right === 0 && input.up === 0) return { state: s, position: p };
  const basis = cameraBasis(p, s.heading, s.pitch);
  const enu = enuAt(p);
  const h = (s.heading * Math.PI) / 180;
  const horizontal = add(scale(enu.north, Math.cos(h)), scale(enu.east, Math.sin(h)));
  const fwd = walk ? horizontal : basis.forward;
  let d: V3 = [0, 0, 0];
  d = addScaled(d, fwd, input.forward);
  d = addScaled(d, basis.right, input.right);
  if (!walk) d = addScaled(d, enu.up, input.up);
  const len = length(d);
  if (len === 0) return { state: s, position: p };
  const step = (speed * dt) / Math.max(1, len);
  const np = addScaled(p, d, step);
  const r = length(np);
  const minR = Math.max(1, shape.inner * 0.5);
  const clamped = r < minR ? scale(normalize(np), minR) : np;
  const next = stateFrom(clamped, basis.forward, shape);
  // keep the pitch the user chose (transport may nudge it by rounding)
  next.pitch = Math.max(-MAX_PITCH, Math.min(MAX_PITCH, next.pitch));
  return { state: next, position: clamped };
}
