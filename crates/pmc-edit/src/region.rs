//! Cone shells: the directions within an angle of an axis, between two radii. They bound a batch
//! of samples or a chunk, and their distance to a point is exact, so testing a brush against
//! them is both sound and tight.

use pmc_geometry::glam::DVec3;

/// The angle between two unit vectors, accurate for small angles.
pub(crate) fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The points `d r` with `angle(d, axis) <= angle` and `r0 <= r <= r1` (`0 <= r0 <= r1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ConeShell {
    pub axis: DVec3,
    pub angle: f64,
    pub r0: f64,
    pub r1: f64,
}

impl ConeShell {
    /// All of space.
    pub fn everything() -> ConeShell {
        ConeShell {
            axis: DVec3::Y,
            angle: std::f64::consts::PI,
            r0: 0.0,
            r1: f64::INFINITY,
        }
    }

    /// A cone shell holding every point `dirs[d] * radii[r]` (any directions, not only unit ones).
    /// Falls back to [`ConeShell::everything`] when the directions spread too widely to have a
    /// mean, or when an input is not finite or a radius is negative.
    pub fn of_batch(dirs: &[DVec3], radii: &[f64]) -> ConeShell {
        let sum: DVec3 = dirs.iter().copied().sum();
        let (mut rmin, mut rmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for r in radii {
            rmin = rmin.min(*r);
            rmax = rmax.max(*r);
        }
        if !(sum.is_finite() && rmin.is_finite() && rmax.is_finite() && rmin >= 0.0)
            || sum.length() <= 1e-6 * dirs.len() as f64
        {
            return ConeShell::everything();
        }
        let axis = sum.normalize();
        // Directions within 60 degrees of the axis (all of them for a chunk) are ranked by their
        // squared sine, with no transcendental call: `asin` of the largest is well conditioned
        // there (its slope is at most 2), so one call at the end gives the widest angle to within
        // a few 1e-16. Wider directions take the exact angle.
        let (mut sin2, mut wide, mut l2min, mut l2max) = (0.0f64, 0.0f64, f64::INFINITY, 0.0f64);
        for d in dirs {
            let l2 = d.length_squared();
            if !(l2.is_finite() && l2 > 0.0) {
                return ConeShell::everything();
            }
            let c = axis.dot(*d);
            if c >= 0.0 && 4.0 * c * c >= l2 {
                sin2 = sin2.max(axis.cross(*d).length_squared() / l2);
            } else {
                wide = wide.max(angle_between(axis, *d / l2.sqrt()));
            }
            l2min = l2min.min(l2);
            l2max = l2max.max(l2);
        }
        let angle = sin2.sqrt().min(1.0).asin().max(wide);
        // Rounding of the angle and of the products `d r`: widen by a hair.
        ConeShell {
            axis,
            angle: (angle + 1e-12).min(std::f64::consts::PI),
            r0: rmin * l2min.sqrt() * (1.0 - 1e-12),
            r1: rmax * l2max.sqrt() * (1.0 + 1e-12),
        }
    }

    /// Distance from `c` to the nearest point of the shell (0 inside it).
    pub fn distance(&self, c: DVec3) -> f64 {
        let len = c.length();
        if len == 0.0 {
            return self.r0;
        }
        // The nearest direction of the cap lies on the great circle towards `c`, `gamma` away.
        let gamma = (angle_between(self.axis, c / len) - self.angle).clamp(0.0, std::f64::consts::PI);
        let r = (len * gamma.cos()).clamp(self.r0, self.r1);
        if r.is_infinite() {
            return 0.0;
        }
        let s = (0.5 * gamma).sin();
        ((len - r) * (len - r) + 4.0 * len * r * s * s).max(0.0).sqrt()
    }

    /// Whether a ball of radius `reach` around `c` may meet the shell (conservative by a hair).
    pub fn may_meet_ball(&self, c: DVec3, reach: f64) -> bool {
        let slack = 1e-9 * (c.length() + reach) + 1e-9;
        // NaN keeps the brush (conservative).
        let d = self.distance(c);
        d.is_nan() || d <= reach + slack
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The distance is exact: never above the distance to any point of the shell, and reached.
        #[test]
        fn distance_is_a_lower_bound_and_tight(
            axis in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
            angle in 0.0f64..3.0,
            r0 in 0.0f64..50.0,
            dr in 0.0f64..50.0,
            c in [-120.0f64..120.0, -120.0f64..120.0, -120.0f64..120.0],
        ) {
            let axis = DVec3::from_array(axis);
            prop_assume!(axis.length() > 0.1);
            let shell = ConeShell { axis: axis.normalize(), angle, r0, r1: r0 + dr };
            let c = DVec3::from_array(c);
            let dist = shell.distance(c);
            let mut best = f64::INFINITY;
            let n = 60;
            let ortho = shell.axis.any_orthonormal_vector();
            for a in 0..=n {
                let t = angle * a as f64 / n as f64;
                for b in 0..n {
                    let phi = std::f64::consts::TAU * b as f64 / n as f64;
                    let rot = pmc_geometry::glam::DQuat::from_axis_angle(shell.axis, phi);
                    let d = pmc_geometry::glam::DQuat::from_axis_angle(rot * ortho, t) * shell.axis;
                    for k in 0..=8 {
                        let r = r0 + dr * k as f64 / 8.0;
                        let e = (d * r - c).length();
                        prop_assert!(dist <= e + 1e-9, "{dist} > {e}");
                        best = best.min(e);
                    }
                }
            }
            // The sampled shell comes within its sampling spacing of the exact distance.
            prop_assert!(best - dist <= 0.06 * (r0 + dr) + dr / 8.0 + 1e-9, "{best} vs {dist}");
        }
    }

    #[test]
    fn batch_shell_holds_its_samples() {
        let dirs: Vec<DVec3> = (0..50)
            .map(|i| DVec3::new(1.0, (i as f64 * 0.37).sin() * 0.3, (i as f64 * 0.11).cos() * 0.2).normalize())
            .collect();
        let radii = [90.0, 95.5, 100.0];
        let s = ConeShell::of_batch(&dirs, &radii);
        for d in &dirs {
            for r in radii {
                assert_eq!(s.distance(*d * r), 0.0);
            }
        }
        assert!(s.angle < 0.5);
        // The angle bounds every direction's exact angle, tightly.
        let exact = dirs.iter().map(|d| angle_between(s.axis, *d)).fold(0.0, f64::max);
        assert!(s.angle >= exact && s.angle - exact < 1e-11, "{} vs {exact}", s.angle);
        // Directions past 60 degrees (the exact path) are held too.
        let wide = [DVec3::Y, DVec3::Y, DVec3::Y, DVec3::X];
        let w = ConeShell::of_batch(&wide, &radii);
        let exact = wide.iter().map(|d| angle_between(w.axis, *d)).fold(0.0, f64::max);
        assert!(exact > std::f64::consts::FRAC_PI_3);
        assert!(w.angle >= exact && w.angle - exact < 1e-11, "{} vs {exact}", w.angle);
        for d in wide {
            for r in radii {
                assert_eq!(w.distance(d * r), 0.0);
            }
        }
        assert_eq!(
            ConeShell::of_batch(&[DVec3::X, -DVec3::X], &radii),
            ConeShell::everything()
        );
        assert_eq!(ConeShell::everything().distance(DVec3::new(3.0, 4.0, 5.0)), 0.0);
    }
}
