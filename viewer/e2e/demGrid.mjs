// An elevation model's grid as the steps read it (NOAA ETOPO's netCDF classic: coordinates
// ETOPO05_X, ETOPO05_Y in degrees, heights in metres), to project the data into screenshots.

import { readFileSync } from 'node:fs';
import { NetCDFReader } from 'netcdfjs';

/**
 * The grid of the netCDF file `path`: its longitudes and latitudes (ascending or descending, evenly
 * spaced) and heights, with the bilinear interpolant and the extremes near a place.
 */
export function readDemGrid(path, { x = 'ETOPO05_X', y = 'ETOPO05_Y', z = 'ROSE' } = {}) {
  const r = new NetCDFReader(readFileSync(path));
  const lons = Array.from(r.getDataVariable(x));
  const lats = Array.from(r.getDataVariable(y));
  const heights = Array.from(r.getDataVariable(z));
  const nx = lons.length;
  const ny = lats.length;
  if (heights.length !== nx * ny) throw new Error(`${path}: ${z} has ${heights.length} values, not ${nx} x ${ny}`);
  const dx = (lons[nx - 1] - lons[0]) / (nx - 1);
  const dy = (lats[ny - 1] - lats[0]) / (ny - 1);
  /** The height of data point (column i, row j). */
  const at = (i, j) => heights[j * nx + i];
  /** Fractional column and row of a place (degrees). */
  const cell = (lat, lon) => ({ fx: (lon - lons[0]) / dx, fy: (lat - lats[0]) / dy });
  const inside = (fx, fy) => fx >= 0 && fy >= 0 && fx <= nx - 1 && fy <= ny - 1;
  return {
    nx,
    ny,
    /** Degrees between neighbouring columns and rows (positive). */
    spacing: { lon: Math.abs(dx), lat: Math.abs(dy) },
    at,
    /** Whether a place lies inside the grid by at least `margin` cells. */
    covers(lat, lon, margin = 0) {
      const { fx, fy } = cell(lat, lon);
      return fx >= margin && fy >= margin && fx <= nx - 1 - margin && fy <= ny - 1 - margin;
    },
    /** The bilinear interpolant at a place (degrees), null outside the grid. */
    bilinear(lat, lon) {
      const { fx, fy } = cell(lat, lon);
      if (!inside(fx, fy)) return null;
      const i = Math.min(nx - 2, Math.floor(fx));
      const j = Math.min(ny - 2, Math.floor(fy));
      const u = fx - i;
      const v = fy - j;
      return (1 - v) * ((1 - u) * at(i, j) + u * at(i + 1, j)) + v * ((1 - u) * at(i, j + 1) + u * at(i + 1, j + 1));
    },
    /**
     * The lowest and highest data point within `cells` cells of a place: those of the cell
     * holding it and of the cells around it. A contour of the data passes within that distance
     * of a place exactly when there are points of both signs (relative to the contour) here.
     */
    around(lat, lon, cells = 1) {
      const { fx, fy } = cell(lat, lon);
      let min = Infinity;
      let max = -Infinity;
      for (let j = Math.max(0, Math.floor(fy) - cells); j <= Math.min(ny - 1, Math.ceil(fy) + cells); j++) {
        for (let i = Math.max(0, Math.floor(fx) - cells); i <= Math.min(nx - 1, Math.ceil(fx) + cells); i++) {
          min = Math.min(min, at(i, j));
          max = Math.max(max, at(i, j));
        }
      }
      return { min, max };
    },
  };
}
