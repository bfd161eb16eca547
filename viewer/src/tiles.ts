// The 3D Tiles mode's pure parts (the mode itself, with 3DTilesRendererJS, is tilesMode.ts,
// loaded when the mode is first turned on): the tiles' frame in the viewer, what the mode reports,
// and whether the tiles are of the planet shown. Pure: no three.js, no DOM.
//
// The frame: the tiles of `/tiles/sphere/` are in Earth-centred, Earth-fixed metres
// (docs/specs/tiles-v1.md: Z to the north pole, X to longitude 0, Y to 90 E), the viewer's planet
// frame is Y-up with longitude 0 on +Z and 90 E on +X (frames.ts). So
// viewer (x, y, z) = ECEF (Y, Z, X): a cyclic permutation of the axes, a rotation (det +1). The
// tiles' group is drawn around the floating origin as the chunks are: rotated into the planet
// frame, then moved by -camera, the matrix built from f64 numbers (the JS numbers three.js keeps
// its matrices in), so the model-view matrix three.js multiplies out for each tile holds the
// tile's place relative to the eye to the millimetre before the GPU rounds it to f32.

import type { V3 } from './frames';

/** A planet-frame (viewer) point of an ECEF point of the tiles. */
export function ecefToViewer(p: V3): V3 {
  return [p[1], p[2], p[0]];
}

/** An ECEF point of a planet-frame (viewer) point. */
export function viewerToEcef(p: V3): V3 {
  return [p[2], p[0], p[1]];
}

/**
 * The tiles' group's matrix with the camera at `camera` (planet frame, metres): ECEF to the
 * viewer's axes, then a translation by -camera (render space, relative to the camera). Column-major
 * 4 x 4 (three.js `Matrix4.elements`), written into `out` and returned.
 */
export function tilesGroupMatrix(camera: V3, out: number[] = new Array<number>(16)): number[] {
  // columns: the images of ECEF's X, Y and Z axes (viewer +Z, +X and +Y), then the translation
  out[0] = 0;
  out[1] = 0;
  out[2] = 1;
  out[3] = 0;
  out[4] = 1;
  out[5] = 0;
  out[6] = 0;
  out[7] = 0;
  out[8] = 0;
  out[9] = 1;
  out[10] = 0;
  out[11] = 0;
  out[12] = -camera[0];
  out[13] = -camera[1];
  out[14] = -camera[2];
  out[15] = 1;
  return out;
}

/** The tileset the mode loads, relative to the page (the sphere frame: the planet as drawn here). */
export const TILESET_PATH = 'tiles/sphere/tileset.json';

/** How long nothing may have been queued, downloading or parsing for the tiles to be settled (ms). */
export const TILES_QUIET_MS = 500;

/** The 3D Tiles mode as `__pmc.stats().tiles`, `__pmc.tiles()` and the HUD show it. */
export interface TilesStats {
  /** Whether the 3D Tiles mode is on. */
  on: boolean;
  /** Whether the tiles' renderer runs (false while its code loads, the moment the mode is first turned on). */
  running: boolean;
  /** Tiles whose content is loaded (kept in the cache, drawn or not), drawn, and used this frame. */
  loaded: number;
  visible: number;
  active: number;
  /** Tiles waiting for a download, downloading, and being parsed. */
  queued: number;
  downloading: number;
  parsing: number;
  /** Tiles (or the tileset) that failed to load. */
  failed: number;
  /** Milliseconds since anything was last queued, downloading or parsing (0 while something is). */
  quietMs: number;
  /** Nothing queued, downloading or parsing for TILES_QUIET_MS, the tileset read. */
  settled: boolean;
  /** The tileset's `extras.pmc.frame` and `terrain`, once read. */
  frame: string | null;
  terrain: string | null;
}

/** The stats of the mode with no tiles (`on`: the mode is on, its renderer's code loading). */
export function noTiles(on: boolean): TilesStats {
  return {
    on,
    running: false,
    loaded: 0,
    visible: 0,
    active: 0,
    queued: 0,
    downloading: 0,
    parsing: 0,
    failed: 0,
    quietMs: 0,
    settled: false,
    frame: null,
    terrain: null,
  };
}

/**
 * Whether the tileset's `extras.pmc.terrain` (`preset:NAME:SEED` for a preset) names another
 * planet than `shown` (`/planet`'s `terrain`); false when either is not known.
 */
export function otherPlanet(terrain: string | null, shown: { kind: string; name: string; seed: string } | null): boolean {
  if (terrain === null || shown === null || shown.kind !== 'preset') return false;
  const m = /^preset:([^:]+):(\d+)$/.exec(terrain);
  return m !== null && (m[1] !== shown.name || m[2] !== shown.seed);
}
