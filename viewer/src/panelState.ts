// The side panel's state kept in local storage: whether it is open, and which of its sections
// are. A damaged entry or a browser that refuses to store gives the defaults, never an error.
// Pure: the storage is passed in.

/** The local storage key. */
export const PANEL_KEY = 'pmc.panel';

/** The side panel's sections (their `data-section` names in index.html). */
export const PANEL_SECTIONS = ['stats', 'view', 'planet', 'detail', 'debug', 'sky'] as const;
export type PanelSection = (typeof PANEL_SECTIONS)[number];

export interface PanelState {
  /** Whether the side panel shows. */
  open: boolean;
  /** Which sections are unfolded. */
  sections: Record<PanelSection, boolean>;
}

/** The first visit's state: the panel folded away; unfolded, its statistics, view and planet. */
export function defaultPanelState(): PanelState {
  return { open: false, sections: { stats: true, view: true, planet: true, detail: false, debug: false, sky: false } };
}

/** The part of `Storage` used (a fake in tests). */
export interface StorageLike {
  getItem(key: string): string | null;
  setItem(key: string, value: string): void;
}

/** The stored state; the defaults for what is missing or damaged. */
export function loadPanelState(storage: StorageLike | undefined | null): PanelState {
  const state = defaultPanelState();
  let raw: string | null = null;
  try {
    raw = storage?.getItem(PANEL_KEY) ?? null;
  } catch {
    return state;
  }
  if (raw === null) return state;
  let parsed: unknown;
  try {
    parsed = JSON.parse(raw);
  } catch {
    return state;
  }
  if (typeof parsed !== 'object' || parsed === null) return state;
  const p = parsed as { open?: unknown; sections?: unknown };
  if (typeof p.open === 'boolean') state.open = p.open;
  if (typeof p.sections === 'object' && p.sections !== null) {
    const sections = p.sections as Record<string, unknown>;
    for (const name of PANEL_SECTIONS) {
      const v = sections[name];
      if (typeof v === 'boolean') state.sections[name] = v;
    }
  }
  return state;
}

/** Keeps `state`; false when the browser refuses. */
export function savePanelState(storage: StorageLike | undefined | null, state: PanelState): boolean {
  if (!storage) return false;
  try {
    storage.setItem(PANEL_KEY, JSON.stringify(state));
    return true;
  } catch {
    return false;
  }
}
