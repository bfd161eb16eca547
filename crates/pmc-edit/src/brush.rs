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
        Ok(BrushOp {
            kind,
            center,
            radius,
            strength,
        })
    }

    /// Whether the brush can change anything within `r` metres of `p` (its sphere of influence,
    /// [`BrushOp::reach`], touches that ball).
    pub fn touches_ball(&self, p: DVec3, r: f64) -> bool {
        (p - self.center).length() <= self.reach() + r
    }

    /// Radius of the brush's influence: at and beyond it, density and paint are unchanged.
    ///
    /// Smooth, flatten and paint act within `radius`. Add and remove carve or fill a ball of radius
    /// `strength * radius` and then fade the density back to the terrain's over a shell of
    /// [`BLEND_MARGIN`]` * radius` around `radius`, so the density stays continuous where the
    /// brush stops (see [`BrushOp::apply`]).
    pub fn reach(&self) -> f64 {
        match self.kind {
            BrushKind::Add | BrushKind::Remove => self.radius * (1.0 + BLEND_MARGIN),
            BrushKind::Smooth | BrushKind::Flatten | BrushKind::Paint { .. } => self.radius,
        }
    }

    /// The span of radii `(lo, hi)` where points `dir * r` of the column along `dir` may lie
    /// within [`reach`](Self::reach) of the centre: the exact span widened by a generous slack
    /// for rounding, so every point with `|dir r - center| < reach` (computed in `f64`) has
    /// `lo <= r <= hi`. `None` when the column passes wide of the reach, or `dir` is zero or NaN.
    pub fn column_span(&self, dir: DVec3) -> Option<(f64, f64)> {
        let (c, reach) = (self.center, self.reach());
        let slack = 1e-7 * (c.length() + reach) + 1e-7;
        let outer = reach + slack;
        let len2 = dir.length_squared();
        if len2.is_nan() || len2 == 0.0 {
            return None;
        }
        // Distance from the centre to the column's line, and the span of `r` where the line is
        // inside the (slightly enlarged) ball.
        let t = dir.dot(c) / len2;
        let perp = (c - dir * t).length();
        if perp.is_nan() || perp > outer {
            return None;
        }
        let half = (outer * outer - perp * perp).max(0.0).sqrt() / len2.sqrt() + slack;
        Some((t - half, t + half))
    }

    /// Whether the brush changes the density (every kind but paint).
    pub fn shapes(&self) -> bool {
        !matches!(self.kind, BrushKind::Paint { .. })
    }

    /// The radius of the ball that add fills and remove carves: `strength * radius`.
    pub fn ball_radius(&self) -> f64 {
        self.strength * self.radius
    }

    /// Distance between smoothing's sample points and the point they smooth: `radius / 4`.
    pub fn smooth_step(&self) -> f64 {
        0.25 * self.radius
    }

    /// The unit "up" of flattening: the direction of the centre from the planet centre (`+Y` for a
    /// brush at the planet centre).
    pub fn up(&self) -> DVec3 {
        self.center.try_normalize().unwrap_or(DVec3::Y)
    }

    /// Applies the brush to density `d` (the density before this brush) at world point `p`, which
    /// must lie at distance `q = |p - center| < reach()` (callers leave `d` unchanged elsewhere).
    /// `neighbours` gives the density before this brush at another point; only smoothing calls it
    /// (six times, at `p +- smooth_step()` along the world axes).
    ///
    /// With `s` the strength, `R` the radius and `w(x) = (1 - x^2)^2` (1 at the centre, 0 with zero
    /// slope at the edge):
    ///
    /// - **Add**: `d' = max(d, rho - q)` with `rho = s R` (union with the ball of radius `rho`, an
    ///   exact distance near its surface); between `R` and `reach` the change fades out by
    ///   `w((q - R) / (reach - R))`, which only ever touches air (`rho - q < 0` there), so the solid
    ///   is exactly the terrain's plus the open ball.
    /// - **Remove**: `d' = min(d, q - rho)`, faded the same way: the solid is the terrain's minus
    ///   the closed ball of radius `rho`.
    /// - **Smooth**: `d' = d + s w(q / R) (avg - d)`, `avg` the mean of the density before this
    ///   brush at the six points `p +- (R / 4) e_x, e_y, e_z`.
    /// - **Flatten**: `d' = d + s w(q / R) (plane - d)`, `plane = dot(center - p, up)`, the signed
    ///   distance to the plane through the centre perpendicular to `up`, positive below it.
    /// - **Paint**: `d' = d`.
    ///
    /// Every change is continuous and vanishes at `reach`, so no seam appears where the brush
    /// stops. Pure: the result depends on `d`, `p` and the brush only.
    pub fn apply(&self, d: f64, p: DVec3, q: f64, mut neighbours: impl FnMut(DVec3) -> f64) -> f64 {
        let r = self.radius;
        match self.kind {
            BrushKind::Add | BrushKind::Remove => {
                let ball = self.ball_radius() - q;
                let target = if self.kind == BrushKind::Add {
                    d.max(ball)
                } else {
                    d.min(-ball)
                };
                if q < r {
                    target
                } else {
                    let x = (q - r) / (self.reach() - r);
                    d + falloff(x) * (target - d)
                }
            }
            BrushKind::Smooth => {
                let w = self.strength * falloff(q / r);
                if w == 0.0 {
                    return d;
                }
                let h = self.smooth_step();
                let mut sum = 0.0;
                for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                    sum += neighbours(p + axis * h) + neighbours(p - axis * h);
                }
                d + w * (sum / 6.0 - d)
            }
            BrushKind::Flatten => {
                let w = self.strength * falloff(q / r);
                let plane = (self.center - p).dot(self.up());
                d + w * (plane - d)
            }
            BrushKind::Paint { .. } => d,
        }
    }
}

/// How far beyond its radius an add or remove brush fades back to the terrain, as a fraction of
/// the radius (see [`BrushOp::reach`]).
pub const BLEND_MARGIN: f64 = 0.25;

/// The brushes' weight falloff `(1 - x^2)^2` for `x` in `[0, 1]`: 1 at 0, 0 (with zero slope) at 1
/// and beyond.
pub fn falloff(x: f64) -> f64 {
    let t = (1.0 - x * x).max(0.0);
    t * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(BrushOp::new(BrushKind::Add, DVec3::ONE, 4.0, 1.0).is_ok());
        assert!(matches!(
            BrushOp::new(BrushKind::Add, DVec3::new(f64::NAN, 0.0, 0.0), 4.0, 1.0),
            Err(BrushError::Center(..))
        ));
        assert!(matches!(
            BrushOp::new(BrushKind::Add, DVec3::ONE, 0.0, 1.0),
            Err(BrushError::Radius(_))
        ));
        assert!(matches!(
            BrushOp::new(BrushKind::Add, DVec3::ONE, f64::INFINITY, 1.0),
            Err(BrushError::Radius(_))
        ));
        assert!(matches!(
            BrushOp::new(BrushKind::Add, DVec3::ONE, 1.0, 1.5),
            Err(BrushError::Strength(_))
        ));
        assert!(matches!(
            BrushOp::new(BrushKind::Add, DVec3::ONE, 1.0, f64::NAN),
            Err(BrushError::Strength(_))
        ));
    }
}
