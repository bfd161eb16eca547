// The connection monitor on a fake clock: offline at the first unreachable request, probes with
// a back-off, the retry button, back online at the first answer.

import { describe, expect, it } from 'vitest';
import { ConnectionMonitor, offlineMessage, probeDelay, type ConnectionState } from '../src/connection';

function harness(probeResults: (boolean | 'hang')[]) {
  let now = 0;
  const timers: { at: number; fn: () => void; id: number }[] = [];
  let nextId = 1;
  const states: ConnectionState[] = [];
  let onlines = 0;
  let probes = 0;
  let aborted = 0;
  const m = new ConnectionMonitor({
    probe: (signal) => {
      probes++;
      const r = probeResults.shift();
      if (r === 'hang') {
        // never answered: settles only when the monitor gives it up
        return new Promise<void>((_, reject) =>
          signal.addEventListener('abort', () => {
            aborted++;
            reject(new Error('aborted'));
          }),
        );
      }
      return r ? Promise.resolve() : Promise.reject(new Error('refused'));
    },
    onChange: (s) => states.push(s),
    onOnline: () => onlines++,
    now: () => now,
    setTimer: (fn, ms) => {
      const t = { at: now + ms, fn, id: nextId++ };
      timers.push(t);
      return t.id;
    },
    clearTimer: (id) => {
      const i = timers.findIndex((t) => t.id === id);
      if (i >= 0) timers.splice(i, 1);
    },
  });
  /** Runs the clock to `t`, firing timers (and the probes' promises) on the way. */
  const advance = async (t: number): Promise<void> => {
    for (;;) {
      timers.sort((a, b) => a.at - b.at);
      const next = timers[0];
      if (!next || next.at > t) break;
      timers.shift();
      now = next.at;
      next.fn();
      for (let i = 0; i < 5; i++) await Promise.resolve();
    }
    now = t;
  };
  return { m, states, advance, onlines: () => onlines, probes: () => probes, aborted: () => aborted, pending: () => timers.length };
}

describe('ConnectionMonitor', () => {
  it('goes offline at an unreachable request and probes 1, 2, 4, 8, 10, 10 s apart until an answer', async () => {
    const h = harness([false, false, false, false, false, true]);
    h.m.reached(); // online already: nothing
    expect(h.states).toEqual([]);
    h.m.unreachable();
    h.m.unreachable(); // once is enough
    expect(h.m.state()).toMatchObject({ online: false, since: 0, attempts: 0, nextProbeAt: 1000 });
    await h.advance(999);
    expect(h.probes()).toBe(0);
    await h.advance(1000);
    expect([h.probes(), h.m.state().nextProbeAt]).toEqual([1, 3000]);
    await h.advance(3000 + 4000 + 8000 + 10_000 - 1);
    expect(h.probes()).toBe(4);
    await h.advance(25_000);
    expect(h.probes()).toBe(5);
    expect(h.m.state().nextProbeAt).toBe(35_000);
    await h.advance(35_000);
    expect(h.probes()).toBe(6);
    expect(h.m.state()).toEqual({ online: true, since: null, attempts: 0, nextProbeAt: null });
    expect([h.onlines(), h.pending()]).toEqual([1, 0]);
  });

  it('retries at once on the button, and an answer to any request brings it back', async () => {
    const h = harness([false, true]);
    h.m.unreachable();
    h.m.retryNow();
    for (let i = 0; i < 5; i++) await Promise.resolve();
    expect(h.probes()).toBe(1);
    expect(h.m.state()).toMatchObject({ online: false, attempts: 1, nextProbeAt: 2000 });
    // a chunk request answered meanwhile: online, the probe's timer cancelled
    h.m.reached();
    expect([h.m.state().online, h.onlines(), h.pending()]).toEqual([true, 1, 0]);
    h.m.retryNow(); // online: nothing
    expect(h.probes()).toBe(1);
  });

  it('says since when and when it tries again', () => {
    const s: ConnectionState = { online: false, since: 1000, attempts: 2, nextProbeAt: 9500 };
    expect(offlineMessage(s, 5000)).toBe('The PMC server does not answer (for 4 s): trying again in 5 s');
    expect(offlineMessage({ ...s, nextProbeAt: null }, 5000)).toMatch(/trying now/);
    expect(offlineMessage({ online: true, since: null, attempts: 0, nextProbeAt: null }, 0)).toBeNull();
    expect([0, 1, 2, 3, 4, 30].map((a) => probeDelay(a))).toEqual([1000, 2000, 4000, 8000, 10_000, 10_000]);
  });

  it('a probe that never answers does not keep the viewer offline (the chunk streamer paused with it)', async () => {
    const h = harness(['hang', 'hang', true]);
    h.m.unreachable();
    await h.advance(1000);
    expect([h.probes(), h.m.state().nextProbeAt]).toEqual([1, null]);
    // the first probe hangs: given up after 10 s, the next one after the back-off (2 s)
    await h.advance(10_999);
    expect([h.probes(), h.aborted(), h.m.state().online]).toEqual([1, 0, false]);
    await h.advance(11_000);
    expect([h.aborted(), h.m.state().nextProbeAt]).toEqual([1, 13_000]);
    await h.advance(13_000);
    expect(h.probes()).toBe(2);
    // so does the second; the third answers
    await h.advance(23_000);
    expect([h.aborted(), h.m.state().nextProbeAt]).toEqual([2, 27_000]);
    await h.advance(27_000);
    expect([h.probes(), h.m.state().online, h.onlines(), h.pending()]).toEqual([3, true, 1, 0]);
  });
});
