//! The integration tests of `pmc-formats`, one test binary for all of them (`cargo test -p pmc-formats
//! --test formats MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod chunk_encoding;
mod common;
mod errors;
mod glb;
mod welded;
