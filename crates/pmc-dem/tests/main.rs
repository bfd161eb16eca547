//! The integration tests of `pmc-dem`, one test binary for all of them (`cargo test -p pmc-dem
//! --test dem MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod common;
mod cube;
mod etopo60;
mod fuzz_readers;
mod geotiff;
mod landmarks;
mod mutations;
mod netcdf_files;
mod netcdf_source;
mod png16;
mod reader_fixtures;
mod source_grid;
