//! The integration tests of `pmc-lod`, one test binary for all of them (`cargo test -p pmc-lod
//! --test lod MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod adjacency;
mod closed;
mod common;
mod dem;
mod errors;
mod heightfield;
mod selection;
mod vectors;
