//! Scalar helpers shared by the crates above: interpolation and the sRGB transfer function.
//!
//! One definition each, so that every caller rounds the same way: `lerp(a, b, t)` takes the
//! ends first and the parameter last, as `glam` does.

/// Linear interpolation from `a` (at `t = 0`) to `b` (at `t = 1`): `a + (b - a) t`.
///
/// ```
/// use pmc_geometry::math::lerp;
/// assert_eq!(lerp(2.0, 6.0, 0.25), 3.0);
/// ```
#[inline(always)]
pub fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// `smoothstep` from `e0` to `e1` (either order): 0 before `e0`, 1 after `e1`, C1 in between.
/// Exactly 0 and exactly 1 outside the ramp, which callers may rely on to skip work.
///
/// ```
/// use pmc_geometry::math::smoothstep;
/// assert_eq!(smoothstep(1.0, 3.0, 2.0), 0.5);
/// assert_eq!(smoothstep(3.0, 1.0, 0.0), 1.0);
/// ```
#[inline]
pub fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// One sRGB-encoded channel (0-255) in linear light (0-1).
///
/// ```
/// use pmc_geometry::math::srgb_to_linear;
/// assert_eq!((srgb_to_linear(0), srgb_to_linear(255)), (0.0, 1.0));
/// ```
pub fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lerp_takes_the_ends_first() {
        assert_eq!(lerp(1.0, 3.0, 0.0), 1.0);
        assert_eq!(lerp(1.0, 3.0, 1.0), 3.0);
        assert_eq!(lerp(1.0, 3.0, 0.5), 2.0);
        assert_eq!(lerp(1.0, 3.0, 2.0), 5.0, "not clamped");
    }

    #[test]
    fn smoothstep_is_exact_outside_the_ramp() {
        for (e0, e1) in [(1.0, 3.0), (3.0, 1.0)] {
            assert_eq!(smoothstep(e0, e1, e0), 0.0);
            assert_eq!(smoothstep(e0, e1, e1), 1.0);
            assert_eq!(smoothstep(e0, e1, 2.0), 0.5);
        }
        assert_eq!(smoothstep(1.0, 3.0, -1e300), 0.0);
        assert_eq!(smoothstep(1.0, 3.0, 1e300), 1.0);
    }

    #[test]
    fn srgb_to_linear_is_monotonic_from_0_to_1() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert_eq!(srgb_to_linear(255), 1.0);
        assert!((srgb_to_linear(10) - 10.0 / 255.0 / 12.92).abs() < 1e-15, "linear toe");
        assert!((srgb_to_linear(188) - 0.5).abs() < 0.01);
        assert!((1..=255).all(|c| srgb_to_linear(c) > srgb_to_linear(c - 1)));
    }
}
