//! Elevation files (seed 003 Sec. 4.5, 4.6, 8.2): an equirectangular grid stored as a `.pmcdem`
//! file (`docs/specs/pmcdem-v2.md`) with its reprojection onto the six faces of the cube-sphere,
//! then sampled anywhere by interpolating the stored grid (exact at every source sample) plus
//! detail noise below the data resolution that fades to zero at every source sample. Version 1
//! files (`docs/specs/pmcdem-v1.md`, faces only) are sampled from the faces as before.

mod accuracy;
mod detail;
mod format;
mod import;
mod lattice;
mod reader;
mod sample;
mod source_grid;
mod source_sample;

pub use accuracy::{accuracy, Accuracy, WorstSample, ACCURACY_FINEST_SPACING_M};
pub use detail::{
    DetailNoise, DEFAULT_DETAIL_SEED, DEFAULT_MAX_AMPLITUDE, DEFAULT_RELIEF_SLOPE, DEFAULT_ROUGHNESS,
    MAX_DETAIL_OCTAVES,
};
pub use format::{
    stored_levels, SampleFormat, COARSEST_OVERVIEW_LOG2, DEFAULT_SOURCE_TILE_SIZE, DEFAULT_TILE_SIZE, HEADER_BYTES,
    HEADER_BYTES_V2, MAGIC, MAX_DATA_LEVEL, VERSION,
};
pub use import::{
    centre_spacing_radians, default_level, import_cube, FormatChoice, ImportOptions, ImportReport,
    DEFAULT_MEMORY_BUDGET, DEFAULT_RADIUS, MAX_TILES,
};
pub use reader::{CubeDem, SourceAxes, StorageRow, DEFAULT_CACHE_BYTES};
pub use sample::{Interpolation, MAX_LATTICE_RESOLUTION};
pub use source_sample::SAMPLE_FADE_RADIUS;
