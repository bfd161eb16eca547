//! The integration tests of `pmc-planet`, one test binary for all of them (`cargo test -p pmc-planet
//! --test planet MODULE::` runs one file's): each file below is a module.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod closed_chunks;
mod edit;
mod lod_seams;
mod planet;
