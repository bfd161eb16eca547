//! Each preset's layout, and a layout for any radius.
//!
//! # The rule for a radius `R`
//!
//! The shell is centred on `R`: the middle layer of the shell (the datum, where the earth preset
//! puts its sea) lies at `R`, so `d_b = R - T/2` with `T = l_d n_t d_c`, and the outermost layer
//! (the paper's Eq. 4 radius) at `R + T/2`.
//!
//! - `n_t = 32`.
//! - `n_c` is the largest power of two whose voxels are at least 1 m across the face on average,
//!   `(pi/2) R / (32 n_c) >= 1 m`, at most `2^18` (so the voxel counts stay within 64 bits) and
//!   at least 1. Voxels are then between 1 and 2 m across up to `R` of about 10 700 km, and the
//!   octree has `log2(n_c) + 1` levels of detail (19 at Earth's radius).
//! - `l_d` is the largest power of two of metres at most that voxel width: radial and lateral voxel
//!   sizes agree within a factor of two (1 m for every radius up to about 10 700 km).
//! - `d_c` is the smallest power of two with `T >= max(R / 200, min(256 m, R / 8))`, at most 1024
//!   (so `T >= R / 400` however large the planet): every preset sets its relief in proportion to
//!   `T` (the earth preset in metres scaled by `T / 32 768 m`), so this keeps the relief of the
//!   default planet for small radii and Earth's relief (`T = 32 768 m`, from -16 km to +16 km
//!   around the sea) at Earth's radius.
//!
//! Radii must be finite and between [`MIN_RADIUS`] and [`MAX_RADIUS`].

use super::PresetKind;
use pmc_geometry::{Layout, LayoutError};

/// The mean radius of the Earth in metres: the sea radius of the earth preset at true scale.
pub const EARTH_RADIUS: f64 = 6_371_000.0;
/// The smallest radius [`layout_for_radius`] accepts, in metres.
pub const MIN_RADIUS: f64 = 100.0;
/// The largest radius [`layout_for_radius`] accepts, in metres (about 16 times Jupiter's).
pub const MAX_RADIUS: f64 = 1e8;

/// Tiles per chunk side of the layouts chosen for a radius.
const TILES: u32 = 32;
/// Largest `n_c` chosen for a radius (`2^18`: with `n_t = 32` the face has `2^23` tiles a side).
const MAX_CHUNKS_PER_SIDE_LOG2: u32 = 18;
/// Largest `d_c` chosen for a radius.
const MAX_DEPTH_CHUNKS: u32 = 1024;

/// Why no layout could be chosen for a radius.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RadiusError {
    /// The radius is NaN or infinite.
    #[error("the radius must be a finite number of metres, got {0}")]
    NotFinite(f64),
    /// The radius is zero or negative.
    #[error("the radius must be above 0 m, got {0} m")]
    NotPositive(f64),
    /// The radius is outside [`MIN_RADIUS`]..=[`MAX_RADIUS`].
    #[error("the radius must be between {MIN_RADIUS} m and {MAX_RADIUS:e} m, got {0} m")]
    OutOfRange(f64),
    /// The chosen parameters were refused by the layout (not expected for accepted radii).
    #[error(transparent)]
    Layout(#[from] LayoutError),
}

/// The layout of about radius `radius` metres (see the module docs for the rule): the shell's
/// middle layer lies at `radius`.
pub fn layout_for_radius(radius: f64) -> Result<Layout, RadiusError> {
    if !radius.is_finite() {
        return Err(RadiusError::NotFinite(radius));
    }
    if radius <= 0.0 {
        return Err(RadiusError::NotPositive(radius));
    }
    if !(MIN_RADIUS..=MAX_RADIUS).contains(&radius) {
        return Err(RadiusError::OutOfRange(radius));
    }
    let tiles = f64::from(TILES);
    // Largest power of two with (pi/2) R / (32 n_c) >= 1 m.
    let fit = (std::f64::consts::FRAC_PI_2 * radius / tiles).log2().floor();
    let log_n_c = fit.clamp(0.0, f64::from(MAX_CHUNKS_PER_SIDE_LOG2)) as u32;
    let n_c = 1u32 << log_n_c;
    let across = std::f64::consts::FRAC_PI_2 * radius / (tiles * f64::from(n_c));
    let l_d = 2f64.powi(across.log2().floor().max(0.0) as i32);
    let wanted = (radius / 200.0).max(256f64.min(radius / 8.0));
    let d_c = ((wanted / (l_d * tiles)).ceil() as u32)
        .max(1)
        .next_power_of_two()
        .min(MAX_DEPTH_CHUNKS);
    let thickness = l_d * tiles * f64::from(d_c);
    Ok(Layout::new(n_c, TILES, radius - 0.5 * thickness, l_d, d_c)?)
}

impl PresetKind {
    /// The preset's layout: with a radius, [`layout_for_radius`] for every preset; without, the
    /// Earth at true scale for [`PresetKind::Earth`] (`Layout::new(2^18, 32, 6 371 000 - 16 384,
    /// 1, 2^10)`: 1 m voxels, sea level at 6 371 000 m in the middle of the shell) and
    /// [`Layout::default`] (radius 2000 m) for the others.
    pub fn default_layout(self, radius: Option<f64>) -> Result<Layout, RadiusError> {
        match (radius, self) {
            (Some(r), _) => layout_for_radius(r),
            (None, PresetKind::Earth) => layout_for_radius(EARTH_RADIUS),
            (None, _) => Ok(Layout::default()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn earth_at_true_scale() {
        let l = PresetKind::Earth.default_layout(None).unwrap();
        assert_eq!(
            l,
            Layout::new(1 << 18, 32, 6_371_000.0 - 16_384.0, 1.0, 1 << 10).unwrap()
        );
        assert_eq!(l.max_level(), 18);
        assert_eq!(l.d_b() + 0.5 * l.l_d() * l.depth_tiles() as f64, EARTH_RADIUS);
        let across = std::f64::consts::FRAC_PI_2 * EARTH_RADIUS / l.face_tiles() as f64;
        assert!((1.1..1.3).contains(&across), "{across}");
        for kind in [
            PresetKind::Sphere,
            PresetKind::Earthlike,
            PresetKind::Moon,
            PresetKind::Mars,
        ] {
            assert_eq!(kind.default_layout(None).unwrap(), Layout::default());
            assert_eq!(kind.default_layout(Some(EARTH_RADIUS)).unwrap(), l);
        }
    }

    #[test]
    fn every_radius_gets_a_sound_layout() {
        let mut r = MIN_RADIUS;
        while r <= MAX_RADIUS {
            let l = layout_for_radius(r).unwrap();
            let t = l.l_d() * l.depth_tiles() as f64;
            assert!((l.d_b() + 0.5 * t - r).abs() < 1e-9 * r, "{r}: datum off");
            assert!(l.n_c().is_power_of_two() && l.d_c().is_power_of_two(), "{r}");
            assert_eq!(l.n_t(), 32);
            // Comparable voxel sizes across and along the radius.
            let across = std::f64::consts::FRAC_PI_2 * r / l.face_tiles() as f64;
            assert!(
                across >= l.l_d() && across < 2.0 * l.l_d() + 1e-9,
                "{r}: {across} vs {}",
                l.l_d()
            );
            // The shell is thick enough for the relief, and not more than a quarter of the radius.
            assert!(t >= r / 400.0 && t >= 32.0 * l.l_d(), "{r}: T = {t}");
            assert!(t <= 0.35 * r, "{r}: T = {t}");
            // Many levels of detail for large planets; voxel counts fit in 64 bits.
            if r > 1e5 {
                assert!(l.max_level() >= 10, "{r}: {} levels", l.max_level());
            }
            let n = l.face_tiles() as u64 + 1;
            let voxels = n.checked_mul(n).and_then(|x| x.checked_mul(l.depth_tiles() as u64 + 1));
            assert!(
                voxels.and_then(|x| x.checked_mul(6)).is_some(),
                "{r}: voxel count overflows"
            );
            r *= 1.37;
        }
        assert!(layout_for_radius(MAX_RADIUS).is_ok());
    }

    #[test]
    fn bad_radii_are_refused() {
        assert!(layout_for_radius(f64::NAN).unwrap_err().to_string().contains("finite"));
        assert!(matches!(
            layout_for_radius(f64::INFINITY),
            Err(RadiusError::NotFinite(_))
        ));
        assert_eq!(layout_for_radius(0.0), Err(RadiusError::NotPositive(0.0)));
        assert_eq!(layout_for_radius(-5.0), Err(RadiusError::NotPositive(-5.0)));
        assert_eq!(layout_for_radius(99.0), Err(RadiusError::OutOfRange(99.0)));
        assert_eq!(layout_for_radius(2e8), Err(RadiusError::OutOfRange(2e8)));
        let msg = PresetKind::Moon.default_layout(Some(1e9)).unwrap_err().to_string();
        assert!(msg.contains("between 100 m"), "{msg}");
    }

    #[test]
    fn moon_at_true_scale() {
        let l = PresetKind::Moon.default_layout(Some(1_737_400.0)).unwrap();
        assert_eq!((l.n_c(), l.n_t(), l.l_d(), l.d_c()), (1 << 16, 32, 1.0, 512));
        assert_eq!(l.d_b(), 1_737_400.0 - 8192.0);
    }
}
