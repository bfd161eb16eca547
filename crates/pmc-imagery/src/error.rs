//! Why an image could not be imported, read or written.

/// A failure to import, read, write or encode imagery. Each variant names the file (the path as
/// given, or the name given with bytes held in memory), says what is wrong and what to do about
/// it. Every check that can be made from a header is made before pixels are decoded or memory is
/// reserved for them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImageryError {
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
    /// The output file (or its temporary file next to it) could not be created, written or
    /// renamed into place; nothing is left at the output path. Fix: check that the directory
    /// exists, is writable and has room.
    #[error("{file}: cannot write the file: {source}; check that the directory exists, is writable and has room")]
    Write {
        /// The file.
        file: String,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// The input is not an image this importer reads (JPEG, PNG or TIFF, by its first bytes);
    /// says what it looks like instead. Fix: check the path, or convert the image to PNG.
    #[error("{file}: not a JPEG, PNG or TIFF image: {detail}")]
    UnknownFormat {
        /// The file.
        file: String,
        /// What the file looks like.
        detail: String,
    },
    /// The image is valid but holds pixels this importer does not read (CMYK, 12-bit JPEG,
    /// a TIFF colour model other than grey, RGB or RGBA of 8 or 16 bits, a compression the TIFF
    /// reader lacks). Fix: convert it to an 8-bit RGB PNG, for instance with
    /// `convert IN -colorspace sRGB -depth 8 OUT.png`.
    #[error("{file}: {detail}; convert it to an 8-bit RGB PNG (for instance `convert IN -colorspace sRGB -depth 8 OUT.png`)")]
    Unsupported {
        /// The file.
        file: String,
        /// What was found.
        detail: String,
    },
    /// The image is damaged: its decoder failed (a bad marker, checksum or compressed stream),
    /// or it ends early. Fix: obtain an intact copy of the file.
    #[error("{file}: the image is damaged: {detail}; obtain an intact copy of the file")]
    Corrupt {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// The image has more pixels than imagery may hold ([`MAX_PIXELS`](crate::MAX_PIXELS)), or
    /// a side longer than [`MAX_SIDE`](crate::MAX_SIDE); refused before its pixels are decoded.
    /// Fix: scale it down, for instance with `convert IN -resize 16384x8192 OUT.png`.
    #[error("{file}: the image is {width} x {height} pixels; imagery holds at most {max_pixels} pixels and {max_side} a side: scale it down (for instance `convert IN -resize 16384x8192 OUT.png`)")]
    TooLarge {
        /// The file.
        file: String,
        /// Columns.
        width: u64,
        /// Rows.
        height: u64,
        /// The largest number of pixels accepted.
        max_pixels: u64,
        /// The longest side accepted.
        max_side: u64,
    },
    /// The extent is unusable: a bound is not a finite number, west is not less than east,
    /// south not less than north, a latitude outside [-90, 90], or more than 360 degrees of
    /// longitude; or the text given is not four numbers. Fix: give the image's true extent,
    /// `WEST,SOUTH,EAST,NORTH` in degrees (the outer edges of its pixels).
    #[error("{file}: the extent is unusable: {detail}")]
    InvalidExtent {
        /// The file the extent is for (or the option that gave it).
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// A TIFF given without an extent is not georeferenced as a longitude-latitude grid
    /// (missing GeoTIFF tags, a projected system, ...). Fix: georeference or reproject it, or
    /// give its extent.
    #[error("{detail}; or give the image's extent (WEST,SOUTH,EAST,NORTH, the outer edges of its pixels)")]
    Georeference {
        /// The file.
        file: String,
        /// What is wrong, naming the file.
        detail: String,
    },
    /// The file is not a `.pmcimg` imagery file: it does not start with the `.pmcimg`
    /// signature. Fix: check the path; make `.pmcimg` files with `pmc imagery import`.
    #[error("{file}: not a .pmcimg imagery file: {detail}")]
    NotImagery {
        /// The file.
        file: String,
        /// What was found instead.
        detail: String,
    },
    /// The `.pmcimg` file has a format version this reader does not know. Fix: read it with a
    /// newer version of this crate, or import its source image again.
    #[error("{file}: .pmcimg version {version} is not supported (this reader knows version 1); use a newer reader or import the image again")]
    UnsupportedVersion {
        /// The file.
        file: String,
        /// The version found in the header.
        version: u32,
    },
    /// The `.pmcimg` file is damaged: it is shorter or longer than its header says, a checksum
    /// or the content digest does not match, or a header field is invalid. Fix: copy the file
    /// again or import its source image again.
    #[error("{file}: the .pmcimg file is damaged: {detail}; copy it again or import its source image again")]
    Damaged {
        /// The file.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// Encoding the imagery as a PNG failed (it never should for valid imagery).
    #[error("cannot encode the imagery as PNG: {0}")]
    Encode(String),
}

impl ImageryError {
    /// The file the error is about, as named in its message (empty for [`ImageryError::Encode`]).
    pub fn file(&self) -> &str {
        match self {
            ImageryError::Io { file, .. }
            | ImageryError::Write { file, .. }
            | ImageryError::UnknownFormat { file, .. }
            | ImageryError::Unsupported { file, .. }
            | ImageryError::Corrupt { file, .. }
            | ImageryError::TooLarge { file, .. }
            | ImageryError::InvalidExtent { file, .. }
            | ImageryError::Georeference { file, .. }
            | ImageryError::NotImagery { file, .. }
            | ImageryError::UnsupportedVersion { file, .. }
            | ImageryError::Damaged { file, .. } => file,
            ImageryError::Encode(_) => "",
        }
    }

    /// Whether the error is about the input (a missing, unreadable or bad file, bad options)
    /// rather than the work (writing or encoding failed).
    pub fn is_input_error(&self) -> bool {
        !matches!(self, ImageryError::Write { .. } | ImageryError::Encode(_))
    }
}
