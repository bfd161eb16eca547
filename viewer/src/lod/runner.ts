// Runs the level-of-detail selection for one planet, keeping the chunks' bounding spheres between
// calls, and packs its answer into an Int32Array (seven numbers per chunk) so that it crosses from
// a Web Worker to the page without copying objects. Used by `worker.ts` and, where workers are not
// available, directly by `../lodSelector.ts`.

import type { BoundingSphere } from './bounds';
import { Layout, type LayoutParams } from './layout';
import { selectLod, type LodParams, type LodSelection, type LodView } from './select';

/** The planet a runner selects for. */
export interface RunnerPlanet {
  layout: LayoutParams;
  errors: number[];
  occluder: number;
}

/** A packed selection: per chunk `face, level, i, j, k, coarser, drawn (0 or 1)`, in key order. */
export interface PackedSelection {
  rows: Int32Array;
  truncated: boolean;
  /** Milliseconds the selection took. */
  ms: number;
}

/** Numbers per chunk in `PackedSelection.rows`. */
export const ROW = 7;

export class SelectionRunner {
  private readonly layout: Layout;
  private readonly spheres = new Map<string, BoundingSphere>();

  constructor(private readonly planet: RunnerPlanet) {
    this.layout = new Layout(planet.layout);
  }

  select(view: LodView, params: LodParams, now: () => number = () => performance.now()): PackedSelection {
    const t0 = now();
    // the spheres of a long flight would pile up: keep at most a few selections' worth
    if (this.spheres.size > 200_000) this.spheres.clear();
    const s = selectLod(this.layout, this.planet.errors, this.planet.occluder, view, params, this.spheres);
    return { ...pack(s), ms: now() - t0 };
  }
}

export function pack(s: LodSelection): { rows: Int32Array; truncated: boolean } {
  const rows = new Int32Array(ROW * s.chunks.length);
  s.chunks.forEach((c, n) => {
    rows.set([c.key.face, c.key.level, c.key.i, c.key.j, c.key.k, c.coarser, c.drawn ? 1 : 0], ROW * n);
  });
  return { rows, truncated: s.truncated };
}

export function unpack(p: { rows: Int32Array; truncated: boolean }): LodSelection {
  const chunks: LodSelection['chunks'] = [];
  for (let n = 0; n + ROW <= p.rows.length; n += ROW) {
    const r = p.rows;
    chunks.push({
      key: { face: r[n]!, level: r[n + 1]!, i: r[n + 2]!, j: r[n + 3]!, k: r[n + 4]! },
      coarser: r[n + 5]!,
      drawn: r[n + 6] === 1,
    });
  }
  return { chunks, truncated: p.truncated };
}
