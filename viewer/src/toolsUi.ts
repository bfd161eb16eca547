// The tools panel of index.html: tool bar (the editing tools and Path), brush radius and
// strength, paint material, undo and redo, the status line (why editing is off, the last error)
// and the Path tool's line (its ends, the length found, no path and why). Plain DOM.

import { TOOLS, MIN_STRENGTH, type ToolName } from './editTools';
import type { EditStatus } from './editSession';
import { PATH_TOOL, type PathStatus } from './pathTool';

export interface ToolsUiCallbacks {
  onTool(tool: ToolName): void;
  /** The Path button. */
  onPathTool(): void;
  onRadius(r: number): void;
  onStrength(s: number): void;
  onMaterial(m: string): void;
  onUndo(): void;
  onRedo(): void;
}

function byId<T extends HTMLElement>(id: string): T {
  const el = document.getElementById(id);
  if (!el) throw new Error(`index.html lacks #${id}`);
  return el as T;
}

/** The radius slider works on a log scale: position 0..1000 between the limits. */
const SLIDER_STEPS = 1000;

export class ToolsUi {
  private readonly panel = byId<HTMLElement>('tools');
  private readonly bar = byId<HTMLDivElement>('tool-bar');
  private readonly radiusRange = byId<HTMLInputElement>('brush-radius-range');
  private readonly radiusNumber = byId<HTMLInputElement>('brush-radius');
  private readonly strengthRange = byId<HTMLInputElement>('brush-strength');
  private readonly strengthValue = byId<HTMLSpanElement>('brush-strength-value');
  private readonly materialRow = byId<HTMLElement>('material-row');
  private readonly material = byId<HTMLSelectElement>('brush-material');
  private readonly undoButton = byId<HTMLButtonElement>('undo');
  private readonly redoButton = byId<HTMLButtonElement>('redo');
  private readonly statusLine = byId<HTMLParagraphElement>('tools-status');
  private readonly pathLine = byId<HTMLParagraphElement>('path-status');
  private readonly pathButton: HTMLButtonElement;
  private readonly buttons = new Map<ToolName, HTMLButtonElement>();
  private limits = { min: 0.5, max: 64 };
  private shownMaterials = '';

  constructor(private readonly callbacks: ToolsUiCallbacks) {
    for (const t of TOOLS) {
      const b = document.createElement('button');
      b.type = 'button';
      b.id = `tool-${t.name}`;
      b.textContent = t.label;
      b.dataset['tool'] = t.name;
      b.setAttribute('aria-pressed', 'false');
      b.title = `${t.label} (${t.key}): ${t.help}`;
      b.addEventListener('click', () => {
        this.callbacks.onTool(t.name);
        b.blur(); // keep Space and the arrows for flying
      });
      this.bar.append(b);
      this.buttons.set(t.name, b);
    }
    // Path: no world needed, never disabled
    const pb = document.createElement('button');
    pb.type = 'button';
    pb.id = 'tool-path';
    pb.textContent = PATH_TOOL.label;
    pb.dataset['tool'] = 'path';
    pb.setAttribute('aria-pressed', 'false');
    pb.title = `${PATH_TOOL.label} (${PATH_TOOL.key}): ${PATH_TOOL.help}; Esc clears`;
    pb.addEventListener('click', () => {
      this.callbacks.onPathTool();
      pb.blur();
    });
    this.bar.append(pb);
    this.pathButton = pb;
    this.radiusRange.min = '0';
    this.radiusRange.max = String(SLIDER_STEPS);
    this.radiusRange.step = '1';
    this.radiusRange.addEventListener('input', () => {
      this.callbacks.onRadius(this.fromSlider(Number(this.radiusRange.value)));
    });
    this.radiusRange.addEventListener('change', () => this.radiusRange.blur());
    this.radiusNumber.addEventListener('change', () => {
      this.callbacks.onRadius(Number(this.radiusNumber.value));
    });
    this.strengthRange.min = String(MIN_STRENGTH);
    this.strengthRange.max = '1';
    this.strengthRange.step = '0.05';
    this.strengthRange.addEventListener('input', () => this.callbacks.onStrength(Number(this.strengthRange.value)));
    this.strengthRange.addEventListener('change', () => this.strengthRange.blur());
    this.material.addEventListener('change', () => {
      this.callbacks.onMaterial(this.material.value);
      this.material.blur();
    });
    this.undoButton.addEventListener('click', () => {
      this.callbacks.onUndo();
      this.undoButton.blur();
    });
    this.redoButton.addEventListener('click', () => {
      this.callbacks.onRedo();
      this.redoButton.blur();
    });
  }

  private fromSlider(pos: number): number {
    const { min, max } = this.limits;
    const t = Math.max(0, Math.min(1, pos / SLIDER_STEPS));
    const r = min * (max / min) ** t;
    return Math.round(r * 10) / 10;
  }

  private toSlider(r: number): number {
    const { min, max } = this.limits;
    if (!(max > min)) return 0;
    return Math.round((SLIDER_STEPS * Math.log(r / min)) / Math.log(max / min));
  }

  /** Shows `s` (call whenever the session changed); `pathActive`: the Path tool is chosen. */
  update(s: EditStatus, pathActive = false): void {
    const off = !s.enabled;
    this.panel.classList.toggle('disabled', off);
    // a brush's settings open above the tool bar while a brush is chosen
    this.panel.classList.toggle('brushing', !off && s.tool !== 'look' && !pathActive);
    const why = off ? `editing is off: ${s.reason ?? ''}` : '';
    this.pathButton.classList.toggle('active', pathActive);
    this.pathButton.setAttribute('aria-pressed', String(pathActive));
    for (const [name, b] of this.buttons) {
      const on = name === s.tool && !pathActive;
      b.classList.toggle('active', on);
      b.setAttribute('aria-pressed', String(on));
      b.disabled = off && name !== 'look';
      if (off && name !== 'look') b.title = why;
      else {
        const t = TOOLS.find((t) => t.name === name)!;
        b.title = `${t.label} (${t.key}): ${t.help}`;
      }
    }
    for (const el of [this.radiusRange, this.radiusNumber, this.strengthRange, this.material, this.undoButton, this.redoButton]) {
      el.disabled = off;
      if (off) el.title = why;
    }
    if (s.enabled) {
      this.limits = { min: s.minRadius, max: s.maxRadius };
      this.radiusNumber.min = String(s.minRadius);
      this.radiusNumber.max = String(s.maxRadius);
      this.radiusNumber.step = '0.5';
      this.radiusRange.title = `brush radius, ${s.minRadius}–${s.maxRadius} m ([ and ])`;
      this.radiusNumber.title = this.radiusRange.title;
      this.strengthRange.title = 'brush strength (above 0, at most 1)';
      this.material.title = 'the material Paint puts on the surface';
      this.undoButton.title = 'undo the last edit (Ctrl+Z)';
      this.redoButton.title = 'redo (Ctrl+Shift+Z or Ctrl+Y)';
    }
    if (document.activeElement !== this.radiusNumber) this.radiusNumber.value = String(s.settings.radius);
    if (document.activeElement !== this.radiusRange) this.radiusRange.value = String(this.toSlider(s.settings.radius));
    this.strengthRange.value = String(s.settings.strength);
    this.strengthValue.textContent = s.settings.strength.toFixed(2);
    const names = s.materials.join('\n');
    if (names !== this.shownMaterials) {
      this.material.replaceChildren(
        ...s.materials.map((m) => {
          const o = document.createElement('option');
          o.value = m;
          o.textContent = m;
          return o;
        }),
      );
      this.shownMaterials = names;
    }
    if (s.settings.material !== null) this.material.value = s.settings.material;
    this.materialRow.hidden = s.tool !== 'paint';

    let text = '';
    let kind = '';
    if (off) {
      text = `Editing is off: ${s.reason ?? 'unknown reason'}`;
      kind = 'off';
    } else if (s.error) {
      text = s.error;
      kind = 'error';
    } else if (s.notice) {
      text = s.notice;
    } else if (s.tool !== 'look' && !pathActive) {
      text = 'left button: apply (hold and drag to repeat) · right drag: camera';
    }
    this.statusLine.textContent = text;
    this.statusLine.dataset['kind'] = kind;
    // why editing is off stays in the buttons' tooltips (the line would cover the planet)
    this.statusLine.hidden = text === '' || off;
  }

  /**
   * The Path tool's line: shown while the tool is chosen or a path (or its start) is shown;
   * errors in the error colour.
   */
  setPath(p: PathStatus, pathActive: boolean): void {
    const show = pathActive || p.phase !== 'empty' || p.notice !== null;
    let text = p.message;
    if (pathActive && (p.phase === 'found' || p.phase === 'none' || p.phase === 'error')) text += ' · click again to start over, Esc clears';
    else if (!pathActive && p.phase !== 'empty') text += ' · Esc clears';
    this.pathLine.textContent = show ? text : '';
    this.pathLine.dataset['kind'] = p.phase === 'error' ? 'error' : p.phase === 'none' ? 'none' : p.phase === 'found' ? 'found' : '';
    this.pathLine.dataset['phase'] = p.phase;
    this.pathLine.hidden = !show;
  }
}
