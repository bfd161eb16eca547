//! The integration tests of `pmc-tiles`, one test binary for all of them (`cargo test -p pmc-tiles
//! --test tiles MODULE::` runs one file's): each file below is a module.

mod tiles;
