// The three.js side of navigation: the path (a wide line a little above the ground, with a faint
// copy drawn through the terrain where it is hidden), the start and goal markers, and the grid
// overlay (nodes as points, steps as lines, coloured by component). Floating origin like the
// chunks: every object keeps its planet-frame origin and `place(camera)` puts it at
// origin - camera (f64) every frame.

import * as THREE from 'three';
import { Line2 } from 'three/examples/jsm/lines/Line2.js';
import { LineGeometry } from 'three/examples/jsm/lines/LineGeometry.js';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';
import { relativeToCamera, type V3 } from './frames';
import { GOAL_COLOUR, PATH_COLOUR, START_COLOUR, liftPoint, type NavOverlayData, type Rgb } from './navOverlay';

/** Metres the path is drawn above the surface points it walks. */
export const PATH_LIFT = 0.4;
/** Line width of the path, CSS pixels (its faint see-through copy: XRAY_WIDTH). */
const PATH_WIDTH = 5;
const XRAY_WIDTH = 3;
/** Screen size of the node points, pixels: the main grid, and detached grids (larger). */
const MAIN_POINT = 4;
const OTHER_POINT = 7;
/** Marker radius as a fraction of its distance from the camera (about 6 px at 50° fov, 640 px). */
const MARKER_SCALE = 0.009;

const colour = (c: Rgb): THREE.Color => new THREE.Color().setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);

interface Placed {
  object: THREE.Object3D;
  origin: V3;
  /** Scaled with the distance from the camera (markers). */
  constantSize: boolean;
}

export class NavScene {
  readonly group = new THREE.Group();
  private readonly placed: Placed[] = [];
  /** Objects added and removed so far (a part of the picture's key: see pictureKey.ts). */
  private changes = 0;

  private readonly pathMaterial = new LineMaterial({ color: colour(PATH_COLOUR), linewidth: PATH_WIDTH, worldUnits: false });
  private readonly xrayMaterial = new LineMaterial({
    color: colour(PATH_COLOUR),
    linewidth: XRAY_WIDTH,
    worldUnits: false,
    transparent: true,
    opacity: 0.4,
    depthTest: false,
    depthWrite: false,
  });
  private path: { line: Line2; xray: Line2; geometry: LineGeometry; placed: Placed[] } | null = null;
  /** The lifted waypoints drawn, planet frame. */
  private pathPoints: V3[] = [];

  private readonly markerGeometry = new THREE.SphereGeometry(1, 16, 8);
  private readonly startMaterial = new THREE.MeshBasicMaterial({ color: colour(START_COLOUR), depthTest: false, depthWrite: false, transparent: true, opacity: 0.95 });
  private readonly goalMaterial = new THREE.MeshBasicMaterial({ color: colour(GOAL_COLOUR), depthTest: false, depthWrite: false, transparent: true, opacity: 0.95 });
  private markers: Placed[] = [];

  private readonly edgeMaterial = new THREE.LineBasicMaterial({ vertexColors: true });
  private readonly mainPointMaterial = new THREE.PointsMaterial({ vertexColors: true, size: MAIN_POINT, sizeAttenuation: false });
  private readonly otherPointMaterial = new THREE.PointsMaterial({ vertexColors: true, size: OTHER_POINT, sizeAttenuation: false });
  /** Detached grids are also drawn faintly through the terrain (cave pockets, hidden ledges). */
  private readonly otherXrayMaterial = new THREE.PointsMaterial({
    vertexColors: true,
    size: OTHER_POINT - 2,
    sizeAttenuation: false,
    transparent: true,
    opacity: 0.6,
    depthTest: false,
    depthWrite: false,
  });
  private grid: { objects: THREE.Object3D[]; geometries: THREE.BufferGeometry[]; placed: Placed } | null = null;

  constructor() {
    this.group.name = 'navigation';
  }

  /** Draws the path through `waypoints` (planet frame, surface points); null or < 2 points: none. */
  setPath(waypoints: V3[] | null): void {
    this.removePath();
    if (!waypoints || waypoints.length < 2) return;
    const lifted = waypoints.map((p) => liftPoint(p, PATH_LIFT));
    const origin = lifted[0]!;
    const flat: number[] = [];
    for (const p of lifted) {
      const r = relativeToCamera(p, origin);
      flat.push(r[0], r[1], r[2]);
    }
    const geometry = new LineGeometry();
    geometry.setPositions(flat);
    const line = new Line2(geometry, this.pathMaterial);
    line.name = 'path';
    line.renderOrder = 30;
    const xray = new Line2(geometry, this.xrayMaterial);
    xray.name = 'path-xray';
    xray.renderOrder = 31;
    const placed = [line, xray].map((object) => ({ object, origin, constantSize: false }));
    for (const p of placed) this.add(p);
    this.path = { line, xray, geometry, placed };
    this.pathPoints = lifted;
  }

  private removePath(): void {
    if (!this.path) return;
    for (const p of this.path.placed) this.remove(p);
    this.path.geometry.dispose();
    this.path = null;
    this.pathPoints = [];
  }

  /** The start and goal markers (planet frame); null hides one. */
  setMarkers(start: V3 | null, goal: V3 | null): void {
    for (const m of this.markers) this.remove(m);
    this.markers = [];
    for (const [at, material, name] of [
      [start, this.startMaterial, 'path-start'],
      [goal, this.goalMaterial, 'path-goal'],
    ] as const) {
      if (!at) continue;
      const mesh = new THREE.Mesh(this.markerGeometry, material);
      mesh.name = name;
      mesh.renderOrder = 32;
      mesh.frustumCulled = false;
      const p: Placed = { object: mesh, origin: liftPoint(at, PATH_LIFT), constantSize: true };
      this.add(p);
      this.markers.push(p);
    }
  }

  /** Draws the grid overlay of `data`; null removes it. */
  setGrid(data: NavOverlayData | null): void {
    if (this.grid) {
      this.remove(this.grid.placed);
      for (const g of this.grid.geometries) g.dispose();
      this.grid = null;
    }
    if (!data || data.count === 0) return;
    const position = new THREE.BufferAttribute(data.positions, 3);
    const col = new THREE.BufferAttribute(data.colours, 3);
    const make = (index: Uint32Array): THREE.BufferGeometry => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', position);
      g.setAttribute('color', col);
      g.setIndex(new THREE.BufferAttribute(index, 1));
      g.computeBoundingSphere();
      return g;
    };
    const root = new THREE.Group();
    root.name = 'navgrid';
    const geometries: THREE.BufferGeometry[] = [];
    const objects: THREE.Object3D[] = [];
    if (data.edges.length > 0) {
      const g = make(data.edges);
      geometries.push(g);
      const lines = new THREE.LineSegments(g, this.edgeMaterial);
      lines.name = 'navgrid-edges';
      lines.renderOrder = 25;
      objects.push(lines);
    }
    if (data.mainNodes.length > 0) {
      const g = make(data.mainNodes);
      geometries.push(g);
      const pts = new THREE.Points(g, this.mainPointMaterial);
      pts.name = 'navgrid-main';
      pts.renderOrder = 26;
      objects.push(pts);
    }
    if (data.otherNodes.length > 0) {
      const g = make(data.otherNodes);
      geometries.push(g);
      const pts = new THREE.Points(g, this.otherPointMaterial);
      pts.name = 'navgrid-other';
      pts.renderOrder = 27;
      const xray = new THREE.Points(g, this.otherXrayMaterial);
      xray.name = 'navgrid-other-xray';
      xray.renderOrder = 28;
      objects.push(pts, xray);
    }
    root.add(...objects);
    const placed: Placed = { object: root, origin: [data.origin[0], data.origin[1], data.origin[2]], constantSize: false };
    this.add(placed);
    this.grid = { objects, geometries, placed };
  }

  /** Objects added and removed so far: the overlay's part of the picture's key. */
  pictureChanges(): number {
    return this.changes;
  }

  /** Whether the grid overlay has something drawn. */
  gridShown(): boolean {
    return this.grid !== null;
  }

  /** The lifted path points drawn (planet frame). */
  drawnPath(): V3[] {
    return this.pathPoints;
  }

  private add(p: Placed): void {
    this.placed.push(p);
    this.group.add(p.object);
    this.changes++;
  }

  private remove(p: Placed): void {
    const i = this.placed.indexOf(p);
    if (i >= 0) this.placed.splice(i, 1);
    this.group.remove(p.object);
    this.changes++;
  }

  /** Floating origin: every object at (its origin - camera), computed in f64. */
  place(camera: V3): void {
    const rel: V3 = [0, 0, 0];
    for (const p of this.placed) {
      relativeToCamera(p.origin, camera, rel);
      p.object.position.set(rel[0], rel[1], rel[2]);
      if (p.constantSize) p.object.scale.setScalar(Math.max(0.05, Math.hypot(rel[0], rel[1], rel[2]) * MARKER_SCALE));
    }
  }

  dispose(): void {
    this.setPath(null);
    this.setMarkers(null, null);
    this.setGrid(null);
    for (const m of [this.pathMaterial, this.xrayMaterial, this.startMaterial, this.goalMaterial, this.edgeMaterial, this.mainPointMaterial, this.otherPointMaterial, this.otherXrayMaterial]) {
      m.dispose();
    }
    this.markerGeometry.dispose();
  }
}
