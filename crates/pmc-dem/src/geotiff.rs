//! Reading elevation grids from GeoTIFF files, whole or a band of rows at a time.

use crate::axis::{self, Regular, EVEN_TOLERANCE};
use crate::dem::EquirectDem;
use crate::error::DemError;
use crate::read::{self, Layout};
use crate::source::check_request;
use crate::source::EquirectSource;
use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::{Arc, Mutex};
use tiff::decoder::{ChunkType, Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};

/// The most heights one row of strips or tiles may hold once decoded (2^28: 1 GiB of `f32`);
/// a [`GeoTiffSource`] keeps one such row in memory.
pub const MAX_CHUNK_ROW_CELLS: u64 = 1 << 28;

/// GeoKey ids (GeoTIFF 1.0, section 6.2).
const GT_MODEL_TYPE: u16 = 1024;
const GT_RASTER_TYPE: u16 = 1025;
const GEOGRAPHIC_TYPE: u16 = 2048;
const GEOG_ANGULAR_UNITS: u16 = 2054;
const PROJECTED_CS_TYPE: u16 = 3072;
/// GTModelTypeGeoKey values.
const MODEL_PROJECTED: u16 = 1;
const MODEL_GEOGRAPHIC: u16 = 2;
const MODEL_GEOCENTRIC: u16 = 3;
/// GTRasterTypeGeoKey value for pixels that are points (nodes) rather than areas.
const RASTER_PIXEL_IS_POINT: u16 = 2;
/// EPSG angular units accepted: degree, degree (supplier to define).
const DEGREE_UNITS: [u16; 2] = [9102, 9122];

/// What a source reads from: a file, or bytes in memory.
trait Input: Read + Seek + Send {}
impl<T: Read + Seek + Send> Input for T {}

/// The decoder and the last row of strips or tiles it decoded.
struct State {
    decoder: Decoder<Box<dyn Input>>,
    /// Index of the cached row of chunks, and its heights (TIFF order, `NaN` where missing).
    cached: Option<(usize, Vec<f32>)>,
}

/// The single-band elevation grid of a GeoTIFF file, read a band of rows at a time: only the
/// strips or tiles holding the rows asked for are decoded, and one row of them is kept, so that
/// a grid larger than memory can be imported piece by piece.
///
/// What is read:
/// - strips or tiles, uncompressed or compressed with deflate, LZW or PackBits (with or without
///   the horizontal predictor), of one band of 8-, 16-, 32- or 64-bit integers (signed or not)
///   or 32- or 64-bit floats; classic TIFF or BigTIFF;
/// - the extent from ModelPixelScale (33550) with ModelTiepoint (33922), or from a
///   ModelTransformation (34264) without rotation;
/// - the GeoKeyDirectory (34735), which must describe a geographic model (GTModelTypeGeoKey 2,
///   or a GeographicTypeGeoKey without a projected system) in degrees: projected and geocentric
///   systems are refused with [`DemError::NotGeographic`];
/// - GTRasterTypeGeoKey: with PixelIsArea (the default) the tie point is the outer corner of its
///   pixel and each height is taken at its pixel's centre, so a global grid of 1-degree pixels
///   from -180 has its first column at -179.5; with PixelIsPoint the tie point is the pixel's
///   own position (a grid of nodes, whose first column may be at -180 and whose last column may
///   repeat it at 180: that repeated column is dropped);
/// - GDAL_NODATA (42113, text) as the fill value: samples equal to it, and float samples that
///   are not finite numbers, are missing (`NaN`). Scale and offset held in GDAL's metadata are
///   not applied.
///
/// The grid is normalised to [`EquirectDem`]'s layout: rows from the south (a TIFF runs from the
/// north), columns from the west, the first longitude in [-180, 180), and a grid spanning 360
/// degrees of longitude [wraps](EquirectSource::wraps_in_longitude).
pub struct GeoTiffSource {
    file: String,
    source: String,
    layout: Layout,
    lat: Regular,
    /// Rows of the TIFF in one row of chunks (rows per strip, or the tile height).
    chunk_rows: usize,
    /// Columns of one tile; the width for strips.
    chunk_cols: usize,
    tiled: bool,
    nodata: Option<f64>,
    /// The file's length in bytes.
    len: u64,
    state: Mutex<State>,
}

impl std::fmt::Debug for GeoTiffSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GeoTiffSource")
            .field("file", &self.file)
            .field("width", &self.width())
            .field("height", &self.height())
            .field("lon_first", &self.lon_first())
            .field("lat_first", &self.lat_first())
            .field("tiled", &self.tiled)
            .field("nodata", &self.nodata)
            .finish_non_exhaustive()
    }
}

impl GeoTiffSource {
    /// Opens the GeoTIFF file at `path` and reads its directory and georeferencing; no heights
    /// are decoded until [`read_rows`](EquirectSource::read_rows).
    ///
    /// Errors, each naming `path` as displayed: [`DemError::Io`], [`DemError::NotTiff`],
    /// [`DemError::Truncated`] (strips or tiles past the end of the file),
    /// [`DemError::TiffCorrupt`], [`DemError::TiffUnsupported`], [`DemError::NoGeoreference`],
    /// [`DemError::NotGeographic`], the axis errors ([`DemError::AxisInvalid`],
    /// [`DemError::LatitudeOutOfRange`]).
    pub fn open(path: impl AsRef<Path>) -> Result<GeoTiffSource, DemError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let io = |source: std::io::Error| DemError::Io {
            file: file.clone(),
            source,
        };
        let input = std::fs::File::open(path).map_err(io)?;
        let len = input.metadata().map_err(io)?.len();
        let input = std::io::BufReader::new(input);
        GeoTiffSource::build(file.clone(), read::file_name(path), Box::new(input), len)
    }

    /// As [`open`](Self::open), for a file held in memory; `name` stands for the file in error
    /// messages and in [`name`](EquirectSource::name).
    pub fn from_bytes(name: &str, bytes: Vec<u8>) -> Result<GeoTiffSource, DemError> {
        let len = bytes.len() as u64;
        let shared: Arc<[u8]> = bytes.into();
        GeoTiffSource::build(name.to_owned(), name.to_owned(), Box::new(Cursor::new(shared)), len)
    }

    fn build(file: String, source: String, mut input: Box<dyn Input>, len: u64) -> Result<GeoTiffSource, DemError> {
        sniff(&file, &mut input, len)?;
        let limits = {
            let mut l = Limits::default();
            l.ifd_value_size = 16 << 20;
            l
        };
        let mut decoder = Decoder::new(input)
            .map_err(|e| tiff_error(&file, len, e))?
            .with_limits(limits);
        let err = |e| tiff_error(&file, len, e);
        let (w, h) = decoder.dimensions().map_err(err)?;
        if w == 0 || h == 0 {
            return Err(DemError::TiffCorrupt {
                file,
                detail: format!("the image is {w} x {h} pixels"),
            });
        }
        match decoder.colortype().map_err(err)? {
            ColorType::Gray(8 | 16 | 32 | 64) => {}
            other => {
                return Err(DemError::TiffUnsupported {
                    file,
                    detail: format!("its pixels are {other:?}, not a single band of 8 to 64 bits"),
                })
            }
        }
        let tiled = decoder.get_chunk_type() == ChunkType::Tile;
        let (cw, ch) = decoder.chunk_dimensions();
        let chunk_rows = ch.min(h) as usize;
        let chunk_cols = if tiled { cw as usize } else { w as usize };
        if (chunk_rows as u64).saturating_mul(u64::from(w)) > MAX_CHUNK_ROW_CELLS {
            return Err(DemError::TiffUnsupported {
                file,
                detail: format!(
                    "a row of its {} holds {chunk_rows} rows of {w} pixels, more than the {MAX_CHUNK_ROW_CELLS} this reader decodes at once",
                    if tiled { "tiles" } else { "strips" }
                ),
            });
        }
        check_chunks_in_file(&file, &mut decoder, tiled, len)?;
        let geo = Georeference::read(&file, &mut decoder, len)?;
        let nodata = nodata(&file, &mut decoder, len)?;

        // Position of pixel (i, j)'s sample: its centre for areas, itself for points.
        let half = if geo.pixel_is_point { 0.0 } else { 0.5 };
        let (w_in, h_in) = (w as usize, h as usize);
        let lon_axis = regular_axis(geo.x0 + geo.x_scale * half, geo.x_scale, w_in);
        let lon =
            axis::longitudes(lon_axis, w_in).map_err(|p| read::axis_error(&file, "longitude (GeoTIFF columns)", p))?;
        let lat_axis = regular_axis(geo.y0 + geo.y_scale * half, geo.y_scale, h_in);
        let lat = axis::latitudes(lat_axis, h_in).map_err(|p| read::axis_error(&file, "latitude (GeoTIFF rows)", p))?;
        if !geo.pixel_is_point {
            // Areas: their outer edges, not only their centres, must lie on the globe.
            let span = w_in as f64 * lon_axis.step;
            if span > 360.0 + lon_axis.tolerance {
                return Err(read::axis_error(
                    &file,
                    "longitude (GeoTIFF columns)",
                    axis::AxisProblem::SpansMoreThanATurn { span },
                ));
            }
            for edge in [lat.first - 0.5 * lat.step, lat.first + (h_in as f64 - 0.5) * lat.step] {
                if edge.abs() > 90.0 + lat.tolerance {
                    return Err(read::axis_error(
                        &file,
                        "latitude (GeoTIFF rows)",
                        axis::AxisProblem::LatitudeOutOfRange { value: edge },
                    ));
                }
            }
        }
        Ok(GeoTiffSource {
            file,
            source,
            layout: Layout {
                lon_first_dim: false,
                lon_in: w_in,
                lat_in: h_in,
                lon,
                lat_reversed: lat.reversed,
            },
            lat,
            chunk_rows,
            chunk_cols,
            tiled,
            nodata,
            len,
            state: Mutex::new(State { decoder, cached: None }),
        })
    }

    /// Whether the file stores tiles (rather than strips).
    pub fn is_tiled(&self) -> bool {
        self.tiled
    }

    /// The fill value read from GDAL_NODATA, if any.
    pub fn nodata(&self) -> Option<f64> {
        self.nodata
    }

    /// Decodes row `k` of chunks (TIFF rows `k * chunk_rows ..`) into heights, TIFF order.
    fn decode_chunk_row(&self, decoder: &mut Decoder<Box<dyn Input>>, k: usize) -> Result<Vec<f32>, DemError> {
        let (w, h) = (self.layout.lon_in, self.layout.lat_in);
        let top = k * self.chunk_rows;
        let rows = self.chunk_rows.min(h - top);
        let mut out = vec![f32::NAN; rows * w];
        let across = w.div_ceil(self.chunk_cols);
        for t in 0..across {
            let index = if self.tiled { k * across + t } else { k };
            let col0 = t * self.chunk_cols;
            let cols = self.chunk_cols.min(w - col0);
            let index = u32::try_from(index).map_err(|_| DemError::TiffCorrupt {
                file: self.file.clone(),
                detail: format!("chunk {index} is past the 2^32 a TIFF can index"),
            })?;
            let chunk = decoder
                .read_chunk(index)
                .map_err(|e| tiff_error(&self.file, self.len, e))?;
            let values = heights(chunk, self.nodata);
            if values.len() != rows * cols {
                return Err(DemError::TiffCorrupt {
                    file: self.file.clone(),
                    detail: format!(
                        "chunk {index} decodes to {} values where {cols} x {rows} are expected",
                        values.len()
                    ),
                });
            }
            for (r, src) in values.chunks_exact(cols).enumerate() {
                out[r * w + col0..r * w + col0 + cols].copy_from_slice(src);
            }
        }
        Ok(out)
    }
}

impl EquirectSource for GeoTiffSource {
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
        let w = self.width();
        check_request(&self.file, w, self.height(), row0, rows, out.len())?;
        let mut guard = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let state = &mut *guard;
        let w_in = self.layout.lon_in;
        for (r, out_row) in out.chunks_exact_mut(w).enumerate() {
            let tiff_row = self.layout.file_lat(row0 + r);
            let k = tiff_row / self.chunk_rows;
            if state.cached.as_ref().is_none_or(|c| c.0 != k) {
                state.cached = None;
                let decoded = self.decode_chunk_row(&mut state.decoder, k)?;
                state.cached = Some((k, decoded));
            }
            let Some((_, chunk)) = &state.cached else {
                unreachable!("a row of chunks was just decoded");
            };
            let src = &chunk[(tiff_row - k * self.chunk_rows) * w_in..][..w_in];
            for (col, o) in out_row.iter_mut().enumerate() {
                *o = src[self.layout.file_lon(col)];
            }
        }
        Ok(())
    }
}

impl EquirectDem {
    /// Reads the whole single-band grid of the GeoTIFF file at `path`; see [`GeoTiffSource`]
    /// for what is read and how it is normalised. [`variable`](Self::variable) is `band 1`.
    ///
    /// Errors: those of [`GeoTiffSource::open`], [`DemError::TooLarge`] for a grid of more than
    /// [`MAX_CELLS`](crate::MAX_CELLS) cells (refused before the heights are allocated) and
    /// [`DemError::NoValidData`] when every sample is missing; each names `path` as displayed.
    pub fn read_geotiff(path: impl AsRef<Path>) -> Result<EquirectDem, DemError> {
        let src = GeoTiffSource::open(path)?;
        EquirectDem::from_source(&src, &src.file, "band 1")
    }

    /// As [`read_geotiff`](Self::read_geotiff), for a file held in memory; `name` stands for the
    /// file in error messages and in [`source`](Self::source).
    pub fn from_geotiff_bytes(name: &str, bytes: Vec<u8>) -> Result<EquirectDem, DemError> {
        EquirectDem::from_source(&GeoTiffSource::from_bytes(name, bytes)?, name, "band 1")
    }

    /// Reads every row of `src` (whose errors name `file`) into memory, refusing more than
    /// [`MAX_CELLS`](crate::MAX_CELLS) cells before allocating and a grid without a valid
    /// sample after reading.
    pub(crate) fn from_source(src: &dyn EquirectSource, file: &str, variable: &str) -> Result<EquirectDem, DemError> {
        let (w, h) = (src.width(), src.height());
        read::check_cells(file, w as u64, h as u64)?;
        let mut heights = vec![0.0f32; w * h];
        src.read_rows(0, h, &mut heights)?;
        if heights.iter().all(|v| v.is_nan()) {
            return Err(DemError::NoValidData {
                file: file.to_owned(),
                variable: variable.to_owned(),
            });
        }
        Ok(EquirectDem {
            source: src.name().to_owned(),
            variable: variable.to_owned(),
            width: w,
            height: h,
            lon_first: src.lon_first(),
            lon_step: src.lon_step(),
            lat_first: src.lat_first(),
            lat_step: src.lat_step(),
            wraps: src.wraps_in_longitude(),
            heights,
        })
    }
}

/// An evenly spaced axis of `n` values `first + i * step` (`step` of either sign), in increasing
/// order, with the tolerance of values computed in `f64`.
fn regular_axis(first: f64, step: f64, n: usize) -> Regular {
    let last = first + step * (n as f64 - 1.0);
    let tolerance = EVEN_TOLERANCE * step.abs() + 4.0 * f64::EPSILON * first.abs().max(last.abs());
    if step > 0.0 {
        Regular {
            first,
            step,
            reversed: false,
            tolerance,
        }
    } else {
        Regular {
            first: last,
            step: -step,
            reversed: true,
            tolerance,
        }
    }
}

/// Refuses what is not a TIFF file by its first bytes, saying what it looks like instead.
fn sniff(file: &str, input: &mut Box<dyn Input>, len: u64) -> Result<(), DemError> {
    let io = |source: std::io::Error| DemError::Io {
        file: file.to_owned(),
        source,
    };
    let mut head = [0u8; 8];
    let n = (len.min(8)) as usize;
    input.seek(SeekFrom::Start(0)).map_err(io)?;
    input.read_exact(&mut head[..n]).map_err(io)?;
    input.seek(SeekFrom::Start(0)).map_err(io)?;
    let head = &head[..n];
    const SIGNATURES: [&[u8]; 4] = [b"II*\0", b"MM\0*", b"II+\0", b"MM\0+"];
    if SIGNATURES.iter().any(|s| head.starts_with(s)) && n == 8 {
        return Ok(());
    }
    if n == 0 {
        return Err(DemError::NotTiff {
            file: file.to_owned(),
            detail: "the file is empty (0 bytes)".to_owned(),
        });
    }
    if SIGNATURES
        .iter()
        .any(|s| s.starts_with(&head[..n.min(4)]) || head.starts_with(s))
    {
        return Err(DemError::Truncated {
            file: file.to_owned(),
            expected: 8,
            actual: len,
        });
    }
    Err(DemError::NotTiff {
        file: file.to_owned(),
        detail: format!("{}; a TIFF file starts with \"II*\\0\" or \"MM\\0*\"", looks_like(head)),
    })
}

/// What a file starting with `head` appears to be.
pub(crate) fn looks_like(head: &[u8]) -> String {
    if head.starts_with(b"CDF\x01") || head.starts_with(b"CDF\x02") {
        "it is a netCDF classic file: read it with EquirectDem::read_netcdf".to_owned()
    } else if head.starts_with(b"\x89HDF") {
        "it is an HDF5 (netCDF-4) file".to_owned()
    } else if head.starts_with(b"\x89PNG") {
        "it is a PNG file: read it with EquirectDem::read_png16".to_owned()
    } else if head.starts_with(b"II*\0") || head.starts_with(b"MM\0*") {
        "it is a TIFF file: read it with EquirectDem::read_geotiff".to_owned()
    } else {
        format!("it starts with \"{}\"", head.escape_ascii())
    }
}

/// The error for a failure reported by the `tiff` crate; `len` is the file's length when known.
fn tiff_error(file: &str, len: u64, e: TiffError) -> DemError {
    let file = file.to_owned();
    match e {
        // The directory, or a value it points to, runs past the end of the file.
        TiffError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => DemError::Truncated {
            file,
            expected: len.saturating_add(1),
            actual: len,
        },
        TiffError::IoError(source) => DemError::Io { file, source },
        TiffError::UnsupportedError(e) => DemError::TiffUnsupported {
            file,
            detail: e.to_string(),
        },
        TiffError::LimitsExceeded => DemError::TiffUnsupported {
            file,
            detail: "a strip, tile or tag is larger than this reader decodes at once".to_owned(),
        },
        e => DemError::TiffCorrupt {
            file,
            detail: e.to_string(),
        },
    }
}

/// Refuses strips or tiles that lie past the end of the file, before any is decoded.
fn check_chunks_in_file(
    file: &str,
    decoder: &mut Decoder<Box<dyn Input>>,
    tiled: bool,
    len: u64,
) -> Result<(), DemError> {
    let (offsets, counts) = if tiled {
        (Tag::TileOffsets, Tag::TileByteCounts)
    } else {
        (Tag::StripOffsets, Tag::StripByteCounts)
    };
    let offsets = decoder.get_tag_u64_vec(offsets).map_err(|e| tiff_error(file, len, e))?;
    let counts = decoder.get_tag_u64_vec(counts).map_err(|e| tiff_error(file, len, e))?;
    let end = offsets
        .iter()
        .zip(&counts)
        .map(|(&o, &c)| o.saturating_add(c))
        .max()
        .unwrap_or(0);
    if end > len {
        return Err(DemError::Truncated {
            file: file.to_owned(),
            expected: end,
            actual: len,
        });
    }
    Ok(())
}

/// The GDAL_NODATA fill value, if the tag is present.
fn nodata(file: &str, decoder: &mut Decoder<Box<dyn Input>>, len: u64) -> Result<Option<f64>, DemError> {
    let Some(value) = decoder
        .find_tag(Tag::GdalNodata)
        .map_err(|e| tiff_error(file, len, e))?
    else {
        return Ok(None);
    };
    let text = value.into_string().map_err(|e| tiff_error(file, len, e))?;
    let text = text.trim_matches(|c: char| c == '\0' || c.is_whitespace());
    text.parse::<f64>().map(Some).map_err(|_| DemError::TiffCorrupt {
        file: file.to_owned(),
        detail: format!("its GDAL_NODATA tag holds {text:?}, not a number"),
    })
}

/// Heights from decoded samples; `nodata` and non-finite values become `NaN`.
fn heights(chunk: DecodingResult, nodata: Option<f64>) -> Vec<f32> {
    fn ints<T: Copy + Into<f64>>(v: Vec<T>, nodata: Option<f64>) -> Vec<f32> {
        v.into_iter()
            .map(|x| {
                let x: f64 = x.into();
                if Some(x) == nodata {
                    f32::NAN
                } else {
                    x as f32
                }
            })
            .collect()
    }
    let float = |x: f64| -> f32 {
        if !x.is_finite() || Some(x) == nodata {
            f32::NAN
        } else {
            x as f32
        }
    };
    match chunk {
        DecodingResult::U8(v) => ints(v, nodata),
        DecodingResult::I8(v) => ints(v, nodata),
        DecodingResult::U16(v) => ints(v, nodata),
        DecodingResult::I16(v) => ints(v, nodata),
        DecodingResult::U32(v) => ints(v, nodata),
        DecodingResult::I32(v) => ints(v, nodata),
        DecodingResult::U64(v) => v.into_iter().map(|x| float(x as f64)).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| float(x as f64)).collect(),
        DecodingResult::F16(v) => v.into_iter().map(|x| float(f64::from(x))).collect(),
        DecodingResult::F32(v) => {
            // Compared as stored: GDAL writes the nodata of a float32 grid as its f32 value.
            let nd = nodata.map(|n| n as f32);
            v.into_iter()
                .map(|x| if !x.is_finite() || Some(x) == nd { f32::NAN } else { x })
                .collect()
        }
        DecodingResult::F64(v) => v.into_iter().map(float).collect(),
    }
}

/// Where the pixels of a GeoTIFF lie: longitude of raster x coordinate `i` is
/// `x0 + x_scale * i`, latitude of raster y coordinate `j` is `y0 + y_scale * j` (raster
/// coordinates: 0 at the outer corner of the first pixel for PixelIsArea, at its centre for
/// PixelIsPoint). Read by [`GeoTiffSource`] and by other readers of georeferenced TIFF files
/// (colour imagery), so that both accept the same tags.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Georeference {
    /// Longitude of raster x coordinate 0, degrees.
    pub x0: f64,
    /// Degrees of longitude per pixel (finite, nonzero; negative when columns run west).
    pub x_scale: f64,
    /// Latitude of raster y coordinate 0, degrees.
    pub y0: f64,
    /// Degrees of latitude per pixel (finite, nonzero; negative when rows run south, as usual).
    pub y_scale: f64,
    /// Whether pixels are points (GTRasterTypeGeoKey 2) rather than areas.
    pub pixel_is_point: bool,
}

impl Georeference {
    /// Reads the georeferencing tags of the TIFF that `decoder` reads (see [`GeoTiffSource`] for
    /// those accepted); `file` names it in errors and `len` is its length in bytes.
    ///
    /// Errors: [`DemError::NoGeoreference`], [`DemError::NotGeographic`], and the TIFF errors
    /// ([`DemError::TiffCorrupt`], [`DemError::Truncated`], ...) of reading the tags.
    pub fn read<R: Read + Seek>(file: &str, decoder: &mut Decoder<R>, len: u64) -> Result<Georeference, DemError> {
        let no_geo = |detail: String| DemError::NoGeoreference {
            file: file.to_owned(),
            detail,
        };
        let mut f64s = |tag: Tag| -> Result<Option<Vec<f64>>, DemError> {
            match decoder.find_tag(tag).map_err(|e| tiff_error(file, len, e))? {
                None => Ok(None),
                Some(v) => v
                    .into_f64_vec()
                    .map(Some)
                    .map_err(|_| no_geo(format!("its {tag:?} does not hold numbers"))),
            }
        };
        let scale = f64s(Tag::ModelPixelScaleTag)?;
        let tiepoints = f64s(Tag::ModelTiepointTag)?;
        let transform = f64s(Tag::ModelTransformationTag)?;
        let keys = match decoder
            .find_tag(Tag::GeoKeyDirectoryTag)
            .map_err(|e| tiff_error(file, len, e))?
        {
            None => None,
            Some(v) => Some(
                v.into_u16_vec()
                    .map_err(|_| no_geo("its GeoKeyDirectory does not hold 16-bit keys".to_owned()))?,
            ),
        };
        let (x0, x_scale, y0, y_scale) = match (scale, tiepoints, transform) {
            (_, _, Some(m)) => {
                if m.len() < 16 {
                    return Err(no_geo(format!(
                        "its ModelTransformation holds {} values, not 16",
                        m.len()
                    )));
                }
                if m[1] != 0.0 || m[4] != 0.0 {
                    return Err(no_geo(
                        "its ModelTransformation rotates or shears the grid; resample it north-up".to_owned(),
                    ));
                }
                (m[3], m[0], m[7], m[5])
            }
            (Some(s), Some(t), None) => {
                if s.len() < 2 || t.len() < 6 {
                    return Err(no_geo(format!(
                        "its ModelPixelScale holds {} values and its ModelTiepoint {}; at least 2 and 6 are needed",
                        s.len(),
                        t.len()
                    )));
                }
                // Tie point: raster (I, J) is at model (X, Y); rows run south.
                let (i, j, x, y) = (t[0], t[1], t[3], t[4]);
                (x - i * s[0], s[0], y + j * s[1], -s[1])
            }
            (None, Some(_), None) => {
                return Err(no_geo(
                    "it has tie points but no ModelPixelScale (a warped grid); resample it onto a regular grid"
                        .to_owned(),
                ))
            }
            _ => {
                return Err(no_geo(
                    "it has neither ModelPixelScale with ModelTiepoint nor ModelTransformation".to_owned(),
                ))
            }
        };
        for (what, v) in [
            ("origin", x0),
            ("pixel width", x_scale),
            ("origin", y0),
            ("pixel height", y_scale),
        ] {
            if !v.is_finite() {
                return Err(no_geo(format!("its {what} is {v:?}, not a finite number")));
            }
        }
        if x_scale == 0.0 || y_scale == 0.0 {
            return Err(no_geo(format!("its pixels are {x_scale} x {y_scale} degrees")));
        }
        let keys = keys.ok_or_else(|| {
            no_geo("it has no GeoKeyDirectory (tag 34735), so its coordinate system is unknown".to_owned())
        })?;
        let key = geo_keys(&keys).map_err(no_geo)?;
        let not_geographic = |detail: String| DemError::NotGeographic {
            file: file.to_owned(),
            detail,
        };
        match key(GT_MODEL_TYPE) {
            Some(MODEL_GEOGRAPHIC) => {}
            Some(MODEL_PROJECTED) => {
                return Err(not_geographic(match key(PROJECTED_CS_TYPE) {
                    Some(code) => format!("it is projected (ProjectedCSTypeGeoKey {code})"),
                    None => "it is projected (GTModelTypeGeoKey 1)".to_owned(),
                }))
            }
            Some(MODEL_GEOCENTRIC) => return Err(not_geographic("it is geocentric (GTModelTypeGeoKey 3)".to_owned())),
            Some(other) => return Err(not_geographic(format!("GTModelTypeGeoKey is {other}"))),
            None => {
                if let Some(code) = key(PROJECTED_CS_TYPE) {
                    return Err(not_geographic(format!(
                        "it is projected (ProjectedCSTypeGeoKey {code})"
                    )));
                }
                if key(GEOGRAPHIC_TYPE).is_none() {
                    return Err(no_geo(
                        "its GeoKeyDirectory gives neither a model type nor a geographic system".to_owned(),
                    ));
                }
            }
        }
        if let Some(unit) = key(GEOG_ANGULAR_UNITS).filter(|u| !DEGREE_UNITS.contains(u)) {
            return Err(not_geographic(format!(
                "its angles are in unit EPSG:{unit}, not degrees (EPSG:9102)"
            )));
        }
        Ok(Georeference {
            x0,
            x_scale,
            y0,
            y_scale,
            pixel_is_point: key(GT_RASTER_TYPE) == Some(RASTER_PIXEL_IS_POINT),
        })
    }
}

/// Looks up short GeoKeys (those stored in the directory itself) of a GeoKeyDirectory.
fn geo_keys(keys: &[u16]) -> Result<impl Fn(u16) -> Option<u16> + '_, String> {
    if keys.len() < 4 {
        return Err(format!(
            "its GeoKeyDirectory holds {} values, fewer than its header's 4",
            keys.len()
        ));
    }
    let n = usize::from(keys[3]);
    if keys.len() < 4 + 4 * n {
        return Err(format!(
            "its GeoKeyDirectory announces {n} keys but holds {} values",
            keys.len()
        ));
    }
    let entries = &keys[4..4 + 4 * n];
    Ok(move |id: u16| entries.chunks_exact(4).find(|e| e[0] == id && e[1] == 0).map(|e| e[3]))
}
