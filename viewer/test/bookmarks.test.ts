import { describe, expect, it } from 'vitest';
import { BOOKMARKS_KEY, MAX_BOOKMARKS, bookmarkName, loadBookmarks, saveBookmarks, withBookmark, withoutBookmark, type KeyValueStore } from '../src/bookmarks';

const memory = (): KeyValueStore & { data: Map<string, string> } => {
  const data = new Map<string, string>();
  return { data, getItem: (k) => data.get(k) ?? null, setItem: (k, v) => void data.set(k, v) };
};

const b = (name: string) => ({ name, planet: 'earthlike · seed 7', hash: `#preset=earthlike&seed=7&lat=1&lon=2&alt=300` });

describe('bookmarks', () => {
  it('round-trip through the store', () => {
    const s = memory();
    expect(loadBookmarks(s)).toEqual([]);
    const list = withBookmark(withBookmark([], b('a')), b('b'));
    expect(saveBookmarks(s, list)).toBe(true);
    expect(loadBookmarks(s)).toEqual(list);
    expect(withoutBookmark(list, 'a')).toEqual([b('b')]);
    // the same name replaces, last
    expect(withBookmark(list, { ...b('a'), planet: 'x' }).map((x) => [x.name, x.planet])).toEqual([['b', 'earthlike · seed 7'], ['a', 'x']]);
  });

  it('keep at most MAX_BOOKMARKS, the newest', () => {
    let list = withBookmark([], b('0'));
    for (let i = 1; i < MAX_BOOKMARKS + 5; i++) list = withBookmark(list, b(String(i)));
    expect(list.length).toBe(MAX_BOOKMARKS);
    expect(list[0]!.name).toBe('5');
  });

  it('ignore what is damaged or foreign, and a store that refuses', () => {
    const s = memory();
    for (const text of ['{', 'null', '{"a":1}', '"x"', JSON.stringify([{ name: 1 }, { name: 'x', planet: 'p', hash: 'lat=1' }, { name: 'y', planet: 'p', hash: '#mode=orbit' }, b('ok')])]) {
      s.data.set(BOOKMARKS_KEY, text);
      expect(loadBookmarks(s)).toEqual(text.includes('"ok"') ? [b('ok')] : []);
    }
    const refusing: KeyValueStore = { getItem: () => { throw new Error('denied'); }, setItem: () => { throw new Error('full'); } };
    expect(loadBookmarks(refusing)).toEqual([]);
    expect(saveBookmarks(refusing, [b('a')])).toBe(false);
    expect(loadBookmarks(undefined)).toEqual([]);
    expect(saveBookmarks(undefined, [])).toBe(false);
  });

  it('name a view by its place', () => {
    expect(bookmarkName(27.98333, 86.91667, 300)).toBe('27.983° N 86.917° E, 300 m');
    expect(bookmarkName(-33.9, -18.4, 2_500_000)).toBe('33.900° S 18.400° W, 2500 km');
  });
});
