//! The integration tests of `pmc-nav`, one test binary for all of them (`cargo test -p pmc-nav
//! --test nav MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod common;
mod hierarchical;
mod lazy;
mod paper;
mod properties;
mod rebuild_from_chunks;
mod smooth;
