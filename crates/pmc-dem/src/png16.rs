//! Reading elevation grids from 16-bit grayscale PNG files, whose extent the caller gives.

use crate::axis::{self, Regular, EVEN_TOLERANCE};
use crate::dem::EquirectDem;
use crate::error::DemError;
use crate::geotiff::looks_like;
use crate::read;
use std::path::Path;

/// Where a PNG's pixels lie and how its values become heights: PNG files carry neither.
///
/// Rows of the image run from `north` (its first row) to `south`, columns from `west` to `east`.
/// A height is `value * scale + offset` metres; pixels equal to `nodata` are missing.
///
/// With `cell_centres` the bounds are the outer edges of the pixels and each height lies at its
/// pixel's centre: `width` pixels of `(east - west) / width` degrees, the first centred half a
/// pixel east of `west`. Without, the bounds are the positions of the first and last columns and
/// rows (a grid of nodes): `(east - west) / (width - 1)` degrees apart, and a last column one
/// turn after the first is dropped. Either way, columns that span 360 degrees wrap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PngExtent {
    /// Western bound, degrees east.
    pub west: f64,
    /// Southern bound, degrees north, in [-90, 90).
    pub south: f64,
    /// Eastern bound, degrees east, greater than `west` and at most 360 degrees east of it.
    pub east: f64,
    /// Northern bound, degrees north, in (`south`, 90].
    pub north: f64,
    /// Metres per unit of pixel value; finite and nonzero.
    pub scale: f64,
    /// Metres of a pixel value of 0; finite.
    pub offset: f64,
    /// The pixel value that marks a missing height, if any.
    pub nodata: Option<u16>,
    /// Whether the bounds are the pixels' outer edges (true) or the positions of the outer
    /// columns and rows (false).
    pub cell_centres: bool,
}

impl PngExtent {
    /// Pixels covering the whole globe (-180 to 180, -90 to 90) with heights `value * scale +
    /// offset` and no missing value.
    pub fn global(scale: f64, offset: f64) -> PngExtent {
        PngExtent {
            west: -180.0,
            south: -90.0,
            east: 180.0,
            north: 90.0,
            scale,
            offset,
            nodata: None,
            cell_centres: true,
        }
    }

    /// The reason the extent is unusable, if it is.
    fn problem(&self) -> Option<String> {
        let named = [
            ("west", self.west),
            ("south", self.south),
            ("east", self.east),
            ("north", self.north),
            ("scale", self.scale),
            ("offset", self.offset),
        ];
        if let Some((name, v)) = named.iter().find(|(_, v)| !v.is_finite()) {
            return Some(format!("{name} is {v:?}, not a finite number"));
        }
        if self.scale == 0.0 {
            return Some("the scale is 0, which makes every height the offset".to_owned());
        }
        if self.west >= self.east {
            return Some(format!("west ({}) is not less than east ({})", self.west, self.east));
        }
        if self.east - self.west > 360.0 {
            return Some(format!(
                "west to east spans {} degrees, more than 360",
                self.east - self.west
            ));
        }
        if self.south >= self.north {
            return Some(format!(
                "south ({}) is not less than north ({})",
                self.south, self.north
            ));
        }
        if self.south < -90.0 || self.north > 90.0 {
            return Some(format!(
                "the latitudes {} to {} leave [-90, 90]",
                self.south, self.north
            ));
        }
        None
    }
}

impl EquirectDem {
    /// Reads the 16-bit grayscale PNG file at `path` as a grid of heights over `extent` (see
    /// [`PngExtent`]). [`variable`](Self::variable) is `gray`.
    ///
    /// Errors, each naming `path` as displayed: [`DemError::InvalidExtent`] (checked first),
    /// [`DemError::Io`], [`DemError::NotPng`], [`DemError::PngUnsupported`] (8-bit, colour, or
    /// with alpha: says what was found), [`DemError::PngCorrupt`], [`DemError::Truncated`],
    /// [`DemError::TooLarge`] (more than [`MAX_CELLS`](crate::MAX_CELLS) pixels, refused before
    /// decoding), [`DemError::AxisInvalid`] (one column or row of nodes), [`DemError::NoValidData`].
    pub fn read_png16(path: impl AsRef<Path>, extent: &PngExtent) -> Result<EquirectDem, DemError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        check_extent(&file, extent)?;
        let bytes = std::fs::read(path).map_err(|source| DemError::Io {
            file: file.clone(),
            source,
        })?;
        decode(&file, read::file_name(path), &bytes, extent)
    }

    /// As [`read_png16`](Self::read_png16), for a file held in memory; `name` stands for the file
    /// in error messages and in [`source`](Self::source).
    pub fn from_png16_bytes(name: &str, bytes: &[u8], extent: &PngExtent) -> Result<EquirectDem, DemError> {
        check_extent(name, extent)?;
        decode(name, name.to_owned(), bytes, extent)
    }
}

impl EquirectDem {
    /// A grid of heights held in memory: an array another program read (any GDAL format through
    /// rasterio, netCDF4 or Zarr through xarray), `width` columns by `height` rows, row by row
    /// from the **north** (the order of images and of most rasters) when `north_first`, else from
    /// the south. `extent` places it as it places a PNG's pixels (only its bounds and
    /// `cell_centres` are used: heights are in metres). Heights equal to `nodata`, and those that
    /// are not finite, are missing. `name` names the grid in errors and in the import's report.
    ///
    /// Errors: [`DemError::InvalidExtent`] (also when `heights` does not hold `width * height`
    /// values), [`DemError::AxisInvalid`] (one column or row of nodes), [`DemError::TooLarge`],
    /// [`DemError::NoValidData`].
    pub fn from_heights(
        name: &str,
        width: usize,
        height: usize,
        north_first: bool,
        heights: &[f32],
        extent: &PngExtent,
        nodata: Option<f32>,
    ) -> Result<EquirectDem, DemError> {
        check_extent(name, extent)?;
        if width == 0 || height == 0 || heights.len() as u64 != (width as u64).saturating_mul(height as u64) {
            return Err(DemError::InvalidExtent {
                file: name.to_owned(),
                detail: format!(
                    "the grid is {width} x {height} but holds {} heights; give a 2-D array of rows",
                    heights.len()
                ),
            });
        }
        let (lon, lat) = axes(name, width, height, extent, "array")?;
        let mut out = Vec::with_capacity(lon.width * height);
        for r in 0..height {
            let src = if north_first { height - 1 - r } else { r };
            let row = &heights[src * width..][..width];
            out.extend(row[..lon.width].iter().map(|&v| {
                if Some(v) == nodata || !v.is_finite() {
                    f32::NAN
                } else {
                    v
                }
            }));
        }
        if out.iter().all(|v| v.is_nan()) {
            return Err(DemError::NoValidData {
                file: name.to_owned(),
                variable: "heights".to_owned(),
            });
        }
        Ok(EquirectDem {
            source: name.to_owned(),
            variable: "heights".to_owned(),
            width: lon.width,
            height,
            lon_first: lon.first,
            lon_step: lon.step,
            lat_first: lat.first,
            lat_step: lat.step,
            wraps: lon.wraps,
            heights: out,
        })
    }
}

fn check_extent(file: &str, extent: &PngExtent) -> Result<(), DemError> {
    match extent.problem() {
        Some(detail) => Err(DemError::InvalidExtent {
            file: file.to_owned(),
            detail,
        }),
        None => Ok(()),
    }
}

fn png_error(file: &str, len: u64, e: png::DecodingError) -> DemError {
    let file = file.to_owned();
    match e {
        png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => DemError::Truncated {
            file,
            expected: len.saturating_add(1),
            actual: len,
        },
        png::DecodingError::IoError(source) => DemError::Io { file, source },
        e => DemError::PngCorrupt {
            file,
            detail: e.to_string(),
        },
    }
}

fn decode(file: &str, source: String, bytes: &[u8], extent: &PngExtent) -> Result<EquirectDem, DemError> {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    let len = bytes.len() as u64;
    if !bytes.starts_with(SIGNATURE) {
        if !bytes.is_empty() && SIGNATURE.starts_with(bytes) {
            return Err(DemError::Truncated {
                file: file.to_owned(),
                expected: 8,
                actual: len,
            });
        }
        let head = &bytes[..bytes.len().min(8)];
        return Err(DemError::NotPng {
            file: file.to_owned(),
            detail: if head.is_empty() {
                "the file is empty (0 bytes)".to_owned()
            } else {
                format!("{}; a PNG file starts with \"\\x89PNG\"", looks_like(head))
            },
        });
    }
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().map_err(|e| png_error(file, len, e))?;
    let info = reader.info();
    let (w, h) = (info.width as usize, info.height as usize);
    if (info.color_type, info.bit_depth) != (png::ColorType::Grayscale, png::BitDepth::Sixteen) {
        return Err(DemError::PngUnsupported {
            file: file.to_owned(),
            found: format!("{}-bit {:?}", info.bit_depth as u8, info.color_type),
        });
    }
    if w == 0 || h == 0 {
        return Err(DemError::PngCorrupt {
            file: file.to_owned(),
            detail: format!("the image is {w} x {h} pixels"),
        });
    }
    let (lon, lat) = axes(file, w, h, extent, "PNG")?;

    let mut raw = vec![0u8; w * h * 2];
    reader.next_frame(&mut raw).map_err(|e| png_error(file, len, e))?;
    let mut heights = Vec::with_capacity(lon.width * h);
    for r in 0..h {
        // Row r from the south is the image's row h - 1 - r.
        let row = &raw[(h - 1 - r) * w * 2..][..w * 2];
        for c in 0..lon.width {
            let v = u16::from_be_bytes([row[2 * c], row[2 * c + 1]]);
            let height = (f64::from(v) * extent.scale + extent.offset) as f32;
            heights.push(if Some(v) == extent.nodata || !height.is_finite() {
                f32::NAN
            } else {
                height
            });
        }
    }
    if heights.iter().all(|v| v.is_nan()) {
        return Err(DemError::NoValidData {
            file: file.to_owned(),
            variable: "gray".to_owned(),
        });
    }
    Ok(EquirectDem {
        source,
        variable: "gray".to_owned(),
        width: lon.width,
        height: h,
        lon_first: lon.first,
        lon_step: lon.step,
        lat_first: lat.first,
        lat_step: lat.step,
        wraps: lon.wraps,
        heights,
    })
}

/// The axes of a grid of `w` columns and `h` rows placed by `extent` (`what` names its columns
/// and rows in errors: "PNG", "array"), refused when it has more than
/// [`MAX_CELLS`](crate::MAX_CELLS) cells.
fn axes(
    file: &str,
    w: usize,
    h: usize,
    extent: &PngExtent,
    what: &str,
) -> Result<(axis::Longitudes, Regular), DemError> {
    read::check_cells(file, w as u64, h as u64)?;
    let lon_label = format!("longitude ({what} columns)");
    let lat_label = format!("latitude ({what} rows)");
    let lon = axis::longitudes(
        positions(file, &lon_label, extent.west, extent.east, w, extent.cell_centres)?,
        w,
    )
    .map_err(|p| read::axis_error(file, &lon_label, p))?;
    let lat = positions(file, &lat_label, extent.south, extent.north, h, extent.cell_centres)?;
    Ok((lon, lat))
}

/// The axis of `n` samples between bounds `lo` and `hi`: pixel centres or nodes.
fn positions(file: &str, label: &str, lo: f64, hi: f64, n: usize, cell_centres: bool) -> Result<Regular, DemError> {
    let (first, step) = if cell_centres {
        let step = (hi - lo) / n as f64;
        (lo + 0.5 * step, step)
    } else if n < 2 {
        return Err(read::axis_error(file, label, axis::AxisProblem::TooShort(n)));
    } else {
        (lo, (hi - lo) / (n - 1) as f64)
    };
    Ok(Regular {
        first,
        step,
        reversed: false,
        tolerance: EVEN_TOLERANCE * step + 4.0 * f64::EPSILON * lo.abs().max(hi.abs()),
    })
}
