// Bookmarks of views, kept in the browser's local storage: a name, the planet's name and the
// view's URL hash (urlState.ts), so that a bookmark opens the same picture. Pure over a
// Storage-like object: a damaged or foreign entry is ignored, never thrown on.

import { parseHash } from './urlState';

/** Where the bookmarks are kept (`localStorage`). */
export const BOOKMARKS_KEY = 'pmc.bookmarks';
/** The most bookmarks kept (the oldest go first). */
export const MAX_BOOKMARKS = 50;

export interface Bookmark {
  /** What the list shows. */
  name: string;
  /** The planet's name when it was saved (planetName.ts). */
  planet: string;
  /** The view: a URL hash with the planet, the mode and the camera. */
  hash: string;
}

/** What bookmarks need of `localStorage`. */
export interface KeyValueStore {
  getItem(key: string): string | null;
  setItem(key: string, value: string): void;
}

const isBookmark = (b: unknown): b is Bookmark => {
  if (typeof b !== 'object' || b === null) return false;
  const o = b as Record<string, unknown>;
  if (typeof o.name !== 'string' || typeof o.planet !== 'string' || typeof o.hash !== 'string') return false;
  const u = parseHash(o.hash);
  return o.hash.startsWith('#') && u.lat !== undefined && u.lon !== undefined;
};

/** The bookmarks kept in `store` (none when there are none, or what is there is not ours). */
export function loadBookmarks(store: KeyValueStore | undefined): Bookmark[] {
  let text: string | null = null;
  try {
    text = store?.getItem(BOOKMARKS_KEY) ?? null;
  } catch {
    return [];
  }
  if (text === null) return [];
  try {
    const v: unknown = JSON.parse(text);
    return Array.isArray(v) ? v.filter(isBookmark).slice(-MAX_BOOKMARKS) : [];
  } catch {
    return [];
  }
}

/** Keeps `list` in `store`; false when the store refuses (full, or private browsing). */
export function saveBookmarks(store: KeyValueStore | undefined, list: readonly Bookmark[]): boolean {
  try {
    store?.setItem(BOOKMARKS_KEY, JSON.stringify(list.slice(-MAX_BOOKMARKS)));
    return store !== undefined;
  } catch {
    return false;
  }
}

/** `list` with `b` added last (one of the same name replaced), at most MAX_BOOKMARKS. */
export function withBookmark(list: readonly Bookmark[], b: Bookmark): Bookmark[] {
  return [...list.filter((x) => x.name !== b.name), b].slice(-MAX_BOOKMARKS);
}

/** `list` without the bookmark named `name`. */
export function withoutBookmark(list: readonly Bookmark[], name: string): Bookmark[] {
  return list.filter((x) => x.name !== name);
}

/** A bookmark's default name: the place, e.g. `27.983° N 86.917° E, 300 m`. */
export function bookmarkName(lat: number, lon: number, alt: number): string {
  const ns = `${Math.abs(lat).toFixed(3)}° ${lat >= 0 ? 'N' : 'S'}`;
  const ew = `${Math.abs(lon).toFixed(3)}° ${lon >= 0 ? 'E' : 'W'}`;
  const a = Math.abs(alt) >= 10_000 ? `${(alt / 1000).toFixed(0)} km` : `${alt.toFixed(0)} m`;
  return `${ns} ${ew}, ${a}`;
}
