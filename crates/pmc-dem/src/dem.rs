//! The elevation grid: accessors, statistics and bilinear sampling.

/// Fractions of a step closer than this to a sample point are taken as the sample point itself,
/// so that sampling at a grid point returns its stored value exactly.
const SNAP: f64 = 1e-9;

/// A digital elevation model on an equirectangular grid: `width` x `height` heights in metres at
/// evenly spaced longitudes and latitudes.
///
/// Layout, whatever the order of the file it was read from:
/// - columns run **east**: column `col` is at longitude [`lon(col)`](Self::lon) =
///   `lon_first + col * lon_step`, with `lon_first` in [-180, 180) and `lon_step` > 0 (so `lon`
///   may exceed 180: ETOPO60's last column is at 379.5);
/// - rows run **north**: row 0 is the southernmost, row `row` is at latitude
///   [`lat(row)`](Self::lat) = `lat_first + row * lat_step`, with `lat_step` > 0. A file whose
///   latitudes decrease has its rows reversed;
/// - heights are stored row by row ([`heights`](Self::heights)), `NaN` where the file had its
///   fill or missing value or a value that is not a finite number.
///
/// Positions are those of the file's coordinate variables: cell centres for a grid of cells,
/// nodes for a grid that includes the poles. A grid whose columns cover 360 degrees
/// [wraps](Self::wraps_in_longitude): its last column is followed by its first.
#[derive(Clone)]
pub struct EquirectDem {
    pub(crate) source: String,
    pub(crate) variable: String,
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) lon_first: f64,
    pub(crate) lon_step: f64,
    pub(crate) lat_first: f64,
    pub(crate) lat_step: f64,
    pub(crate) wraps: bool,
    pub(crate) heights: Vec<f32>,
}

/// Summary statistics of a grid's valid samples, from [`EquirectDem::stats`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DemStats {
    /// The lowest valid height, in metres.
    pub min: f32,
    /// `(col, row)` of the first sample (row by row from the south-west) holding `min`.
    pub min_at: (usize, usize),
    /// The highest valid height, in metres.
    pub max: f32,
    /// `(col, row)` of the first sample (row by row from the south-west) holding `max`.
    pub max_at: (usize, usize),
    /// Number of valid samples.
    pub valid: usize,
    /// Number of missing samples.
    pub missing: usize,
}

impl std::fmt::Debug for EquirectDem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EquirectDem")
            .field("source", &self.source)
            .field("variable", &self.variable)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("lon_first", &self.lon_first)
            .field("lon_step", &self.lon_step)
            .field("lat_first", &self.lat_first)
            .field("lat_step", &self.lat_step)
            .field("wraps", &self.wraps)
            .finish_non_exhaustive()
    }
}

impl EquirectDem {
    /// Name of the file the grid was read from (its last path component; for
    /// [`from_netcdf_bytes`](Self::from_netcdf_bytes), the name given).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Name of the netCDF variable that was read.
    pub fn variable(&self) -> &str {
        &self.variable
    }

    /// Number of columns (longitudes).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of rows (latitudes).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Longitude of column 0, in degrees, in [-180, 180).
    pub fn lon_first(&self) -> f64 {
        self.lon_first
    }

    /// Degrees of longitude from one column to the next, > 0. Exactly `360 / width` when the grid
    /// wraps.
    pub fn lon_step(&self) -> f64 {
        self.lon_step
    }

    /// Latitude of row 0 (the southernmost), in degrees.
    pub fn lat_first(&self) -> f64 {
        self.lat_first
    }

    /// Degrees of latitude from one row to the next (northwards), > 0.
    pub fn lat_step(&self) -> f64 {
        self.lat_step
    }

    /// Longitude of column `col`, in degrees east: `lon_first + col * lon_step`, not reduced to
    /// [-180, 180) (so that it increases with `col`).
    pub fn lon(&self, col: usize) -> f64 {
        self.lon_first + col as f64 * self.lon_step
    }

    /// Latitude of row `row`, in degrees north: `lat_first + row * lat_step`.
    pub fn lat(&self, row: usize) -> f64 {
        self.lat_first + row as f64 * self.lat_step
    }

    /// Whether the columns span 360 degrees, so that the last column is followed by the first.
    pub fn wraps_in_longitude(&self) -> bool {
        self.wraps
    }

    /// The height at `(col, row)` in metres; `None` if it is missing or outside the grid.
    pub fn value(&self, col: usize, row: usize) -> Option<f32> {
        if col >= self.width || row >= self.height {
            return None;
        }
        let v = self.heights[row * self.width + col];
        (!v.is_nan()).then_some(v)
    }

    /// All heights in metres, row by row from the south (row 0) and west to east within a row:
    /// `(col, row)` is at `row * width + col`. `NaN` marks missing samples.
    pub fn heights(&self) -> &[f32] {
        &self.heights
    }

    /// Lowest and highest valid heights, where they are, and how many samples are missing.
    pub fn stats(&self) -> DemStats {
        let mut s = DemStats {
            min: f32::INFINITY,
            min_at: (0, 0),
            max: f32::NEG_INFINITY,
            max_at: (0, 0),
            valid: 0,
            missing: 0,
        };
        for (i, &v) in self.heights.iter().enumerate() {
            if v.is_nan() {
                s.missing += 1;
                continue;
            }
            s.valid += 1;
            let at = (i % self.width, i / self.width);
            if v < s.min {
                s.min = v;
                s.min_at = at;
            }
            if v > s.max {
                s.max = v;
                s.max_at = at;
            }
        }
        s
    }

    /// The height in metres at latitude `lat_deg` and longitude `lon_deg`, interpolated
    /// bilinearly between the four surrounding samples.
    ///
    /// - At a sample point it returns that sample's value exactly (samples whose weight is zero
    ///   are not consulted).
    /// - Any longitude is accepted (-170, 190 and 550 are the same place). When the grid
    ///   [wraps](Self::wraps_in_longitude), the last column is interpolated with the first, so
    ///   the result is continuous all the way round; otherwise a longitude outside the columns
    ///   gives `None`.
    /// - A latitude beyond the first or last row is clamped to that row (the grid's edge values
    ///   extend to the poles).
    /// - `None` if either input is not finite or a sample with nonzero weight is missing.
    pub fn sample_bilinear(&self, lat_deg: f64, lon_deg: f64) -> Option<f64> {
        if !lat_deg.is_finite() || !lon_deg.is_finite() {
            return None;
        }
        let (c0, c1, fx) = self.columns_around(lon_deg)?;
        let (r0, r1, fy) = self.rows_around(lat_deg);
        let at = |c: usize, r: usize| self.value(c, r).map(f64::from);
        let along_row = |r: usize| -> Option<f64> {
            let a = at(c0, r)?;
            if fx == 0.0 {
                return Some(a);
            }
            let b = at(c1, r)?;
            Some(a + fx * (b - a))
        };
        let south = along_row(r0)?;
        if fy == 0.0 {
            return Some(south);
        }
        let north = along_row(r1)?;
        Some(south + fy * (north - south))
    }

    /// The columns on either side of `lon` and the fraction of the way from the first to the
    /// second; `None` outside a grid that does not wrap.
    fn columns_around(&self, lon: f64) -> Option<(usize, usize, f64)> {
        let x = snap((lon - self.lon_first).rem_euclid(360.0) / self.lon_step);
        let last = self.width - 1;
        if self.wraps {
            // x is in [0, width], width only by rounding (the first column, one turn later).
            let x = if x >= self.width as f64 { 0.0 } else { x };
            let c0 = (x.floor() as usize).min(last);
            let fx = x - c0 as f64;
            Some((c0, (c0 + 1) % self.width, fx))
        } else if x > last as f64 {
            None
        } else {
            let c0 = (x.floor() as usize).min(last);
            let fx = x - c0 as f64;
            Some((c0, (c0 + 1).min(last), fx))
        }
    }

    /// The rows on either side of `lat` (clamped to the grid) and the fraction of the way from the
    /// first to the second.
    fn rows_around(&self, lat: f64) -> (usize, usize, f64) {
        let last = self.height - 1;
        let y = snap(((lat - self.lat_first) / self.lat_step).clamp(0.0, last as f64));
        let r0 = (y.floor() as usize).min(last);
        (r0, (r0 + 1).min(last), y - r0 as f64)
    }
}

/// `x`, or the nearest integer if it is within [`SNAP`] of it.
fn snap(x: f64) -> f64 {
    let r = x.round();
    if (x - r).abs() < SNAP {
        r
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 3 grid, columns at 0, 90, 180, 270 (wrapping) and rows at -45, 0, 45.
    fn grid(wraps: bool) -> EquirectDem {
        EquirectDem {
            source: "test".into(),
            variable: "z".into(),
            width: 4,
            height: 3,
            lon_first: 0.0,
            lon_step: 90.0,
            lat_first: -45.0,
            lat_step: 45.0,
            wraps,
            heights: vec![
                0.0,
                10.0,
                20.0,
                30.0, //
                100.0,
                110.0,
                120.0,
                130.0, //
                200.0,
                210.0,
                f32::NAN,
                230.0,
            ],
        }
    }

    #[test]
    fn exact_at_samples_and_linear_between() {
        let g = grid(true);
        assert_eq!(g.sample_bilinear(0.0, 90.0), Some(110.0));
        assert_eq!(g.sample_bilinear(-22.5, 45.0), Some(55.0));
        // The missing sample is consulted only where it has weight.
        assert_eq!(g.sample_bilinear(45.0, 90.0), Some(210.0));
        assert_eq!(g.sample_bilinear(45.0, 135.0), None);
        assert_eq!(g.sample_bilinear(22.5, 90.0), Some(160.0));
    }

    #[test]
    fn wraps_round_the_globe_or_stops_at_the_edge() {
        let g = grid(true);
        assert_eq!(g.sample_bilinear(-45.0, 315.0), Some(15.0));
        assert_eq!(g.sample_bilinear(-45.0, -45.0), Some(15.0));
        assert_eq!(g.sample_bilinear(-45.0, 675.0), Some(15.0));
        let g = grid(false);
        assert_eq!(g.sample_bilinear(-45.0, 315.0), None);
        assert_eq!(g.sample_bilinear(-45.0, 270.0), Some(30.0));
        assert_eq!(g.sample_bilinear(-45.0, -90.0), Some(30.0));
    }

    #[test]
    fn latitudes_clamp_and_non_finite_inputs_give_none() {
        let g = grid(true);
        assert_eq!(g.sample_bilinear(-90.0, 0.0), Some(0.0));
        assert_eq!(g.sample_bilinear(1e300, 270.0), Some(230.0));
        assert_eq!(g.sample_bilinear(f64::NAN, 0.0), None);
        assert_eq!(g.sample_bilinear(0.0, f64::INFINITY), None);
    }

    #[test]
    fn stats_skip_missing_values() {
        let s = grid(true).stats();
        assert_eq!((s.min, s.min_at, s.max, s.max_at), (0.0, (0, 0), 230.0, (3, 2)));
        assert_eq!((s.valid, s.missing), (11, 1));
    }
}
