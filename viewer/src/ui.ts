// The DOM overlays of index.html: the slim HUD (place, height, compass, scale bar), the go-to
// box, the side panel (statistics, view, planet, detail, debug, sky; folded away by default, its
// state remembered), the loading bar and notices, the error banner and the server-gone notice.
// Plain DOM, no framework.

import type { SkySettings, SkyState } from './atmosphere';
import type { CameraMode } from './cameraModel';
import type { PresetInfo } from './api';
import type { DebugFlags } from './planetScene';
import type { NavGridStatus } from './navOverlay';
import type { TilesStats } from './tiles';
import { MOUSE_HELP, SHORTCUTS, SHORTCUT_GROUPS } from './shortcuts';
import { formatLat, formatLon, loadingShare, type ScaleBar } from './hud';
import { PANEL_SECTIONS, loadPanelState, savePanelState, type PanelSection, type PanelState, type StorageLike } from './panelState';

export interface UiCallbacks {
  onPlanet(preset: string, seed: string): void;
  onMode(mode: CameraMode): void;
  onWalk(walk: boolean): void;
  onDebug(flags: Partial<DebugFlags>): void;
  /** The nav grid checkbox. */
  onNavGrid(on: boolean): void;
  /** The 3D Tiles button: the planet from the server's 3D Tiles (on) or its chunks (off). */
  onTiles(on: boolean): void;
  /** The detail fields: largest screen-space error in pixels, chunk budget. */
  onLod(settings: { maxPixelError?: number; maxChunks?: number }): void;
  /** The sky fields: the atmosphere checkbox, the sun's elevation and azimuth (degrees). */
  onSky(settings: Partial<SkySettings>): void;
  /** The go-to box's text, submitted. */
  onGoTo(text: string): void;
  /** Bookmarks: this view kept; one chosen (by its name); one forgotten. */
  onBookmarkAdd(): void;
  onBookmarkOpen(name: string): void;
  onBookmarkRemove(name: string): void;
  /** The screenshot button. */
  onScreenshot(): void;
  /** The compass: face north. */
  onNorth(): void;
  /** The server-gone notice's retry button. */
  onRetry(): void;
}

export interface StatsView {
  planet: string;
  /** Chunks shown, and loaded (shown or kept). */
  chunks: number;
  loaded: number;
  pending: number;
  /** Chunks shown per level, e.g. `L0 12 · L1 40 · L2 18`. */
  levels: string;
  triangles: number;
  fps: number;
  lat: number;
  lon: number;
  alt: number;
  aboveGround: number | null;
  heading: number;
  /** The scale bar at the centre of the view; null where the view's centre is sky. */
  scale: ScaleBar | null;
}

function byId<T extends HTMLElement>(id: string): T {
  const el = document.getElementById(id);
  if (!el) throw new Error(`index.html lacks #${id}`);
  return el as T;
}

const fmtInt = (n: number): string => Math.round(n).toLocaleString('en-US');

export function formatDistance(m: number): string {
  const a = Math.abs(m);
  if (a >= 100_000) return `${(m / 1000).toFixed(0)} km`;
  if (a >= 10_000) return `${(m / 1000).toFixed(1)} km`;
  if (a >= 1000) return `${(m / 1000).toFixed(2)} km`;
  return `${m.toFixed(1)} m`;
}

export class Ui {
  private readonly preset = byId<HTMLSelectElement>('preset');
  private readonly seed = byId<HTMLInputElement>('seed');
  private readonly modeButton = byId<HTMLButtonElement>('mode');
  private readonly walk = byId<HTMLInputElement>('walk');
  private readonly tilesButton = byId<HTMLButtonElement>('tiles');
  private tilesOn = false;
  private shownTiles = '';
  private readonly wireframe = byId<HTMLInputElement>('wireframe');
  private readonly faces = byId<HTMLInputElement>('faces');
  private readonly borders = byId<HTMLInputElement>('borders');
  private readonly backfaces = byId<HTMLInputElement>('backfaces');
  private readonly pixelError = byId<HTMLInputElement>('lod-px');
  private readonly budget = byId<HTMLInputElement>('lod-budget');
  private readonly navgrid = byId<HTMLInputElement>('navgrid');
  private readonly atmosphere = byId<HTMLInputElement>('atmosphere');
  private readonly skyKind = byId<HTMLSpanElement>('sky-kind');
  private readonly sunElevation = byId<HTMLInputElement>('sun-elevation');
  private readonly sunElevationValue = byId<HTMLOutputElement>('sun-elevation-value');
  private readonly sunAzimuth = byId<HTMLInputElement>('sun-azimuth');
  private readonly sunAzimuthValue = byId<HTMLOutputElement>('sun-azimuth-value');
  private readonly navgridStatus = byId<HTMLParagraphElement>('navgrid-status');
  private shownNavGrid = '';
  private readonly loading = byId<HTMLDivElement>('loading');
  private readonly loadingBar = byId<HTMLDivElement>('loading-bar');
  private readonly loadingBarFill = byId<HTMLDivElement>('loading-bar-fill');
  private readonly offline = byId<HTMLDivElement>('offline');
  private readonly offlineText = byId<HTMLSpanElement>('offline-text');
  private readonly side = byId<HTMLElement>('side');
  private readonly panelToggle = byId<HTMLButtonElement>('panel-toggle');
  private readonly storage: StorageLike | null = (() => {
    try {
      return globalThis.localStorage ?? null;
    } catch {
      return null;
    }
  })();
  private panel: PanelState = loadPanelState(this.storage);
  private readonly hud = {
    planet: byId('hud-planet'),
    lat: byId('hud-lat'),
    lon: byId('hud-lon'),
    alt: byId('hud-alt'),
    ground: byId('hud-ground'),
    heading: byId('hud-heading'),
    tiles: byId('hud-tiles'),
    needle: document.getElementById('compass-needle') as Element | null,
    scale: byId('scale'),
    scaleBar: byId('scale-bar'),
    scaleText: byId('scale-text'),
  };
  private readonly loadingText = byId<HTMLSpanElement>('loading-text');
  private readonly error = byId<HTMLDivElement>('error');
  private readonly errorText = byId<HTMLSpanElement>('error-text');
  private readonly fields = {
    planet: byId('s-planet'),
    chunks: byId('s-chunks'),
    loaded: byId('s-loaded'),
    pending: byId('s-pending'),
    levels: byId('s-levels'),
    triangles: byId('s-triangles'),
    fps: byId('s-fps'),
    lat: byId('s-lat'),
    lon: byId('s-lon'),
    alt: byId('s-alt'),
    ground: byId('s-ground'),
    heading: byId('s-heading'),
    edits: byId('s-edits'),
    push: byId('s-push'),
    editError: byId('s-edit-error'),
    path: byId('s-path'),
  };
  private mode: CameraMode = 'orbit';

  constructor(private readonly callbacks: UiCallbacks) {
    this.renderKeysHelp();
    this.applyPanel();
    this.panelToggle.addEventListener('click', () => {
      this.togglePanel();
      this.panelToggle.blur();
    });
    const sections = [...this.side.querySelectorAll<HTMLDetailsElement>('details[data-section]')];
    /** Keeps what the sections show (false when nothing changed). */
    const keepSections = (): void => {
      let changed = false;
      for (const d of sections) {
        const name = d.dataset['section'] as PanelSection;
        if (!PANEL_SECTIONS.includes(name) || this.panel.sections[name] === d.open) continue;
        this.panel.sections[name] = d.open;
        changed = true;
      }
      if (changed) savePanelState(this.storage, this.panel);
    };
    for (const d of sections) d.addEventListener('toggle', keepSections);
    // (`toggle` comes a task after the click: a section folded just before leaving the page is
    // kept as the page goes)
    window.addEventListener('pagehide', keepSections);
    byId<HTMLButtonElement>('compass').addEventListener('click', (e) => {
      this.callbacks.onNorth();
      (e.currentTarget as HTMLElement).blur();
    });
    byId<HTMLButtonElement>('offline-retry').addEventListener('click', () => this.callbacks.onRetry());
    const marks = byId<HTMLSelectElement>('bookmarks');
    marks.addEventListener('change', () => {
      if (marks.value !== '') this.callbacks.onBookmarkOpen(marks.value);
    });
    byId<HTMLButtonElement>('bookmark-add').addEventListener('click', () => this.callbacks.onBookmarkAdd());
    byId<HTMLButtonElement>('screenshot').addEventListener('click', () => this.callbacks.onScreenshot());
    byId<HTMLButtonElement>('bookmark-remove').addEventListener('click', () => {
      if (marks.value !== '') this.callbacks.onBookmarkRemove(marks.value);
    });
    byId<HTMLFormElement>('goto-form').addEventListener('submit', (e) => {
      e.preventDefault();
      this.callbacks.onGoTo(byId<HTMLInputElement>('goto').value);
    });
    byId<HTMLButtonElement>('keys-help-close').addEventListener('click', () => this.toggleHelp(false));
    byId<HTMLFormElement>('planet-form').addEventListener('submit', (e) => {
      e.preventDefault();
      this.submitPlanet();
    });
    // choosing another preset regenerates at once
    this.preset.addEventListener('change', () => this.submitPlanet());
    this.modeButton.addEventListener('click', () => {
      this.callbacks.onMode(this.mode === 'orbit' ? 'fly' : 'orbit');
    });
    this.walk.addEventListener('change', () => this.callbacks.onWalk(this.walk.checked));
    this.tilesButton.addEventListener('click', () => {
      this.callbacks.onTiles(!this.tilesOn);
      this.tilesButton.blur();
    });
    this.wireframe.addEventListener('change', () =>
      this.callbacks.onDebug({ wireframe: this.wireframe.checked }),
    );
    this.faces.addEventListener('change', () =>
      this.callbacks.onDebug({ faceColours: this.faces.checked }),
    );
    this.borders.addEventListener('change', () =>
      this.callbacks.onDebug({ borders: this.borders.checked }),
    );
    this.backfaces.addEventListener('change', () =>
      this.callbacks.onDebug({ backfaces: this.backfaces.checked }),
    );
    const lodField = (input: HTMLInputElement, apply: (v: number) => void, valid: (v: number) => boolean): void => {
      input.addEventListener('change', () => {
        const v = Number(input.value);
        if (input.value.trim() !== '' && valid(v)) {
          apply(v);
        } else {
          this.showError(`"${input.value}" is not a valid ${input.getAttribute('aria-label') ?? 'value'}`);
        }
      });
    };
    lodField(this.pixelError, (v) => this.callbacks.onLod({ maxPixelError: v }), (v) => Number.isFinite(v) && v > 0);
    lodField(this.budget, (v) => this.callbacks.onLod({ maxChunks: v }), (v) => Number.isInteger(v) && v >= 1);
    this.atmosphere.addEventListener('change', () => this.callbacks.onSky({ atmosphere: this.atmosphere.checked }));
    this.sunElevation.addEventListener('input', () => this.callbacks.onSky({ sunElevation: Number(this.sunElevation.value) }));
    this.sunAzimuth.addEventListener('input', () => this.callbacks.onSky({ sunAzimuth: Number(this.sunAzimuth.value) }));
    this.navgrid.addEventListener('change', () => {
      this.callbacks.onNavGrid(this.navgrid.checked);
      this.navgrid.blur();
    });
    byId('error-close').addEventListener('click', () => this.clearError());
  }

  private submitPlanet(): void {
    const seed = this.seed.value.trim();
    if (!/^\d{1,20}$/.test(seed) || BigInt(seed) > 18446744073709551615n) {
      this.showError(`the seed must be a whole number from 0 to 18446744073709551615, not "${seed}"`);
      return;
    }
    this.callbacks.onPlanet(this.preset.value, seed);
  }

  setPresets(presets: (PresetInfo & { label?: string })[], current: string): void {
    const names = presets.map((p) => `${p.name}=${p.label ?? ''}`).join('\n');
    if (this.preset.dataset['names'] !== names) {
      this.preset.replaceChildren(
        ...presets.map((p) => {
          const o = document.createElement('option');
          o.value = p.name;
          o.textContent = p.label ?? p.name;
          o.title = p.description;
          return o;
        }),
      );
      this.preset.dataset['names'] = names;
    }
    this.preset.value = current;
  }

  setPlanet(preset: string, seed: string): void {
    this.preset.value = preset;
    this.seed.value = seed;
  }

  setMode(mode: CameraMode, walk: boolean): void {
    this.mode = mode;
    this.modeButton.textContent = `Mode: ${mode}`;
    this.walk.checked = walk;
    this.walk.disabled = mode !== 'fly';
  }

  /** The 3D Tiles button, and the HUD's line of the mode (hidden when off). */
  setTilesMode(on: boolean): void {
    this.tilesOn = on;
    this.tilesButton.textContent = `3D Tiles: ${on ? 'on' : 'off'}`;
    this.tilesButton.setAttribute('aria-pressed', String(on));
    if (!on) this.setTiles(null);
  }

  /** The HUD's line of the 3D Tiles mode: tiles drawn, loaded and loading; null hides it. */
  setTiles(s: TilesStats | null): void {
    const loading = s ? s.queued + s.downloading + s.parsing : 0;
    const text = s
      ? `3D Tiles · ${fmtInt(s.visible)} drawn · ${fmtInt(s.loaded)} loaded${loading > 0 ? ` · ${fmtInt(loading)} loading` : ''}${s.failed > 0 ? ` · ${fmtInt(s.failed)} failed` : ''}`
      : '';
    if (text === this.shownTiles) return;
    this.shownTiles = text;
    this.hud.tiles.hidden = s === null;
    this.hud.tiles.textContent = text;
  }

  setDebug(flags: DebugFlags): void {
    this.wireframe.checked = flags.wireframe;
    this.faces.checked = flags.faceColours;
    this.borders.checked = flags.borders;
    this.backfaces.checked = flags.backfaces;
  }

  /** The sky fields: the atmosphere checkbox, the planet's air, the sun's place. */
  setSky(s: SkyState): void {
    this.atmosphere.checked = s.atmosphere;
    this.skyKind.textContent = s.kind === null ? 'none on this planet' : s.drawn ? s.kind : `${s.kind} (not drawn)`;
    if (document.activeElement !== this.sunElevation) this.sunElevation.value = String(s.sunElevation);
    if (document.activeElement !== this.sunAzimuth) this.sunAzimuth.value = String(s.sunAzimuth);
    this.sunElevationValue.textContent = `${s.sunElevation.toFixed(1)}°`;
    this.sunAzimuthValue.textContent = `${s.sunAzimuth.toFixed(0)}°`;
  }

  /** The detail fields. */
  setLod(s: { maxPixelError: number; maxChunks: number }): void {
    if (document.activeElement !== this.pixelError) this.pixelError.value = String(s.maxPixelError);
    if (document.activeElement !== this.budget) this.budget.value = String(s.maxChunks);
  }

  /**
   * The nav grid checkbox and its line: nodes and components in view, a legend (the main grid's
   * colour and the other components' colours), or the error.
   */
  setNavGrid(s: NavGridStatus): void {
    this.navgrid.checked = s.enabled;
    const key = JSON.stringify([s.enabled, s.loading, s.error, s.nodes, s.fetches, s.truncated, s.components.length]);
    if (key === this.shownNavGrid) return;
    this.shownNavGrid = key;
    const el = this.navgridStatus;
    el.hidden = !s.enabled;
    el.dataset['kind'] = s.error ? 'error' : '';
    if (!s.enabled) {
      el.replaceChildren();
      return;
    }
    if (s.error) {
      el.textContent = s.error;
      return;
    }
    if (s.nodes === 0) {
      el.textContent = s.loading ? 'loading the navigation grid…' : 'no walkable ground in range';
      return;
    }
    const swatch = (hex: string, title: string): HTMLElement => {
      const sp = document.createElement('span');
      sp.className = 'swatch';
      sp.style.background = hex;
      sp.title = title;
      return sp;
    };
    const others = s.components.filter((c) => !c.main);
    const main = s.components.find((c) => c.main);
    const parts: (HTMLElement | string)[] = [
      `${fmtInt(s.nodes)} nodes${s.truncated ? ' (the nearest only)' : ''}, ${s.components.length} component${s.components.length === 1 ? '' : 's'}${s.loading ? ' · updating' : ''}`,
      document.createElement('br'),
    ];
    if (main) parts.push(swatch(main.hex, `${fmtInt(main.size)} nodes`), ' main grid ');
    if (others.length > 0) {
      for (const c of others.slice(0, 8)) parts.push(swatch(c.hex, `component ${c.label}: ${fmtInt(c.size)} nodes, ${c.nodes} here`));
      parts.push(` ${others.length} detached`);
    } else {
      parts.push('nothing detached here');
    }
    el.replaceChildren(...parts);
  }

  /** The path row of the stats panel. */
  setPathStats(text: string): void {
    this.fields.path.textContent = text;
  }

  /**
   * The loading bar (chunks shown among those wanted, while any are loading or missing) and the
   * notice of what the viewer waits for (`busyText`: the planet, the server).
   */
  setLoading(shown: number, pending: number, missing: number, busyText: string | null): void {
    this.loading.hidden = busyText === null;
    if (busyText !== null) this.loadingText.textContent = busyText;
    const share = busyText === null ? loadingShare(shown, pending, missing) : null;
    this.loadingBar.hidden = share === null;
    if (share !== null) {
      const left = pending + missing;
      this.loadingBarFill.style.width = `${(100 * share).toFixed(1)}%`;
      this.loadingBar.setAttribute('aria-valuenow', (100 * share).toFixed(0));
      this.loadingBar.title = `loading ${left} chunk${left === 1 ? '' : 's'}`;
    }
  }

  /** The server-gone notice: shown with `message`, or hidden (null). */
  setOffline(message: string | null): void {
    this.offline.hidden = message === null;
    if (message !== null && this.offlineText.textContent !== message) this.offlineText.textContent = message;
  }

  /** Whether the side panel shows. */
  get panelOpen(): boolean {
    return this.panel.open;
  }

  /** Opens the side panel, or closes it; toggles when `open` is not given. Remembered. */
  togglePanel(open?: boolean): boolean {
    this.panel.open = open ?? !this.panel.open;
    savePanelState(this.storage, this.panel);
    this.applyPanel();
    return this.panel.open;
  }

  private applyPanel(): void {
    this.side.hidden = !this.panel.open;
    this.panelToggle.setAttribute('aria-expanded', String(this.panel.open));
    for (const d of this.side.querySelectorAll<HTMLDetailsElement>('details[data-section]')) {
      const name = d.dataset['section'] as PanelSection;
      if (PANEL_SECTIONS.includes(name)) d.open = this.panel.sections[name];
    }
  }

  /** Puts the caret in the go-to box (`/`). */
  focusGoTo(): void {
    const input = byId<HTMLInputElement>('goto');
    input.focus();
    input.select();
  }

  /** The bookmarks' list (names, with their planets), `chosen` selected. */
  setBookmarks(list: readonly { name: string; planet: string }[], chosen = ''): void {
    const marks = byId<HTMLSelectElement>('bookmarks');
    const first = document.createElement('option');
    first.value = '';
    first.textContent = list.length === 0 ? 'no bookmarks: ☆ keeps one' : `bookmarks (${list.length})…`;
    const options = list.map((b) => {
      const o = document.createElement('option');
      o.value = b.name;
      o.textContent = `${b.name} · ${b.planet}`;
      return o;
    });
    marks.replaceChildren(first, ...options);
    marks.value = chosen;
  }

  /** Whether the keyboard help shows. */
  get helpShown(): boolean {
    return !byId<HTMLElement>('keys-help').hidden;
  }

  /** Shows the keyboard help (`?`), or hides it; toggles when `show` is not given. Returns whether it shows. */
  toggleHelp(show?: boolean): boolean {
    const help = byId<HTMLElement>('keys-help');
    help.hidden = !(show ?? help.hidden);
    return !help.hidden;
  }

  /** Hides every overlay but an error (`H`: the planet alone), or shows them; toggles when not given. */
  toggleOverlays(hidden?: boolean): boolean {
    const on = hidden ?? !document.body.classList.contains('overlays-hidden');
    document.body.classList.toggle('overlays-hidden', on);
    return on;
  }

  /** The keyboard help, from the table the handlers use (shortcuts.ts): one row per shortcut. */
  private renderKeysHelp(): void {
    const body = byId<HTMLElement>('keys-help-body');
    const section = (title: string, rows: readonly { keys: string; what: string }[]): void => {
      const h = document.createElement('h3');
      h.textContent = title;
      const table = document.createElement('table');
      for (const r of rows) {
        const tr = table.insertRow();
        const th = document.createElement('th');
        th.textContent = r.keys;
        tr.appendChild(th);
        tr.insertCell().textContent = r.what;
      }
      body.append(h, table);
    };
    for (const g of SHORTCUT_GROUPS) section(g, SHORTCUTS.filter((s) => s.group === g));
    section('Mouse and touch', MOUSE_HELP);
  }

  showError(message: string): void {
    this.errorText.textContent = message;
    this.error.hidden = false;
  }

  clearError(): void {
    this.error.hidden = true;
    this.errorText.textContent = '';
  }

  errorMessage(): string | null {
    return this.error.hidden ? null : this.errorText.textContent;
  }

  /**
   * The edit lines of the stats panel (the revision and counts, the push state) and the last edit
   * error (null: none; its row hides).
   */
  setEditStats(text: string, push: string, error: string | null): void {
    this.fields.edits.textContent = text;
    this.fields.push.textContent = push;
    this.fields.editError.textContent = error ?? '';
    for (const el of document.querySelectorAll<HTMLElement>('#stats .edit-error')) el.hidden = error === null;
  }

  setStats(s: StatsView): void {
    const f = this.fields;
    f.planet.textContent = s.planet;
    f.chunks.textContent = fmtInt(s.chunks);
    f.loaded.textContent = fmtInt(s.loaded);
    f.pending.textContent = fmtInt(s.pending);
    f.levels.textContent = s.levels;
    f.triangles.textContent = fmtInt(s.triangles);
    f.fps.textContent = s.fps.toFixed(0);
    f.lat.textContent = formatLat(s.lat);
    f.lon.textContent = formatLon(s.lon);
    f.alt.textContent = formatDistance(s.alt);
    f.ground.textContent = s.aboveGround === null ? '–' : formatDistance(s.aboveGround);
    f.heading.textContent = `${s.heading.toFixed(0)}°`;
    const h = this.hud;
    h.planet.textContent = s.planet;
    h.lat.textContent = formatLat(s.lat);
    h.lon.textContent = formatLon(s.lon);
    h.alt.textContent = `alt ${formatDistance(s.alt)}`;
    h.ground.textContent = s.aboveGround === null ? '' : `· ${formatDistance(s.aboveGround)} over ground`;
    h.heading.textContent = `heading ${s.heading.toFixed(0)}°`;
    h.needle?.setAttribute('transform', `rotate(${(-s.heading).toFixed(1)})`);
    h.scale.classList.toggle('none', s.scale === null);
    if (s.scale !== null) {
      h.scaleBar.style.width = `${s.scale.px.toFixed(1)}px`;
      h.scaleText.textContent = s.scale.label;
    }
  }
}
