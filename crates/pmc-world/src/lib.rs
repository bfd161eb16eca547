//! The PMC world file: a planet's parameters and its edits, in order, with undo and redo, in one
//! durable SQLite file (format `pmc-world` version 2, specified in
//! `docs/specs/world-sqlite-v2.md`; version 1 files still open).
//!
//! ```
//! use pmc_edit::{BrushKind, BrushOp};
//! use pmc_geometry::{glam::DVec3, Layout};
//! use pmc_density::{presets::PresetKind, terrain::TerrainSpec};
//! use pmc_world::World;
//!
//! let dir = std::env::temp_dir().join(format!("pmc-world-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("doc.world");
//! # let _ = std::fs::remove_file(&path);
//! let mut world = World::create(&path, &TerrainSpec::preset(PresetKind::Earthlike, 7), &Layout::default())?;
//! let op = BrushOp::new(BrushKind::Remove, DVec3::new(0.0, 0.0, 1990.0), 6.0, 1.0)?;
//! let id = world.append(&op)?; // committed to disk when it returns
//! assert_eq!(world.undo()?, Some(id));
//! assert!(world.active_edits()?.is_empty());
//! world.redo()?;
//! drop(world);
//! let world = World::open(&path)?;
//! assert_eq!(world.active_edits()?, vec![op]);
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod error;
mod format;
mod world;

pub use error::{Result, WorldError};
pub use format::{APPLICATION_ID, FORMAT_NAME, FORMAT_VERSION, OLDEST_FORMAT_VERSION};
pub use world::{EditId, Entry, World};
