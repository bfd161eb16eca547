// Server push of edits (`GET /api/v1/events`, Server-Sent Events): parsing the events, the
// revision bookkeeping that decides what to reload, and a reconnecting EventSource wrapper.
// No DOM beyond an injectable EventSource constructor, no three.js.

export type EditAction = 'apply' | 'undo' | 'redo';

export type EditEvent =
  | { type: 'hello'; revision: number }
  | { type: 'edit'; revision: number; action: EditAction; id: number | null; chunks: string[] }
  | { type: 'resync'; revision: number };

const isRevision = (v: unknown): v is number => typeof v === 'number' && Number.isInteger(v) && v >= 0;

/**
 * Parses one event of the stream (`type` is the SSE event name, `data` its data). Throws an Error
 * that says what is wrong for an unknown type or malformed data.
 */
export function parseEditEvent(type: string, data: string): EditEvent {
  let body: unknown;
  try {
    body = JSON.parse(data);
  } catch {
    throw new Error(`the server sent a "${type}" event whose data is not JSON: ${data.slice(0, 120)}`);
  }
  if (!body || typeof body !== 'object' || Array.isArray(body)) {
    throw new Error(`the server sent a "${type}" event whose data is not an object: ${data.slice(0, 120)}`);
  }
  const b = body as Record<string, unknown>;
  if (!isRevision(b['revision'])) {
    throw new Error(`the server sent a "${type}" event without a valid revision: ${data.slice(0, 120)}`);
  }
  const revision = b['revision'];
  switch (type) {
    case 'hello':
      return { type, revision };
    case 'resync':
      return { type, revision };
    case 'edit': {
      const action = b['action'];
      if (action !== 'apply' && action !== 'undo' && action !== 'redo') {
        throw new Error(`the server sent an edit event with an unknown action ${JSON.stringify(action)}`);
      }
      const chunks = b['chunks'];
      if (!Array.isArray(chunks) || !chunks.every((k) => typeof k === 'string')) {
        throw new Error(`the server sent an edit event without a list of chunk keys: ${data.slice(0, 120)}`);
      }
      const id = b['id'];
      return { type, revision, action, id: typeof id === 'number' ? id : null, chunks: chunks as string[] };
    }
    default:
      throw new Error(`the server sent an unknown event "${type}"`);
  }
}

/**
 * Which changes of the edit list the viewer has taken in. Every change (an applied, undone or
 * redone edit) has its own revision, and it can reach the viewer twice: as the answer to its own
 * request and as a pushed `edit` event, in either order. The tracker keeps the revision up to
 * which every change was seen, plus the ones seen beyond it, so each change's chunks are reloaded
 * once; and on a (re)connection it says whether something may have been missed.
 */
export class RevisionTracker {
  private mark: number;
  private readonly beyond = new Set<number>();

  /** `revision`: the edit revision of the data the viewer shows (`/planet`'s `edit.revision`). */
  constructor(revision: number) {
    this.mark = revision;
  }

  /** The newest revision seen. */
  get revision(): number {
    let r = this.mark;
    for (const b of this.beyond) r = Math.max(r, b);
    return r;
  }

  /** A change with `revision` arrived (answer or event): true when it is new (reload its chunks). */
  change(revision: number): boolean {
    if (revision <= this.mark || this.beyond.has(revision)) return false;
    this.beyond.add(revision);
    while (this.beyond.delete(this.mark + 1)) this.mark++;
    return true;
  }

  /**
   * The push stream (re)connected and says the server is at `revision`: true when the viewer may
   * have missed a change (the revision differs from everything seen, or some change in between
   * was never seen): then every chunk must be reloaded.
   */
  hello(revision: number): boolean {
    const missed = revision !== this.mark || this.beyond.size > 0;
    this.reset(revision);
    return missed;
  }

  /** Everything was (or is being) reloaded at `revision`. */
  reset(revision: number): void {
    this.mark = revision;
    this.beyond.clear();
  }
}

/** The part of `EventSource` the feed uses (a fake in tests). */
export interface EventSourceLike {
  readonly readyState: number;
  onopen: ((e: Event) => void) | null;
  onerror: ((e: Event) => void) | null;
  addEventListener(type: string, listener: (e: MessageEvent) => void): void;
  close(): void;
}

export type EventSourceFactory = (url: string) => EventSourceLike;

export type FeedState = 'connecting' | 'open' | 'closed';

export interface FeedCallbacks {
  onEvent(e: EditEvent): void;
  /** The connection state changed; `detail` says why when it broke. */
  onState?(state: FeedState, detail?: string): void;
  /** An event could not be understood (the message says why). */
  onBadEvent?(message: string): void;
}

export interface FeedOptions {
  /** First delay before reconnecting after the browser gave up, ms (doubles to 30 s). */
  retryMs?: number;
  setTimer?: (fn: () => void, ms: number) => unknown;
  clearTimer?: (handle: unknown) => void;
}

const CLOSED = 2;

/**
 * One subscription to the push stream. The browser's EventSource reconnects by itself after a
 * dropped connection; when it gives up (an HTTP error, a server that is gone for good) the feed
 * opens a new one after a back-off. Each connection starts with `hello`.
 */
export class EditFeed {
  private source: EventSourceLike | null = null;
  private timer: unknown = null;
  private failures = 0;
  private readonly retryMs: number;
  private readonly setTimer: (fn: () => void, ms: number) => unknown;
  private readonly clearTimer: (handle: unknown) => void;

  constructor(
    private readonly url: string,
    private readonly factory: EventSourceFactory,
    private readonly callbacks: FeedCallbacks,
    opts: FeedOptions = {},
  ) {
    this.retryMs = opts.retryMs ?? 1000;
    this.setTimer = opts.setTimer ?? ((fn, ms) => setTimeout(fn, ms));
    this.clearTimer = opts.clearTimer ?? ((h) => clearTimeout(h as ReturnType<typeof setTimeout>));
  }

  get active(): boolean {
    return this.source !== null || this.timer !== null;
  }

  /** Connects (nothing when already connected or about to reconnect). */
  open(): void {
    if (this.active) return;
    this.connect();
  }

  /** Reconnects now when waiting to (the server is back), instead of after the back-off. */
  reconnectNow(): void {
    if (this.timer === null) return;
    this.clearTimer(this.timer);
    this.failures = 0;
    this.connect();
  }

  /** Disconnects and stops reconnecting. */
  close(): void {
    if (this.timer !== null) this.clearTimer(this.timer);
    this.timer = null;
    if (this.source) {
      this.source.onopen = null;
      this.source.onerror = null;
      this.source.close();
      this.source = null;
      this.callbacks.onState?.('closed');
    }
  }

  private connect(): void {
    this.timer = null;
    const source = this.factory(this.url);
    this.source = source;
    this.callbacks.onState?.('connecting');
    source.onopen = () => {
      if (this.source !== source) return;
      this.failures = 0;
      this.callbacks.onState?.('open');
    };
    source.onerror = () => {
      if (this.source !== source) return;
      if (source.readyState === CLOSED) {
        // the browser gave up on this one: open another later
        source.close();
        this.source = null;
        this.failures++;
        const delay = Math.min(30_000, this.retryMs * 2 ** Math.min(5, this.failures - 1));
        this.callbacks.onState?.('connecting', `the edit stream failed; reconnecting in ${Math.round(delay / 1000)} s`);
        this.timer = this.setTimer(() => this.connect(), delay);
      } else {
        this.callbacks.onState?.('connecting', 'the edit stream was interrupted; reconnecting');
      }
    };
    for (const type of ['hello', 'edit', 'resync']) {
      source.addEventListener(type, (e: MessageEvent) => {
        if (this.source !== source) return;
        let event: EditEvent;
        try {
          event = parseEditEvent(type, String(e.data));
        } catch (err) {
          this.callbacks.onBadEvent?.(err instanceof Error ? err.message : String(err));
          return;
        }
        this.callbacks.onEvent(event);
      });
    }
  }
}
