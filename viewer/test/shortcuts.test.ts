import { describe, expect, it } from 'vitest';
import { TOOLS } from '../src/editTools';
import { BOUND_KEYS } from '../src/input';
import { PATH_TOOL } from '../src/pathTool';
import { SHORTCUTS, SHORTCUT_GROUPS, heldCodes, shortcutOf, type KeyLike } from '../src/shortcuts';

const press = (code: string, more: Partial<KeyLike> = {}): KeyLike => ({
  code,
  key: '',
  ctrlKey: false,
  metaKey: false,
  altKey: false,
  shiftKey: false,
  ...more,
});

describe('the shortcut table', () => {
  it('gives every key one meaning', () => {
    // (a code may serve two entries only when the modifiers tell them apart: Ctrl+Z and Ctrl+Shift+Z)
    const seen = new Map<string, number>();
    for (const s of SHORTCUTS) {
      for (const c of s.codes) {
        const k = `${c} ${s.ctrl ?? false} ${s.shift ?? 'any'}`;
        expect(seen.has(k), `${k} twice`).toBe(false);
        seen.set(k, 1);
      }
    }
    for (const s of SHORTCUTS) expect(SHORTCUT_GROUPS).toContain(s.group);
  });

  it('finds the pressed shortcuts the handlers act on', () => {
    expect(shortcutOf(press('Tab'))?.action).toBe('mode');
    expect(shortcutOf(press('KeyG'))?.action).toBe('walk');
    expect(shortcutOf(press('KeyN'))?.action).toBe('navgrid');
    expect(shortcutOf(press('KeyN', { shiftKey: true }))).toBeNull();
    expect(shortcutOf(press('KeyH'))?.action).toBe('overlays');
    expect(shortcutOf(press('KeyT'))?.action).toBe('tiles');
    expect(shortcutOf(press('KeyT', { shiftKey: true }))).toBeNull();
    expect(shortcutOf(press('Slash', { key: '?', shiftKey: true }))?.action).toBe('help');
    // '?' wherever a layout puts it
    expect(shortcutOf(press('Minus', { key: '?', shiftKey: true }))?.action).toBe('help');
    expect(shortcutOf(press('KeyZ', { ctrlKey: true }))?.action).toBe('undo');
    expect(shortcutOf(press('KeyZ', { metaKey: true }))?.action).toBe('undo');
    expect(shortcutOf(press('KeyZ', { ctrlKey: true, shiftKey: true }))?.action).toBe('redo');
    expect(shortcutOf(press('KeyY', { ctrlKey: true }))?.action).toBe('redo');
    expect(shortcutOf(press('KeyZ'))).toBeNull();
    expect(shortcutOf(press('KeyZ', { ctrlKey: true, altKey: true }))).toBeNull();
    expect(shortcutOf(press(PATH_TOOL.code))?.action).toBe('path');
    for (const t of TOOLS) expect(shortcutOf(press(t.code))?.tool).toBe(t.name);
    // the keys held to move are not pressed shortcuts
    expect(shortcutOf(press('KeyW'))).toBeNull();
  });

  it('gives the motion keys input.ts polls', () => {
    expect([...heldCodes('forward')]).toEqual(['KeyW', 'ArrowUp']);
    expect([...heldCodes('down')]).toContain('ShiftLeft');
    expect([...heldCodes('fast')]).toEqual(['ControlLeft', 'AltLeft']);
    for (const c of ['KeyW', 'KeyS', 'KeyA', 'KeyD', 'KeyE', 'KeyQ', 'Space', 'Tab', 'KeyG']) expect(BOUND_KEYS.has(c)).toBe(true);
  });

  it('prints every entry for the help', () => {
    for (const s of SHORTCUTS) {
      expect(s.keys.length).toBeGreaterThan(0);
      expect(s.what.length).toBeGreaterThan(0);
    }
  });
});
