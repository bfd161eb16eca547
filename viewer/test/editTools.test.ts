import { describe, expect, it } from 'vitest';
import type { EditEnabled } from '../src/api';
import {
  BrushThrottle,
  DEFAULT_RADIUS,
  TOOLS,
  clampRadius,
  clampStrength,
  editRequest,
  resolveMaterial,
  stepRadius,
} from '../src/editTools';
import type { V3 } from '../src/frames';
import { BOUND_KEYS } from '../src/input';
import { shortcutOf } from '../src/shortcuts';

const EDIT: EditEnabled = {
  enabled: true, world: 'w.pmcw', revision: 0, active: 0, redo: 0,
  min_brush_radius: 0.5, max_brush_radius: 64, rate_per_second: 20, burst: 40,
  brushes: ['add', 'remove', 'smooth', 'flatten', 'paint'],
};
const MATERIALS = ['sand', 'grass', 'forest', 'rock', 'snow', 'cave'];

describe('tools', () => {
  it('map to the brushes of the API, Look to none', () => {
    expect(TOOLS.map((t) => [t.name, t.brush])).toEqual([
      ['look', null], ['dig', 'remove'], ['build', 'add'], ['smooth', 'smooth'], ['flatten', 'flatten'], ['paint', 'paint'],
    ]);
  });

  it('have hotkeys 1-6 (Escape: look) that clash with no key of input.ts', () => {
    expect(TOOLS.map((t) => t.code)).toEqual(['Digit1', 'Digit2', 'Digit3', 'Digit4', 'Digit5', 'Digit6']);
    const key = (code: string) => shortcutOf({ code, key: '', ctrlKey: false, metaKey: false, altKey: false, shiftKey: false });
    for (const t of TOOLS) {
      expect(BOUND_KEYS.has(t.code)).toBe(false);
      expect(key(t.code)?.tool).toBe(t.name);
    }
    expect(BOUND_KEYS.has('KeyW') && BOUND_KEYS.has('Tab') && BOUND_KEYS.has('KeyG')).toBe(true);
    for (const k of ['Escape', 'BracketLeft', 'BracketRight', 'KeyZ', 'KeyY']) expect(BOUND_KEYS.has(k)).toBe(false);
    expect(key('Escape')?.action).toBe('escape');
    expect(key('KeyW')).toBeNull();
    expect(key('Digit7')?.action).toBe('path');
  });
});

describe('brush settings', () => {
  it('clamp the radius to the server limits, non-numbers to the default', () => {
    expect(clampRadius(4, EDIT)).toBe(4);
    expect(clampRadius(0.1, EDIT)).toBe(0.5);
    expect(clampRadius(100, EDIT)).toBe(64);
    expect(clampRadius(Number.NaN, EDIT)).toBe(DEFAULT_RADIUS);
    expect(clampRadius(Infinity, EDIT)).toBe(DEFAULT_RADIUS);
    expect(clampRadius(3, { min_brush_radius: 5, max_brush_radius: 8 })).toBe(5);
    // a default outside the limits is clamped too
    expect(clampRadius(Number.NaN, { min_brush_radius: 10, max_brush_radius: 20 })).toBe(10);
  });

  it('step the radius by 25 % within the limits', () => {
    expect(stepRadius(4, 1, EDIT)).toBe(5);
    expect(stepRadius(5, -1, EDIT)).toBe(4);
    expect(stepRadius(60, 1, EDIT)).toBe(64);
    expect(stepRadius(0.5, -1, EDIT)).toBe(0.5);
  });

  it('clamp the strength into (0, 1]', () => {
    expect(clampStrength(0.5)).toBe(0.5);
    expect(clampStrength(0)).toBe(0.05);
    expect(clampStrength(-3)).toBe(0.05);
    expect(clampStrength(2)).toBe(1);
    expect(clampStrength(Number.NaN)).toBe(1);
  });

  it('resolve the paint material by name or index, defaulting to a surface material', () => {
    expect(resolveMaterial(MATERIALS, 'rock')).toBe('rock');
    expect(resolveMaterial(MATERIALS, 4)).toBe('snow');
    expect(resolveMaterial(MATERIALS, 'lava')).toBe('sand');
    expect(resolveMaterial(MATERIALS, 9)).toBe('sand');
    expect(resolveMaterial(MATERIALS, null)).toBe('sand');
    expect(resolveMaterial(['cave', 'rock'], null)).toBe('rock');
    expect(resolveMaterial(['cave'], null)).toBe('cave');
    expect(resolveMaterial([], 'rock')).toBeNull();
  });

  it('build the request body of POST /edits', () => {
    const c: V3 = [812.5, 1650, 402.1];
    expect(editRequest('dig', c, { radius: 100, strength: 1, material: 'sand' }, EDIT)).toEqual({
      brush: 'remove', x: 812.5, y: 1650, z: 402.1, radius: 64, strength: 1,
    });
    expect(editRequest('paint', c, { radius: 4, strength: 0.5, material: 'rock' }, EDIT)).toEqual({
      brush: 'paint', x: 812.5, y: 1650, z: 402.1, radius: 4, strength: 0.5, material: 'rock',
    });
    expect(() => editRequest('look', c, { radius: 4, strength: 1, material: null }, EDIT)).toThrow(/choose a tool/);
    expect(() => editRequest('paint', c, { radius: 4, strength: 1, material: null }, EDIT)).toThrow(/no materials/);
    expect(() => editRequest('dig', [Number.NaN, 0, 0], { radius: 4, strength: 1, material: null }, EDIT)).toThrow(/finite/);
    expect(() => editRequest('build', c, { radius: 4, strength: 1, material: null }, { ...EDIT, brushes: ['remove'] }))
      .toThrow(/does not offer the add brush/);
  });
});

describe('BrushThrottle', () => {
  const at = (x: number): V3 => [x, 0, 0];

  it('applies a press at once, then repeats a drag only after 120 ms and half a radius', () => {
    const t = new BrushThrottle({ ratePerSecond: 20 });
    expect(t.press(1000, at(0))).toBe(true);
    expect(t.poll(1000, at(0), 4, false)).toEqual(at(0));
    // held still: nothing more
    expect(t.poll(1500, at(0), 4, false)).toBeNull();
    // moved 3 m (more than half of 4) but too soon after the last edit? no: 500 ms passed
    expect(t.poll(1510, at(1.9), 4, false)).toBeNull(); // moved less than 2 m
    expect(t.poll(1520, at(2.5), 4, false)).toEqual(at(2.5));
    expect(t.poll(1600, at(6), 4, false)).toBeNull(); // 80 ms later: too soon
    expect(t.poll(1640, at(6), 4, false)).toEqual(at(6)); // 120 ms later
    t.release();
    expect(t.poll(5000, at(20), 4, false)).toBeNull(); // released: no drag
  });

  it('keeps a press while an edit is in flight and sends it afterwards, even after release', () => {
    const t = new BrushThrottle();
    t.press(0, at(1));
    t.release();
    expect(t.poll(10, at(1), 4, true)).toBeNull();
    expect(t.poll(20, at(9), 4, false)).toEqual(at(1)); // the pressed point, not the current one
    expect(t.poll(400, at(9), 4, false)).toBeNull();
  });

  it('never sends faster than the server rate', () => {
    const t = new BrushThrottle({ ratePerSecond: 2, minIntervalMs: 120 });
    t.press(0, at(0));
    expect(t.poll(0, at(0), 1, false)).toEqual(at(0));
    expect(t.poll(200, at(5), 1, false)).toBeNull();
    expect(t.poll(499, at(5), 1, false)).toBeNull();
    expect(t.poll(500, at(5), 1, false)).toEqual(at(5));
    // a new press also waits for the rate
    t.release();
    t.press(600, at(10));
    expect(t.poll(600, at(10), 1, false)).toBeNull();
    expect(t.poll(1000, at(10), 1, false)).toEqual(at(10));
  });

  it('starts a drag that began off the terrain once the cursor reaches it', () => {
    const t = new BrushThrottle();
    expect(t.press(0, null)).toBe(true);
    expect(t.poll(0, null, 4, false)).toBeNull();
    expect(t.poll(16, at(3), 4, false)).toEqual(at(3));
  });

  it('sends nothing while blocked by a 429 and refuses presses meanwhile', () => {
    const t = new BrushThrottle();
    t.press(0, at(0));
    expect(t.poll(0, at(0), 4, false)).toEqual(at(0));
    t.block(2000);
    expect(t.blockedFor(500)).toBe(1500);
    expect(t.poll(1000, at(10), 4, false)).toBeNull();
    t.release();
    expect(t.press(1500, at(20))).toBe(false);
    expect(t.poll(1600, at(20), 4, false)).toBeNull();
    expect(t.poll(2100, at(30), 4, false)).toEqual(at(30)); // still held: the drag goes on
    expect(t.blockedFor(2100)).toBe(0);
  });
});
