import { describe, expect, it } from 'vitest';
import { GpuTimer, RedrawPolicy, SLOW_FRAME_MS, SLOW_GPU_MS, STREAMING_DRAW_SHARE, STREAMING_REDRAW_MS, type FenceContext } from '../src/frameLoop';

/**
 * Runs frames for `ms`, drawing when the policy says: a frame that draws takes `cost` ms, one that
 * does not `every` ms. Returns when the frames that drew started.
 */
function run(p: RedrawPolicy, t0: number, ms: number, every: number, active: boolean, settled: boolean, cost = every): number[] {
  const drawn: number[] = [];
  let step = every;
  for (let now = t0; now < t0 + ms; now += step) {
    p.frameStarted(step);
    step = every;
    if (p.shouldDraw(now, active, settled)) {
      p.drew(now);
      drawn.push(now);
      step = cost;
    }
  }
  return drawn;
}

describe('RedrawPolicy', () => {
  it('draws every frame on a fast renderer, streaming or not', () => {
    const p = new RedrawPolicy();
    expect(run(p, 0, 1000, 16, false, false)).toHaveLength(63);
    expect(p.renderMs).toBeLessThan(SLOW_FRAME_MS);
  });

  it('on a slow renderer, redraws a still view while streaming at most once in a while', () => {
    const p = new RedrawPolicy();
    // frames that draw take 200 ms (while the camera moves): the renderer is slow
    for (let i = 0; i < 10; i++) {
      p.frameStarted(200);
      expect(p.shouldDraw(i * 200, true, false)).toBe(true);
      p.drew(i * 200);
    }
    expect(p.renderMs).toBeGreaterThan(SLOW_FRAME_MS);
    // frames that do not draw are fast; draws are spaced by a share of the time a draw takes
    // (the mean moves a little with the first fast frame)
    const gap = Math.max(STREAMING_REDRAW_MS, (STREAMING_DRAW_SHARE - 1) * 200);
    const drawn = run(p, 2000, 5000, 16, false, false, 200);
    expect(drawn.length).toBeGreaterThan(0);
    for (let i = 1; i < drawn.length; i++) expect(drawn[i] - drawn[i - 1]).toBeGreaterThanOrEqual(gap);
    expect(drawn.length).toBeLessThanOrEqual(Math.ceil(5000 / gap));
  });

  it('a frame whose picture is the last drawn does not draw, settled or streaming, fast or slow; input still draws', () => {
    const p = new RedrawPolicy();
    p.frameStarted(16);
    expect(p.shouldDraw(0, false, true, false)).toBe(false);
    expect(p.shouldDraw(0, false, false, false)).toBe(false);
    expect(p.shouldDraw(0, false, true, true)).toBe(true);
    expect(p.shouldDraw(0, true, true, false)).toBe(true);
  });

  it('a moving camera, input or a settled view that changed draws every frame, however slow', () => {
    const p = new RedrawPolicy();
    p.frameStarted(0);
    p.drew(0);
    p.frameStarted(500);
    expect(p.renderMs).toBe(500);
    expect(run(p, 500, 2000, 10, true, false, 500)).toHaveLength(4);
    expect(p.renderMs).toBe(500);
    expect(run(p, 2500, 2000, 10, false, true, 500)).toHaveLength(4);
  });

  it('a frame the GPU takes long to finish makes a slow renderer, whatever the frame interval after it', () => {
    // software WebGL: three.js hands a frame over in 20 ms, the GPU process draws it for 8 s
    const p = new RedrawPolicy();
    p.frameStarted(0);
    p.drew(0);
    p.frameStarted(20);
    expect(p.renderMs).toBe(20);
    expect(p.shouldDraw(20, false, false)).toBe(true);
    p.gpuFinished(8000);
    expect(p.costMs).toBe(8000);
    // streaming under a still camera: the next draw waits STREAMING_DRAW_SHARE frame times
    expect(p.shouldDraw(8000, false, false)).toBe(false);
    expect(p.shouldDraw(STREAMING_DRAW_SHARE * 8000 - 1, false, false)).toBe(false);
    expect(p.shouldDraw(STREAMING_DRAW_SHARE * 8000, false, false)).toBe(true);
    // a settled view, a moving camera or input draw at once
    expect(p.shouldDraw(8000, false, true)).toBe(true);
    expect(p.shouldDraw(8000, true, false)).toBe(true);
  });

  it('on a slow renderer, no streaming draw is queued behind one the GPU has not finished', () => {
    const p = new RedrawPolicy();
    p.frameStarted(0);
    p.drew(0);
    p.frameStarted(500);
    expect(p.shouldDraw(10_000, false, false, true, false)).toBe(true);
    expect(p.shouldDraw(10_000, false, false, true, true)).toBe(false);
    // ... but a settled view or a moving camera draws
    expect(p.shouldDraw(10_000, false, true, true, true)).toBe(true);
    expect(p.shouldDraw(10_000, true, false, true, true)).toBe(true);
    // a fast renderer draws whatever the fence says (a GPU a frame or two behind is normal)
    const fast = new RedrawPolicy();
    fast.frameStarted(0);
    fast.drew(0);
    fast.frameStarted(16);
    expect(fast.shouldDraw(16, false, false, true, true)).toBe(true);
  });

  it('a fence read a frame or two late on a fast GPU (a 30 Hz display) is no slow renderer', () => {
    const p = new RedrawPolicy();
    p.frameStarted(0);
    p.drew(0);
    p.frameStarted(33);
    p.gpuFinished(66);
    expect(p.slow).toBe(false);
    expect(p.shouldDraw(40, false, false, true, true)).toBe(true);
    for (let i = 0; i < 20; i++) p.gpuFinished(SLOW_GPU_MS + 100);
    expect(p.slow).toBe(true);
    expect(p.shouldDraw(80, false, false, true, false)).toBe(false);
  });
});

/** A fake WebGL 2 context whose fences signal when `signal()` is called. */
function fakeFences() {
  let next = 1;
  const signalled = new Set<number>();
  const live = new Set<number>();
  const gl = {
    SYNC_GPU_COMMANDS_COMPLETE: 0x9117,
    SYNC_STATUS: 0x9114,
    SIGNALED: 0x9119,
    fenceSync: () => {
      const id = next++;
      live.add(id);
      return id as unknown as WebGLSync;
    },
    getSyncParameter: (sync: WebGLSync, pname: number) => {
      expect(pname).toBe(0x9114);
      return signalled.has(sync as unknown as number) ? 0x9119 : 0x9118;
    },
    deleteSync: (sync: WebGLSync | null) => {
      live.delete(sync as unknown as number);
    },
  } as unknown as FenceContext;
  return { gl, live, signal: () => live.forEach((id) => signalled.add(id)) };
}

describe('GpuTimer', () => {
  it('times a drawn frame from the draw to its fence, one at a time, and frees the fence', () => {
    const f = fakeFences();
    const t = new GpuTimer(f.gl);
    expect(t.busy).toBe(false);
    expect(t.poll(0)).toBeNull();
    t.drew(100);
    expect(t.busy).toBe(true);
    expect(t.poll(200)).toBeNull();
    // a draw while the fence is out is not timed (the first one is)
    t.drew(300);
    expect(f.live.size).toBe(1);
    f.signal();
    expect(t.poll(8100)).toBe(8000);
    expect(t.busy).toBe(false);
    expect(f.live.size).toBe(0);
    expect(t.poll(9000)).toBeNull();
  });

  it('without WebGL 2 measures nothing and is never busy', () => {
    const t = new GpuTimer(null);
    t.drew(0);
    expect(t.busy).toBe(false);
    expect(t.poll(10)).toBeNull();
  });
});
