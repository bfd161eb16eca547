//! Cube-face elevation models (seed 003 Sec. 4.5, 4.6, 8.2): an equirectangular grid reprojected
//! once onto the six faces of the cube-sphere and stored as a `.pmcdem` file
//! (`docs/specs/pmcdem-v1.md`), then sampled anywhere with interpolation that is exact at the
//! data samples and detail noise below the data resolution that is zero at them.

mod detail;
mod format;
mod import;
mod lattice;
mod reader;
mod sample;
mod source_grid;

pub use detail::{
    DetailNoise, DEFAULT_DETAIL_SEED, DEFAULT_MAX_AMPLITUDE, DEFAULT_RELIEF_SLOPE, DEFAULT_ROUGHNESS,
    MAX_DETAIL_OCTAVES,
};
pub use format::{
    stored_levels, SampleFormat, COARSEST_OVERVIEW_LOG2, DEFAULT_TILE_SIZE, HEADER_BYTES, MAGIC, MAX_DATA_LEVEL,
    VERSION,
};
pub use import::{
    centre_spacing_radians, default_level, import_cube, FormatChoice, ImportOptions, ImportReport,
    DEFAULT_MEMORY_BUDGET, DEFAULT_RADIUS, MAX_TILES,
};
pub use reader::{CubeDem, StorageRow, DEFAULT_CACHE_BYTES};
pub use sample::{Interpolation, MAX_LATTICE_RESOLUTION};
