import { describe, expect, it } from 'vitest';
import {
  chooseDisplay,
  chunkName,
  fetchPriority,
  formatLevels,
  HOLE_PRIORITY,
  levelHistogram,
  loadRange,
  parseChunkName,
  splitChunks,
  type SelectedLeaf,
} from '../src/chunkSelection';
import { parentOf } from '../src/lod/layout';
import type { LodSelection } from '../src/lod/select';
import { LAYOUT, selection } from './lodFixture';

const TOP = 'top/2/0/0/0';

/** The display for `sel` with these loaded variants (`name~seams`) and these shown ones. */
function display(sel: LodSelection, loaded: string[], shown: string[] = [], visible: (name: string) => boolean = () => true) {
  const leaves = new Map<string, SelectedLeaf>();
  for (const c of sel.chunks) {
    const name = chunkName(c.key);
    leaves.set(name, { key: c.key, name, seams: c.coarser, drawn: c.drawn });
  }
  const variants = new Map<string, Set<number>>();
  for (const v of loaded) {
    const [name, seams] = v.split('~') as [string, string];
    variants.set(name, new Set([...(variants.get(name) ?? []), Number(seams)]));
  }
  const below = new Set<string>();
  for (const name of variants.keys()) {
    for (let k = parseChunkName(name)!; k.level < LAYOUT.maxLevel(); ) {
      k = parentOf(k);
      below.add(chunkName(k));
    }
  }
  const choice = chooseDisplay({
    layout: LAYOUT,
    leaves,
    split: splitChunks(leaves.values(), LAYOUT.maxLevel()),
    loaded: variants,
    loadedBelow: (name) => below.has(name),
    shown: new Map(shown.map((v) => v.split('~') as [string, string]).map(([n, s]) => [n, Number(s)])),
    visible: (key) => visible(chunkName(key)),
  });
  return { ...choice, list: [...choice.show].map(([n, s]) => `${n}~${s}`).sort() };
}

const roots = ['top', 'bottom', 'north', 'south', 'east', 'west'].map((f) => `${f}/2/0/0/0~0`);
const topKids = ['top/1/0/0/0', 'top/1/0/1/0', 'top/1/1/0/0', 'top/1/1/1/0'];

describe('chunk names', () => {
  it('name keys as the API does, and back', () => {
    const key = { face: 4, level: 1, i: 3, j: 0, k: 12 };
    expect(chunkName(key)).toBe('east/1/3/0/12');
    expect(parseChunkName('east/1/3/0/12')).toEqual(key);
    for (const bad of ['east/1/3/0', 'venus/0/0/0/0', 'top/0/0/0/-1', 'top/0/0/0/0~3']) expect(parseChunkName(bad)).toBeNull();
  });

  it('lists the split chunks of a selection', () => {
    const sel = selection([TOP, 'top/1/0/0/0']);
    const leaves = sel.chunks.map((c) => ({ key: c.key, name: chunkName(c.key), seams: 0, drawn: true }));
    expect([...splitChunks(leaves, LAYOUT.maxLevel())].sort()).toEqual(['top/1/0/0/0', TOP]);
  });
});

describe('chooseDisplay', () => {
  it('shows exactly the wanted variants once they are loaded', () => {
    const d = display(selection([TOP], { 'top/1/0/0/0': 3 }), [...roots, ...topKids.map((k) => `${k}~0`), 'top/1/0/0/0~3']);
    expect(d.list).toEqual([...roots.filter((r) => !r.startsWith('top')), 'top/1/0/0/0~3', ...topKids.slice(1).map((k) => `${k}~0`)].sort());
    expect(d).toMatchObject({ exact: true, complete: true });
  });

  it('keeps the chunk being refined while a wanted child is missing, and does not show the others', () => {
    const d = display(selection([TOP]), [...roots, 'top/1/0/0/0~0', 'top/1/0/1/0~0', 'top/1/1/0/0~0'], roots);
    expect(d.list).toEqual([...roots].sort());
    expect(d).toMatchObject({ exact: false, complete: true });
  });

  it('does not wait for a child that is not drawn', () => {
    const d = display(selection([TOP], {}, ['top/1/1/1/0']), [...roots, 'top/1/0/0/0~0', 'top/1/0/1/0~0', 'top/1/1/0/0~0'], roots);
    expect(d.list).toContain('top/1/0/0/0~0');
    expect(d.list).not.toContain(`${TOP}~0`);
    expect(d).toMatchObject({ exact: true, complete: true });
  });

  it('keeps the children of a chunk being coarsened until it is loaded', () => {
    const kids = topKids.map((k) => `${k}~0`);
    const d = display(selection(), [...roots.slice(1), ...kids], [...roots.slice(1), ...kids]);
    expect(d.list).toEqual([...roots.slice(1), ...kids].sort());
    expect(d).toMatchObject({ exact: false, complete: true });
    // a child missing whose place is out of the view is not needed
    const out = display(selection(), [...roots.slice(1), ...kids.slice(1)], [...roots.slice(1), ...kids.slice(1)], (n) => n !== 'top/1/0/0/0');
    expect(out.list).toEqual([...roots.slice(1), ...kids.slice(1)].sort());
    expect(out.complete).toBe(true);
    // one in the view: the place is not covered
    const hole = display(selection(), [...roots.slice(1), ...kids.slice(1)], [...roots.slice(1), ...kids.slice(1)]);
    expect(hole.complete).toBe(false);
  });

  it('keeps the variant shown until the wanted one is loaded, else takes any loaded one', () => {
    const sel = selection([TOP], { 'top/1/0/0/0': 5 });
    const loaded = [...roots, ...topKids.map((k) => `${k}~0`), 'top/1/0/0/0~1'];
    expect(display(sel, loaded, ['top/1/0/0/0~1']).list).toContain('top/1/0/0/0~1');
    expect(display(sel, loaded, ['top/1/0/0/0~0']).list).toContain('top/1/0/0/0~0');
    expect(display(sel, [...loaded, 'top/1/0/0/0~5'], ['top/1/0/0/0~0']).list).toContain('top/1/0/0/0~5');
  });

  it('takes a coarser chunk from the cache over a hole two levels up, and shows what it can with nothing above', () => {
    const sel = selection([TOP, 'top/1/0/0/0']);
    // the level-1 chunk is loaded, not its four children: it stands in for them
    const d = display(sel, [...roots, ...topKids.map((k) => `${k}~0`)]);
    expect(d.list).toContain('top/1/0/0/0~0');
    expect(d.list.filter((n) => n.startsWith('top/0/'))).toEqual([]);
    expect(d.complete).toBe(true);
    // nothing above the missing ones: the loaded siblings are shown, the place stays open
    const partial = display(sel, ['top/0/0/0/0~0', 'top/0/1/1/0~0', 'top/1/0/1/0~0']);
    expect(partial.list).toEqual(['top/0/0/0/0~0', 'top/0/1/1/0~0', 'top/1/0/1/0~0']);
    expect(partial.complete).toBe(false);
  });
});

describe('fetchPriority and the level histogram', () => {
  const sphere = { center: [0, 100, 0] as [number, number, number], radius: 10 };
  it('is the pixel error of the level replaced, plus a bonus for a hole', () => {
    // 40 m from the sphere, the level-1 error (1 m) at 600 px per radian-ish scale
    expect(fetchPriority(0, [0, 1, 2], sphere, [0, 150, 0], 600, false)).toBe(15);
    expect(fetchPriority(1, [0, 1, 2], sphere, [0, 150, 0], 600, false)).toBe(30);
    expect(fetchPriority(2, [0, 1, 2], sphere, [0, 150, 0], 600, false)).toBe(30);
    expect(fetchPriority(0, [0, 1, 2], sphere, [0, 150, 0], 600, true)).toBe(HOLE_PRIORITY + 15);
    // inside the sphere: as urgent as it gets without being a hole
    expect(fetchPriority(0, [0, 1, 2], sphere, [0, 100, 0], 600, false)).toBe(HOLE_PRIORITY);
    // nearer is more urgent
    expect(fetchPriority(0, [0, 1, 2], sphere, [0, 120, 0], 600, false)).toBeGreaterThan(15);
  });

  it('counts the chunks shown per level', () => {
    const h = levelHistogram(['top/0/0/0/0', 'top/0/1/0/0', 'top/2/0/0/0', 'bottom/0/0/0/0']);
    expect(h).toEqual([3, 0, 1]);
    expect(formatLevels(h)).toBe('L0 3 · L2 1');
    expect(formatLevels([])).toBe('–');
  });
});

describe('loadRange', () => {
  const extent = { innerRadius: 1814, outerRadius: 1870 };
  it('reaches the horizon plus what sticks out behind it', () => {
    const r = 3 * 1870;
    const expected = Math.sqrt(r * r - 1814 ** 2) + Math.sqrt(1870 ** 2 - 1814 ** 2);
    expect(loadRange(r, extent, 100)).toBeCloseTo(expected, 9);
  });
  it('is at least the minimum near the ground and at most the maximum', () => {
    expect(loadRange(1814, extent, 500)).toBe(500);
    expect(loadRange(1e6, extent, 100, 5000)).toBe(5000);
  });
  it('grows with altitude', () => {
    expect(loadRange(2500, extent, 1)).toBeGreaterThan(loadRange(2000, extent, 1));
  });
  it('reaches past the horizon at Earth radius, 2 m above the sea', () => {
    const earth = { innerRadius: 6371000, outerRadius: 6384108 };
    const far = loadRange(6371002, earth, 100);
    expect(far).toBeGreaterThan(400_000); // the highest mountains behind the horizon
    expect(far).toBeLessThan(420_000);
  });
});
