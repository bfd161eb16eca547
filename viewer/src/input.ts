// Mouse, wheel, touch and keyboard input on the canvas, turned into deltas the app consumes each
// frame. Touch: one finger drags as the mouse does, two fingers pinch (zoom) or move up and down
// together (tilt); the middle button's drag tilts too.

import { SHORTCUTS, heldCodes, shortcutOf } from './shortcuts';

export interface InputFrame {
  /** Pointer drag (or pointer-lock motion) since the last frame, pixels. */
  dragX: number;
  dragY: number;
  /** Wheel delta since the last frame (pixels, positive = away / zoom out). */
  wheel: number;
  /** Tilt since the last frame, degrees (positive: toward the horizon): middle drag, two fingers. */
  tilt: number;
  /** Pinch since the last frame: the log of the fingers' distance ratio (positive: spread, zoom in). */
  pinch: number;
  forward: number;
  right: number;
  up: number;
  /** Held "fast" modifier (Ctrl / Alt) */
  fast: boolean;
  /** With a brush tool: where the left button went down (canvas pixels) since the last frame. */
  brushPress: { x: number; y: number } | null;
  /** Every such press since the last frame, in order (two quick clicks can fall in one frame). */
  brushPresses: { x: number; y: number }[];
  /** With a brush tool: the left button went up since the last frame (after `brushPress`). */
  brushRelease: boolean;
}

const FORWARD = heldCodes('forward');
const BACK = heldCodes('back');
const LEFT = heldCodes('left');
const RIGHT = heldCodes('right');
const UP = heldCodes('up');
const DOWN = heldCodes('down');
const FAST = heldCodes('fast');
/** Every key this module gives a meaning to (other shortcuts must not use them). */
export const BOUND_KEYS: ReadonlySet<string> = new Set(
  SHORTCUTS.filter((s) => s.held || s.action === 'mode' || s.action === 'walk').flatMap((s) => s.codes),
);

/** Degrees of tilt per pixel of a middle drag (or of two fingers' midpoint). */
export const TILT_PER_PX = 0.25;

export interface InputCallbacks {
  /** Tab: switch between orbit and fly. */
  onToggleMode(): void;
  /** G: walk on / off. */
  onToggleWalk(): void;
  /**
   * Whether a brush tool is chosen: then the left button edits (see `brushPress`) and only the
   * right button moves the camera.
   */
  brushActive?(): boolean;
  /** A key went down outside text fields; return true when it was a shortcut (consumed). */
  onShortcut?(e: KeyboardEvent): boolean;
}

export class Input {
  private readonly held = new Set<string>();
  private dragX = 0;
  private dragY = 0;
  private wheel = 0;
  private tilt = 0;
  private pinch = 0;
  private dragging = false;
  private tilting = false;
  /** The touches on the canvas (pointer id to its last position, client pixels). */
  private readonly touches = new Map<number, { x: number; y: number }>();
  private lastX = 0;
  private lastY = 0;
  private brushing = false;
  private brushPresses: { x: number; y: number }[] = [];
  private brushRelease = false;
  /** The mouse over the canvas (canvas pixels), or null when it is elsewhere. */
  private hover: { x: number; y: number } | null = null;
  private readonly disposers: (() => void)[] = [];

  constructor(
    private readonly element: HTMLElement,
    private readonly callbacks: InputCallbacks,
  ) {
    const on = <K extends keyof HTMLElementEventMap>(
      target: HTMLElement | Window | Document,
      type: K,
      fn: (e: HTMLElementEventMap[K]) => void,
      opts?: AddEventListenerOptions,
    ): void => {
      target.addEventListener(type, fn as EventListener, opts);
      this.disposers.push(() => target.removeEventListener(type, fn as EventListener, opts));
    };
    on(element, 'pointerdown', (e) => {
      if (e.pointerType === 'touch') {
        this.touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
        if (this.touches.size >= 2) {
          // a second finger: a pinch or a tilt, not a drag nor an edit
          this.dragging = false;
          if (this.brushing) {
            this.brushing = false;
            this.brushPresses = [];
            this.brushRelease = true;
          }
          element.setPointerCapture?.(e.pointerId);
          return;
        }
      }
      if (e.button === 1) {
        e.preventDefault();
        this.tilting = true;
        this.lastY = e.clientY;
        element.setPointerCapture?.(e.pointerId);
        element.focus();
        return;
      }
      if (e.button !== 0 && e.button !== 2) return;
      this.hover = this.local(e);
      if (e.button === 0 && this.callbacks.brushActive?.()) {
        this.brushing = true;
        this.brushPresses.push(this.local(e));
        this.brushRelease = false;
      } else {
        this.dragging = true;
        this.lastX = e.clientX;
        this.lastY = e.clientY;
      }
      element.setPointerCapture?.(e.pointerId);
      element.focus();
    });
    on(element, 'pointermove', (e) => {
      if (document.pointerLockElement === element) {
        this.dragX += e.movementX;
        this.dragY += e.movementY;
        return;
      }
      if (e.pointerType === 'touch' && this.touches.has(e.pointerId) && this.touches.size >= 2) {
        this.twoFingers(e.pointerId, e.clientX, e.clientY);
        return;
      }
      if (e.pointerType === 'touch' && this.touches.has(e.pointerId)) this.touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
      this.hover = this.local(e);
      if (this.tilting) {
        this.tilt -= (e.clientY - this.lastY) * TILT_PER_PX;
        this.lastY = e.clientY;
        return;
      }
      if (!this.dragging) return;
      this.dragX += e.clientX - this.lastX;
      this.dragY += e.clientY - this.lastY;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
    });
    const stop = (e: PointerEvent): void => {
      if (e.pointerType === 'touch' && this.touches.delete(e.pointerId)) {
        if (this.touches.size === 1) {
          // back to one finger: it drags on from where it is (no jump)
          const [rest] = [...this.touches.values()];
          this.dragging = !this.callbacks.brushActive?.();
          this.lastX = rest!.x;
          this.lastY = rest!.y;
          return;
        }
        if (this.touches.size > 1) return;
      }
      if (e.button === 1 || e.type === 'pointercancel') this.tilting = false;
      if (this.brushing && (e.button === 0 || e.type === 'pointercancel')) {
        this.brushing = false;
        this.brushRelease = true;
      }
      if (e.button === 0 || e.button === 2 || e.type === 'pointercancel') this.dragging = false;
      if (!this.brushing && !this.dragging && !this.tilting && element.hasPointerCapture?.(e.pointerId)) {
        element.releasePointerCapture(e.pointerId);
      }
    };
    on(element, 'pointerup', stop);
    on(element, 'pointercancel', stop);
    on(element, 'pointerleave', () => {
      if (!this.brushing && !this.dragging) this.hover = null;
    });
    on(
      element,
      'wheel',
      (e) => {
        e.preventDefault();
        const scale = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
        this.wheel += e.deltaY * scale;
      },
      { passive: false },
    );
    on(element, 'contextmenu', (e) => e.preventDefault());
    // the middle button tilts: no autoscroll, no paste
    on(element, 'mousedown', (e) => {
      if (e.button === 1) e.preventDefault();
    });
    on(window, 'keydown', (e) => {
      if (isTyping(e.target)) return;
      if (this.callbacks.onShortcut?.(e)) {
        e.preventDefault();
        return;
      }
      const action = shortcutOf(e)?.action;
      if (action === 'mode') {
        e.preventDefault();
        this.callbacks.onToggleMode();
        return;
      }
      if (action === 'walk') {
        if (!e.repeat) this.callbacks.onToggleWalk();
        return;
      }
      if (e.code === 'Space' || e.code.startsWith('Arrow') || e.code.startsWith('Page')) {
        e.preventDefault();
      }
      this.held.add(e.code);
    });
    on(window, 'keyup', (e) => {
      this.held.delete(e.code);
    });
    on(window, 'blur', () => {
      this.held.clear();
      this.dragging = false;
      this.tilting = false;
      this.touches.clear();
      if (this.brushing) {
        this.brushing = false;
        this.brushRelease = true;
      }
    });
  }

  /**
   * Finger `id` of two or more moved to (`x`, `y`): against the first other finger, a pinch when
   * their distance changed more than their midpoint rose or fell, else a tilt by the midpoint's
   * vertical motion.
   */
  private twoFingers(id: number, x: number, y: number): void {
    const before = this.touches.get(id)!;
    const other = [...this.touches.entries()].find(([k]) => k !== id)?.[1];
    this.touches.set(id, { x, y });
    if (!other) return;
    const d0 = Math.hypot(before.x - other.x, before.y - other.y);
    const d1 = Math.hypot(x - other.x, y - other.y);
    const rise = (y - before.y) / 2;
    if (Math.abs(d1 - d0) > Math.abs(rise)) {
      if (d0 > 1 && d1 > 1) this.pinch += Math.log(d1 / d0);
    } else {
      this.tilt -= rise * TILT_PER_PX;
    }
  }

  private local(e: PointerEvent): { x: number; y: number } {
    if (document.pointerLockElement === this.element) {
      return { x: this.element.clientWidth / 2, y: this.element.clientHeight / 2 };
    }
    const r = this.element.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  }

  /**
   * The point the mouse is over, canvas pixels (the centre under pointer lock), or null when it
   * is not over the canvas.
   */
  pointer(): { x: number; y: number } | null {
    if (document.pointerLockElement === this.element) {
      return { x: this.element.clientWidth / 2, y: this.element.clientHeight / 2 };
    }
    return this.hover;
  }

  /** Whether the left button is held for a brush. */
  get brushHeld(): boolean {
    return this.brushing;
  }

  /** Asks for pointer lock (fly mode mouse look without dragging). */
  requestPointerLock(): void {
    if (document.pointerLockElement !== this.element) {
      const r = this.element.requestPointerLock?.() as unknown;
      if (r instanceof Promise) r.catch(() => undefined);
    }
  }

  releasePointerLock(): void {
    if (document.pointerLockElement === this.element) document.exitPointerLock();
  }

  /** The input since the last call. */
  take(): InputFrame {
    // with Ctrl (or Cmd) held, Shift is part of a shortcut (Ctrl+Shift+Z: redo), not "down"
    const chord = ['ControlLeft', 'ControlRight', 'MetaLeft', 'MetaRight'].some((k) => this.held.has(k));
    const axis = (pos: ReadonlySet<string>, neg: ReadonlySet<string>): number => {
      let v = 0;
      for (const k of this.held) {
        if (chord && (k === 'ShiftLeft' || k === 'ShiftRight')) continue;
        if (pos.has(k)) v = Math.min(1, v + 1);
        if (neg.has(k)) v = Math.max(-1, v - 1);
      }
      return v;
    };
    const frame: InputFrame = {
      dragX: this.dragX,
      dragY: this.dragY,
      wheel: this.wheel,
      tilt: this.tilt,
      pinch: this.pinch,
      forward: axis(FORWARD, BACK),
      right: axis(RIGHT, LEFT),
      up: axis(UP, DOWN),
      fast: [...FAST].some((k) => this.held.has(k)),
      brushPress: this.brushPresses[0] ?? null,
      brushPresses: this.brushPresses,
      brushRelease: this.brushRelease,
    };
    this.brushPresses = [];
    this.brushRelease = false;
    this.dragX = 0;
    this.dragY = 0;
    this.wheel = 0;
    this.tilt = 0;
    this.pinch = 0;
    return frame;
  }

  dispose(): void {
    for (const d of this.disposers) d();
  }
}

function isTyping(target: EventTarget | null): boolean {
  return (
    target instanceof HTMLInputElement ||
    target instanceof HTMLSelectElement ||
    target instanceof HTMLTextAreaElement
  );
}
