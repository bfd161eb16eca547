//! A planet: layout plus terrain, meshed chunk by chunk.
//!
//! [`Planet::chunk_mesh`] runs the whole pipeline for one chunk (sample the density in one batch
//! call, apply the shell boundary contract, march the cubes, shade the vertices);
//! [`Planet::generate`] does it for every chunk on all threads. Output is deterministic: the same
//! preset, seed and layout give byte-identical meshes at any thread count, because every chunk is
//! computed from canonical voxel keys alone and results are ordered by chunk key.
//!
//! Edits ([`pmc_edit`] brush operations) apply through [`Planet::set_edits`]; after an edit,
//! [`Planet::remesh`] meshes exactly the chunks it can change. With
//! [`Planet::with_base_cache`] the terrain's density batches are kept per chunk, so remeshing
//! after an edit pays only for the edit, not for the terrain noise again.
//!
//! ```
//! use pmc_planet::{Planet, PresetKind};
//! use pmc_geometry::Layout;
//! let planet = Planet::new(PresetKind::Sphere, 1, Layout::new(1, 8, 40.0, 1.0, 1).unwrap());
//! let meshes = planet.generate(|_| {});
//! assert!(meshes.iter().map(|m| m.triangle_count()).sum::<usize>() > 0);
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod cache;
pub mod heightfield;
mod planet;
mod spec;
mod terrain;

pub use cache::BaseCacheStats;
pub use planet::{ChunkScratch, Planet};
pub use pmc_density::presets::{PresetKind, Terrain, UnknownPreset};
pub use pmc_density::terrain::{DemSpec, Interpolation, TerrainSpec};
pub use pmc_edit;
pub use spec::{dem_terrain, LayoutChoice};
pub use terrain::{build_terrain, default_layout, TerrainError};
