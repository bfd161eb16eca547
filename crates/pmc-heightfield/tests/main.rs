//! The integration tests of `pmc-heightfield`, one test binary for all of them (`cargo test -p pmc-heightfield
//! --test heightfield MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod closed;
mod common;
mod patches;
