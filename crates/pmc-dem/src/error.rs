//! Why a file could not be read as an elevation model.

/// A failure to read an elevation model. Each variant names the file (the path as given to
/// [`EquirectDem::read_netcdf`](crate::EquirectDem::read_netcdf), or the name given to
/// [`EquirectDem::from_netcdf_bytes`](crate::EquirectDem::from_netcdf_bytes)), says what is wrong
/// and what to do about it.
///
/// Every check that can be made from the header is made before any grid data are read or any
/// memory is reserved for them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DemError {
    /// The operating system refused to open or read the file (missing, unreadable, a directory).
    /// Fix: check the path and its permissions.
    #[error("{file}: cannot read the file: {source}; check the path and its permissions")]
    Io {
        /// The file.
        file: String,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a netCDF classic file: it is empty, it does not start with the signature
    /// `CDF` followed by version byte 1 (classic) or 2 (64-bit offset), or it is a netCDF-4 (HDF5)
    /// or CDF-5 file, which this reader does not support. Fix: check the path; convert netCDF-4 or
    /// CDF-5 files with `nccopy -k classic IN OUT`.
    #[error("{file}: not a netCDF classic file: {detail}")]
    NotNetcdf {
        /// The file.
        file: String,
        /// What was found instead, and how to convert it if that is possible.
        detail: String,
    },
    /// The file is shorter than its header says: its header lists more bytes (of header or of
    /// data) than the file holds. Usually an interrupted copy or download; a damaged header that
    /// announces absurd sizes reads the same. Fix: copy or download the file again.
    #[error(
        "{file}: the file is shorter than its header says: at least {expected} bytes are needed but it holds {actual}; it was cut short (an interrupted copy or download) or its header is damaged: copy it again"
    )]
    Truncated {
        /// The file.
        file: String,
        /// The smallest size, in bytes, that the header requires.
        expected: u64,
        /// The size of the file, in bytes.
        actual: u64,
    },
    /// The header is longer than [`MAX_HEADER_BYTES`](crate::MAX_HEADER_BYTES); refused before it
    /// is decoded. Headers are normally a few kilobytes; a huge attribute (a long `history`, say)
    /// is the usual cause. Fix: delete that attribute (for instance with NCO's `ncatted -a
    /// history,global,d,, IN OUT`).
    #[error(
        "{file}: the netCDF header holds at least {size} bytes, more than the {limit} this reader accepts; a huge attribute (such as a long history) is the usual cause: delete it, for instance with `ncatted -a history,global,d,, IN OUT`"
    )]
    HeaderTooLarge {
        /// The file.
        file: String,
        /// Bytes of header seen before refusing.
        size: u64,
        /// The largest header accepted.
        limit: u64,
    },
    /// The header is damaged: a negative count, an unknown data type, a variable over a dimension
    /// that does not exist, an invalid name, data that start inside the header. Fix: obtain an
    /// intact copy of the file.
    #[error("{file}: the netCDF header is damaged: {detail}; obtain an intact copy of the file")]
    Corrupt {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// No variable was named and the file has no variable that can be the grid: a 2-D numeric
    /// (byte, short, int, float or double) variable whose two dimensions each have a coordinate
    /// variable. Lists the variables found. Fix: check that the file is a gridded elevation model,
    /// or name the variable to read.
    #[error(
        "{file}: no elevation grid found (a 2-D numeric variable whose two dimensions have coordinate variables); the file holds: {}",
        list(.variables)
    )]
    NoGridVariable {
        /// The file.
        file: String,
        /// Every variable of the file, as `NAME(DIM, ...) TYPE`.
        variables: Vec<String>,
    },
    /// No variable was named and the file has several variables that could be the grid. Fix: name
    /// the one to read.
    #[error("{file}: several variables could be the elevation grid ({}); name the one to read", list(.candidates))]
    AmbiguousVariable {
        /// The file.
        file: String,
        /// The candidates, as `NAME(DIM, DIM) TYPE`.
        candidates: Vec<String>,
    },
    /// The variable named by the caller does not exist in the file. Fix: name one of those listed.
    #[error("{file}: no variable named {name:?}; the file holds: {}", list(.variables))]
    VariableNotFound {
        /// The file.
        file: String,
        /// The name that was asked for.
        name: String,
        /// Every variable of the file, as `NAME(DIM, ...) TYPE`.
        variables: Vec<String>,
    },
    /// The variable named by the caller cannot be a grid: it does not have exactly two
    /// dimensions, it holds characters, or its `scale_factor` or `add_offset` is not a finite
    /// number. Fix: name another variable.
    #[error("{file}: variable {name:?} cannot be read as an elevation grid: {reason}")]
    UnsuitableVariable {
        /// The file.
        file: String,
        /// The variable.
        name: String,
        /// Why not.
        reason: String,
    },
    /// A dimension of the grid has no coordinate variable (a 1-D numeric variable over that
    /// dimension, by convention of the same name), so its longitudes or latitudes are unknown.
    /// Fix: add the coordinate variable to the file (for instance with NCO's `ncap2`).
    #[error(
        "{file}: dimension {dimension:?} of variable {variable:?} has no coordinate variable (a 1-D numeric variable over it), so its positions are unknown"
    )]
    MissingAxis {
        /// The file.
        file: String,
        /// The grid variable.
        variable: String,
        /// The dimension without a coordinate variable.
        dimension: String,
    },
    /// A coordinate variable is neither increasing nor decreasing: value `index` repeats or
    /// reverses the direction of the values before it. Fix: the file is not a regular grid;
    /// resample it onto one (for instance with GDAL's `gdalwarp`).
    #[error(
        "{file}: the {axis} axis is not monotonic: value {index} does not continue the direction of the values before it; resample the grid onto a regular one"
    )]
    AxisNotMonotonic {
        /// The file.
        file: String,
        /// The axis, as `longitude (VAR)` or `latitude (VAR)`.
        axis: String,
        /// The index of the first offending value.
        index: usize,
    },
    /// A coordinate variable is not evenly spaced: value `index` departs from the straight line
    /// through the first and last values by more than a millionth of a step (plus the rounding of
    /// the values' storage type). Fix: resample the grid onto a regular one.
    #[error(
        "{file}: the {axis} axis is not evenly spaced: value {index} is {found:?} where even steps give {expected:?}; resample the grid onto a regular one"
    )]
    AxisUneven {
        /// The file.
        file: String,
        /// The axis, as `longitude (VAR)` or `latitude (VAR)`.
        axis: String,
        /// The index of the first offending value.
        index: usize,
        /// The value that even spacing gives at `index`.
        expected: f64,
        /// The value found in the file.
        found: f64,
    },
    /// A coordinate variable cannot describe a grid axis: it has fewer than two values, a value
    /// that is not a finite number, or longitudes that span more than 360 degrees. Fix: check
    /// the file; crop an overlapping grid to one turn.
    #[error("{file}: the {axis} axis is unusable: {detail}")]
    AxisInvalid {
        /// The file.
        file: String,
        /// The axis, as `longitude (VAR)` or `latitude (VAR)`.
        axis: String,
        /// What is wrong.
        detail: String,
    },
    /// A latitude lies outside [-90, 90] degrees. Fix: check which variable holds the latitudes
    /// (the axes may be swapped or not in degrees).
    #[error(
        "{file}: the {axis} axis holds latitude {value:?}, outside [-90, 90] degrees; check that the axis is a latitude in degrees"
    )]
    LatitudeOutOfRange {
        /// The file.
        file: String,
        /// The axis, as `latitude (VAR)`.
        axis: String,
        /// The offending latitude.
        value: f64,
    },
    /// The grid has more cells than this reader accepts; refused before anything is allocated.
    /// Fix: crop or subsample the file (for instance with `ncks -d`).
    #[error(
        "{file}: the grid is {width} x {height} cells, more than the {limit} this reader accepts; crop or subsample it"
    )]
    TooLarge {
        /// The file.
        file: String,
        /// Number of columns (longitudes) declared.
        width: u64,
        /// Number of rows (latitudes) declared.
        height: u64,
        /// The largest number of cells accepted ([`MAX_CELLS`](crate::MAX_CELLS)).
        limit: u64,
    },
    /// Every sample of the grid is missing: equal to the fill or missing value, or not a finite
    /// number. Fix: check that the right variable was read and that the file was written fully.
    #[error(
        "{file}: variable {variable:?} holds no valid sample: every value is the fill or missing value or not a number"
    )]
    NoValidData {
        /// The file.
        file: String,
        /// The variable read.
        variable: String,
    },
    /// The file is not a `.pmcdem` cube-face elevation file: it does not start with the
    /// `.pmcdem` signature (it is empty, a netCDF grid, an image, or something else). Fix: check
    /// the path; make `.pmcdem` files from an equirectangular grid with
    /// [`import_cube`](crate::import_cube).
    #[error("{file}: not a .pmcdem cube elevation file: {detail}")]
    NotCubeDem {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
    /// The `.pmcdem` file has a format version this reader does not know (a newer writer, or a
    /// damaged header). Fix: read it with a newer version of this crate, or import the source
    /// again.
    #[error("{file}: .pmcdem version {version} is not supported (this reader knows versions 1 and 2); use a newer reader or import the source again")]
    UnsupportedVersion {
        /// The file.
        file: String,
        /// The version found in the header.
        version: u32,
    },
    /// A `.pmcdem` file is damaged: a checksum (header, tile table or tile) does not match its
    /// bytes, or a header field or table entry contradicts the others or the file's length. Fix:
    /// copy the file again or import its source again.
    #[error("{file}: the .pmcdem file is damaged: {detail}; copy it again or import its source again")]
    CubeCorrupt {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// The output file (or its temporary file next to it) could not be created, written, or
    /// renamed into place; nothing is left at the output path. Fix: check the directory exists,
    /// is writable and has room.
    #[error("{file}: cannot write the file: {source}; check that the directory exists, is writable and has room")]
    Write {
        /// The file.
        file: String,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// Import options that cannot work (a level above the maximum, a memory budget too small
    /// for two rows of the source, a radius that is not a positive number); refused before
    /// anything is written. Fix: change the option named in the message.
    #[error("{file}: {detail}")]
    InvalidOptions {
        /// The source file the import was for.
        file: String,
        /// Which option is wrong and what is accepted.
        detail: String,
    },
    /// The source to import holds no valid sample (every value missing). Fix: check the source
    /// grid and the variable read.
    #[error("{file}: the grid holds no valid sample to import: every value is missing")]
    EmptySource {
        /// The file.
        file: String,
    },
    /// A read asked for samples outside the grid, or gave a buffer of the wrong size: a bug in
    /// the caller, reported instead of panicking.
    #[error("{file}: {detail}")]
    OutOfGrid {
        /// The file.
        file: String,
        /// What was asked.
        detail: String,
    },
    /// The file given to the GeoTIFF reader is not a TIFF file: it does not start with `II*\0`
    /// or `MM\0*` (or the BigTIFF signatures). Says what it looks like instead (a netCDF or PNG
    /// file, say). Fix: check the path, or use the reader for that format.
    #[error("{file}: not a TIFF file: {detail}")]
    NotTiff {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
    /// The TIFF file is valid but uses something this reader does not read: several bands,
    /// a sample type other than 8-, 16-, 32- or 64-bit integers or 32- or 64-bit floats, JPEG or
    /// another compression than none, deflate, LZW or PackBits. Fix: convert it, for instance
    /// with `gdal_translate -b 1 -ot Float32 -co COMPRESS=DEFLATE IN OUT`.
    #[error("{file}: this TIFF cannot be read as an elevation model: {detail}; convert it, for instance with `gdal_translate -b 1 -ot Float32 -co COMPRESS=DEFLATE IN OUT`")]
    TiffUnsupported {
        /// The file.
        file: String,
        /// What was found.
        detail: String,
    },
    /// The TIFF file is damaged: its directory or its compressed data cannot be decoded. Fix:
    /// obtain an intact copy of the file.
    #[error("{file}: the TIFF file is damaged: {detail}; obtain an intact copy of the file")]
    TiffCorrupt {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// The TIFF file does not say where on Earth its pixels lie: the GeoTIFF tags
    /// (ModelPixelScale with ModelTiepoint, or ModelTransformation, and the GeoKeyDirectory) are
    /// missing or unusable (rotated, zero or not finite scales). Fix: georeference it, for
    /// instance with `gdal_translate -a_srs EPSG:4326 -a_ullr WEST NORTH EAST SOUTH IN OUT`.
    #[error("{file}: the file is not georeferenced as a longitude-latitude grid: {detail}; georeference it, for instance with `gdal_translate -a_srs EPSG:4326 -a_ullr WEST NORTH EAST SOUTH IN OUT`")]
    NoGeoreference {
        /// The file.
        file: String,
        /// What is missing or wrong.
        detail: String,
    },
    /// The GeoTIFF is georeferenced in a projected (or geocentric) coordinate system, or in
    /// angular units other than degrees; this reader needs longitudes and latitudes in degrees.
    /// Fix: reproject it, for instance with `gdalwarp -t_srs EPSG:4326 IN OUT`.
    #[error("{file}: the grid is not in geographic coordinates (longitude and latitude in degrees): {detail}; reproject it, for instance with `gdalwarp -t_srs EPSG:4326 IN OUT`")]
    NotGeographic {
        /// The file.
        file: String,
        /// The coordinate system found.
        detail: String,
    },
    /// The file given to the PNG reader is not a PNG file (it does not start with the PNG
    /// signature); says what it looks like instead. Fix: check the path.
    #[error("{file}: not a PNG file: {detail}")]
    NotPng {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
    /// The PNG file is not a single-channel 16-bit image (grayscale, 16 bits per sample), so its
    /// values are not heights. Fix: export the heights as a 16-bit grayscale PNG, for instance
    /// with `gdal_translate -of PNG -ot UInt16 IN OUT.png`.
    #[error("{file}: the PNG holds {found}, not 16-bit grayscale heights; export the heights as a 16-bit grayscale PNG (for instance `gdal_translate -of PNG -ot UInt16 IN OUT.png`)")]
    PngUnsupported {
        /// The file.
        file: String,
        /// What the file holds (bit depth and colour type).
        found: String,
    },
    /// The PNG file is damaged: a chunk, a checksum or the compressed data cannot be decoded, or
    /// it ends early. Fix: obtain an intact copy of the file.
    #[error("{file}: the PNG file is damaged: {detail}; obtain an intact copy of the file")]
    PngCorrupt {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// The extent or value mapping given by the caller for a file that does not carry its own
    /// (a PNG) is unusable: a bound or the scale or offset is not a finite number, west is not
    /// less than east, south not less than north, a latitude outside [-90, 90], more than 360
    /// degrees of longitude, or a zero scale. Fix: pass the file's true extent.
    #[error("{file}: the extent given for the file is unusable: {detail}")]
    InvalidExtent {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
}

/// The names in `items`, separated by commas, or `no variables` when there are none.
fn list(items: &[String]) -> String {
    if items.is_empty() {
        "no variables".to_owned()
    } else {
        items.join(", ")
    }
}

impl DemError {
    /// The file the error is about, as named in its message.
    pub fn file(&self) -> &str {
        match self {
            DemError::Io { file, .. }
            | DemError::NotNetcdf { file, .. }
            | DemError::Truncated { file, .. }
            | DemError::HeaderTooLarge { file, .. }
            | DemError::Corrupt { file, .. }
            | DemError::NoGridVariable { file, .. }
            | DemError::AmbiguousVariable { file, .. }
            | DemError::VariableNotFound { file, .. }
            | DemError::UnsuitableVariable { file, .. }
            | DemError::MissingAxis { file, .. }
            | DemError::AxisNotMonotonic { file, .. }
            | DemError::OutOfGrid { file, .. }
            | DemError::AxisUneven { file, .. }
            | DemError::AxisInvalid { file, .. }
            | DemError::LatitudeOutOfRange { file, .. }
            | DemError::TooLarge { file, .. }
            | DemError::NoValidData { file, .. }
            | DemError::NotCubeDem { file, .. }
            | DemError::UnsupportedVersion { file, .. }
            | DemError::CubeCorrupt { file, .. }
            | DemError::Write { file, .. }
            | DemError::InvalidOptions { file, .. }
            | DemError::EmptySource { file }
            | DemError::NotTiff { file, .. }
            | DemError::TiffUnsupported { file, .. }
            | DemError::TiffCorrupt { file, .. }
            | DemError::NoGeoreference { file, .. }
            | DemError::NotGeographic { file, .. }
            | DemError::NotPng { file, .. }
            | DemError::PngUnsupported { file, .. }
            | DemError::PngCorrupt { file, .. }
            | DemError::InvalidExtent { file, .. } => file,
        }
    }
}
