//! Reading an [`EquirectDem`] from a netCDF classic file.

use crate::axis::{self, AxisProblem, Longitudes, Regular};
use crate::dem::EquirectDem;
use crate::error::DemError;
use crate::header::{self, HeaderInfo, HeaderProblem, MAX_HEADER_BYTES};
use netcdf3::error::parse_header_error::ParseHeaderErrorKind;
use netcdf3::{DataSet, DataType, DataVector, FileReader, ReadError, Variable};
use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;

/// The largest grid accepted, in cells (2^31: 8 GiB of heights). Larger grids are refused with
/// [`DemError::TooLarge`] before anything is allocated for them.
pub const MAX_CELLS: u64 = 1 << 31;

/// Refuses a grid of `width` x `height` cells (of `file`) with more than [`MAX_CELLS`] of them,
/// before anything is allocated for it.
pub(crate) fn check_cells(file: &str, width: u64, height: u64) -> Result<(), DemError> {
    if width.saturating_mul(height) > MAX_CELLS {
        return Err(DemError::TooLarge {
            file: file.to_owned(),
            width,
            height,
            limit: MAX_CELLS,
        });
    }
    Ok(())
}

/// Bytes of a file read first to check its header; more are read if the header is longer.
const FIRST_HEADER_READ: u64 = 64 * 1024;

impl EquirectDem {
    /// Reads the elevation grid of the netCDF classic (CDF-1) or 64-bit offset (CDF-2) file at
    /// `path`.
    ///
    /// `variable` names the variable holding the heights; with `None`, the file's only 2-D numeric
    /// variable whose two dimensions have coordinate variables is read. Its axes come from those
    /// coordinate variables (a 1-D numeric variable over the dimension, preferably of the same
    /// name). The longitude axis is the one whose `units` are `degrees_east` (or `axis` is `X`,
    /// or `standard_name` is `longitude`, or whose name starts with `lon` or ends with `x`), the
    /// latitude axis likewise with `degrees_north`, `Y`, `latitude`, `lat` or `y`; failing all
    /// of those, the last dimension is the longitude.
    ///
    /// Both axes must be evenly spaced (to a millionth of a step, plus the rounding of the
    /// values' storage type). A longitude axis whose columns span 360 degrees to within a tenth
    /// of a step wraps, and its step becomes exactly 360 / width: files round their steps
    /// (ETOPO5 stores 0.0833341 degrees for 1/12). A last column one turn after the first, as in
    /// ETOPO20, is dropped. The first longitude is moved into [-180, 180). Heights are `value * scale_factor +
    /// add_offset` when those attributes are present; values equal to `_FillValue` or to
    /// `missing_value` (or, when neither is given, to netCDF's default fill value of the type)
    /// and values that are not finite numbers become missing samples. See [`EquirectDem`] for
    /// the layout of the result.
    ///
    /// Errors: every [`DemError`] variant; each names `path` as displayed.
    pub fn read_netcdf(path: impl AsRef<Path>, variable: Option<&str>) -> Result<EquirectDem, DemError> {
        let opened = open_checked(path.as_ref())?;
        load(
            opened.file,
            opened.source,
            opened.input,
            opened.len,
            &opened.info,
            variable,
        )
    }

    /// Reads the elevation grid of a netCDF classic file held in memory; `name` stands for the
    /// file in error messages and in [`source`](Self::source). Otherwise as
    /// [`read_netcdf`](Self::read_netcdf).
    pub fn from_netcdf_bytes(name: &str, bytes: Vec<u8>, variable: Option<&str>) -> Result<EquirectDem, DemError> {
        let len = bytes.len() as u64;
        let info = check_bytes(name, &bytes)?;
        load(
            name.to_owned(),
            name.to_owned(),
            Cursor::new(bytes),
            len,
            &info,
            variable,
        )
    }
}

/// A netCDF file opened, its header through the bounds check.
pub(crate) struct CheckedFile {
    /// The path as displayed, for messages.
    pub file: String,
    /// The file's name (its last path component).
    pub source: String,
    /// The file, positioned at its start.
    pub input: std::fs::File,
    /// Its length in bytes.
    pub len: u64,
    /// What the bounds check found.
    pub info: HeaderInfo,
}

/// Opens the file at `path` and checks its header's bounds, reading no more of it than the
/// header needs.
pub(crate) fn open_checked(path: &Path) -> Result<CheckedFile, DemError> {
    let file = path.display().to_string();
    let io = |source: std::io::Error| DemError::Io {
        file: file.clone(),
        source,
    };
    let mut input = std::fs::File::open(path).map_err(io)?;
    let len = input.metadata().map_err(io)?.len();
    let mut want = FIRST_HEADER_READ;
    let info = loop {
        let n = want.min(len);
        let mut prefix = vec![0; usize::try_from(n).unwrap_or(usize::MAX)];
        input.seek(SeekFrom::Start(0)).map_err(io)?;
        input.read_exact(&mut prefix).map_err(io)?;
        match header::check(&prefix, len) {
            Err(HeaderProblem::NeedMore) if n < len => want = want.saturating_mul(4),
            result => break result.map_err(|p| header_error(&file, p, len))?,
        }
    };
    input.seek(SeekFrom::Start(0)).map_err(io)?;
    let source = file_name(path);
    Ok(CheckedFile {
        file,
        source,
        input,
        len,
        info,
    })
}

/// The last component of `path`, or the whole path displayed when it has none.
pub(crate) fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Checks the header of a netCDF file held in memory.
pub(crate) fn check_bytes(name: &str, bytes: &[u8]) -> Result<HeaderInfo, DemError> {
    let len = bytes.len() as u64;
    header::check(bytes, len).map_err(|p| header_error(name, p, len))
}

/// The error for a header that failed the bounds check.
fn header_error(file: &str, problem: HeaderProblem, len: u64) -> DemError {
    let file = file.to_owned();
    match problem {
        HeaderProblem::NotNetcdf(detail) => DemError::NotNetcdf { file, detail },
        HeaderProblem::Corrupt(detail) => DemError::Corrupt { file, detail },
        HeaderProblem::Truncated { needed } => DemError::Truncated {
            file,
            expected: needed,
            actual: len,
        },
        HeaderProblem::TooLarge { at_least } => DemError::HeaderTooLarge {
            file,
            size: at_least,
            limit: MAX_HEADER_BYTES,
        },
        // Only when the whole file was given, so the header ends past it.
        HeaderProblem::NeedMore => DemError::Truncated {
            file,
            expected: len.saturating_add(1),
            actual: len,
        },
    }
}

/// The error for a failure reported by the `netcdf3` crate.
fn netcdf_error(file: &str, e: ReadError) -> DemError {
    let file = file.to_owned();
    let detail = match e {
        ReadError::IOErrorKind(kind) => {
            return DemError::Io {
                file,
                source: kind.into(),
            }
        }
        ReadError::ParseHeader(p) => {
            let what = match p.kind {
                ParseHeaderErrorKind::MagicWord | ParseHeaderErrorKind::VersionNumber => "its signature",
                ParseHeaderErrorKind::NonNegativeI32 => "a count or size",
                ParseHeaderErrorKind::ZeroPadding => "padding bytes that should be zero",
                ParseHeaderErrorKind::DimTag | ParseHeaderErrorKind::AttrTag | ParseHeaderErrorKind::VarTag => {
                    "a list tag"
                }
                ParseHeaderErrorKind::DataType => "a data type",
                ParseHeaderErrorKind::DataElements => "attribute values",
                ParseHeaderErrorKind::Utf8 => "a name that is not valid UTF-8",
                ParseHeaderErrorKind::Offset => "a data offset",
            };
            format!("it cannot be decoded at {what}")
        }
        ReadError::DataSet(d) => format!("its definitions are inconsistent: {d:?}"),
        ReadError::ComputationNumberOfRecords => "the record data do not fill a whole number of records".to_owned(),
        other => format!("{other:?}"),
    };
    DemError::Corrupt { file, detail }
}

/// A grid variable chosen and its axes read and checked; its values not yet read.
pub(crate) struct Prepared {
    /// The `netcdf3` reader, positioned anywhere.
    pub reader: FileReader,
    /// The grid variable's name.
    pub variable: String,
    /// Where the file's values go in the grid.
    pub layout: Layout,
    /// How stored values become heights.
    pub values: Values,
    /// The latitude axis, in increasing order.
    pub lat: Regular,
}

/// Chooses the grid variable of a file whose header passed the bounds check, reads and checks
/// its axes and packing, and checks that its data lie within the file. Reads no grid values.
pub(crate) fn prepare<R: Read + Seek + 'static>(
    file: &str,
    input: R,
    len: u64,
    info: &HeaderInfo,
    variable: Option<&str>,
) -> Result<Prepared, DemError> {
    let mut reader = FileReader::open_seek_read(file, Box::new(input)).map_err(|e| netcdf_error(file, e))?;
    let plan = plan(file, reader.data_set(), variable)?;
    let width_in = plan.lon_dim_size as u64;
    let height_in = plan.lat_dim_size as u64;
    check_cells(file, width_in, height_in)?;
    for name in [&plan.lon_var, &plan.lat_var, &plan.grid_var] {
        check_extent(file, info, name, len)?;
    }

    let (lon_values, lon_slack) = read_axis(file, &mut reader, &plan.lon_var)?;
    let lon_label = format!("longitude ({})", plan.lon_var);
    let lon = axis::regular(&lon_values, lon_slack.0, lon_slack.1)
        .and_then(|a| axis::longitudes(a, lon_values.len()))
        .map_err(|p| axis_error(file, &lon_label, p))?;
    let (lat_values, lat_slack) = read_axis(file, &mut reader, &plan.lat_var)?;
    let lat_label = format!("latitude ({})", plan.lat_var);
    let lat = axis::regular(&lat_values, lat_slack.0, lat_slack.1)
        .and_then(|a| axis::latitudes(a, lat_values.len()))
        .map_err(|p| axis_error(file, &lat_label, p))?;

    let var = reader
        .data_set()
        .get_var(&plan.grid_var)
        .ok_or_else(|| DemError::VariableNotFound {
            file: file.to_owned(),
            name: plan.grid_var.clone(),
            variables: Vec::new(),
        })?;
    let values = Values::new(&Packing::of(file, var)?, var.data_type());
    let layout = Layout {
        lon_first_dim: plan.lon_dim_index == 0,
        lon_in: plan.lon_dim_size,
        lat_in: plan.lat_dim_size,
        lon,
        lat_reversed: lat.reversed,
    };
    Ok(Prepared {
        reader,
        variable: plan.grid_var,
        layout,
        values,
        lat,
    })
}

/// Reads the grid once the header has passed the bounds check.
fn load<R: Read + Seek + 'static>(
    file: String,
    source: String,
    input: R,
    len: u64,
    info: &HeaderInfo,
    variable: Option<&str>,
) -> Result<EquirectDem, DemError> {
    let Prepared {
        mut reader,
        variable,
        layout,
        values,
        lat,
    } = prepare(&file, input, len, info, variable)?;
    let raw = reader
        .read_var(&variable)
        .map_err(|e| data_error(&file, info, &variable, len, e))?;
    let heights = decode(raw, &layout, &values);
    if heights.iter().all(|v| v.is_nan()) {
        return Err(DemError::NoValidData { file, variable });
    }
    let lon = layout.lon;
    Ok(EquirectDem {
        source,
        variable,
        width: lon.width,
        height: layout.lat_in,
        lon_first: lon.first,
        lon_step: lon.step,
        lat_first: lat.first,
        lat_step: lat.step,
        wraps: lon.wraps,
        heights,
    })
}

/// Which variables to read, and how the grid's dimensions map to longitude and latitude.
struct Plan {
    grid_var: String,
    lon_var: String,
    lat_var: String,
    /// Index (0 or 1) of the longitude among the grid variable's dimensions.
    lon_dim_index: usize,
    lon_dim_size: usize,
    lat_dim_size: usize,
}

fn is_numeric(t: DataType) -> bool {
    !matches!(t, DataType::U8)
}

fn type_name(t: DataType) -> &'static str {
    match t {
        DataType::I8 => "byte",
        DataType::U8 => "char",
        DataType::I16 => "short",
        DataType::I32 => "int",
        DataType::F32 => "float",
        DataType::F64 => "double",
    }
}

/// `NAME(DIM, ...) TYPE`.
fn describe(v: &Variable) -> String {
    format!(
        "{}({}) {}",
        v.name(),
        v.dim_names().join(", "),
        type_name(v.data_type())
    )
}

/// The coordinate variable of dimension `dim`: the 1-D numeric variable over it of the same name,
/// or else the only 1-D numeric variable over it.
fn coordinate_var<'a>(ds: &'a DataSet, dim: &str) -> Option<&'a Variable> {
    let over = |v: &&Variable| v.num_dims() == 1 && v.dim_names()[0] == dim && is_numeric(v.data_type());
    if let Some(v) = ds.get_var(dim).filter(over) {
        return Some(v);
    }
    let mut others = ds.get_vars().into_iter().filter(over);
    match (others.next(), others.next()) {
        (Some(v), None) => Some(v),
        _ => None,
    }
}

/// Chooses the grid variable and its axes.
fn plan(file: &str, ds: &DataSet, variable: Option<&str>) -> Result<Plan, DemError> {
    let all = || ds.get_vars().into_iter().map(describe).collect::<Vec<_>>();
    // The coordinate variables of a 2-D variable's dimensions, or the error for the first missing.
    let axes = |v: &Variable| -> Result<[&Variable; 2], DemError> {
        let names = v.dim_names();
        let coord = |dimension: &String| {
            coordinate_var(ds, dimension).ok_or_else(|| DemError::MissingAxis {
                file: file.to_owned(),
                variable: v.name().to_owned(),
                dimension: dimension.clone(),
            })
        };
        Ok([coord(&names[0])?, coord(&names[1])?])
    };
    let grid_shaped = |v: &Variable| v.num_dims() == 2 && is_numeric(v.data_type());
    let (var, coords) = match variable {
        Some(name) => {
            let v = ds.get_var(name).ok_or_else(|| DemError::VariableNotFound {
                file: file.to_owned(),
                name: name.to_owned(),
                variables: all(),
            })?;
            let unsuitable = |reason: String| DemError::UnsuitableVariable {
                file: file.to_owned(),
                name: name.to_owned(),
                reason,
            };
            if v.num_dims() != 2 {
                return Err(unsuitable(format!(
                    "it has {} dimension(s) ({}), not 2",
                    v.num_dims(),
                    v.dim_names().join(", ")
                )));
            }
            if !is_numeric(v.data_type()) {
                return Err(unsuitable("it holds characters, not numbers".to_owned()));
            }
            (v, axes(v)?)
        }
        None => {
            let shaped: Vec<&Variable> = ds.get_vars().into_iter().filter(|v| grid_shaped(v)).collect();
            let mut with_axes = Vec::new();
            let mut first_missing = None;
            for &v in &shaped {
                match axes(v) {
                    Ok(coords) => with_axes.push((v, coords)),
                    Err(e) => {
                        first_missing.get_or_insert(e);
                    }
                }
            }
            match (with_axes.len(), shaped.len(), first_missing) {
                (1, _, _) => with_axes.remove(0),
                // One variable has the shape of a grid: say which axis it lacks.
                (0, 1, Some(missing)) => return Err(missing),
                (0, _, _) => {
                    return Err(DemError::NoGridVariable {
                        file: file.to_owned(),
                        variables: all(),
                    })
                }
                _ => {
                    return Err(DemError::AmbiguousVariable {
                        file: file.to_owned(),
                        candidates: with_axes.iter().map(|(v, _)| describe(v)).collect(),
                    })
                }
            }
        }
    };
    let dims = var.get_dims();
    let lon_dim_index = longitude_index(&coords);
    let lat_dim_index = 1 - lon_dim_index;
    Ok(Plan {
        grid_var: var.name().to_owned(),
        lon_var: coords[lon_dim_index].name().to_owned(),
        lat_var: coords[lat_dim_index].name().to_owned(),
        lon_dim_index,
        lon_dim_size: dims[lon_dim_index].size(),
        lat_dim_size: dims[lat_dim_index].size(),
    })
}

/// Whether an axis is a longitude or a latitude.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Lon,
    Lat,
}

/// A text attribute, without the trailing NULs and spaces some writers leave, in lower case.
fn text_attr(v: &Variable, name: &str) -> Option<String> {
    v.get_attr_as_string(name).map(|s| {
        s.trim_matches(|c: char| c == '\0' || c.is_whitespace())
            .to_ascii_lowercase()
    })
}

fn kind_by_units(v: &Variable) -> Option<Kind> {
    match text_attr(v, "units")?.as_str() {
        "degrees_east" | "degree_east" | "degrees_e" | "degree_e" | "degreese" | "degreee" => Some(Kind::Lon),
        "degrees_north" | "degree_north" | "degrees_n" | "degree_n" | "degreesn" | "degreen" => Some(Kind::Lat),
        _ => None,
    }
}

fn kind_by_attributes(v: &Variable) -> Option<Kind> {
    match text_attr(v, "standard_name").as_deref() {
        Some("longitude") => return Some(Kind::Lon),
        Some("latitude") => return Some(Kind::Lat),
        _ => {}
    }
    match text_attr(v, "axis").as_deref() {
        Some("x") => Some(Kind::Lon),
        Some("y") => Some(Kind::Lat),
        _ => None,
    }
}

fn kind_by_name(v: &Variable) -> Option<Kind> {
    let name = v.name().to_ascii_lowercase();
    if name.starts_with("lon") || name.ends_with('x') {
        Some(Kind::Lon)
    } else if name.starts_with("lat") || name.ends_with('y') {
        Some(Kind::Lat)
    } else {
        None
    }
}

/// Which of the two coordinate variables (0 or 1) holds longitudes: by units, then by
/// `standard_name` or `axis`, then by name, then the last one.
fn longitude_index(coords: &[&Variable; 2]) -> usize {
    let rules: [fn(&Variable) -> Option<Kind>; 3] = [kind_by_units, kind_by_attributes, kind_by_name];
    for rule in rules {
        match (rule(coords[0]), rule(coords[1])) {
            (Some(Kind::Lon), None | Some(Kind::Lat)) | (None, Some(Kind::Lat)) => return 0,
            (Some(Kind::Lat), None | Some(Kind::Lon)) | (None, Some(Kind::Lon)) => return 1,
            _ => {}
        }
    }
    1
}

/// Refuses a variable whose data would run past the end of the file.
fn check_extent(file: &str, info: &HeaderInfo, name: &str, len: u64) -> Result<(), DemError> {
    let Some(extent) = info.var(name) else {
        return Err(DemError::Corrupt {
            file: file.to_owned(),
            detail: format!("variable {name:?} is not where the header check found it"),
        });
    };
    let end = info.data_end(extent, len).unwrap_or(u64::MAX);
    if end > len {
        return Err(DemError::Truncated {
            file: file.to_owned(),
            expected: end,
            actual: len,
        });
    }
    Ok(())
}

/// The error for a failure to read variable `name`'s data.
fn data_error(file: &str, info: &HeaderInfo, name: &str, len: u64, e: ReadError) -> DemError {
    match e {
        ReadError::IOErrorKind(std::io::ErrorKind::UnexpectedEof) => DemError::Truncated {
            file: file.to_owned(),
            expected: info
                .var(name)
                .and_then(|v| info.data_end(v, len))
                .unwrap_or(u64::MAX)
                .max(len.saturating_add(1)),
            actual: len,
        },
        e => netcdf_error(file, e),
    }
}

/// The values of a coordinate variable (unpacked), with the relative precision of their storage
/// type and the absolute precision of their packing.
fn read_axis(file: &str, reader: &mut FileReader, name: &str) -> Result<(Vec<f64>, (f64, f64)), DemError> {
    let var = reader.data_set().get_var(name).ok_or_else(|| DemError::Corrupt {
        file: file.to_owned(),
        detail: format!("coordinate variable {name:?} vanished"),
    })?;
    let packing = Packing::of(file, var)?;
    let raw = reader.read_var(name).map_err(|e| netcdf_error(file, e))?;
    let (values, relative): (Vec<f64>, f64) = match raw {
        DataVector::I8(v) => (v.into_iter().map(f64::from).collect(), 0.0),
        DataVector::U8(v) => (v.into_iter().map(f64::from).collect(), 0.0),
        DataVector::I16(v) => (v.into_iter().map(f64::from).collect(), 0.0),
        DataVector::I32(v) => (v.into_iter().map(f64::from).collect(), 0.0),
        DataVector::F32(v) => (v.into_iter().map(f64::from).collect(), f64::from(f32::EPSILON)),
        DataVector::F64(v) => (v, f64::EPSILON),
    };
    let values = values.into_iter().map(|v| packing.apply(v)).collect();
    // Packed values were rounded to whole multiples of the scale factor.
    let absolute = packing.scale.map_or(0.0, |s| 0.5 * s.abs());
    Ok((values, (relative, absolute)))
}

/// The error for an unusable axis; `axis` names it as `longitude (VAR)` or `latitude (VAR)`.
pub(crate) fn axis_error(file: &str, axis: &str, p: AxisProblem) -> DemError {
    let file = file.to_owned();
    let axis = axis.to_owned();
    match p {
        AxisProblem::TooShort(n) => DemError::AxisInvalid {
            file,
            axis,
            detail: format!("it has {n} value(s); at least 2 are needed to define a step"),
        },
        AxisProblem::NotFinite { index, value } => DemError::AxisInvalid {
            file,
            axis,
            detail: format!("value {index} is {value:?}, not a finite number"),
        },
        AxisProblem::NotMonotonic { index } => DemError::AxisNotMonotonic { file, axis, index },
        AxisProblem::Uneven { index, expected, found } => DemError::AxisUneven {
            file,
            axis,
            index,
            expected,
            found,
        },
        AxisProblem::SpansMoreThanATurn { span } => DemError::AxisInvalid {
            file,
            axis,
            detail: format!("the longitudes span {span:?} degrees, more than 360; crop the grid to one turn"),
        },
        AxisProblem::LatitudeOutOfRange { value } => DemError::LatitudeOutOfRange { file, axis, value },
    }
}

/// How stored values become heights: packing and missing values.
struct Packing {
    scale: Option<f64>,
    offset: Option<f64>,
    /// Stored values that mean "missing".
    fills: Vec<f64>,
}

/// A numeric attribute's values as `f64`.
fn numeric_attr(v: &Variable, name: &str) -> Option<Vec<f64>> {
    let a = v.get_attr(name)?;
    if let Some(x) = a.get_f64() {
        Some(x.to_vec())
    } else if let Some(x) = a.get_f32() {
        Some(x.iter().map(|&x| f64::from(x)).collect())
    } else if let Some(x) = a.get_i32() {
        Some(x.iter().map(|&x| f64::from(x)).collect())
    } else if let Some(x) = a.get_i16() {
        Some(x.iter().map(|&x| f64::from(x)).collect())
    } else {
        a.get_i8().map(|x| x.iter().map(|&x| f64::from(x)).collect())
    }
}

impl Packing {
    fn of(file: &str, v: &Variable) -> Result<Packing, DemError> {
        let single = |attr: &str| -> Result<Option<f64>, DemError> {
            match numeric_attr(v, attr).and_then(|x| x.first().copied()) {
                Some(x) if !x.is_finite() => Err(DemError::UnsuitableVariable {
                    file: file.to_owned(),
                    name: v.name().to_owned(),
                    reason: format!("its {attr} is {x:?}, not a finite number"),
                }),
                x => Ok(x),
            }
        };
        let scale = single("scale_factor")?;
        let offset = single("add_offset")?;
        let mut fills: Vec<f64> = Vec::new();
        if let Some(f) = numeric_attr(v, "_FillValue").and_then(|x| x.first().copied()) {
            fills.push(f);
        }
        fills.extend(numeric_attr(v, "missing_value").unwrap_or_default());
        if v.get_attr("_FillValue").is_none() && v.get_attr("missing_value").is_none() {
            fills.push(match v.data_type() {
                DataType::I8 => f64::from(netcdf3::NC_FILL_I8),
                DataType::U8 => f64::from(netcdf3::NC_FILL_U8),
                DataType::I16 => f64::from(netcdf3::NC_FILL_I16),
                DataType::I32 => f64::from(netcdf3::NC_FILL_I32),
                DataType::F32 => f64::from(netcdf3::NC_FILL_F32),
                DataType::F64 => netcdf3::NC_FILL_F64,
            });
        }
        Ok(Packing { scale, offset, fills })
    }

    fn apply(&self, v: f64) -> f64 {
        v * self.scale.unwrap_or(1.0) + self.offset.unwrap_or(0.0)
    }
}

/// How the stored values of one variable become heights: its type, packing and missing values.
/// The one conversion used by both the whole-grid reader and [`NetcdfSource`](crate::NetcdfSource),
/// so that both give the same bits.
pub(crate) struct Values {
    data_type: DataType,
    packing: Packing,
    /// The fill values as floats (compared with `float` values).
    fills_f32: Vec<f32>,
    /// The fill values that are whole numbers (compared with integer values).
    fills_int: Vec<i64>,
}

impl Values {
    fn new(packing: &Packing, data_type: DataType) -> Values {
        let fills_int = packing
            .fills
            .iter()
            .filter(|f| f.fract() == 0.0 && f.abs() < 9.0e15)
            .map(|&f| f as i64)
            .collect();
        Values {
            data_type,
            fills_f32: packing.fills.iter().map(|&f| f as f32).collect(),
            fills_int,
            packing: Packing {
                scale: packing.scale,
                offset: packing.offset,
                fills: packing.fills.clone(),
            },
        }
    }

    /// Bytes of one stored value.
    pub fn size(&self) -> usize {
        match self.data_type {
            DataType::I8 | DataType::U8 => 1,
            DataType::I16 => 2,
            DataType::I32 | DataType::F32 => 4,
            DataType::F64 => 8,
        }
    }

    /// The height of a packed or integer value `v`, `NaN` if not finite.
    fn height(&self, v: f64) -> f32 {
        let h = self.packing.apply(v) as f32;
        if h.is_finite() {
            h
        } else {
            f32::NAN
        }
    }

    fn height_of_f32(&self, x: f32) -> f32 {
        if !x.is_finite() || self.fills_f32.contains(&x) {
            f32::NAN
        } else if self.packing.scale.is_some() || self.packing.offset.is_some() {
            self.height(f64::from(x))
        } else {
            x
        }
    }

    fn height_of_f64(&self, x: f64) -> f32 {
        if !x.is_finite() || self.packing.fills.contains(&x) {
            f32::NAN
        } else {
            self.height(x)
        }
    }

    fn height_of_int(&self, x: i64) -> f32 {
        if self.fills_int.contains(&x) {
            f32::NAN
        } else {
            self.height(x as f64)
        }
    }

    /// The height of one value stored big-endian in `b` (`size()` bytes), as the file holds it.
    pub fn height_of_be_bytes(&self, b: &[u8]) -> f32 {
        match self.data_type {
            DataType::I8 => self.height_of_int(i64::from(b[0] as i8)),
            DataType::U8 => self.height_of_int(i64::from(b[0])),
            DataType::I16 => self.height_of_int(i64::from(i16::from_be_bytes([b[0], b[1]]))),
            DataType::I32 => self.height_of_int(i64::from(i32::from_be_bytes([b[0], b[1], b[2], b[3]]))),
            DataType::F32 => self.height_of_f32(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
            DataType::F64 => self.height_of_f64(f64::from_be_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])),
        }
    }
}

/// Where the file's values go in the grid.
pub(crate) struct Layout {
    /// Whether longitude is the grid variable's first (outer) dimension.
    pub lon_first_dim: bool,
    /// Longitudes in the file.
    pub lon_in: usize,
    /// Latitudes in the file (= rows of the grid).
    pub lat_in: usize,
    /// The longitude axis, normalised.
    pub lon: Longitudes,
    /// Whether the file stores latitudes in decreasing order.
    pub lat_reversed: bool,
}

impl Layout {
    /// Whether the file's order is the grid's, value for value.
    fn is_identity(&self) -> bool {
        !self.lon_first_dim && !self.lon.reversed && !self.lat_reversed && self.lon.width == self.lon_in
    }

    /// The file's latitude index of the grid's row `row`.
    pub fn file_lat(&self, row: usize) -> usize {
        if self.lat_reversed {
            self.lat_in - 1 - row
        } else {
            row
        }
    }

    /// The file's longitude index of the grid's column `col`.
    pub fn file_lon(&self, col: usize) -> usize {
        if self.lon.reversed {
            self.lon_in - 1 - col
        } else {
            col
        }
    }

    /// Index in the file's values of the grid's `(col, row)`.
    fn file_index(&self, col: usize, row: usize) -> usize {
        let (i_lat, i_lon) = (self.file_lat(row), self.file_lon(col));
        if self.lon_first_dim {
            i_lon * self.lat_in + i_lat
        } else {
            i_lat * self.lon_in + i_lon
        }
    }
}

/// Heights in grid order from the file's values; missing values become `NaN`.
fn decode(raw: DataVector, layout: &Layout, values: &Values) -> Vec<f32> {
    match raw {
        DataVector::F32(mut v) => {
            if layout.is_identity() {
                v.iter_mut().for_each(|x| *x = values.height_of_f32(*x));
                v
            } else {
                reorder(layout, |i| values.height_of_f32(v[i]))
            }
        }
        DataVector::F64(v) => reorder(layout, |i| values.height_of_f64(v[i])),
        DataVector::I32(v) => reorder(layout, |i| values.height_of_int(i64::from(v[i]))),
        DataVector::I16(v) => reorder(layout, |i| values.height_of_int(i64::from(v[i]))),
        DataVector::I8(v) => reorder(layout, |i| values.height_of_int(i64::from(v[i]))),
        DataVector::U8(v) => reorder(layout, |i| values.height_of_int(i64::from(v[i]))),
    }
}

/// The grid, row by row, from the height of each file index.
fn reorder(layout: &Layout, height_at: impl Fn(usize) -> f32) -> Vec<f32> {
    let width = layout.lon.width;
    let mut out = Vec::with_capacity(width * layout.lat_in);
    for row in 0..layout.lat_in {
        for col in 0..width {
            out.push(height_at(layout.file_index(col, row)));
        }
    }
    out
}
