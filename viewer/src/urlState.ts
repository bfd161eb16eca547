// The viewer's state in the URL hash, e.g.
// `#preset=earthlike&seed=7&mode=orbit&lat=12.5&lon=-40&alt=3000&heading=0&pitch=-90`, and the
// detail settings when they are not the defaults (`&px=1&chunks=4000`), and the 3D Tiles mode when
// it is on (`&tiles=1`).
// Pure: parse and format only.

import type { CameraMode } from './cameraModel';

export interface UrlState {
  preset?: string;
  seed?: string;
  mode?: CameraMode;
  walk?: boolean;
  lat?: number;
  lon?: number;
  alt?: number;
  heading?: number;
  pitch?: number;
  /** The detail settings: the largest screen-space error (pixels) and the chunk budget. */
  px?: number;
  chunks?: number;
  /** Antialiasing (multisampling) off when false; on when absent. */
  aa?: boolean;
  /** The 3D Tiles mode: the planet from the server's 3D Tiles (true) or its chunks (false). */
  tiles?: boolean;
}

const NUMBER_KEYS = ['lat', 'lon', 'alt', 'heading', 'pitch'] as const;

export function parseHash(hash: string): UrlState {
  const params = new URLSearchParams(hash.startsWith('#') ? hash.slice(1) : hash);
  const out: UrlState = {};
  const preset = params.get('preset');
  if (preset && /^[a-z0-9_-]{1,32}$/i.test(preset)) out.preset = preset;
  const seed = params.get('seed');
  if (seed !== null && /^\d{1,20}$/.test(seed)) out.seed = seed;
  const mode = params.get('mode');
  if (mode === 'orbit' || mode === 'fly') out.mode = mode;
  const walk = params.get('walk');
  if (walk !== null) out.walk = walk === '1' || walk === 'true';
  for (const k of NUMBER_KEYS) {
    const v = params.get(k);
    if (v === null || v.trim() === '') continue;
    const n = Number(v);
    if (Number.isFinite(n)) out[k] = n;
  }
  if (out.lat !== undefined) out.lat = Math.max(-90, Math.min(90, out.lat));
  const px = Number(params.get('px') ?? NaN);
  if (Number.isFinite(px) && px >= 0.1 && px <= 100) out.px = px;
  const chunks = Number(params.get('chunks') ?? NaN);
  if (Number.isInteger(chunks) && chunks >= 1 && chunks <= 1_000_000) out.chunks = chunks;
  const aa = params.get('aa');
  if (aa === '0' || aa === 'false' || aa === 'off') out.aa = false;
  else if (aa === '1' || aa === 'true' || aa === 'on') out.aa = true;
  const tiles = params.get('tiles');
  if (tiles === '0' || tiles === 'false' || tiles === 'off') out.tiles = false;
  else if (tiles === '1' || tiles === 'true' || tiles === 'on') out.tiles = true;
  return out;
}

/** Rounds to `digits` decimals without trailing zeros. */
function fmt(n: number, digits: number): string {
  return String(Number(n.toFixed(digits)));
}

export function formatHash(s: UrlState): string {
  const params = new URLSearchParams();
  if (s.preset) params.set('preset', s.preset);
  if (s.seed !== undefined) params.set('seed', s.seed);
  if (s.mode) params.set('mode', s.mode);
  if (s.walk) params.set('walk', '1');
  if (s.lat !== undefined) params.set('lat', fmt(s.lat, 5));
  if (s.lon !== undefined) params.set('lon', fmt(s.lon, 5));
  if (s.alt !== undefined) params.set('alt', fmt(s.alt, 1));
  if (s.heading !== undefined) params.set('heading', fmt(s.heading, 1));
  if (s.pitch !== undefined) params.set('pitch', fmt(s.pitch, 1));
  if (s.px !== undefined) params.set('px', fmt(s.px, 2));
  if (s.chunks !== undefined) params.set('chunks', String(Math.round(s.chunks)));
  if (s.aa === false) params.set('aa', '0');
  if (s.tiles) params.set('tiles', '1');
  return `#${params.toString()}`;
}
