//! Digital elevation models: equirectangular grids read from netCDF classic, GeoTIFF and 16-bit
//! PNG files (heights in metres at evenly spaced longitudes and latitudes, with bilinear sampling
//! that wraps round the globe), and `.pmcdem` files made from them (see "Elevation files"
//! below).
//!
//! [`EquirectDem::read_netcdf`] reads a netCDF classic (CDF-1) or 64-bit offset (CDF-2) file such
//! as NOAA's ETOPO relief grids; [`EquirectDem::read_geotiff`] a single-band GeoTIFF in
//! longitudes and latitudes (strips or tiles, integer or float samples); and
//! [`EquirectDem::read_png16`] a 16-bit grayscale PNG over an extent the caller gives
//! ([`PngExtent`]). Every grid is normalised to one layout (rows from south to north, columns
//! from west to east, the first longitude in [-180, 180), a column repeated one turn later
//! dropped) whatever the file's order. [`NetcdfSource`] and [`GeoTiffSource`] read a band of
//! rows at a time ([`EquirectSource`]), so that grids larger than memory can be imported.
//! Input from outside is checked before it is trusted: every problem is a [`DemError`] naming the
//! file, never a panic (the readers are mutation-fuzzed, see [`fuzz`]), and sizes are checked
//! against the file before memory is reserved.
//!
//! ```
//! use pmc_dem::EquirectDem;
//!
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
//! let dem = EquirectDem::read_netcdf(&path, None)?; // the variable ROSE, found by shape
//! assert_eq!((dem.width(), dem.height()), (360, 180)); // one-degree cells
//! assert_eq!((dem.lon(0), dem.lat(0)), (20.5, -89.5)); // cell centres, from the south-west
//! assert!(dem.wraps_in_longitude());
//!
//! // Interpolated heights, in metres; any longitude, wrapping across the antimeridian.
//! let himalaya = dem.sample_bilinear(28.0, 87.0).unwrap();
//! let pacific = dem.sample_bilinear(0.0, -150.0).unwrap();
//! assert!(himalaya > 3000.0 && pacific < -3000.0);
//! assert_eq!(dem.sample_bilinear(0.0, 210.0), Some(pacific));
//!
//! let stats = dem.stats();
//! assert_eq!(stats.missing, 0);
//! assert!(stats.min < -7000.0 && stats.max > 5000.0); // a trench, the Himalaya
//! # Ok::<(), pmc_dem::DemError>(())
//! ```
//!
//! # Elevation files
//!
//! [`import_cube`] writes a `.pmcdem` file (spec: `docs/specs/pmcdem-v2.md`) from any
//! [`EquirectSource`]: the source grid itself in checksummed tiles, and its reprojection onto
//! the six faces of the cube-sphere (`2^n + 1` samples a face side with bit-identical shared
//! edges, decimated overviews down to 65 samples), read in bands of rows within a memory budget.
//! [`CubeDem`] reads it tile by tile (a bounded cache, `Send + Sync`) and gives heights anywhere:
//! the source grid interpolated in its own index space, **exact at every source sample**, plus
//! [`DetailNoise`] octaves below the data resolution that fade to zero at every source sample
//! (seed 003 Sec. 4.5, 4.6). [`cube::accuracy`] measures that over every source sample. Version
//! 1 files (`docs/specs/pmcdem-v1.md`, cube faces only) are still read.
//!
//! ```
//! use pmc_dem::cube::{accuracy, import_cube, CubeDem, DetailNoise, ImportOptions, Interpolation};
//! use pmc_dem::EquirectDem;
//! use pmc_geometry::{glam::IVec3, LatLon};
//!
//! let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
//! let dem = EquirectDem::read_netcdf(&src, None)?;
//! let out = std::env::temp_dir().join(format!("pmc-dem-doc-{}.pmcdem", std::process::id()));
//! let options = ImportOptions { level: Some(6), ..Default::default() }; // 65 samples a side
//! let report = import_cube(&dem, &out, &options, &|_done, _total| {})?;
//! assert_eq!(report.level, 6);
//!
//! let cube = CubeDem::open(&out)?;
//! cube.verify()?; // every tile's checksum and the content digest
//! let detail = DetailNoise::default();
//! // Any direction, with detail octaves down to 10 m.
//! let everest = LatLon::new(28.0, 87.0).unwrap().to_unit();
//! let h = cube.height(everest, Interpolation::Bicubic, &detail, 10.0);
//! assert!(h > 2000.0, "{h}");
//! // Every source sample is kept: here at cell (3, 4) of the one-degree grid.
//! let (lat, lon) = (dem.lat(4), dem.lon(3));
//! let at = LatLon::new(lat, lon).unwrap().to_unit();
//! let kept = cube.height(at, Interpolation::Bicubic, &detail, 1.0);
//! assert!((kept - f64::from(dem.value(3, 4).unwrap())).abs() < 1e-6);
//! // And over all of them.
//! let check = accuracy(&cube, &dem, Interpolation::Bilinear, &detail)?;
//! assert!(check.max < 1e-6 && check.samples == 360 * 180);
//! // A lattice point has the same height at every resolution that holds it.
//! let centre = IVec3::new(0, 0, 64);
//! let coarse = cube.height_at_lattice(centre, 64, Interpolation::Bilinear, &detail);
//! assert_eq!(coarse, cube.height_at_lattice(centre * 4, 256, Interpolation::Bilinear, &detail));
//! # std::fs::remove_file(&out).unwrap();
//! # Ok::<(), pmc_dem::DemError>(())
//! ```
//!
//! The example `dem_import` times an import by hand:
//! `cargo run --release -p pmc-dem --example dem_import -- IN.cdf OUT.pmcdem [LEVEL] [BUDGET_MIB]`.
//!
//! The example `dem_info` prints what is read from a file:
//! `cargo run --release -p pmc-dem --example dem_info -- FILE.cdf [VARIABLE]`.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod axis;
pub mod cube;
mod dem;
mod error;
mod header;
mod read;
mod source;
mod terrain;

mod netcdf_source;
pub use netcdf_source::NetcdfSource;
mod geotiff;
pub use geotiff::{GeoTiffSource, Georeference, MAX_CHUNK_ROW_CELLS};
mod png16;
pub use png16::PngExtent;
pub mod fuzz;

pub use cube::{import_cube, CubeDem, DetailNoise, ImportOptions, ImportReport, Interpolation};
pub use cube::{FormatChoice, SourceAxes, StorageRow, DEFAULT_RADIUS};
pub use dem::{DemStats, EquirectDem};
pub use error::DemError;
pub use header::MAX_HEADER_BYTES;
pub use pmc_density::terrain::HeightField;
pub use read::MAX_CELLS;
pub use source::EquirectSource;
pub use terrain::{dem_heights, dem_layout, dem_terrain, nearest_sample, DemHeights, DemTerrainError, NearestSample};
