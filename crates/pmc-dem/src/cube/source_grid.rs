//! Where a latitude and longitude fall on an equirectangular source, bilinear values from a band
//! of its rows, and the coarse filled grid that supplies values where the source has none.

use crate::source::EquirectSource;
use std::collections::VecDeque;

/// Tolerance, in grid steps, for positions a rounding error outside a regional grid.
const EDGE_TOLERANCE: f64 = 1e-9;

/// The axes of a source, and whether latitudes past its first or last row are clamped.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SourceGrid {
    pub w: usize,
    pub h: usize,
    lon_first: f64,
    lon_step: f64,
    lat_first: f64,
    lat_step: f64,
    pub wraps: bool,
    clamp_south: bool,
    clamp_north: bool,
}

/// A position on the source grid: fractional column and row, clamped into the grid, and
/// whether it lies within the grid's extent (outside a regional grid it is missing).
#[derive(Clone, Copy, Debug)]
pub(crate) struct GridPos {
    pub x: f64,
    pub y: f64,
    pub inside: bool,
}

impl SourceGrid {
    pub fn new(s: &dyn EquirectSource) -> SourceGrid {
        SourceGrid::from_axes(
            s.width(),
            s.height(),
            [s.lon_first(), s.lon_step(), s.lat_first(), s.lat_step()],
            s.wraps_in_longitude(),
        )
    }

    /// The grid of `w x h` samples with axes `[lon_first, lon_step, lat_first, lat_step]`
    /// (degrees), wrapping in longitude or not.
    pub fn from_axes(w: usize, h: usize, axes: [f64; 4], wraps: bool) -> SourceGrid {
        let [lon_first, lon_step, lat_first, lat_step] = axes;
        let lat_last = lat_first + (h.saturating_sub(1)) as f64 * lat_step;
        SourceGrid {
            w,
            h,
            lon_first,
            lon_step,
            lat_first,
            lat_step,
            wraps,
            // A global grid whose first (last) row lies within one step of the pole: the cap
            // beyond it takes the row's values. Otherwise the cap is outside the data.
            clamp_south: wraps && lat_first - lat_step <= -90.0 + 1e-9,
            clamp_north: wraps && lat_last + lat_step >= 90.0 - 1e-9,
        }
    }

    /// The latitude and longitude (degrees) of sample `(c, r)`.
    pub fn lat_lon(&self, c: usize, r: usize) -> (f64, f64) {
        (
            self.lat_first + r as f64 * self.lat_step,
            self.lon_first + c as f64 * self.lon_step,
        )
    }

    /// West, east, south and north bounds of the samples, in degrees.
    pub fn extent(&self) -> [f64; 4] {
        [
            self.lon_first,
            self.lon_first + (self.w - 1) as f64 * self.lon_step,
            self.lat_first,
            self.lat_first + (self.h - 1) as f64 * self.lat_step,
        ]
    }

    /// The latitude and longitude (degrees) of direction `p` (any length), as
    /// `LatLon::from_point` gives them but for rounding (`sqrt` in place of `hypot`, which is
    /// several times slower and guards only against overflow, impossible for a direction on the
    /// unit sphere or the cube); `None` for the origin or non-finite input. At the poles the
    /// longitude is 0.
    #[inline]
    pub fn lat_lon_of(p: pmc_geometry::glam::DVec3) -> Option<(f64, f64)> {
        if !p.is_finite() || p == pmc_geometry::glam::DVec3::ZERO {
            return None;
        }
        let h = (p.x * p.x + p.z * p.z).sqrt();
        let lat = p.y.atan2(h).to_degrees();
        let lon = if h == 0.0 { 0.0 } else { p.x.atan2(p.z).to_degrees() };
        Some((lat, lon))
    }

    /// The grid position of a latitude and longitude (degrees).
    pub fn position(&self, lat: f64, lon: f64) -> GridPos {
        let hmax = (self.h - 1) as f64;
        let wmax = (self.w - 1) as f64;
        let mut inside = true;
        let mut y = (lat - self.lat_first) / self.lat_step;
        if y < 0.0 {
            inside &= self.clamp_south || y > -EDGE_TOLERANCE;
            y = 0.0;
        } else if y > hmax {
            inside &= self.clamp_north || y < hmax + EDGE_TOLERANCE;
            y = hmax;
        }
        let d = (lon - self.lon_first).rem_euclid(360.0);
        let mut x = d / self.lon_step;
        if self.wraps {
            if x >= self.w as f64 {
                x -= self.w as f64;
            }
            x = x.max(0.0);
        } else if x > wmax {
            // Past the east edge, or a rounding error west of the west edge.
            let west = (d - 360.0) / self.lon_step;
            if west > -EDGE_TOLERANCE {
                x = 0.0;
            } else if x < wmax + EDGE_TOLERANCE {
                x = wmax;
            } else {
                inside = false;
                // The nearer edge, for the fill.
                x = if x - wmax < -west { wmax } else { 0.0 };
            }
        }
        GridPos { x, y, inside }
    }

    /// How far a latitude and longitude (degrees) lie outside the grid's extent, in cells (the
    /// larger of the overshoots in rows and columns); 0 inside, and in the polar caps that a
    /// global grid clamps.
    pub fn outside_cells(&self, lat: f64, lon: f64) -> f64 {
        let hmax = (self.h - 1) as f64;
        let y = (lat - self.lat_first) / self.lat_step;
        let mut over = 0.0f64;
        if y < 0.0 && !self.clamp_south {
            over = -y;
        } else if y > hmax && !self.clamp_north {
            over = y - hmax;
        }
        if !self.wraps {
            let wmax = (self.w - 1) as f64;
            let d = (lon - self.lon_first).rem_euclid(360.0);
            let x = d / self.lon_step;
            if x > wmax {
                over = over.max((x - wmax).min((360.0 - d) / self.lon_step));
            }
        }
        over
    }

    /// The lower of the two rows a position interpolates between (`0 ..= h - 2`).
    #[inline]
    pub fn key_row(&self, p: &GridPos) -> usize {
        (p.y.floor() as usize).min(self.h - 2)
    }

    /// The bilinear value at `p` from rows `row0 ..` held in `band` (which must hold rows
    /// `key_row(p)` and the next). Corners that are missing (`NaN`) are left out and the weights
    /// of the others renormalised; `None` when no corner with weight remains. Exact at samples:
    /// with all four corners valid this is `sample_bilinear`'s formula.
    pub fn bilinear(&self, p: &GridPos, band: &[f32], row0: usize) -> Option<f64> {
        let r = self.key_row(p);
        let fy = p.y - r as f64;
        let (c0, c1, fx) = if self.wraps {
            let c0 = (p.x.floor() as usize).min(self.w - 1);
            (c0, (c0 + 1) % self.w, p.x - c0 as f64)
        } else {
            let c0 = (p.x.floor() as usize).min(self.w - 2);
            (c0, c0 + 1, p.x - c0 as f64)
        };
        let at = |c: usize, r: usize| f64::from(band[(r - row0) * self.w + c]);
        let (a, b, c, d) = (at(c0, r), at(c1, r), at(c0, r + 1), at(c1, r + 1));
        if a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite() {
            let south = a + fx * (b - a);
            let north = c + fx * (d - c);
            return Some(south + fy * (north - south));
        }
        let ws = [(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy];
        let (mut sum, mut wsum) = (0.0, 0.0);
        for (v, wt) in [a, b, c, d].into_iter().zip(ws) {
            if v.is_finite() && wt > 0.0 {
                sum += v * wt;
                wsum += wt;
            }
        }
        (wsum > 0.0).then(|| sum / wsum)
    }
}

/// A coarse copy of the source (each cell the mean of the valid samples in its block) in which
/// every empty cell took the value of the nearest valid cell (breadth-first, four neighbours,
/// wrapping in longitude for global grids). Supplies the value of missing samples.
#[derive(Clone, Debug)]
pub(crate) struct CoarseFill {
    gw: usize,
    gh: usize,
    w: usize,
    h: usize,
    sum: Vec<f64>,
    count: Vec<u32>,
    values: Vec<f32>,
}

/// Cells along longitude and latitude of the coarse fill grid, at most.
pub(crate) const COARSE_FILL_CELLS: (usize, usize) = (720, 360);

impl CoarseFill {
    pub fn new(w: usize, h: usize) -> CoarseFill {
        let (gw, gh) = (w.min(COARSE_FILL_CELLS.0), h.min(COARSE_FILL_CELLS.1));
        CoarseFill {
            gw,
            gh,
            w,
            h,
            sum: vec![0.0; gw * gh],
            count: vec![0; gw * gh],
            values: Vec::new(),
        }
    }

    #[inline]
    fn cell(&self, c: usize, r: usize) -> usize {
        (r * self.gh / self.h) * self.gw + c * self.gw / self.w
    }

    /// Adds one valid sample at column `c`, row `r`.
    pub fn add(&mut self, c: usize, r: usize, v: f32) {
        let k = self.cell(c, r);
        self.sum[k] += f64::from(v);
        self.count[k] += 1;
    }

    /// Fills the empty cells (at least one sample must have been added).
    pub fn finish(&mut self, wraps: bool) {
        let (gw, gh) = (self.gw, self.gh);
        self.values = (0..gw * gh)
            .map(|k| {
                if self.count[k] > 0 {
                    (self.sum[k] / f64::from(self.count[k])) as f32
                } else {
                    f32::NAN
                }
            })
            .collect();
        let mut queue: VecDeque<usize> = (0..gw * gh).filter(|&k| !self.values[k].is_nan()).collect();
        while let Some(k) = queue.pop_front() {
            let (c, r) = (k % gw, k / gw);
            let v = self.values[k];
            let mut next = [None; 4];
            next[0] = (r > 0).then(|| k - gw);
            next[1] = (r + 1 < gh).then(|| k + gw);
            next[2] = if c > 0 { Some(k - 1) } else { wraps.then(|| k + gw - 1) };
            next[3] = if c + 1 < gw {
                Some(k + 1)
            } else {
                wraps.then(|| k + 1 - gw)
            };
            for m in next.into_iter().flatten() {
                if self.values[m].is_nan() {
                    self.values[m] = v;
                    queue.push_back(m);
                }
            }
        }
        self.sum = Vec::new();
        self.count = Vec::new();
    }

    /// The fill value at grid position `p` (the coarse cell holding it).
    pub fn value(&self, p: &GridPos) -> f32 {
        let c = (p.x.round() as usize).min(self.w - 1);
        let r = (p.y.round() as usize).min(self.h - 1);
        self.values[self.cell(c, r)]
    }
}
