// Input with the DOM stubbed by EventTargets (vitest runs in node): the mouse buttons with and
// without a brush tool, the editing shortcuts, Shift inside a Ctrl chord, the middle button's
// tilt and the touch gestures (one finger drags, a pinch zooms, two fingers together tilt).

import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { Input } from '../src/input';

const g = globalThis as Record<string, unknown>;
const saved: Record<string, unknown> = {};

beforeAll(() => {
  for (const k of ['window', 'document', 'HTMLInputElement', 'HTMLSelectElement', 'HTMLTextAreaElement']) saved[k] = g[k];
  g['window'] = new EventTarget();
  g['document'] = { pointerLockElement: null };
  g['HTMLInputElement'] = class {};
  g['HTMLSelectElement'] = class {};
  g['HTMLTextAreaElement'] = class {};
});

afterAll(() => {
  for (const [k, v] of Object.entries(saved)) g[k] = v;
});

class FakeCanvas extends EventTarget {
  clientWidth = 800;
  clientHeight = 600;
  captured = new Set<number>();
  focus(): void {}
  getBoundingClientRect() {
    return { left: 10, top: 20, width: 800, height: 600 };
  }
  setPointerCapture(id: number): void {
    this.captured.add(id);
  }
  hasPointerCapture(id: number): boolean {
    return this.captured.has(id);
  }
  releasePointerCapture(id: number): void {
    this.captured.delete(id);
  }
}

const pointer = (type: string, button: number, x: number, y: number): Event =>
  Object.assign(new Event(type), { button, clientX: x, clientY: y, pointerId: 1, movementX: 0, movementY: 0 });
const touch = (type: string, id: number, x: number, y: number): Event =>
  Object.assign(new Event(type), { button: type === 'pointermove' ? -1 : 0, clientX: x, clientY: y, pointerId: id, pointerType: 'touch', movementX: 0, movementY: 0 });
const key = (type: string, code: string, mods: Partial<KeyboardEvent> = {}): Event =>
  Object.assign(new Event(type, { cancelable: true }), { code, repeat: false, ctrlKey: false, shiftKey: false, metaKey: false, altKey: false, ...mods });

function setup(brush: { active: boolean }) {
  const canvas = new FakeCanvas();
  const shortcuts: string[] = [];
  const input = new Input(canvas as unknown as HTMLElement, {
    onToggleMode: () => shortcuts.push('mode'),
    onToggleWalk: () => shortcuts.push('walk'),
    brushActive: () => brush.active,
    onShortcut: (e) => {
      if (e.code === 'KeyZ' && e.ctrlKey) {
        shortcuts.push(e.shiftKey ? 'redo' : 'undo');
        return true;
      }
      return false;
    },
  });
  const win = g['window'] as EventTarget;
  return { canvas, input, shortcuts, win };
}

describe('Input', () => {
  it('drags the camera with either button when no brush tool is chosen', () => {
    const { canvas, input } = setup({ active: false });
    canvas.dispatchEvent(pointer('pointerdown', 0, 100, 100));
    canvas.dispatchEvent(pointer('pointermove', 0, 130, 90));
    canvas.dispatchEvent(pointer('pointerup', 0, 130, 90));
    const f = input.take();
    expect([f.dragX, f.dragY, f.brushPress, f.brushRelease]).toEqual([30, -10, null, false]);
    input.dispose();
  });

  it('with a brush: the left button presses the brush, the right one still drags the camera', () => {
    const brush = { active: true };
    const { canvas, input } = setup(brush);
    canvas.dispatchEvent(pointer('pointermove', -1, 60, 70));
    expect(input.pointer()).toEqual({ x: 50, y: 50 });
    canvas.dispatchEvent(pointer('pointerdown', 0, 110, 120));
    canvas.dispatchEvent(pointer('pointermove', 0, 150, 120));
    let f = input.take();
    expect(f.brushPress).toEqual({ x: 100, y: 100 });
    expect([f.dragX, f.dragY]).toEqual([0, 0]); // the left button does not move the camera
    expect(input.brushHeld).toBe(true);
    expect(input.pointer()).toEqual({ x: 140, y: 100 });
    canvas.dispatchEvent(pointer('pointerup', 0, 150, 120));
    f = input.take();
    expect([f.brushPress, f.brushRelease, input.brushHeld]).toEqual([null, true, false]);
    // right drag
    canvas.dispatchEvent(pointer('pointerdown', 2, 200, 200));
    canvas.dispatchEvent(pointer('pointermove', 2, 190, 230));
    canvas.dispatchEvent(pointer('pointerup', 2, 190, 230));
    f = input.take();
    expect([f.dragX, f.dragY, f.brushPress]).toEqual([-10, 30, null]);
    canvas.dispatchEvent(new Event('pointerleave'));
    expect(input.pointer()).toBeNull();
    input.dispose();
  });

  it('keeps every press of one frame, in order (two quick clicks of the Path tool)', () => {
    const { canvas, input } = setup({ active: true });
    canvas.dispatchEvent(pointer('pointerdown', 0, 110, 120));
    canvas.dispatchEvent(pointer('pointerup', 0, 110, 120));
    canvas.dispatchEvent(pointer('pointerdown', 0, 310, 220));
    canvas.dispatchEvent(pointer('pointerup', 0, 310, 220));
    let f = input.take();
    expect(f.brushPresses).toEqual([{ x: 100, y: 100 }, { x: 300, y: 200 }]);
    expect(f.brushPress).toEqual({ x: 100, y: 100 });
    expect(f.brushRelease).toBe(true);
    f = input.take();
    expect([f.brushPresses, f.brushPress]).toEqual([[], null]);
    input.dispose();
  });

  it('gives shortcuts first say, and Shift inside a Ctrl chord does not fly down', () => {
    const { input, shortcuts, win } = setup({ active: false });
    win.dispatchEvent(key('keydown', 'ControlLeft', { ctrlKey: true }));
    win.dispatchEvent(key('keydown', 'ShiftLeft', { ctrlKey: true, shiftKey: true }));
    let f = input.take();
    expect([f.up, f.fast]).toEqual([0, true]);
    const z = key('keydown', 'KeyZ', { ctrlKey: true, shiftKey: true });
    win.dispatchEvent(z);
    expect(z.defaultPrevented).toBe(true);
    expect(shortcuts).toEqual(['redo']);
    win.dispatchEvent(key('keyup', 'ControlLeft'));
    f = input.take();
    expect(f.up).toBe(-1); // Shift alone is "down" again
    win.dispatchEvent(key('keyup', 'ShiftLeft'));
    win.dispatchEvent(key('keydown', 'KeyG'));
    win.dispatchEvent(key('keydown', 'KeyW'));
    f = input.take();
    expect(shortcuts).toEqual(['redo', 'walk']);
    expect(f.forward).toBe(1);
    input.dispose();
  });

  it('tilts with the middle button: up toward the horizon, without dragging', () => {
    const { canvas, input } = setup({ active: false });
    canvas.dispatchEvent(pointer('pointerdown', 1, 100, 300));
    canvas.dispatchEvent(pointer('pointermove', -1, 140, 260));
    canvas.dispatchEvent(pointer('pointerup', 1, 140, 260));
    const f = input.take();
    expect([f.dragX, f.dragY, f.tilt, f.pinch]).toEqual([0, 0, 10, 0]);
    input.dispose();
  });

  it('touch: one finger drags; spreading two pinches; two moving up together tilt; lifting one drags on without a jump', () => {
    const { canvas, input } = setup({ active: false });
    canvas.dispatchEvent(touch('pointerdown', 7, 100, 400));
    canvas.dispatchEvent(touch('pointermove', 7, 120, 380));
    let f = input.take();
    expect([f.dragX, f.dragY, f.tilt, f.pinch]).toEqual([20, -20, 0, 0]);
    // a second finger 100 px to the right; spread to 200 px apart
    canvas.dispatchEvent(touch('pointerdown', 8, 220, 380));
    canvas.dispatchEvent(touch('pointermove', 7, 70, 380));
    canvas.dispatchEvent(touch('pointermove', 8, 270, 380));
    f = input.take();
    expect([f.dragX, f.dragY, f.tilt]).toEqual([0, 0, 0]);
    expect(f.pinch).toBeCloseTo(Math.log(200 / 100), 12);
    // both fingers 40 px up: a tilt of 40 px of the midpoint toward the horizon
    canvas.dispatchEvent(touch('pointermove', 7, 70, 340));
    canvas.dispatchEvent(touch('pointermove', 8, 270, 340));
    f = input.take();
    expect([f.dragX, f.dragY]).toEqual([0, 0]);
    expect(f.tilt).toBeCloseTo(40 * 0.25, 12);
    expect(Math.abs(f.pinch)).toBeLessThan(0.02);
    // one finger lifted: the other drags on from where it is
    canvas.dispatchEvent(touch('pointerup', 8, 270, 340));
    canvas.dispatchEvent(touch('pointermove', 7, 80, 350));
    f = input.take();
    expect([f.dragX, f.dragY, f.tilt, f.pinch]).toEqual([10, 10, 0, 0]);
    canvas.dispatchEvent(touch('pointerup', 7, 80, 350));
    canvas.dispatchEvent(touch('pointermove', 7, 90, 360));
    f = input.take();
    expect([f.dragX, f.dragY]).toEqual([0, 0]);
    input.dispose();
  });

  it('touch with a brush: a tap edits; a second finger takes the gesture back from the brush', () => {
    const { canvas, input } = setup({ active: true });
    canvas.dispatchEvent(touch('pointerdown', 3, 110, 120));
    canvas.dispatchEvent(touch('pointerup', 3, 110, 120));
    let f = input.take();
    expect([f.brushPresses, f.brushRelease]).toEqual([[{ x: 100, y: 100 }], true]);
    canvas.dispatchEvent(touch('pointerdown', 4, 110, 120));
    canvas.dispatchEvent(touch('pointerdown', 5, 210, 120));
    f = input.take();
    expect(f.brushPresses).toEqual([]);
    expect([f.brushRelease, input.brushHeld]).toEqual([true, false]);
    input.dispose();
  });
});
