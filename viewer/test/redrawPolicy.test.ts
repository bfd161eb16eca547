import { describe, expect, it } from 'vitest';
import { RedrawPolicy, SLOW_FRAME_MS, STREAMING_DRAW_SHARE, STREAMING_REDRAW_MS } from '../src/frameLoop';

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
});
