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

/// `x` rounded half away from zero and clamped to a byte: `x.round().clamp(0.0, 255.0) as u8`
/// bit for bit (NaN gives 0), without the call to the C library's `round` that `f64::round`
/// makes on CPUs without SSE4.1 rounding (a colour channel per vertex).
///
/// ```
/// use pmc_geometry::math::round_to_byte;
/// assert_eq!([round_to_byte(2.5), round_to_byte(-3.0), round_to_byte(300.0)], [3, 0, 255]);
/// ```
#[inline]
pub fn round_to_byte(x: f64) -> u8 {
    let y = x.clamp(0.0, 255.0);
    // On [0, 255] the cast truncates exactly and the fraction `y - i` is exact.
    let i = y as u8;
    if y - f64::from(i) >= 0.5 {
        i + 1
    } else {
        i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_to_byte_is_round_then_clamp() {
        let reference = |x: f64| x.round().clamp(0.0, 255.0) as u8;
        let mut xs = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.0,
            0.5,
            254.5,
            255.0,
            255.5,
        ];
        for k in -20..2800 {
            let x = f64::from(k) * 0.1;
            // Each tenth, and the neighbours of each half, one bit either side.
            let h = f64::from(k) + 0.5;
            xs.extend([x, h, f64::from_bits(h.to_bits() - 1), f64::from_bits(h.to_bits() + 1)]);
        }
        for x in xs {
            assert_eq!(round_to_byte(x), reference(x), "{x:e}");
        }
    }

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
