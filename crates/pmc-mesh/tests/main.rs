//! The integration tests of `pmc-mesh`, one test binary for all of them (`cargo test -p pmc-mesh
//! --test mesh MODULE::` runs one file's): each file below is a module.
//! One binary instead of one per file: the suite compiles and links the dependencies'
//! generic code once per crate, not once per file.

mod caps;
mod closed_planet;
mod region;
