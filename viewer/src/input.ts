// Mouse, wheel and keyboard input on the canvas, turned into deltas the app consumes each frame.

export interface InputFrame {
  /** Pointer drag (or pointer-lock motion) since the last frame, pixels. */
  dragX: number;
  dragY: number;
  /** Wheel delta since the last frame (pixels, positive = away / zoom out). */
  wheel: number;
  forward: number;
  right: number;
  up: number;
  /** Held "fast" modifier (Ctrl / Alt) */
  fast: boolean;
}

const FORWARD = new Set(['KeyW', 'ArrowUp']);
const BACK = new Set(['KeyS', 'ArrowDown']);
const LEFT = new Set(['KeyA', 'ArrowLeft']);
const RIGHT = new Set(['KeyD', 'ArrowRight']);
const UP = new Set(['KeyE', 'Space', 'PageUp']);
const DOWN = new Set(['KeyQ', 'ShiftLeft', 'ShiftRight', 'PageDown']);

export interface InputCallbacks {
  /** Tab: switch between orbit and fly. */
  onToggleMode(): void;
  /** G: walk on / off. */
  onToggleWalk(): void;
}

export class Input {
  private readonly held = new Set<string>();
  private dragX = 0;
  private dragY = 0;
  private wheel = 0;
  private dragging = false;
  private lastX = 0;
  private lastY = 0;
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
      if (e.button !== 0 && e.button !== 2) return;
      this.dragging = true;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
      element.setPointerCapture?.(e.pointerId);
      element.focus();
    });
    on(element, 'pointermove', (e) => {
      if (document.pointerLockElement === element) {
        this.dragX += e.movementX;
        this.dragY += e.movementY;
        return;
      }
      if (!this.dragging) return;
      this.dragX += e.clientX - this.lastX;
      this.dragY += e.clientY - this.lastY;
      this.lastX = e.clientX;
      this.lastY = e.clientY;
    });
    const stop = (e: PointerEvent): void => {
      this.dragging = false;
      if (element.hasPointerCapture?.(e.pointerId)) element.releasePointerCapture(e.pointerId);
    };
    on(element, 'pointerup', stop);
    on(element, 'pointercancel', stop);
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
    on(window, 'keydown', (e) => {
      if (isTyping(e.target)) return;
      if (e.code === 'Tab') {
        e.preventDefault();
        this.callbacks.onToggleMode();
        return;
      }
      if (e.code === 'KeyG' && !e.repeat) {
        this.callbacks.onToggleWalk();
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
    });
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
    const axis = (pos: Set<string>, neg: Set<string>): number => {
      let v = 0;
      for (const k of this.held) {
        if (pos.has(k)) v = Math.min(1, v + 1);
        if (neg.has(k)) v = Math.max(-1, v - 1);
      }
      return v;
    };
    const frame: InputFrame = {
      dragX: this.dragX,
      dragY: this.dragY,
      wheel: this.wheel,
      forward: axis(FORWARD, BACK),
      right: axis(RIGHT, LEFT),
      up: axis(UP, DOWN),
      fast: this.held.has('ControlLeft') || this.held.has('AltLeft'),
    };
    this.dragX = 0;
    this.dragY = 0;
    this.wheel = 0;
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
