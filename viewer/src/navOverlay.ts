// The navigation overlay's pure side: colours per grid component, the typed arrays drawn from a
// `/navgrid` answer, lat/lon/altitude <-> planet frame for `/path`, the range and centre of the
// grid shown and when to fetch it again, and `NavGridLoader`, which fetches it as the camera
// moves and edits land. No DOM, no three.js.

import { ApiError, isAbort, type NavGridAnswer, type PathEnd, type Vec3Tuple } from './api';
import { latLonFromPosition, length, normalize, positionFromLatLon, type V3 } from './frames';

/** An sRGB colour, components 0..1. */
export type Rgb = [number, number, number];

/** The main grid (the component holding at least half of the planet's nodes): a calm steel blue. */
export const MAIN_COLOUR: Rgb = [0.56, 0.74, 0.86];
/** The path line: hot pink (no component colour comes near its hue). */
export const PATH_COLOUR: Rgb = [1, 0.16, 0.72];
/** The start and goal markers. */
export const START_COLOUR: Rgb = [0.2, 1, 0.35];
export const GOAL_COLOUR: Rgb = [1, 0.55, 0.1];

/** The hue of PATH_COLOUR (0..1) and the gap kept around it. */
const PATH_HUE = 320 / 360;
const HUE_GAP = 0.1;

/** HSV (0..1 each) to RGB. */
export function hsvToRgb(h: number, s: number, v: number): Rgb {
  const hh = ((h % 1) + 1) % 1 * 6;
  const i = Math.floor(hh);
  const f = hh - i;
  const p = v * (1 - s);
  const q = v * (1 - s * f);
  const t = v * (1 - s * (1 - f));
  switch (i) {
    case 0:
      return [v, t, p];
    case 1:
      return [q, v, p];
    case 2:
      return [p, v, t];
    case 3:
      return [p, q, v];
    case 4:
      return [t, p, v];
    default:
      return [v, p, q];
  }
}

/**
 * The colour of component `label` (any other than the main one): a bright, saturated colour from a
 * Fibonacci hash of the label (consecutive labels, which neighbouring detached grids often have,
 * get hues about 0.618 turns apart), keeping clear of the path's hue. Deterministic.
 */
export function componentColour(label: number): Rgb {
  const hash = Math.imul(label | 0, 0x9e3779b1) >>> 0;
  const t = hash / 2 ** 32;
  const hue = PATH_HUE + HUE_GAP + t * (1 - 2 * HUE_GAP);
  // every other hash bit a little less saturated: more tell-apart colours
  const s = (hash >>> 16) & 1 ? 0.95 : 0.8;
  return hsvToRgb(hue, s, 1);
}

/** `#rrggbb` of an sRGB colour. */
export function colourHex(c: Rgb): string {
  return `#${c.map((x) => Math.round(Math.max(0, Math.min(1, x)) * 255).toString(16).padStart(2, '0')).join('')}`;
}

/** sRGB component (0..1) to linear. */
export function srgbToLinear(c: number): number {
  return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
}

/** Euclidean distance between two colours. */
export function colourDistance(a: Rgb, b: Rgb): number {
  return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/**
 * The label of the main component: the one holding at least half of the planet's nodes (the
 * connected ground most of the planet is, as in the paper's Fig. 10), when it is in the answer;
 * null when it is not (every component shown then gets its own bright colour).
 */
export function mainComponent(a: Pick<NavGridAnswer, 'components' | 'component_sizes' | 'total_nodes'>): number | null {
  for (let i = 0; i < a.components.length; i++) {
    if (2 * a.component_sizes[i]! >= a.total_nodes && a.total_nodes > 0) return a.components[i]!;
  }
  return null;
}

/** A component with nodes in the overlay. */
export interface ComponentInView {
  label: number;
  /** Its node count over the whole planet. */
  size: number;
  /** Its nodes in the overlay. */
  nodes: number;
  main: boolean;
  /** sRGB, and as `#rrggbb`. */
  colour: Rgb;
  hex: string;
}

/** The typed arrays of the overlay, relative to `origin` (floating origin, like the chunks). */
export interface NavOverlayData {
  origin: V3;
  count: number;
  /** Three per node: the surface point lifted along its local up, minus `origin`. */
  positions: Float32Array;
  /** Three per node, linear RGB (three.js vertex colours). */
  colours: Float32Array;
  /** The component label of each node. */
  labels: Uint32Array;
  /** Node index pairs of the steps (an edge joins two nodes of one component: one colour). */
  edges: Uint32Array;
  /** Indices of the main component's nodes and of every other node (drawn larger). */
  mainNodes: Uint32Array;
  otherNodes: Uint32Array;
  main: number | null;
  /** Main first, then by nodes in the overlay, most first. */
  components: ComponentInView[];
  truncated: boolean;
  totalNodes: number;
  totalComponents: number;
  revision: number;
}

/** `p` moved `lift` metres along its local up (away from the planet centre), f64. */
export function liftPoint(p: V3, lift: number): V3 {
  const u = normalize(p);
  return [p[0] + u[0] * lift, p[1] + u[1] * lift, p[2] + u[2] * lift];
}

/**
 * Builds the overlay of a `/navgrid` answer: each node lifted `lift` metres above its surface
 * point (computed in f64 in the planet frame, stored relative to the answer's origin), coloured by
 * component (sRGB colours turned linear), the edges as an index list. Throws for an edge naming a
 * node that is not in the answer.
 */
export function buildNavOverlay(a: NavGridAnswer, lift = 0.25): NavOverlayData {
  const n = a.components.length;
  if (a.positions.length !== 3 * n || a.component_sizes.length !== n) {
    throw new Error(`navgrid answer: ${a.positions.length / 3} positions, ${n} components, ${a.component_sizes.length} sizes`);
  }
  if (a.edges.length % 2 !== 0) throw new Error('navgrid answer: an odd number of edge ends');
  const origin: V3 = [a.origin[0], a.origin[1], a.origin[2]];
  const main = mainComponent(a);
  const positions = new Float32Array(3 * n);
  const colours = new Float32Array(3 * n);
  const labels = Uint32Array.from(a.components);
  const byLabel = new Map<number, ComponentInView & { linear: Rgb }>();
  const mainIdx: number[] = [];
  const otherIdx: number[] = [];
  for (let i = 0; i < n; i++) {
    const label = a.components[i]!;
    let c = byLabel.get(label);
    if (!c) {
      const colour = label === main ? MAIN_COLOUR : componentColour(label);
      c = {
        label,
        size: a.component_sizes[i]!,
        nodes: 0,
        main: label === main,
        colour,
        hex: colourHex(colour),
        linear: [srgbToLinear(colour[0]), srgbToLinear(colour[1]), srgbToLinear(colour[2])],
      };
      byLabel.set(label, c);
    }
    c.nodes++;
    (label === main ? mainIdx : otherIdx).push(i);
    // planet frame in f64, lifted, then relative to the origin
    const p: V3 = [origin[0] + a.positions[3 * i]!, origin[1] + a.positions[3 * i + 1]!, origin[2] + a.positions[3 * i + 2]!];
    const q = liftPoint(p, lift);
    positions[3 * i] = q[0] - origin[0];
    positions[3 * i + 1] = q[1] - origin[1];
    positions[3 * i + 2] = q[2] - origin[2];
    colours.set(c.linear, 3 * i);
  }
  const edges = new Uint32Array(a.edges.length);
  for (let k = 0; k < a.edges.length; k++) {
    const e = a.edges[k]!;
    if (!Number.isInteger(e) || e < 0 || e >= n) throw new Error(`navgrid answer: edge end ${e} is not one of the ${n} nodes`);
    edges[k] = e;
  }
  const components = [...byLabel.values()]
    .map(({ linear: _linear, ...c }) => c)
    .sort((x, y) => Number(y.main) - Number(x.main) || y.nodes - x.nodes || x.label - y.label);
  return {
    origin,
    count: n,
    positions,
    colours,
    labels,
    edges,
    mainNodes: Uint32Array.from(mainIdx),
    otherNodes: Uint32Array.from(otherIdx),
    main,
    components,
    truncated: a.truncated,
    totalNodes: a.total_nodes,
    totalComponents: a.total_components,
    revision: a.revision,
  };
}

// ---- path ends -----------------------------------------------------------------------------------

/** The `/path` end of a planet-frame point: latitude, longitude and metres above `datum`. */
export function pathEndOf(p: V3, datum: number): PathEnd & { alt: number } {
  const { lat, lon, radius } = latLonFromPosition(p);
  return { lat, lon, alt: radius - datum };
}

/** The planet-frame point of a path end or waypoint (`alt` metres above `datum`). */
export function pointOfEnd(e: { lat: number; lon: number; alt: number }, datum: number): V3 {
  return positionFromLatLon(e.lat, e.lon, datum + e.alt);
}

/** `LAT,LON[,ALT]` as `/path` takes it (1e-9 degree, a millimetre). */
export function formatPathEnd(e: PathEnd): string {
  const num = (x: number, digits: number): string => {
    const s = x.toFixed(digits);
    return /^-0\.?0*$/.test(s) ? s.slice(1) : s;
  };
  return `${num(e.lat, 9)},${num(e.lon, 9)}${e.alt !== null ? `,${num(e.alt, 3)}` : ''}`;
}

// ---- what to fetch -----------------------------------------------------------------------------

/** Metres of the grid shown around the ground point: a few hundred, more from higher up. */
export function navRange(heightAboveGround: number): number {
  const h = Number.isFinite(heightAboveGround) ? Math.max(0, heightAboveGround) : 0;
  return Math.min(3000, Math.max(250, 150 + 2.5 * h));
}

/**
 * The point under the camera: `aboveGround` metres down from it when the ground was measured,
 * else where the vertical meets the datum.
 */
export function groundPoint(camera: V3, aboveGround: number | null, datum: number): V3 {
  const r = length(camera);
  const up = normalize(camera);
  const at = aboveGround !== null && Number.isFinite(aboveGround) && aboveGround < r ? r - aboveGround : datum;
  return [up[0] * at, up[1] * at, up[2] * at];
}

/** What a grid fetch asks for. */
export interface NavQuery {
  /** The planet (preset and seed). */
  planet: string;
  centre: V3;
  range: number;
  /** The world revision known to the viewer (0 without editing). */
  revision: number;
}

/**
 * Whether the grid shown for `shown` must be fetched again for `want`: another planet or
 * revision, a ground point moved more than a third of the range, or a range changed by more
 * than half.
 */
export function needsRefetch(shown: NavQuery | null, want: NavQuery): boolean {
  if (!shown) return true;
  if (shown.planet !== want.planet || shown.revision !== want.revision) return true;
  const d = Math.hypot(want.centre[0] - shown.centre[0], want.centre[1] - shown.centre[1], want.centre[2] - shown.centre[2]);
  if (d > shown.range / 3) return true;
  const ratio = want.range / shown.range;
  return ratio > 1.5 || ratio < 1 / 1.5;
}

/** A message for the user about a failed navigation request (`what` names it). */
export function navErrorMessage(what: string, e: unknown): string {
  if (e instanceof ApiError) {
    if (e.status === 0) return `${what} failed: ${e.message}`;
    if (e.status === 200) return `${what} failed: ${e.message}`;
    return `${what} failed (${e.status}): ${e.serverMessage ?? e.message}`;
  }
  return `${what} failed: ${e instanceof Error ? e.message : String(e)}`;
}

export interface NavGridLoaderOptions {
  fetchGrid(at: Vec3Tuple, range: number, signal: AbortSignal): Promise<NavGridAnswer>;
  /** Metres the nodes are lifted above their surface points (default 0.25). */
  lift?: number;
  now?: () => number;
  /** Something shown changed (the data, loading, an error). */
  onChange?: () => void;
  /** After a failure, ask again this much later even if nothing moved (default 5000 ms). */
  retryMs?: number;
}

export interface NavGridStatus {
  enabled: boolean;
  loading: boolean;
  error: string | null;
  nodes: number;
  edges: number;
  main: number | null;
  components: ComponentInView[];
  truncated: boolean;
  totalNodes: number | null;
  totalComponents: number | null;
  /** The query of the grid shown. */
  shown: NavQuery | null;
  /** Requests started. */
  fetches: number;
}

/**
 * Fetches the grid around the camera while the overlay is on: once at first, then whenever
 * `needsRefetch` says so (one request at a time; a newer wish waits for it), again after a failure
 * once the camera moved or `retryMs` passed. Off drops the data and cancels the request.
 */
export class NavGridLoader {
  private readonly fetchGrid: NavGridLoaderOptions['fetchGrid'];
  private readonly lift: number;
  private readonly now: () => number;
  private readonly onChange: () => void;
  private readonly retryMs: number;
  private on = false;
  private data: NavOverlayData | null = null;
  private shown: NavQuery | null = null;
  private inFlight: AbortController | null = null;
  private error: string | null = null;
  private failed: { query: NavQuery; at: number } | null = null;
  private fetches = 0;
  /** Bumped whenever `overlay()` changes. */
  version = 0;

  constructor(opts: NavGridLoaderOptions) {
    this.fetchGrid = opts.fetchGrid;
    this.lift = opts.lift ?? 0.25;
    this.now = opts.now ?? (() => performance.now());
    this.onChange = opts.onChange ?? (() => undefined);
    this.retryMs = opts.retryMs ?? 5000;
  }

  get enabled(): boolean {
    return this.on;
  }

  setEnabled(on: boolean): void {
    if (on === this.on) return;
    this.on = on;
    if (!on) this.reset();
    else this.onChange();
  }

  /** Drops what is shown and cancels a request (the planet changed, or the overlay is off). */
  reset(): void {
    this.inFlight?.abort();
    this.inFlight = null;
    if (this.data) this.version++;
    this.data = null;
    this.shown = null;
    this.error = null;
    this.failed = null;
    this.onChange();
  }

  /** Every frame (while on): the grid wanted now. Starts a request when due. */
  update(want: NavQuery): void {
    if (!this.on || this.inFlight) return;
    if (this.failed && !needsRefetch(this.failed.query, want) && this.now() - this.failed.at < this.retryMs) return;
    if (!this.failed && !needsRefetch(this.shown, want)) return;
    void this.start(want);
  }

  private async start(want: NavQuery): Promise<void> {
    const ctl = new AbortController();
    this.inFlight = ctl;
    this.fetches++;
    this.onChange();
    try {
      const answer = await this.fetchGrid([want.centre[0], want.centre[1], want.centre[2]], want.range, ctl.signal);
      if (this.inFlight !== ctl) return;
      this.data = buildNavOverlay(answer, this.lift);
      this.shown = { ...want, centre: [want.centre[0], want.centre[1], want.centre[2]] };
      this.error = null;
      this.failed = null;
      this.version++;
    } catch (e) {
      if (this.inFlight !== ctl || isAbort(e)) return;
      this.error = navErrorMessage('the navigation grid request', e);
      this.failed = { query: want, at: this.now() };
    } finally {
      if (this.inFlight === ctl) {
        this.inFlight = null;
        this.onChange();
      }
    }
  }

  overlay(): NavOverlayData | null {
    return this.data;
  }

  status(): NavGridStatus {
    const d = this.data;
    return {
      enabled: this.on,
      loading: this.inFlight !== null,
      error: this.error,
      nodes: d?.count ?? 0,
      edges: d ? d.edges.length / 2 : 0,
      main: d?.main ?? null,
      components: d ? d.components.map((c) => ({ ...c, colour: [...c.colour] as Rgb })) : [],
      truncated: d?.truncated ?? false,
      totalNodes: d?.totalNodes ?? null,
      totalComponents: d?.totalComponents ?? null,
      shown: this.shown,
      fetches: this.fetches,
    };
  }
}
