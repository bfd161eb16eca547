//! The integration tests of `pmc-server`, one test binary for all of them (`cargo test -p pmc-server
//! --test server MODULE::` runs one file's): each file below is a module; they share `common`.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod api;
mod batch;
mod common;
mod edit;
mod flight;
mod heightfield;
mod imagery;
mod jobs;
mod listen;
mod nav;
mod relief;
mod tiles;
