//! Equirectangular grids read a band of rows at a time.

use crate::dem::EquirectDem;
use crate::error::DemError;

/// An equirectangular elevation grid that can be read a band of rows at a time, so that a grid
/// larger than memory can be reprojected piece by piece.
///
/// The layout is [`EquirectDem`]'s whatever the file's order: rows from the south (row 0) to the
/// north, columns from the west to the east, longitude of column `c` = `lon_first + c *
/// lon_step` with `lon_first` in [-180, 180), latitude of row `r` = `lat_first + r * lat_step`,
/// both steps positive, `NaN` for missing samples.
pub trait EquirectSource: Send + Sync {
    /// The file's name, for messages.
    fn name(&self) -> &str;
    /// Columns (longitudes).
    fn width(&self) -> usize;
    /// Rows (latitudes).
    fn height(&self) -> usize;
    /// Longitude of column 0, degrees, in [-180, 180).
    fn lon_first(&self) -> f64;
    /// Degrees between columns (positive).
    fn lon_step(&self) -> f64;
    /// Latitude of row 0 (the southernmost), degrees.
    fn lat_first(&self) -> f64;
    /// Degrees between rows (positive).
    fn lat_step(&self) -> f64;
    /// Whether the columns cover 360 degrees (the last column is followed by the first).
    fn wraps_in_longitude(&self) -> bool;
    /// Reads rows `row0 .. row0 + rows` into `out` (`rows * width` heights in metres, row by row,
    /// `NaN` where missing). Errors name the file; asking for rows past the grid is an error,
    /// never a panic.
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError>;
}

impl EquirectSource for EquirectDem {
    fn name(&self) -> &str {
        self.source()
    }
    fn width(&self) -> usize {
        EquirectDem::width(self)
    }
    fn height(&self) -> usize {
        EquirectDem::height(self)
    }
    fn lon_first(&self) -> f64 {
        EquirectDem::lon_first(self)
    }
    fn lon_step(&self) -> f64 {
        EquirectDem::lon_step(self)
    }
    fn lat_first(&self) -> f64 {
        EquirectDem::lat_first(self)
    }
    fn lat_step(&self) -> f64 {
        EquirectDem::lat_step(self)
    }
    fn wraps_in_longitude(&self) -> bool {
        EquirectDem::wraps_in_longitude(self)
    }
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError> {
        let w = self.width;
        check_request(&self.source, w, self.height, row0, rows, out.len())?;
        out.copy_from_slice(&self.heights[row0 * w..(row0 + rows) * w]);
        Ok(())
    }
}

/// Refuses a request for rows past the grid or a buffer of the wrong size.
pub(crate) fn check_request(
    file: &str,
    width: usize,
    height: usize,
    row0: usize,
    rows: usize,
    out_len: usize,
) -> Result<(), DemError> {
    if row0.checked_add(rows).is_none_or(|end| end > height) {
        return Err(DemError::OutOfGrid {
            file: file.to_owned(),
            detail: format!(
                "rows {row0}..{} asked of a grid of {height} rows",
                row0.saturating_add(rows)
            ),
        });
    }
    if rows.checked_mul(width) != Some(out_len) {
        return Err(DemError::OutOfGrid {
            file: file.to_owned(),
            detail: format!("a buffer of {out_len} heights given for {rows} rows of {width}"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_of_an_in_memory_grid() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
        let dem = EquirectDem::read_netcdf(&path, None).unwrap();
        let src: &dyn EquirectSource = &dem;
        let mut band = vec![0.0f32; 2 * 360];
        src.read_rows(10, 2, &mut band).unwrap();
        assert_eq!(band[360 + 5], dem.value(5, 11).unwrap());
        assert!(src.read_rows(179, 2, &mut band).is_err());
        assert!(src.read_rows(usize::MAX, 2, &mut band).is_err());
        assert!(src.read_rows(0, 1, &mut band).is_err());
    }
}
