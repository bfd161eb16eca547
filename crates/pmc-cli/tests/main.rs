//! The integration tests of `pmc-cli`, one test binary for all of them (`cargo test -p pmc-cli
//! --test cli MODULE::` runs one file's): each file below is a module.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod cli;
mod dem;
mod edit;
mod imagery;
mod kill;
mod path;
mod region;
mod serve;
mod tiles;
