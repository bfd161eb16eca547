import { describe, expect, it } from 'vitest';
import { EditFeed, RevisionTracker, parseEditEvent, type EditEvent, type EventSourceLike } from '../src/editEvents';

describe('parseEditEvent', () => {
  it('reads hello, edit and resync', () => {
    expect(parseEditEvent('hello', '{"revision": 12}')).toEqual({ type: 'hello', revision: 12 });
    expect(parseEditEvent('resync', '{"revision": 0}')).toEqual({ type: 'resync', revision: 0 });
    expect(
      parseEditEvent('edit', '{"revision": 13, "action": "apply", "id": 11, "chunks": ["top/0/3/4/1", "top/0/3/4/0"]}'),
    ).toEqual({ type: 'edit', revision: 13, action: 'apply', id: 11, chunks: ['top/0/3/4/1', 'top/0/3/4/0'] });
    expect(parseEditEvent('edit', '{"revision": 14, "action": "undo", "id": null, "chunks": []}')).toMatchObject({
      action: 'undo', id: null, chunks: [],
    });
  });

  it('refuses what it cannot trust, saying why', () => {
    expect(() => parseEditEvent('edit', 'not json')).toThrow(/not JSON/);
    expect(() => parseEditEvent('hello', '[1]')).toThrow(/not an object/);
    expect(() => parseEditEvent('hello', '{"revision": -1}')).toThrow(/revision/);
    expect(() => parseEditEvent('hello', '{"revision": "3"}')).toThrow(/revision/);
    expect(() => parseEditEvent('edit', '{"revision": 1, "action": "explode", "chunks": []}')).toThrow(/unknown action/);
    expect(() => parseEditEvent('edit', '{"revision": 1, "action": "apply", "chunks": [1]}')).toThrow(/chunk keys/);
    expect(() => parseEditEvent('edit', '{"revision": 1, "action": "apply"}')).toThrow(/chunk keys/);
    expect(() => parseEditEvent('bye', '{"revision": 1}')).toThrow(/unknown event "bye"/);
  });
});

describe('RevisionTracker', () => {
  it('takes each change once, whether the answer or the event comes first', () => {
    const t = new RevisionTracker(10);
    expect(t.change(11)).toBe(true); // our answer
    expect(t.change(11)).toBe(false); // its event
    expect(t.change(13)).toBe(true); // an event overtakes...
    expect(t.change(12)).toBe(true); // ...another client's change
    expect(t.change(13)).toBe(false);
    expect(t.change(9)).toBe(false);
    expect(t.revision).toBe(13);
  });

  it('says on a (re)connection whether anything may have been missed', () => {
    const t = new RevisionTracker(5);
    expect(t.hello(5)).toBe(false); // first connection, nothing happened meanwhile
    expect(t.change(6)).toBe(true);
    expect(t.hello(6)).toBe(false); // reconnected, nothing missed
    expect(t.hello(8)).toBe(true); // two changes happened while disconnected
    expect(t.revision).toBe(8);
    expect(t.change(10)).toBe(true); // 9 never seen...
    expect(t.hello(10)).toBe(true); // ...so a reconnection at 10 reloads everything
    expect(t.hello(3)).toBe(true); // a restarted server counts anew
    expect(t.change(4)).toBe(true);
  });

  it('starts over on a resync', () => {
    const t = new RevisionTracker(0);
    t.change(2);
    t.reset(7);
    expect(t.revision).toBe(7);
    expect(t.change(7)).toBe(false);
    expect(t.change(8)).toBe(true);
  });
});

class FakeSource implements EventSourceLike {
  readyState = 0;
  onopen: ((e: Event) => void) | null = null;
  onerror: ((e: Event) => void) | null = null;
  closed = false;
  private readonly listeners = new Map<string, ((e: MessageEvent) => void)[]>();
  constructor(readonly url: string) {}
  addEventListener(type: string, fn: (e: MessageEvent) => void): void {
    this.listeners.set(type, [...(this.listeners.get(type) ?? []), fn]);
  }
  close(): void {
    this.closed = true;
    this.readyState = 2;
  }
  emit(type: string, data: string): void {
    for (const fn of this.listeners.get(type) ?? []) fn({ data } as MessageEvent);
  }
  open(): void {
    this.readyState = 1;
    this.onopen?.({} as Event);
  }
  fail(readyState: number): void {
    this.readyState = readyState;
    this.onerror?.({} as Event);
  }
}

function feedWithFakes() {
  const sources: FakeSource[] = [];
  const timers: { fn: () => void; ms: number }[] = [];
  const events: EditEvent[] = [];
  const states: string[] = [];
  const bad: string[] = [];
  const feed = new EditFeed(
    'api/v1/events',
    (url) => {
      const s = new FakeSource(url);
      sources.push(s);
      return s;
    },
    {
      onEvent: (e) => events.push(e),
      onState: (s, d) => states.push(d ? `${s}: ${d}` : s),
      onBadEvent: (m) => bad.push(m),
    },
    { retryMs: 1000, setTimer: (fn, ms) => timers.push({ fn, ms }), clearTimer: () => undefined },
  );
  return { feed, sources, timers, events, states, bad };
}

describe('EditFeed', () => {
  it('passes parsed events on and reports bad ones', () => {
    const f = feedWithFakes();
    f.feed.open();
    f.feed.open(); // idempotent
    expect(f.sources.length).toBe(1);
    expect(f.sources[0]!.url).toBe('api/v1/events');
    f.sources[0]!.open();
    f.sources[0]!.emit('hello', '{"revision": 3}');
    f.sources[0]!.emit('edit', '{"revision": 4, "action": "apply", "id": 1, "chunks": ["top/0/0/0/0"]}');
    f.sources[0]!.emit('edit', '{"revision": "x"}');
    expect(f.events).toEqual([
      { type: 'hello', revision: 3 },
      { type: 'edit', revision: 4, action: 'apply', id: 1, chunks: ['top/0/0/0/0'] },
    ]);
    expect(f.bad.length).toBe(1);
    expect(f.states).toEqual(['connecting', 'open']);
  });

  it('lets the browser reconnect a dropped stream, and reconnects itself when the browser gives up', () => {
    const f = feedWithFakes();
    f.feed.open();
    f.sources[0]!.fail(0); // CONNECTING: the browser retries
    expect(f.sources.length).toBe(1);
    expect(f.timers.length).toBe(0);
    f.sources[0]!.fail(2); // CLOSED: given up
    expect(f.sources[0]!.closed).toBe(true);
    expect(f.timers.map((t) => t.ms)).toEqual([1000]);
    expect(f.feed.active).toBe(true);
    f.timers[0]!.fn();
    expect(f.sources.length).toBe(2);
    f.sources[1]!.fail(2);
    expect(f.timers.map((t) => t.ms)).toEqual([1000, 2000]); // back-off
    // the old source's events are ignored
    f.sources[0]!.emit('hello', '{"revision": 1}');
    expect(f.events).toEqual([]);
    f.timers[1]!.fn();
    f.sources[2]!.open();
    f.sources[2]!.emit('resync', '{"revision": 9}');
    expect(f.events).toEqual([{ type: 'resync', revision: 9 }]);
  });

  it('closes for good', () => {
    const f = feedWithFakes();
    f.feed.open();
    f.feed.close();
    expect(f.sources[0]!.closed).toBe(true);
    expect(f.feed.active).toBe(false);
    f.sources[0]!.emit('hello', '{"revision": 1}');
    expect(f.events).toEqual([]);
    expect(f.states.at(-1)).toBe('closed');
    f.feed.open();
    expect(f.sources.length).toBe(2);
  });
});
