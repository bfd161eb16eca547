// Shared test inputs.

import type { PlanetInfo } from '../src/api';

/** `/planet` of the default planet (earthlike, seed 7, the default layout), abridged. */
export const EARTHLIKE_INFO: PlanetInfo = {
  format: 'pmc-planet', version: 1, preset: 'earthlike', seed: '7', presets: [],
  layout: { n_c: 8, n_t: 32, d_b: 1744, l_d: 4, d_c: 2 },
  radius: 2000, base_radius: 1744, sea_radius: 1884.8, surface_bounds: [1810.6, 1995.5],
  chunk_count: 768, face_tiles: 256, depth_tiles: 64, faces: [], materials: [],
  palette: { a: [0.8, 0.7, 0.5], b: [0.3, 0.5, 0.2] },
};
