// Whether the PMC server answers. A request that cannot reach it (connection refused, network
// gone: not an HTTP error, not a cancelled request) puts the viewer offline: the notice says so
// and a probe (`/health`) retries with a back-off, or at once from the notice's button. The first
// answer, to a probe or to any request, brings the viewer back online, and the app resumes
// (failed chunks fetched again, the edit stream reopened, the planet reloaded if it changed). A
// probe unanswered after `probeTimeoutMs` is aborted and counts as failed: a probe that hung held
// the viewer offline for good, and the chunk streamer paused with it.
// Pure: the probe, the clock and the timers are passed in.

/** What the notice shows. */
export interface ConnectionState {
  online: boolean;
  /** When the server stopped answering (ms of the clock), null online. */
  since: number | null;
  /** Probes tried since. */
  attempts: number;
  /** When the next probe goes (ms of the clock), null online or while one is in flight. */
  nextProbeAt: number | null;
}

export interface ConnectionOptions {
  /** Resolves when the server answers, rejects when it cannot be reached (or `signal` aborts). */
  probe(signal: AbortSignal): Promise<void>;
  /** The state changed. */
  onChange(state: ConnectionState): void;
  /** Back online after being offline. */
  onOnline(): void;
  now?: () => number;
  setTimer?: (fn: () => void, ms: number) => unknown;
  clearTimer?: (handle: unknown) => void;
  /** The first probe's delay, ms (doubled after each failed probe up to `maxDelayMs`). */
  firstDelayMs?: number;
  maxDelayMs?: number;
  /** How long a probe may go unanswered before it counts as failed, ms (default 10 s). */
  probeTimeoutMs?: number;
}

/** Milliseconds before probe number `attempt` (0-based): `first` doubled each time, at most `max`. */
export function probeDelay(attempt: number, first = 1000, max = 10_000): number {
  return Math.min(max, first * 2 ** Math.min(20, Math.max(0, attempt)));
}

export class ConnectionMonitor {
  private online = true;
  private since: number | null = null;
  private attempts = 0;
  private timer: unknown = null;
  private nextAt: number | null = null;
  private probing = false;
  private readonly now: () => number;
  private readonly setTimer: (fn: () => void, ms: number) => unknown;
  private readonly clearTimer: (handle: unknown) => void;
  private readonly first: number;
  private readonly max: number;
  private readonly probeTimeout: number;

  constructor(private readonly opts: ConnectionOptions) {
    this.now = opts.now ?? (() => Date.now());
    this.setTimer = opts.setTimer ?? ((fn, ms) => setTimeout(fn, ms));
    this.clearTimer = opts.clearTimer ?? ((h) => clearTimeout(h as ReturnType<typeof setTimeout>));
    this.first = opts.firstDelayMs ?? 1000;
    this.max = opts.maxDelayMs ?? 10_000;
    this.probeTimeout = opts.probeTimeoutMs ?? 10_000;
  }

  state(): ConnectionState {
    return { online: this.online, since: this.since, attempts: this.attempts, nextProbeAt: this.nextAt };
  }

  /** A request got an answer (any HTTP status): the server is there. */
  reached(): void {
    if (this.online) return;
    this.cancelTimer();
    this.online = true;
    this.since = null;
    this.attempts = 0;
    this.opts.onChange(this.state());
    this.opts.onOnline();
  }

  /** A request could not reach the server. */
  unreachable(): void {
    if (!this.online) return;
    this.online = false;
    this.since = this.now();
    this.attempts = 0;
    this.schedule();
  }

  /** Probes now (the notice's button); nothing while online or while a probe is in flight. */
  retryNow(): void {
    if (this.online || this.probing) return;
    this.cancelTimer();
    void this.probeOnce();
  }

  /** Stops probing (the page goes away). */
  dispose(): void {
    this.cancelTimer();
  }

  private schedule(): void {
    const delay = probeDelay(this.attempts, this.first, this.max);
    this.nextAt = this.now() + delay;
    this.timer = this.setTimer(() => {
      this.timer = null;
      void this.probeOnce();
    }, delay);
    this.opts.onChange(this.state());
  }

  private cancelTimer(): void {
    if (this.timer !== null) this.clearTimer(this.timer);
    this.timer = null;
    this.nextAt = null;
  }

  private async probeOnce(): Promise<void> {
    this.probing = true;
    this.nextAt = null;
    this.attempts++;
    this.opts.onChange(this.state());
    const abort = new AbortController();
    const ok = await new Promise<boolean>((resolve) => {
      const timer = this.setTimer(() => {
        abort.abort();
        resolve(false);
      }, this.probeTimeout);
      this.opts.probe(abort.signal).then(
        () => resolve(true),
        () => resolve(false),
      ).finally(() => this.clearTimer(timer));
    });
    this.probing = false;
    if (this.online) return;
    if (ok) this.reached();
    else this.schedule();
  }
}

/** The notice's text for `s` at `now` (ms of the same clock), or null online. */
export function offlineMessage(s: ConnectionState, now: number): string | null {
  if (s.online) return null;
  const gone = s.since === null ? 0 : Math.max(0, Math.round((now - s.since) / 1000));
  const next =
    s.nextProbeAt === null ? 'trying now…' : `trying again in ${Math.max(1, Math.ceil((s.nextProbeAt - now) / 1000))} s`;
  return `The PMC server does not answer (for ${gone} s): ${next}`;
}
