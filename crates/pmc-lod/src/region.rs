//! A region of a planet at one level of detail: what `pmc generate --region` exports.
//!
//! The region is a ball around a point (usually on the surface) and the chunks are those of one
//! level whose provable bounding spheres ([`crate::bounds`]) meet the ball and that may hold
//! surface. One level throughout means no seam between levels inside the region: the chunks'
//! meshes join by canonical edge keys as a whole planet's do, and the region is cut only at its
//! rim. The level is given, or chosen as the coarsest level whose measured error
//! ([`crate::measure_level_errors`]) stays within a tolerance.

use crate::bounds::{chunks_near, TooManyChunks};
use pmc_geometry::glam::DVec3;
use pmc_geometry::ChunkKey;
use pmc_planet::Planet;

/// The most chunks a region export may hold (`pmc generate --region`, the Python package's
/// `Planet.region`): the `budget` front ends give [`region_chunks`].
pub const REGION_BUDGET: usize = 200_000;

/// Why a region cannot be exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionError {
    /// The radius is not a finite number above zero.
    #[error("the region radius must be a finite number of metres above 0, got {0}")]
    Radius(f64),
    /// The centre is not finite.
    #[error("the region centre must be a finite point")]
    Center,
    /// The level is not one of the layout's.
    #[error("level {level} is not a level of this planet (0 to {max_level})")]
    Level {
        /// The level asked for.
        level: u8,
        /// The layout's coarsest level.
        max_level: u8,
    },
    /// The region holds more chunks of the level than the budget allows.
    #[error(
        "the region holds more than {budget} chunks at level {level}; lower the radius, or pick a coarser level (--level) or a larger error (--max-error)"
    )]
    TooManyChunks {
        /// The level asked for.
        level: u8,
        /// The budget.
        budget: usize,
    },
}

/// The coarsest level whose error `errors[L]` (metres, non-decreasing, as
/// [`crate::measure_level_errors`] gives) is at most `max_error`; level 0 when none is.
pub fn level_for_error(errors: &[f64], max_error: f64) -> u8 {
    errors
        .iter()
        .enumerate()
        .filter(|(_, e)| **e <= max_error)
        .map(|(l, _)| l as u8)
        .max()
        .unwrap_or(0)
}

/// The chunks of `level` that meet the ball of `radius` metres around `center` and may hold
/// surface, in key order. At most `budget` chunks are considered.
pub fn region_chunks(
    planet: &Planet,
    center: DVec3,
    radius: f64,
    level: u8,
    budget: usize,
) -> Result<Vec<ChunkKey>, RegionError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(RegionError::Radius(radius));
    }
    if !center.is_finite() {
        return Err(RegionError::Center);
    }
    let max_level = planet.layout().max_level();
    if level > max_level {
        return Err(RegionError::Level { level, max_level });
    }
    let (hits, _) = chunks_near(planet, level, center, radius, budget, budget)
        .map_err(|TooManyChunks { budget }| RegionError::TooManyChunks { level, budget })?;
    let mut keys: Vec<ChunkKey> = hits.into_iter().map(|h| h.key).collect();
    keys.sort_unstable();
    Ok(keys)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Layout;
    use pmc_planet::PresetKind;

    #[test]
    fn the_level_for_an_error_is_the_coarsest_within_it() {
        let errors = [0.0, 1.0, 3.0, 9.0];
        assert_eq!(level_for_error(&errors, 0.5), 0);
        assert_eq!(level_for_error(&errors, 3.0), 2);
        assert_eq!(level_for_error(&errors, 100.0), 3);
    }

    #[test]
    fn a_region_holds_the_chunks_near_its_centre_and_refuses_bad_input() {
        let planet = Planet::new(PresetKind::Earthlike, 7, Layout::default());
        let centre = DVec3::new(0.2, 1.0, 0.1).normalize() * planet.datum_radius();
        let small = region_chunks(&planet, centre, 50.0, 0, 10_000).unwrap();
        let large = region_chunks(&planet, centre, 400.0, 0, 10_000).unwrap();
        assert!(!small.is_empty() && small.len() < large.len());
        assert!(small.iter().all(|k| large.contains(k) && k.level == 0));
        let coarse = region_chunks(&planet, centre, 400.0, 2, 10_000).unwrap();
        assert!(coarse.len() < large.len() && coarse.iter().all(|k| k.level == 2));
        assert!(matches!(
            region_chunks(&planet, centre, f64::NAN, 0, 10),
            Err(RegionError::Radius(_))
        ));
        assert!(matches!(
            region_chunks(&planet, centre, -1.0, 0, 10),
            Err(RegionError::Radius(_))
        ));
        assert!(matches!(
            region_chunks(&planet, DVec3::NAN, 1.0, 0, 10),
            Err(RegionError::Center)
        ));
        assert!(matches!(
            region_chunks(&planet, centre, 1.0, 9, 10),
            Err(RegionError::Level { .. })
        ));
        assert!(matches!(
            region_chunks(&planet, centre, 1500.0, 0, 10),
            Err(RegionError::TooManyChunks { .. })
        ));
    }
}
