//! A netCDF classic grid read a band of rows at a time, straight from the file.

use crate::axis::Regular;
use crate::error::DemError;
use crate::header::HeaderInfo;
use crate::read::{self, Layout, Prepared, Values};
use crate::source::check_request;
use crate::source::EquirectSource;
use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::{Arc, Mutex};

/// What the source reads from: a file, or bytes in memory.
trait Input: Read + Seek + Send {}
impl<T: Read + Seek + Send> Input for T {}

/// The grid of a netCDF classic (CDF-1) or 64-bit offset (CDF-2) file, read a band of rows at a
/// time with seeks, so that a grid larger than memory can be imported piece by piece.
///
/// Opening reads the header and the coordinate variables only; [`read_rows`](EquirectSource::read_rows)
/// reads just the values of the rows asked for. The grid variable is chosen, its axes normalised
/// and its values unpacked exactly as by [`EquirectDem::read_netcdf`](crate::EquirectDem::read_netcdf)
/// (rows from the south, a longitude column repeated one turn later dropped, `scale_factor`,
/// `add_offset`, fill and missing values), and the rows read are bit for bit those of the grid
/// that function returns. Unlike it, opening does not refuse a grid whose values are all missing
/// (that would need reading them all).
///
/// A file whose latitude is the outer dimension (the usual `z(lat, lon)`) is read with one seek
/// per row; one whose longitude is the outer dimension with one seek per file column and band.
///
/// ```
/// use pmc_dem::{EquirectSource, NetcdfSource};
///
/// let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
/// let src = NetcdfSource::open(&path, None)?;
/// assert_eq!((src.width(), src.height()), (360, 180));
/// let mut band = vec![0.0f32; 10 * src.width()];
/// src.read_rows(85, 10, &mut band)?; // ten rows about the equator
/// # Ok::<(), pmc_dem::DemError>(())
/// ```
pub struct NetcdfSource {
    file: String,
    source: String,
    variable: String,
    layout: Layout,
    values: Values,
    lat: Regular,
    /// Offset of the grid variable's first value.
    begin: u64,
    /// Bytes from one outer index to the next: a record, or a whole inner row.
    outer_stride: u64,
    input: Mutex<Box<dyn Input>>,
}

impl std::fmt::Debug for NetcdfSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NetcdfSource")
            .field("file", &self.file)
            .field("variable", &self.variable)
            .field("width", &self.width())
            .field("height", &self.height())
            .finish_non_exhaustive()
    }
}

impl NetcdfSource {
    /// Opens the netCDF classic file at `path` and reads its header and axes; `variable` as for
    /// [`EquirectDem::read_netcdf`](crate::EquirectDem::read_netcdf).
    ///
    /// Errors: as [`EquirectDem::read_netcdf`](crate::EquirectDem::read_netcdf), but for
    /// [`DemError::NoValidData`]; each names `path` as displayed.
    pub fn open(path: impl AsRef<Path>, variable: Option<&str>) -> Result<NetcdfSource, DemError> {
        let checked = read::open_checked(path.as_ref())?;
        let file = checked.file.clone();
        let second = checked.input.try_clone().map_err(|source| DemError::Io {
            file: file.clone(),
            source,
        })?;
        NetcdfSource::build(
            checked.file,
            checked.source,
            checked.input,
            Box::new(second),
            checked.len,
            &checked.info,
            variable,
        )
    }

    /// As [`open`](Self::open), for a file held in memory; `name` stands for the file in error
    /// messages and in [`name`](EquirectSource::name).
    pub fn from_bytes(name: &str, bytes: Vec<u8>, variable: Option<&str>) -> Result<NetcdfSource, DemError> {
        let info = read::check_bytes(name, &bytes)?;
        let len = bytes.len() as u64;
        let shared: Arc<[u8]> = bytes.into();
        NetcdfSource::build(
            name.to_owned(),
            name.to_owned(),
            Cursor::new(Arc::clone(&shared)),
            Box::new(Cursor::new(shared)),
            len,
            &info,
            variable,
        )
    }

    fn build<R: Read + Seek + 'static>(
        file: String,
        source: String,
        header_input: R,
        input: Box<dyn Input>,
        len: u64,
        info: &HeaderInfo,
        variable: Option<&str>,
    ) -> Result<NetcdfSource, DemError> {
        let Prepared {
            reader,
            variable,
            layout,
            values,
            lat,
        } = read::prepare(&file, header_input, len, info, variable)?;
        drop(reader);
        let extent = info.var(&variable).ok_or_else(|| DemError::Corrupt {
            file: file.clone(),
            detail: format!("variable {variable:?} is not where the header check found it"),
        })?;
        let inner = if layout.lon_first_dim {
            layout.lat_in
        } else {
            layout.lon_in
        };
        let outer_stride = if extent.is_record {
            info.record_size
        } else {
            (inner as u64).saturating_mul(values.size() as u64)
        };
        Ok(NetcdfSource {
            file,
            source,
            variable,
            layout,
            values,
            lat,
            begin: extent.begin,
            outer_stride,
            input: Mutex::new(input),
        })
    }

    /// Name of the netCDF variable read.
    pub fn variable(&self) -> &str {
        &self.variable
    }

    /// Reads `count` values of the variable from `(outer, inner0)` on (contiguous in the file)
    /// into `buf`.
    fn read_run(
        &self,
        input: &mut dyn Input,
        outer: usize,
        inner0: usize,
        count: usize,
        buf: &mut Vec<u8>,
    ) -> Result<(), DemError> {
        let size = self.values.size();
        let at = (outer as u64)
            .checked_mul(self.outer_stride)
            .and_then(|o| o.checked_add((inner0 as u64).checked_mul(size as u64)?))
            .and_then(|o| o.checked_add(self.begin));
        let io = |source: std::io::Error| DemError::Io {
            file: self.file.clone(),
            source,
        };
        let at = at.ok_or_else(|| DemError::Corrupt {
            file: self.file.clone(),
            detail: "a value's offset exceeds 2^64 bytes".to_owned(),
        })?;
        buf.resize(count * size, 0);
        input.seek(SeekFrom::Start(at)).map_err(io)?;
        input.read_exact(buf).map_err(io)
    }
}

impl EquirectSource for NetcdfSource {
    fn name(&self) -> &str {
        &self.source
    }
    fn width(&self) -> usize {
        self.layout.lon.width
    }
    fn height(&self) -> usize {
        self.layout.lat_in
    }
    fn lon_first(&self) -> f64 {
        self.layout.lon.first
    }
    fn lon_step(&self) -> f64 {
        self.layout.lon.step
    }
    fn lat_first(&self) -> f64 {
        self.lat.first
    }
    fn lat_step(&self) -> f64 {
        self.lat.step
    }
    fn wraps_in_longitude(&self) -> bool {
        self.layout.lon.wraps
    }
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError> {
        let (w, h) = (self.width(), self.height());
        check_request(&self.file, w, h, row0, rows, out.len())?;
        if rows == 0 {
            return Ok(());
        }
        let mut guard = self.input.lock().unwrap_or_else(|e| e.into_inner());
        let input: &mut dyn Input = &mut **guard;
        let size = self.values.size();
        let mut buf = Vec::new();
        let l = &self.layout;
        if !l.lon_first_dim {
            // One run per row: the file's row of longitudes.
            for (r, out_row) in out.chunks_exact_mut(w).enumerate() {
                self.read_run(input, l.file_lat(row0 + r), 0, l.lon_in, &mut buf)?;
                for (col, o) in out_row.iter_mut().enumerate() {
                    let i = l.file_lon(col) * size;
                    *o = self.values.height_of_be_bytes(&buf[i..i + size]);
                }
            }
        } else {
            // One run per file column: the latitudes of the band, contiguous in the file.
            let (a, b) = (l.file_lat(row0), l.file_lat(row0 + rows - 1));
            let lat_lo = a.min(b);
            for col in 0..w {
                self.read_run(input, l.file_lon(col), lat_lo, rows, &mut buf)?;
                for r in 0..rows {
                    let i = (l.file_lat(row0 + r) - lat_lo) * size;
                    out[r * w + col] = self.values.height_of_be_bytes(&buf[i..i + size]);
                }
            }
        }
        Ok(())
    }
}
