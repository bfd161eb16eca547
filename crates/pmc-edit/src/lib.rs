//! Runtime terrain editing: world-space brushes over any density, with undo and redo.
//!
//! - [`BrushOp`]: one edit (add, remove, smooth, flatten, paint) at a place, and what it does to a
//!   density value ([`BrushOp::apply`]).
//! - [`EditLog`]: the ordered list of edits with undo and redo; [`EditSnapshot`]: an immutable,
//!   cheaply shared copy of its active edits for meshing threads.
//! - [`EditedDensity`]: any [`pmc_density::Density`] with a snapshot's edits applied in order,
//!   each a pure function of the world position, so chunks keep agreeing bit for bit on shared
//!   voxels. [`paint_at`] gives the paint at a point, for shading.
//! - [`affected_chunks`]: the chunks whose meshes an edit can change (their padded samples may lie
//!   within the brush's reach), found without visiting the whole planet.
//!
//! ```
//! use pmc_density::{Density, Sphere};
//! use pmc_edit::{BrushKind, BrushOp, EditLog, EditedDensity};
//! use pmc_geometry::glam::DVec3;
//! let mut log = EditLog::new();
//! let top = DVec3::Y * 100.0;
//! log.push(BrushOp::new(BrushKind::Remove, top, 5.0, 1.0).unwrap());
//! let dug = EditedDensity::new(Sphere { radius: 100.0 }, log.snapshot());
//! assert!(dug.density(top - DVec3::Y * 2.0) < 0.0, "air where the ball was carved");
//! log.undo();
//! let back = EditedDensity::new(Sphere { radius: 100.0 }, log.snapshot());
//! assert!(back.density(top - DVec3::Y * 2.0) > 0.0);
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod affected;
mod brush;
mod edited;
mod log;
mod region;

pub use affected::{affected_chunks, affected_chunks_at, affected_chunks_lod, effective_reach, LIPSCHITZ};
pub use brush::{falloff, BrushError, BrushKind, BrushOp, BLEND_MARGIN, MAX_BRUSH_RADIUS};
pub use edited::{paint_at, EditedDensity};
pub use log::{EditId, EditLog, EditSnapshot};
