// The side panel's remembered state: round trip, defaults for damaged entries, a refusing store.

import { describe, expect, it } from 'vitest';
import { PANEL_KEY, defaultPanelState, loadPanelState, savePanelState, type StorageLike } from '../src/panelState';

class MemoryStorage implements StorageLike {
  readonly items = new Map<string, string>();
  getItem(key: string): string | null {
    return this.items.get(key) ?? null;
  }
  setItem(key: string, value: string): void {
    this.items.set(key, value);
  }
}

describe('panel state', () => {
  it('starts folded away, with statistics, view and planet unfolded inside', () => {
    const s = loadPanelState(new MemoryStorage());
    expect(s).toEqual(defaultPanelState());
    expect(s.open).toBe(false);
    expect(s.sections).toMatchObject({ stats: true, view: true, planet: true, debug: false });
  });

  it('round-trips what was saved', () => {
    const store = new MemoryStorage();
    const s = defaultPanelState();
    s.open = true;
    s.sections.debug = true;
    s.sections.stats = false;
    expect(savePanelState(store, s)).toBe(true);
    expect(loadPanelState(store)).toEqual(s);
  });

  it('takes what is sound of a damaged entry and the defaults for the rest', () => {
    const store = new MemoryStorage();
    for (const bad of ['{', 'null', '42', '"open"', '[]']) {
      store.setItem(PANEL_KEY, bad);
      expect(loadPanelState(store)).toEqual(defaultPanelState());
    }
    store.setItem(PANEL_KEY, JSON.stringify({ open: 'yes', sections: { sky: true, debug: 3, bogus: true } }));
    const s = loadPanelState(store);
    expect(s.open).toBe(false);
    expect(s.sections).toEqual({ ...defaultPanelState().sections, sky: true });
  });

  it('never throws on a store that refuses, or without one', () => {
    const refusing: StorageLike = {
      getItem: () => {
        throw new Error('denied');
      },
      setItem: () => {
        throw new Error('quota');
      },
    };
    expect(loadPanelState(refusing)).toEqual(defaultPanelState());
    expect(savePanelState(refusing, defaultPanelState())).toBe(false);
    expect(loadPanelState(null)).toEqual(defaultPanelState());
    expect(savePanelState(undefined, defaultPanelState())).toBe(false);
  });
});
