// The editing tools: which brush each tool sends, hotkeys, the brush settings and their limits,
// and the throttle that turns a held, dragged mouse button into a paced series of edits.
// Pure: no DOM, no three.js.

import type { BrushName, EditEnabled, EditRequest } from './api';
import type { V3 } from './frames';

export type ToolName = 'look' | 'dig' | 'build' | 'smooth' | 'flatten' | 'paint';

export interface ToolDef {
  name: ToolName;
  /** Button text. */
  label: string;
  /** The brush it sends; null for Look (no tool: the mouse moves the camera). */
  brush: BrushName | null;
  /** `KeyboardEvent.code` of its hotkey and what to print for it. */
  code: string;
  key: string;
  /** Colour of the brush cursor (linear RGB). */
  colour: [number, number, number];
  help: string;
}

/** The tools in tool-bar order. Hotkeys 1-6 (digits are free: see input.ts). */
export const TOOLS: readonly ToolDef[] = [
  { name: 'look', label: 'Look', brush: null, code: 'Digit1', key: '1', colour: [1, 1, 1], help: 'no tool: the mouse moves the camera' },
  { name: 'dig', label: 'Dig', brush: 'remove', code: 'Digit2', key: '2', colour: [1, 0.3, 0.2], help: 'remove terrain: carve a ball' },
  { name: 'build', label: 'Build', brush: 'add', code: 'Digit3', key: '3', colour: [0.3, 1, 0.35], help: 'add terrain: fill a ball' },
  { name: 'smooth', label: 'Smooth', brush: 'smooth', code: 'Digit4', key: '4', colour: [0.35, 0.65, 1], help: 'smooth the terrain' },
  { name: 'flatten', label: 'Flatten', brush: 'flatten', code: 'Digit5', key: '5', colour: [1, 0.85, 0.25], help: 'flatten toward the level of the point clicked' },
  { name: 'paint', label: 'Paint', brush: 'paint', code: 'Digit6', key: '6', colour: [0.9, 0.45, 1], help: 'paint the surface with the chosen material' },
];

/** The tool-bar entry of the Path tool (next to Look, Dig ... whose hotkeys are 1-6; pathTool.ts). */
export const PATH_TOOL = {
  label: 'Path',
  code: 'Digit7',
  key: '7',
  help: 'click two points of the terrain: the walking path between them (no world needed)',
} as const;

export function toolByName(name: ToolName): ToolDef {
  const t = TOOLS.find((t) => t.name === name);
  if (!t) throw new Error(`unknown tool ${name}`);
  return t;
}

export const DEFAULT_RADIUS = 4;
export const DEFAULT_STRENGTH = 1;
/** The smallest strength the control offers (the server takes anything above 0). */
export const MIN_STRENGTH = 0.05;

export interface RadiusLimits {
  min_brush_radius: number;
  max_brush_radius: number;
}

/** `r` within the server's limits; a value that is not a finite number becomes the default. */
export function clampRadius(r: number, limits: RadiusLimits): number {
  const lo = limits.min_brush_radius;
  const hi = Math.max(lo, limits.max_brush_radius);
  const v = Number.isFinite(r) ? r : DEFAULT_RADIUS;
  return Math.min(hi, Math.max(lo, v));
}

/** `s` within [MIN_STRENGTH, 1]; a value that is not a finite number becomes the default. */
export function clampStrength(s: number): number {
  const v = Number.isFinite(s) ? s : DEFAULT_STRENGTH;
  return Math.min(1, Math.max(MIN_STRENGTH, v));
}

/** The radius one step up (`dir` 1) or down (-1): 25 % per step, within the limits. */
export function stepRadius(r: number, dir: 1 | -1, limits: RadiusLimits): number {
  const next = dir > 0 ? r * 1.25 : r / 1.25;
  return clampRadius(Math.round(next * 10) / 10, limits);
}

/**
 * The paint material to use: `wanted` when it names one of `materials` (by name or index), else
 * the first one that is not `cave` (a material of the inside), else the first; null without any.
 */
export function resolveMaterial(materials: readonly string[], wanted: string | number | null): string | null {
  if (materials.length === 0) return null;
  if (typeof wanted === 'number' && Number.isInteger(wanted) && wanted >= 0 && wanted < materials.length) {
    return materials[wanted]!;
  }
  if (typeof wanted === 'string' && materials.includes(wanted)) return wanted;
  return materials.find((m) => m !== 'cave') ?? materials[0]!;
}

export interface BrushSettings {
  radius: number;
  strength: number;
  /** Paint material (a name of `/planet`'s `materials`). */
  material: string | null;
}

/**
 * The body of `POST /edits` for `tool` at `center` (planet frame, metres), with the settings
 * clamped to the server's limits. Throws (with a message for the user) for Look, for a brush the
 * server does not offer, and for Paint without a material.
 */
export function editRequest(tool: ToolName, center: V3, settings: BrushSettings, edit: EditEnabled): EditRequest {
  const def = toolByName(tool);
  if (!def.brush) throw new Error('choose a tool first (Dig, Build, Smooth, Flatten or Paint)');
  if (edit.brushes.length > 0 && !edit.brushes.includes(def.brush)) {
    throw new Error(`the server does not offer the ${def.brush} brush (it has ${edit.brushes.join(', ')})`);
  }
  if (!center.every(Number.isFinite)) throw new Error('the brush centre is not a finite point');
  const req: EditRequest = {
    brush: def.brush,
    x: center[0],
    y: center[1],
    z: center[2],
    radius: clampRadius(settings.radius, edit),
    strength: clampStrength(settings.strength),
  };
  if (def.brush === 'paint') {
    if (settings.material === null) throw new Error('the planet has no materials to paint with');
    req.material = settings.material;
  }
  return req;
}

export interface ThrottleOptions {
  /** Least time between two edits of one drag, ms (default 120). */
  minIntervalMs?: number;
  /** A drag repeats the brush only once the hit moved this fraction of the radius (default 0.5). */
  minMoveFraction?: number;
  /** The server's rate (edits per second): edits are never sent faster. */
  ratePerSecond?: number;
}

/**
 * Paces the edits of the mouse. A press applies the brush once (as soon as no edit is in flight
 * and the rate allows, even if the button was released meanwhile); holding the button and
 * dragging applies it again at most every `minIntervalMs` and only once the point under the
 * cursor moved `minMoveFraction` of the radius. One edit is in flight at a time, and after a 429
 * nothing is sent until its Retry-After has passed.
 */
export class BrushThrottle {
  private readonly dragInterval: number;
  private readonly rateInterval: number;
  private readonly moveFraction: number;
  private lastAt = -Infinity;
  private lastHit: V3 | null = null;
  private down = false;
  private queued: V3 | null = null;
  private blockedUntil = -Infinity;

  constructor(opts: ThrottleOptions = {}) {
    const rate = opts.ratePerSecond !== undefined && opts.ratePerSecond > 0 ? opts.ratePerSecond : Infinity;
    this.rateInterval = 1000 / rate;
    this.dragInterval = Math.max(opts.minIntervalMs ?? 120, this.rateInterval);
    this.moveFraction = opts.minMoveFraction ?? 0.5;
  }

  /**
   * The button went down with `hit` under the cursor (null: nothing there). Returns false (and
   * queues nothing) while blocked by a 429.
   */
  press(now: number, hit: V3 | null): boolean {
    this.down = true;
    this.lastHit = null;
    if (now < this.blockedUntil) return false;
    this.queued = hit ? [hit[0], hit[1], hit[2]] : null;
    return true;
  }

  release(): void {
    this.down = false;
  }

  get pressed(): boolean {
    return this.down;
  }

  /** The server said 429: send nothing before `until`. Drops a queued press. */
  block(until: number): void {
    this.blockedUntil = Math.max(this.blockedUntil, until);
    this.queued = null;
  }

  /** Milliseconds left of a 429 block (0 when not blocked). */
  blockedFor(now: number): number {
    return Math.max(0, this.blockedUntil - now);
  }

  /**
   * Called every frame with the point under the cursor (null: none) and whether an edit is in
   * flight. Returns the centre to apply the brush at now, or null.
   */
  poll(now: number, hit: V3 | null, radius: number, inFlight: boolean): V3 | null {
    if (inFlight || now < this.blockedUntil) return null;
    if (this.queued) {
      if (now - this.lastAt < this.rateInterval) return null;
      return this.take(now, this.queued);
    }
    if (!this.down || !hit) return null;
    if (now - this.lastAt < this.dragInterval) return null;
    if (this.lastHit) {
      const d = Math.hypot(hit[0] - this.lastHit[0], hit[1] - this.lastHit[1], hit[2] - this.lastHit[2]);
      if (d < this.moveFraction * radius) return null;
    }
    return this.take(now, hit);
  }

  private take(now: number, at: V3): V3 {
    const c: V3 = [at[0], at[1], at[2]];
    this.queued = null;
    this.lastAt = now;
    this.lastHit = c;
    return c;
  }
}
