// The level-of-detail selection in a Web Worker, so that a selection of thousands of chunks never
// stalls a frame. Messages: `{type: 'planet', id, planet}` then any number of
// `{type: 'select', id, view, params}`; each select is answered with `{id, rows, truncated, ms}`
// (rows transferred) or `{id, error}`.

import { SelectionRunner, type RunnerPlanet } from './runner';
import type { LodParams, LodView } from './select';

export type WorkerRequest =
  | { type: 'planet'; id: number; planet: RunnerPlanet }
  | { type: 'select'; id: number; view: LodView; params: LodParams };

export type WorkerAnswer =
  | { id: number; rows: Int32Array; truncated: boolean; ms: number }
  | { id: number; error: string };

interface WorkerScope {
  onmessage: ((e: MessageEvent<WorkerRequest>) => void) | null;
  postMessage(message: WorkerAnswer, transfer?: Transferable[]): void;
}

const scope = self as unknown as WorkerScope;
let runner: SelectionRunner | null = null;

scope.onmessage = (e) => {
  const m = e.data;
  try {
    if (m.type === 'planet') {
      runner = new SelectionRunner(m.planet);
      return;
    }
    if (runner === null) throw new Error('no planet given to the selection worker');
    const s = runner.select(m.view, m.params);
    scope.postMessage({ id: m.id, rows: s.rows, truncated: s.truncated, ms: s.ms }, [s.rows.buffer]);
  } catch (err) {
    scope.postMessage({ id: m.id, error: err instanceof Error ? err.message : String(err) });
  }
};
