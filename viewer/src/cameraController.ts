// The camera controller: the camera's state (cameraModel.ts) and mode, moved by the input every
// frame, kept on the ground when walking and measured above it when flying; the three.js camera
// placed from it (orientation and clip planes, at the render origin: the floating origin); what
// lies under a canvas pixel and where a point shows, with the camera of the last frame.

import * as THREE from 'three';
import {
  cameraPosition,
  flyMove,
  flySpeed,
  look,
  maxAltitude,
  minOrbitAltitude,
  orbitDrag,
  orbitTilt,
  orbitZoom,
  pinchAsWheel,
  ORBIT_MAX_PITCH,
  toFly,
  toOrbit,
  type CameraMode,
  type CameraState,
  type PlanetShape,
} from './cameraModel';
import { loadRange } from './chunkSelection';
import { addScaled, cameraBasis, length, normalize, wrapLon, type CameraBasis, type V3 } from './frames';
import type { InputFrame } from './input';
import type { PlanetParams } from './planetParams';
import type { UrlState } from './urlState';

export const FOV = 50;
const EYE_HEIGHT = 2;
const STEP_CLIMB = 1.5;

/** A point of the loaded terrain under a pixel. */
export interface PickResult {
  /** Metres from the camera along the ray. */
  distance: number;
  /** The point, planet frame, metres. */
  point: V3;
  /** The chunk hit. */
  key: string;
}

/** The camera of a frame. */
export interface CameraFrame {
  /** The camera, planet frame. */
  pos: V3;
  basis: CameraBasis;
  /** The input moved the camera, or walking moved it onto the ground. */
  moved: boolean;
}

export class CameraController {
  readonly camera = new THREE.PerspectiveCamera(FOV, 1, 0.05, 1e5);
  state: CameraState = { lat: 20, lon: 15, alt: NaN, heading: 0, pitch: -90 };
  mode: CameraMode = 'orbit';
  walk = false;
  /** Metres from the eye down to the loaded terrain (walk and fly), null when not known. */
  aboveGround: number | null = null;
  /** The chunks shown changed since the ground was last measured (see `groundChanged`). */
  private groundStale = false;
  /** The load range of the last frame, metres. */
  range = 1;
  /** The camera of the last frame, planet frame (the floating origin). */
  position: V3 = [0, 0, 0];
  private speedFactor = 1;
  private readonly raycaster = Object.assign(new THREE.Raycaster(), { firstHitOnly: true });
  private readonly ndc = new THREE.Vector2();

  /** `terrain()`: the meshes of the loaded terrain, placed around the camera. */
  constructor(
    private readonly canvas: HTMLCanvasElement,
    private readonly terrain: () => THREE.Object3D[],
  ) {
    this.camera.position.set(0, 0, 0);
    this.camera.matrixAutoUpdate = false;
  }

  /** The canvas size, CSS pixels. */
  viewport(): { width: number; height: number } {
    return {
      width: this.canvas.clientWidth || window.innerWidth,
      height: this.canvas.clientHeight || window.innerHeight,
    };
  }

  setAspect(aspect: number): void {
    this.camera.aspect = aspect;
    this.camera.updateProjectionMatrix();
  }

  /** Keeps the altitude between the mode's lowest (above the terrain in orbit) and the highest. */
  clampAltitude(shape: PlanetShape | null): void {
    if (!shape) return;
    const min = this.mode === 'orbit' ? minOrbitAltitude(shape) : -shape.datum + 1;
    this.state.alt = Math.min(maxAltitude(shape), Math.max(min, this.state.alt));
  }

  /** Switches to `mode` (orbit leaves walking); false when it is the mode already. */
  setMode(mode: CameraMode, shape: PlanetShape | null): boolean {
    if (mode === this.mode) return false;
    this.mode = mode;
    if (mode === 'orbit') {
      this.walk = false;
      if (shape) this.state = toOrbit(this.state, shape);
    } else {
      this.state = toFly(this.state);
    }
    this.clampAltitude(shape);
    return true;
  }

  /** Walking on or off (the caller switches to fly first); walking looks at most 60° up or down. */
  setWalk(walk: boolean): void {
    this.walk = walk;
    if (walk) this.state.pitch = Math.max(-60, Math.min(60, this.state.pitch));
  }

  /**
   * Places the camera; a view that is not straight down switches orbit to fly. Returns whether
   * the mode changed.
   */
  setCamera(lat: number, lon: number, alt: number, heading: number | undefined, pitch: number | undefined, shape: PlanetShape | null): boolean {
    if (![lat, lon, alt].every(Number.isFinite)) throw new Error('setCamera: lat, lon and altitude must be finite numbers');
    const s: CameraState = {
      lat: Math.max(-90, Math.min(90, lat)),
      lon: wrapLon(lon),
      alt,
      heading: heading ?? this.state.heading,
      pitch: pitch ?? this.state.pitch,
    };
    let switched = false;
    // a view that is not straight down needs the fly mode
    if (pitch !== undefined && pitch > -89.5 && this.mode === 'orbit') {
      this.mode = 'fly';
      switched = true;
    }
    if (this.mode === 'orbit') s.pitch = -90;
    this.state = s;
    this.clampAltitude(shape);
    return switched;
  }

  /** The mode and the camera of a URL hash (what it holds of them). */
  applyUrlState(u: UrlState, shape: PlanetShape | null): void {
    if (u.mode) this.mode = u.mode;
    if (u.walk !== undefined) this.walk = u.walk && this.mode === 'fly';
    const s = this.state;
    if (u.lat !== undefined) s.lat = u.lat;
    if (u.lon !== undefined) s.lon = wrapLon(u.lon);
    if (u.alt !== undefined) s.alt = u.alt;
    if (u.heading !== undefined) s.heading = u.heading;
    if (u.pitch !== undefined) s.pitch = Math.max(-90, Math.min(90, u.pitch));
    // orbit keeps a tilt (a link to a tilted orbit view opens it tilted), at most ORBIT_MAX_PITCH
    if (this.mode === 'orbit') s.pitch = u.pitch !== undefined ? Math.min(ORBIT_MAX_PITCH, s.pitch) : -90;
    this.clampAltitude(shape);
  }

  /**
   * The camera of frame number `frame`: moved by `input` over `dt` seconds, placed (`place`
   * puts the scene around a camera position, render space relative to it), on the ground when
   * walking, oriented, with its clip planes and the load range.
   */
  frame(input: InputFrame, params: PlanetParams, dt: number, frame: number, place: (pos: V3) => void): CameraFrame {
    const shape = params.shape;
    let moved = this.steer(input, shape, dt);
    this.clampAltitude(shape);
    let pos = cameraPosition(this.state, shape);
    place(pos);

    // ground: walk snaps the eye above it; fly measures it (every few frames)
    const up = normalize(pos);
    if (this.walk) {
      const probe = STEP_CLIMB - EYE_HEIGHT; // ray origin relative to the eye, along up
      const d = this.groundDistance(addScaled([0, 0, 0], up, probe), up, 5000);
      if (d !== null) {
        const below = d - probe; // height of the eye above the ground now
        const want = EYE_HEIGHT - below;
        // climb at once, fall at most 25 m/s
        const adjust = want > 0 ? want : Math.max(want, -25 * Math.max(dt, 1 / 60));
        this.state.alt += adjust;
        this.aboveGround = below + adjust;
        pos = cameraPosition(this.state, shape);
        place(pos);
        moved = true;
      }
    } else if (this.mode === 'fly' && (frame % 6 === 0 || moved || this.groundStale)) {
      this.groundStale = false;
      this.aboveGround = this.groundDistance([0, 0, 0], up, 4 * shape.outer);
    } else if (this.mode === 'orbit') {
      this.aboveGround = null;
    }

    // camera orientation and clip planes
    const basis = cameraBasis(pos, this.state.heading, this.state.pitch);
    const m = new THREE.Matrix4().makeBasis(
      new THREE.Vector3(...basis.right),
      new THREE.Vector3(...basis.up),
      new THREE.Vector3(-basis.forward[0], -basis.forward[1], -basis.forward[2]),
    );
    this.camera.matrix.copy(m);
    this.camera.matrixWorld.copy(m);
    this.camera.matrixWorldInverse.copy(m).invert();
    // clip planes: with the logarithmic depth buffer only the far plane's order of magnitude
    // matters for precision; near stays a few centimetres up to a tenth of the height above the
    // highest terrain (or the ground measured below), far reaches past the horizon
    const r = length(pos);
    const clearance = Math.max(r - shape.outer, this.aboveGround ?? 0);
    this.camera.near = Math.min(1e4, Math.max(0.05, 0.1 * clearance));
    this.range = loadRange(r, params.extent, Math.max(4 * params.chunkWidth, 100));
    this.camera.far = Math.max(this.camera.near * 10, this.range * 1.05 + params.chunkWidth);
    this.camera.updateProjectionMatrix();
    this.position = pos;
    return { pos, basis, moved };
  }

  /**
   * The chunks shown changed: flying, the ground is measured again at the next frame, not up to
   * six frames later. The near plane follows the height above the ground, and the view's
   * selection its frustum, so a view is settled only once the ground under it was measured on
   * the chunks it shows (a selection made from the ground of coarser chunks changed after the
   * view was reported ready).
   */
  groundChanged(): void {
    this.groundStale = true;
  }

  /** Orbit: drag and zoom; fly and walk: look, speed on the wheel, move. True when it moved. */
  private steer(input: InputFrame, shape: PlanetShape, dt: number): boolean {
    let moved = false;
    if (this.mode === 'orbit') {
      if (input.dragX !== 0 || input.dragY !== 0) {
        this.state = orbitDrag(this.state, shape, input.dragX, input.dragY, this.viewport().height, FOV);
        moved = true;
      }
      if (input.wheel !== 0 || input.pinch !== 0) {
        this.state = orbitZoom(this.state, shape, input.wheel + pinchAsWheel(input.pinch));
        moved = true;
      }
      if (input.tilt !== 0) {
        this.state = orbitTilt(this.state, input.tilt);
        moved = true;
      }
    } else {
      if (input.tilt !== 0) {
        this.state = look(this.state, 0, input.tilt);
        if (this.walk) this.state.pitch = Math.max(-80, Math.min(80, this.state.pitch));
        moved = true;
      }
      if (input.pinch !== 0) {
        // a pinch moves along the view: spreading the fingers twice as far goes ln 2 of the
        // height over the ground forward
        const r = length(cameraPosition(this.state, shape));
        const height = this.aboveGround ?? Math.max(1, r - shape.outer);
        const step = Math.max(-2, Math.min(2, input.pinch)) * Math.max(1, height);
        this.state = flyMove(this.state, shape, { forward: Math.sign(step), right: 0, up: 0 }, 1, Math.abs(step), this.walk).state;
        moved = true;
      }
      if (input.dragX !== 0 || input.dragY !== 0) {
        this.state = look(this.state, input.dragX * 0.15, -input.dragY * 0.15);
        if (this.walk) this.state.pitch = Math.max(-80, Math.min(80, this.state.pitch));
        moved = true;
      }
      if (input.wheel !== 0) {
        this.speedFactor = Math.min(100, Math.max(0.01, this.speedFactor * Math.exp(-input.wheel * 0.001)));
      }
      if (input.forward !== 0 || input.right !== 0 || input.up !== 0) {
        const r = length(cameraPosition(this.state, shape));
        const height = this.aboveGround ?? Math.max(1, r - shape.outer);
        const speed = flySpeed(this.walk ? 3 : height) * this.speedFactor * (input.fast ? 4 : 1);
        this.state = flyMove(this.state, shape, input, dt, speed, this.walk).state;
        moved = true;
      }
    }
    return moved;
  }

  /** Distance down to the loaded terrain from `from` (render space), or null without a hit. */
  private groundDistance(from: V3, up: V3, maxDistance: number): number | null {
    this.raycaster.near = 0;
    this.raycaster.far = maxDistance;
    const origin = new THREE.Vector3(from[0], from[1], from[2]);
    const down = new THREE.Vector3(-up[0], -up[1], -up[2]);
    this.raycaster.set(origin, down);
    let hits = this.raycaster.intersectObjects(this.terrain(), false);
    if (hits.length === 0) {
      // A ray exactly along a chunk border (a face's centre line: chunks of every level meet
      // there) can pass between the two chunks' triangles, whose float32 vertices are relative
      // to different origins: tilt it by a microradian and try once more.
      const side = Math.abs(up[1]) < 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0);
      down.addScaledVector(side.cross(down).normalize(), 1e-6).normalize();
      this.raycaster.set(origin, down);
      hits = this.raycaster.intersectObjects(this.terrain(), false);
    }
    return hits.length > 0 ? hits[0]!.distance : null;
  }

  /** The loaded terrain under canvas pixel (x, y), with the camera of the last frame. */
  pick(x: number, y: number): (PickResult & { render: V3 }) | null {
    const { width: w, height: h } = this.viewport();
    if (!(w > 0 && h > 0)) return null;
    this.ndc.set((2 * x) / w - 1, 1 - (2 * y) / h);
    this.raycaster.setFromCamera(this.ndc, this.camera);
    this.raycaster.near = this.camera.near;
    this.raycaster.far = this.camera.far;
    const hits = this.raycaster.intersectObjects(this.terrain(), false);
    const hit = hits[0];
    if (!hit) return null;
    const cam = this.position;
    // render space is relative to the camera (floating origin): add it back in f64
    const render: V3 = [hit.point.x, hit.point.y, hit.point.z];
    return {
      distance: hit.distance,
      point: [render[0] + cam[0], render[1] + cam[1], render[2] + cam[2]],
      key: hit.object.name,
      render,
    };
  }

  /** Canvas pixel (CSS) of a planet-frame point with the camera of the last frame; null behind it. */
  toScreen(p: V3): [number, number] | null {
    const cam = this.position;
    const v = new THREE.Vector3(p[0] - cam[0], p[1] - cam[1], p[2] - cam[2]);
    v.applyMatrix4(this.camera.matrixWorldInverse);
    if (v.z >= 0) return null;
    v.applyMatrix4(this.camera.projectionMatrix);
    const { width: w, height: h } = this.viewport();
    return [((v.x + 1) / 2) * w, ((1 - v.y) / 2) * h];
  }
}
