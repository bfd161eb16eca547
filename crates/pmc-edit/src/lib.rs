//! Runtime terrain editing: world-space brushes over any density, with undo and redo.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod brush;

pub use brush::{BrushError, BrushKind, BrushOp, MAX_BRUSH_RADIUS};
