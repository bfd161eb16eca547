// Every keyboard shortcut of the viewer, in one table: the handlers (input.ts for the keys held
// down to move, app.ts for the rest) look their keys up here, and the keyboard help (`?`) is
// generated from it, so the two cannot drift. Pure: no DOM.

import { PATH_TOOL, TOOLS, type ToolName } from './editTools';

/** What a shortcut does. */
export type ShortcutAction =
  | 'forward'
  | 'back'
  | 'left'
  | 'right'
  | 'up'
  | 'down'
  | 'fast'
  | 'mode'
  | 'walk'
  | 'tool'
  | 'path'
  | 'escape'
  | 'radius-down'
  | 'radius-up'
  | 'undo'
  | 'redo'
  | 'navgrid'
  | 'overlays'
  | 'panel'
  | 'goto'
  | 'north'
  | 'tiles'
  | 'help';

/** The help's sections, in order. */
export const SHORTCUT_GROUPS = ['Camera', 'Tools', 'Edits', 'View'] as const;
export type ShortcutGroup = (typeof SHORTCUT_GROUPS)[number];

export interface Shortcut {
  action: ShortcutAction;
  /** `KeyboardEvent.code`s that trigger it. */
  codes: readonly string[];
  /** A character that triggers it too, whatever the key (`KeyboardEvent.key`: `?` on any layout). */
  char?: string;
  /** With Ctrl (or Cmd): true; Shift: true (held), false (not held), absent (either). */
  ctrl?: boolean;
  shift?: boolean;
  /** Held down rather than pressed (the camera's motion keys: input.ts polls them). */
  held?: boolean;
  /** The tool it chooses (action `tool`). */
  tool?: ToolName;
  /** The keys as the help prints them. */
  keys: string;
  what: string;
  group: ShortcutGroup;
}

const motion = (action: ShortcutAction, codes: string[], keys: string, what: string): Shortcut => ({
  action,
  codes,
  keys,
  what,
  held: true,
  group: 'Camera',
});

/** Every shortcut, in the help's order. */
export const SHORTCUTS: readonly Shortcut[] = [
  motion('forward', ['KeyW', 'ArrowUp'], 'W / ↑', 'fly forward (orbit: toward the planet)'),
  motion('back', ['KeyS', 'ArrowDown'], 'S / ↓', 'fly back'),
  motion('left', ['KeyA', 'ArrowLeft'], 'A / ←', 'fly left'),
  motion('right', ['KeyD', 'ArrowRight'], 'D / →', 'fly right'),
  motion('up', ['KeyE', 'Space', 'PageUp'], 'E / Space / PgUp', 'fly up'),
  motion('down', ['KeyQ', 'ShiftLeft', 'ShiftRight', 'PageDown'], 'Q / Shift / PgDn', 'fly down'),
  motion('fast', ['ControlLeft', 'AltLeft'], 'Ctrl / Alt (held)', 'fly faster'),
  { action: 'mode', codes: ['Tab'], keys: 'Tab', what: 'switch between orbit and fly', group: 'Camera' },
  { action: 'walk', codes: ['KeyG'], keys: 'G', what: 'walk on the ground on / off (fly mode)', group: 'Camera' },
  ...TOOLS.map(
    (t): Shortcut => ({ action: 'tool', tool: t.name, codes: [t.code], keys: t.key, what: `${t.label}: ${t.help}`, group: 'Tools' }),
  ),
  { action: 'path', codes: [PATH_TOOL.code], keys: PATH_TOOL.key, what: `${PATH_TOOL.label}: ${PATH_TOOL.help}`, group: 'Tools' },
  { action: 'escape', codes: ['Escape'], keys: 'Esc', what: 'close this help; clear the path; then back to Look', group: 'Tools' },
  { action: 'radius-down', codes: ['BracketLeft'], keys: '[', what: 'smaller brush', group: 'Tools' },
  { action: 'radius-up', codes: ['BracketRight'], keys: ']', what: 'larger brush', group: 'Tools' },
  { action: 'undo', codes: ['KeyZ'], ctrl: true, shift: false, keys: 'Ctrl+Z', what: 'undo the last edit', group: 'Edits' },
  { action: 'redo', codes: ['KeyZ'], ctrl: true, shift: true, keys: 'Ctrl+Shift+Z', what: 'redo', group: 'Edits' },
  { action: 'redo', codes: ['KeyY'], ctrl: true, shift: false, keys: 'Ctrl+Y', what: 'redo', group: 'Edits' },
  { action: 'navgrid', codes: ['KeyN'], shift: false, keys: 'N', what: 'the navigation grid around the camera on / off', group: 'View' },
  { action: 'overlays', codes: ['KeyH'], shift: false, keys: 'H', what: 'hide / show every overlay (the planet alone)', group: 'View' },
  { action: 'panel', codes: ['KeyP'], shift: false, keys: 'P', what: 'open / close the side panel (statistics, planet, detail, debug, sky)', group: 'View' },
  { action: 'goto', codes: [], char: '/', keys: '/', what: 'type a place in the go-to box', group: 'View' },
  { action: 'tiles', codes: ['KeyT'], shift: false, keys: 'T', what: "3D Tiles mode on / off: the planet from the server's 3D Tiles instead of its chunks", group: 'View' },
  { action: 'north', codes: ['KeyR'], shift: false, keys: 'R', what: 'face north (as clicking the compass does)', group: 'Camera' },
  { action: 'help', codes: [], char: '?', keys: '?', what: 'this help', group: 'View' },
];

/** The mouse's part, printed under the keys (no handler looks these up). */
export const MOUSE_HELP: readonly { keys: string; what: string }[] = [
  { keys: 'drag', what: 'orbit: turn the planet; fly: look around (double-click: pointer lock)' },
  { keys: 'wheel', what: 'orbit: zoom; fly: speed' },
  { keys: 'right drag', what: 'move the camera while a brush tool is chosen' },
  { keys: 'click', what: 'with a tool: edit, or set the ends of a path' },
  { keys: 'middle drag', what: 'tilt: orbit from straight down to 30° under the horizontal; fly: look up and down' },
  { keys: 'one finger', what: 'as a drag: turn the planet, or look around (with a tool: a tap edits)' },
  { keys: 'pinch', what: 'orbit: zoom; fly: move forward and back' },
  { keys: 'two fingers', what: 'drag up and down: tilt' },
];

/** What a key event's shortcut fields are (a `KeyboardEvent` has them all). */
export interface KeyLike {
  code: string;
  key: string;
  ctrlKey: boolean;
  metaKey: boolean;
  altKey: boolean;
  shiftKey: boolean;
}

/** The pressed (not held) shortcut that `e` triggers, or null. Alt never triggers one. */
export function shortcutOf(e: KeyLike): Shortcut | null {
  if (e.altKey) return null;
  const ctrl = e.ctrlKey || e.metaKey;
  for (const s of SHORTCUTS) {
    if (s.held) continue;
    if ((s.ctrl ?? false) !== ctrl) continue;
    if (s.shift !== undefined && s.shift !== e.shiftKey) continue;
    if (s.codes.includes(e.code) || (s.char !== undefined && e.key === s.char)) return s;
  }
  return null;
}

/** The codes of the keys held down for `action` (a motion). */
export function heldCodes(action: ShortcutAction): ReadonlySet<string> {
  return new Set(SHORTCUTS.filter((s) => s.held && s.action === action).flatMap((s) => s.codes));
}

/** Every key code a shortcut uses (tools and other keys must not take these for anything else). */
export const BOUND_CODES: ReadonlySet<string> = new Set(SHORTCUTS.flatMap((s) => s.codes));
