//! Terrain sources as values, and terrains built over height fields.
//!
//! - [`TerrainSpec`]: what a planet's terrain is made from (a preset and a seed, or an elevation
//!   model), with a canonical text form for files and identities.
//! - [`HeightField`] and [`heightfield_terrain`]: a volumetric terrain over any height field
//!   (an elevation model read elsewhere), with caves under its land.

mod heightfield;
mod spec;

pub use heightfield::{heightfield_terrain, HeightField, ReliefError, HEIGHTFIELD_MATERIALS, SHELF_DEPTH};
pub use spec::{DemSpec, Interpolation, TerrainSpec, TerrainSpecError};
