//! Culling of bounding spheres: the view frustum and the planet's horizon.
//!
//! # Horizon
//!
//! Seen from the eye `E` at distance `e` from the centre, a solid ball of radius `R < e` hides
//! everything in its shadow: the points `x` whose segment from `E` meets the ball. The shadow
//! holds every point that lies both
//!
//! - in the cone with apex `E`, axis towards the centre and half angle `alpha`,
//!   `sin alpha = R / e` (the cone tangent to the ball), and
//! - on the far side of the horizon plane `x . E / e <= R^2 / e`, the plane of the circle where
//!   the cone touches the ball.
//!
//! Why: the segment from `E` (on the near side) to such a point crosses the plane inside the cone
//! (which is convex), so in the disc the cone cuts from the plane; that disc has radius
//! `R sqrt(1 - R^2 / e^2)` at distance `R^2 / e` from the centre, so its points lie within `R` of
//! the centre: in the ball. A bounding sphere is hidden when all its points are: its farthest
//! point along `E` is behind the plane and its angular radius seen from `E`,
//! `asin(r / |c - E|)`, plus the angle of its centre from the axis stays below `alpha`. Both
//! tests keep a small relative margin, so rounding can only keep a sphere, never hide one that
//! shows.
//!
//! The ball must be solid at every level of detail: [`occluder_radius`] gives such a radius for
//! a planet (its lowest possible surface, lowered by how far a coarse chunk's flat triangles can
//! cut below it).

use crate::bounds::{angle_between, BoundingSphere, LIPSCHITZ};
use pmc_density::Density;
use pmc_geometry::glam::{DVec3, DVec4};
use pmc_planet::Planet;

/// Relative margin of the culling tests (of the lengths compared).
const MARGIN: f64 = 1e-9;

/// Whether some point of `sphere` may lie inside the frustum: no plane has the whole sphere on
/// its outer side. A plane `(n, d)` (any length of `n`) keeps the points `p` with
/// `n . p + d >= 0`.
///
/// Sound: a sphere holding a point inside every plane is never reported outside (the test keeps
/// spheres near the frustum's edges and corners that lie outside, which costs only drawing them).
pub fn sphere_in_frustum(planes: &[DVec4; 6], sphere: &BoundingSphere) -> bool {
    planes.iter().all(|p| {
        let n = p.truncate();
        let len = n.length();
        let s = n.dot(sphere.center) + p.w;
        let slack = MARGIN * (n.dot(sphere.center).abs() + p.w.abs() + sphere.radius * len);
        s >= -sphere.radius * len - slack
    })
}

/// Whether every point of `sphere` is hidden from `eye` by a solid ball of radius `occluder`
/// around the planet's centre (see the module docs). Always `false` when the eye is inside the
/// ball or inside the sphere, or for a non-positive or non-finite `occluder`.
pub fn sphere_below_horizon(eye: DVec3, occluder: f64, sphere: &BoundingSphere) -> bool {
    let e = eye.length();
    if !(occluder > 0.0 && occluder.is_finite() && e.is_finite() && e > occluder) {
        return false;
    }
    let axis = eye / e;
    // Behind the horizon plane, all of it.
    let plane = occluder * occluder / e;
    if sphere.center.dot(axis) + sphere.radius >= plane - MARGIN * e {
        return false;
    }
    // Inside the shadow cone, all of it.
    let to = sphere.center - eye;
    let d = to.length();
    if d.is_nan() || d <= sphere.radius * (1.0 + MARGIN) {
        return false;
    }
    let alpha = (occluder / e).asin();
    let spread = angle_between(to / d, -axis) + (sphere.radius / d).min(1.0).asin();
    spread < alpha * (1.0 - MARGIN) - MARGIN
}

/// A radius below which the planet's meshes are solid at every level of detail, for
/// [`sphere_below_horizon`].
///
/// Mesh vertices lie on grid edges with one end not solid, so at or above the density's lower
/// radial bound less one coarsest-level depth step, and never below the shell's base `d_b`
/// (layer 0 is solid by the shell contract). A triangle spans at most one cell, whose columns
/// lie within an angle `theta = LIPSCHITZ sqrt(2) 2^(L+1) / N` of each other at the coarsest
/// level `L`, so its points keep at least `cos(theta)` of the lowest vertex radius.
pub fn occluder_radius(planet: &Planet) -> f64 {
    let layout = planet.layout();
    let level = layout.max_level();
    let step = layout.l_d() * (1u64 << level) as f64;
    let lowest = match planet.density().radial_bounds() {
        Some((lo, _)) if lo.is_finite() => (lo - step).max(layout.d_b()),
        _ => layout.d_b(),
    };
    let theta = LIPSCHITZ * std::f64::consts::SQRT_2 * (2u64 << level) as f64 / layout.face_tiles() as f64;
    if theta >= std::f64::consts::FRAC_PI_2 {
        return 0.0;
    }
    (lowest * theta.cos()).max(0.0)
}

/// The six planes of a perspective frustum, inside where `n . p + d >= 0`: left, right, bottom,
/// top, near, far.
///
/// `forward` and `up` need not be unit length or orthogonal (`up` is made orthogonal to
/// `forward`); `fov_y` is the vertical field of view in radians, `aspect` width over height.
pub fn frustum_planes(
    eye: DVec3,
    forward: DVec3,
    up: DVec3,
    fov_y: f64,
    aspect: f64,
    near: f64,
    far: f64,
) -> [DVec4; 6] {
    let f = forward.normalize_or_zero();
    let r = f.cross(up).normalize_or_zero();
    let u = r.cross(f);
    let ty = (0.5 * fov_y).tan();
    let tx = ty * aspect;
    // A side plane through the eye holding the forward axis tilted by the half angle: its
    // inward normal is `f t - s` for the side's axis `s`.
    let plane = |n: DVec3| n.normalize_or_zero().extend(-n.normalize_or_zero().dot(eye));
    [
        plane(f * tx + r),
        plane(f * tx - r),
        plane(f * ty + u),
        plane(f * ty - u),
        f.extend(-f.dot(eye) - near),
        (-f).extend(f.dot(eye) + far),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frustum_planes_keep_the_view_axis_and_drop_what_is_behind() {
        let eye = DVec3::new(10.0, 0.0, 0.0);
        let p = frustum_planes(eye, -DVec3::X, DVec3::Y, 1.0, 1.5, 0.1, 100.0);
        let inside = |x: DVec3| p.iter().all(|q| q.truncate().dot(x) + q.w >= 0.0);
        assert!(inside(DVec3::ZERO));
        assert!(!inside(DVec3::new(20.0, 0.0, 0.0)));
        assert!(!inside(DVec3::new(-95.0, 0.0, 0.0)));
        assert!(!inside(DVec3::new(0.0, 10.0, 0.0)), "above the top plane");
        let tiny = BoundingSphere {
            center: DVec3::new(20.0, 0.0, 0.0),
            radius: 9.0,
        };
        assert!(!sphere_in_frustum(&p, &tiny));
        let big = BoundingSphere { radius: 10.5, ..tiny };
        assert!(sphere_in_frustum(&p, &big));
    }

    #[test]
    fn the_far_side_is_below_the_horizon_and_the_near_side_is_not() {
        let eye = DVec3::new(0.0, 0.0, 300.0);
        let far = BoundingSphere {
            center: DVec3::new(0.0, 0.0, -100.0),
            radius: 5.0,
        };
        assert!(sphere_below_horizon(eye, 100.0, &far));
        let near = BoundingSphere {
            center: DVec3::new(0.0, 0.0, 100.0),
            radius: 5.0,
        };
        assert!(!sphere_below_horizon(eye, 100.0, &near));
        // Inside the occluder nothing is hidden.
        assert!(!sphere_below_horizon(DVec3::new(0.0, 0.0, 50.0), 100.0, &far));
        assert!(!sphere_below_horizon(eye, f64::NAN, &far));
    }
}
