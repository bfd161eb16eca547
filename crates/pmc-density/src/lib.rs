//! Density sources for planetary marching cubes.
//!
//! - [`Density`]: the small composable trait (one point, or a whole chunk in one batch call).
//!   Positive density is solid, the surface is at zero.
//! - [`noise`]: fractal 3D gradient noise in `f64`, sampled on the sphere (seed 000 Sec. 4.6).
//! - [`presets`]: terrains with continents, mountains, seas, caves and overhangs.
//! - [`terrain`]: terrain sources as values ([`terrain::TerrainSpec`]) and volumetric terrains
//!   over any height field, such as an elevation model.
// `unsafe` only in the vector noise kernel (`noise::lanes`), behind a run-time feature check.
#![deny(unsafe_code)]
#![warn(missing_docs)]

mod chunk_samples;
mod density;
pub mod noise;
pub mod presets;
pub mod terrain;

pub use chunk_samples::ChunkSamples;
pub use density::{Density, FnDensity, ShellColumns, Sphere, Subtract, Union};
