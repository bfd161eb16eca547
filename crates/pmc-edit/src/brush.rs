//! Brush operations: edits in world space.
//!
//! An edit is a brush applied once at a place: its kind, centre (world metres, planet-centred),
//! radius and strength. Edits live in world space, never in a chunk or a face, so every chunk,
//! face and level of detail that covers a place sees the same result.

use pmc_geometry::glam::DVec3;

/// Largest brush radius accepted, metres.
pub const MAX_BRUSH_RADIUS: f64 = 1.0e5;

/// What a brush does inside its sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BrushKind {
    /// Adds material: the union with a ball.
    Add,
    /// Removes material: carves a ball.
    Remove,
    /// Smooths the surface: blends the density toward its local average.
    Smooth,
    /// Flattens toward the plane through the centre, perpendicular to the local vertical.
    Flatten,
    /// Paints a material on the surface (no change of shape).
    Paint {
        /// Material id (index into the terrain's material list).
        material: u8,
    },
}

impl BrushKind {
    /// The brush's command-line / API name.
    pub fn name(&self) -> &'static str {
        match self {
            BrushKind::Add => "add",
            BrushKind::Remove => "remove",
            BrushKind::Smooth => "smooth",
            BrushKind::Flatten => "flatten",
            BrushKind::Paint { .. } => "paint",
        }
    }
}

/// One edit: a brush applied at a place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushOp {
    /// What the brush does.
    pub kind: BrushKind,
    /// Centre in world space (metres, planet-centred).
    pub center: DVec3,
    /// Radius in metres, in `(0, MAX_BRUSH_RADIUS]`.
    pub radius: f64,
    /// Strength in `(0, 1]` (how far smoothing and flattening go; add and remove are full balls at
    /// strength 1 and shrink with it).
    pub strength: f64,
}

/// Why a brush operation was refused. Each variant says what to change.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BrushError {
    /// A centre coordinate is NaN or infinite.
    #[error("brush centre ({0}, {1}, {2}) is not a finite point; give metres, planet-centred")]
    Center(f64, f64, f64),
    /// The radius is not in `(0, MAX_BRUSH_RADIUS]`.
    #[error("brush radius {0} must be a number of metres above 0 and at most {MAX_BRUSH_RADIUS}")]
    Radius(f64),
    /// The strength is not in `(0, 1]`.
    #[error("brush strength {0} must be above 0 and at most 1")]
    Strength(f64),
}

impl BrushOp {
    /// A validated brush operation.
    pub fn new(kind: BrushKind, center: DVec3, radius: f64, strength: f64) -> Result<BrushOp, BrushError> {
        if !center.is_finite() {
            return Err(BrushError::Center(center.x, center.y, center.z));
        }
        if !(radius > 0.0 && radius <= MAX_BRUSH_RADIUS) {
            return Err(BrushError::Radius(radius));
        }
        if !(strength > 0.0 && strength <= 1.0) {
            return Err(BrushError::Strength(strength));
        }
        Ok(BrushOp { kind, center, radius, strength })
    }

    /// Whether the brush can change anything within `r` metres of `p` (its sphere of influence,
    /// including the margin smoothing reads, touches that ball).
    pub fn touches_ball(&self, p: DVec3, r: f64) -> bool {
        (p - self.center).length() <= self.reach() + r
    }

    /// Radius of the brush's influence: beyond it, density and paint are unchanged.
    pub fn reach(&self) -> f64 {
        self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(BrushOp::new(BrushKind::Add, DVec3::ONE, 4.0, 1.0).is_ok());
        assert!(matches!(BrushOp::new(BrushKind::Add, DVec3::new(f64::NAN, 0.0, 0.0), 4.0, 1.0), Err(BrushError::Center(..))));
        assert!(matches!(BrushOp::new(BrushKind::Add, DVec3::ONE, 0.0, 1.0), Err(BrushError::Radius(_))));
        assert!(matches!(BrushOp::new(BrushKind::Add, DVec3::ONE, f64::INFINITY, 1.0), Err(BrushError::Radius(_))));
        assert!(matches!(BrushOp::new(BrushKind::Add, DVec3::ONE, 1.0, 1.5), Err(BrushError::Strength(_))));
        assert!(matches!(BrushOp::new(BrushKind::Add, DVec3::ONE, 1.0, f64::NAN), Err(BrushError::Strength(_))));
    }
}
