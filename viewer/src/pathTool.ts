// The Path tool: the first click on the terrain sets the start, the second the goal, and the
// walking path between them is asked of `/path`; a third click starts over. Holds the ends, the
// answer (waypoints in the planet frame) and what to tell the user. Works without editing: paths
// need no world. No DOM, no three.js: the app passes the terrain point under each click.

import { isAbort, type PathAnswer } from './api';
import type { V3 } from './frames';
import { formatPathEnd, navErrorMessage, pathEndOf, pointOfEnd } from './navOverlay';
import { formatDistance } from './ui';

/** The tool-bar entry of the Path tool (defined with the other tools: editTools.ts). */
export { PATH_TOOL } from './editTools';

/**
 * empty: no end set; start: the start is set, the goal is awaited; loading: both set, the path
 * asked; found / none: the answer (a path, or none and why); error: the request failed.
 */
export type PathPhase = 'empty' | 'start' | 'loading' | 'found' | 'none' | 'error';

/** An end picked on the terrain. */
export interface PathPick {
  /** The point clicked, planet frame. */
  point: V3;
  lat: number;
  lon: number;
  /** Metres above the datum. */
  alt: number;
  /** As sent to `/path` (`LAT,LON,ALT`). */
  query: string;
}

export interface PathStatus {
  phase: PathPhase;
  from: PathPick | null;
  to: PathPick | null;
  /** Metres and steps of the path found (its walk of grid steps). */
  length: number | null;
  steps: number | null;
  /** Metres walked and straight legs of its smoothed form, when the answer has one. */
  smoothed: { length: number; legs: number } | null;
  /** Why there is no path (phase none). */
  reason: string | null;
  /** The failed request (phase error). */
  error: string | null;
  /** The waypoints of the path found, planet frame (their surface points). */
  waypoints: V3[];
  /** The points to draw, planet frame: the smoothed path's line, else the waypoints. */
  line: V3[];
  /** The world revision of the answer shown. */
  revision: number | null;
  /** Asking again (after an edit) while the previous answer is still shown. */
  refreshing: boolean;
  /** A note about the last click (nothing under the cursor). */
  notice: string | null;
  /** Requests sent. */
  requests: number;
  /** One line for the user. */
  message: string;
}

export interface PathToolOptions {
  /** Asks `/path` for the walk between `from` and `to` (`LAT,LON,ALT` each). */
  fetchPath(from: string, to: string, signal: AbortSignal): Promise<PathAnswer>;
  /** Something shown changed. */
  onChange?: () => void;
}

/** The line the panel shows for a state. */
export function pathMessage(s: Omit<PathStatus, 'message'>): string {
  const note = s.notice ? `${s.notice} · ` : '';
  switch (s.phase) {
    case 'empty':
      return `${note}click the terrain to set the start of a path`;
    case 'start':
      return `${note}path start set (${s.from!.lat.toFixed(4)}°, ${s.from!.lon.toFixed(4)}°): click the goal`;
    case 'loading':
      return `${note}finding the path…`;
    case 'found': {
      const steps = `${s.steps} step${s.steps === 1 ? '' : 's'}`;
      const shown = s.smoothed
        ? `${formatDistance(s.smoothed.length)} in ${s.smoothed.legs} straight leg${s.smoothed.legs === 1 ? '' : 's'} (grid walk ${formatDistance(s.length!)}, ${steps})`
        : `${formatDistance(s.length!)}, ${steps}`;
      return `${note}path: ${shown}${s.refreshing ? ' (updating)' : ''}`;
    }
    case 'none':
      return `${note}no path: ${s.reason ?? 'no reason given'}${s.refreshing ? ' (updating)' : ''}`;
    case 'error':
      return `${note}${s.error ?? 'the path request failed'}`;
  }
}

export class PathTool {
  private readonly fetchPath: PathToolOptions['fetchPath'];
  private readonly onChange: () => void;
  private datum = 0;
  private phase: PathPhase = 'empty';
  private from: PathPick | null = null;
  private to: PathPick | null = null;
  private answer: PathAnswer | null = null;
  private waypoints: V3[] = [];
  private line: V3[] = [];
  private error: string | null = null;
  private notice: string | null = null;
  private inFlight: AbortController | null = null;
  private requests = 0;
  /** Bumped whenever the ends or the waypoints change (what is drawn). */
  version = 0;

  constructor(opts: PathToolOptions) {
    this.fetchPath = opts.fetchPath;
    this.onChange = opts.onChange ?? (() => undefined);
  }

  /** Another planet (its datum, metres from the centre): drops everything. */
  setPlanet(datum: number): void {
    this.clear();
    this.datum = datum;
  }

  /** A click with `point` (planet frame) under the cursor; null: no terrain there. */
  click(point: V3 | null): void {
    if (!point || !point.every(Number.isFinite)) {
      this.notice = 'no terrain under the cursor (loaded chunks only)';
      this.onChange();
      return;
    }
    this.notice = null;
    const pick = this.pick(point);
    if (this.phase === 'start' && this.from) {
      this.to = pick;
      this.version++;
      void this.request(false);
      return;
    }
    // the first click, or the third: (re)start
    this.abort();
    this.from = pick;
    this.to = null;
    this.answer = null;
    this.setPoints(null);
    this.error = null;
    this.phase = 'start';
    this.version++;
    this.onChange();
  }

  /** Esc: no ends, no path. Returns whether there was anything to clear. */
  clear(): boolean {
    const had = this.phase !== 'empty' || this.notice !== null;
    this.abort();
    this.phase = 'empty';
    this.from = null;
    this.to = null;
    this.answer = null;
    this.setPoints(null);
    this.error = null;
    this.notice = null;
    this.version++;
    this.onChange();
    return had;
  }

  /**
   * Asks for the path between the same ends again (the world changed), keeping the answer shown
   * until the new one arrives. Returns whether it asked (both ends must be set).
   */
  refresh(): boolean {
    if (!this.from || !this.to) return false;
    void this.request(true);
    return true;
  }

  get active(): boolean {
    return this.phase !== 'empty';
  }

  private pick(point: V3): PathPick {
    const end = pathEndOf(point, this.datum);
    return { point: [point[0], point[1], point[2]], ...end, query: formatPathEnd(end) };
  }

  /** The points of `answer` (planet frame), none when null or not found. */
  private setPoints(answer: PathAnswer | null): void {
    const frame = (ws: PathAnswer['waypoints']): V3[] => ws.map((w) => pointOfEnd(w, this.datum));
    this.waypoints = answer?.found ? frame(answer.waypoints) : [];
    this.line = answer?.found && answer.smoothed ? frame(answer.smoothed.line) : this.waypoints;
  }

  private abort(): void {
    this.inFlight?.abort();
    this.inFlight = null;
  }

  private async request(keepShown: boolean): Promise<void> {
    const from = this.from!;
    const to = this.to!;
    this.abort();
    const ctl = new AbortController();
    this.inFlight = ctl;
    this.requests++;
    if (!keepShown || (this.phase !== 'found' && this.phase !== 'none')) {
      this.phase = 'loading';
      this.answer = null;
      this.setPoints(null);
      this.error = null;
      this.version++;
    }
    this.onChange();
    try {
      const answer = await this.fetchPath(from.query, to.query, ctl.signal);
      if (this.inFlight !== ctl) return;
      this.answer = answer;
      this.error = null;
      this.phase = answer.found ? 'found' : 'none';
      this.setPoints(answer);
    } catch (e) {
      if (this.inFlight !== ctl || isAbort(e)) return;
      this.answer = null;
      this.setPoints(null);
      this.phase = 'error';
      this.error = navErrorMessage('the path request', e);
    }
    this.inFlight = null;
    this.version++;
    this.onChange();
  }

  status(): PathStatus {
    const a = this.answer;
    const s: Omit<PathStatus, 'message'> = {
      phase: this.phase,
      from: this.from,
      to: this.to,
      length: a?.found ? a.length : null,
      steps: a?.found ? a.steps : null,
      smoothed: a?.found && a.smoothed ? { length: a.smoothed.length, legs: a.smoothed.legs } : null,
      reason: a && !a.found ? a.reason : null,
      error: this.error,
      waypoints: this.waypoints,
      line: this.line,
      revision: a?.revision ?? null,
      refreshing: this.inFlight !== null && (this.phase === 'found' || this.phase === 'none'),
      notice: this.notice,
      requests: this.requests,
    };
    return { ...s, message: pathMessage(s) };
  }
}
