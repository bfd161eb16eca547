// Whether the view is ready: the frames in a row in which the level-of-detail selection for the
// current view is made and exactly its chunks are shown, nothing pending, and the promises of
// `__pmc.ready()` waiting for two such frames.

interface Waiter {
  resolve: () => void;
  reject: (e: Error) => void;
  timer: number;
}

export class Readiness {
  private settledFrames = 0;
  private waiters: Waiter[] = [];

  /** The last two frames were settled. */
  get ready(): boolean {
    return this.settledFrames >= 2;
  }

  /** What is to be shown changed (a camera, a planet, the selection's settings): count again. */
  reset(): void {
    this.settledFrames = 0;
  }

  /** One frame, settled or not; the second settled frame in a row resolves every waiter. */
  frame(settled: boolean): void {
    this.settledFrames = settled ? this.settledFrames + 1 : 0;
    if (this.settledFrames >= 2 && this.waiters.length > 0) {
      const waiters = this.waiters;
      this.waiters = [];
      for (const w of waiters) {
        clearTimeout(w.timer);
        w.resolve();
      }
    }
  }

  /**
   * Resolves once two frames in a row are settled, at least one of them from now on; rejects with
   * `timedOut()` after `timeoutMs`.
   */
  wait(timeoutMs: number, timedOut: () => Error): Promise<void> {
    return new Promise<void>((resolve, reject) => {
      this.settledFrames = Math.min(this.settledFrames, 1);
      const timer = window.setTimeout(() => {
        this.waiters = this.waiters.filter((w) => w.timer !== timer);
        reject(timedOut());
      }, timeoutMs);
      this.waiters.push({ resolve, reject, timer });
    });
  }
}
