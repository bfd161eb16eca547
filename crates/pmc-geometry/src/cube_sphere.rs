//! Seed 000 Eq. (1): the cube-to-sphere mapping, and its exact inverse.
//!
//! The forward map takes a point on the surface of the cube `[-1, 1]^3` to the unit sphere:
//!
//! ```text
//! x' = x sqrt(1 - y^2/2 - z^2/2 + y^2 z^2 / 3)
//! y' = y sqrt(1 - z^2/2 - x^2/2 + z^2 x^2 / 3)
//! z' = z sqrt(1 - x^2/2 - y^2/2 + x^2 y^2 / 3)
//! ```
//!
//! On a face with `|x| = 1` it preserves the face (`|x'|` stays the largest component), so the
//! inverse first picks the face from the largest component, then solves the two remaining
//! equations in closed form. With `A = y'^2`, `B = z'^2`, the squares `Y = y^2` solve
//! `Y^2 - (3 + 2(A - B)) Y + 6A = 0`; we take the small root in the cancellation-free form
//! `Y = 12A / (P + sqrt(P^2 - 24A))`, `P = 3 + 2(A - B)`, and recover the sign from `y'`:
//! `y = y' sqrt(12 / (P + sqrt(P^2 - 24A)))`.

use crate::face::Face;
use glam::DVec3;

/// Maps a point on the cube surface `[-1, 1]^3` to the unit sphere (seed 000 Eq. (1)).
///
/// The formula is symmetric in the three axes and evaluated in a fixed order, so the same cube
/// point always yields bit-identical output, whichever face it was reached from.
#[inline]
pub fn cube_to_sphere(c: DVec3) -> DVec3 {
    let x2 = c.x * c.x;
    let y2 = c.y * c.y;
    let z2 = c.z * c.z;
    DVec3::new(
        c.x * cube_sphere_factor(y2, z2),
        c.y * cube_sphere_factor(z2, x2),
        c.z * cube_sphere_factor(x2, y2),
    )
}

/// The factor of one component in [`cube_to_sphere`]: `sqrt(1 - a2/2 - b2/2 + a2 b2 / 3)` for the
/// squares `a2`, `b2` of the two other components, in the next-then-previous axis order
/// (`x' = x f(y^2, z^2)`, `y' = y f(z^2, x^2)`, `z' = z f(x^2, y^2)`). Callers mapping a grid of
/// points on one face compute the factors that depend on one grid axis once per row or column,
/// with the same bits as `cube_to_sphere`.
#[inline]
pub fn cube_sphere_factor(a2: f64, b2: f64) -> f64 {
    (1.0 - a2 * 0.5 - b2 * 0.5 + a2 * b2 / 3.0).sqrt()
}

/// Solves one face coordinate of the inverse map. `a` is the squared sphere coordinate along that
/// axis, `b` the squared coordinate along the other face axis, `s` the signed sphere coordinate.
#[inline]
fn inverse_component(s: f64, a: f64, b: f64) -> f64 {
    let p = 3.0 + 2.0 * (a - b);
    let disc = (p * p - 24.0 * a).max(0.0);
    let c = s * (12.0 / (p + disc.sqrt())).sqrt();
    c.clamp(-1.0, 1.0)
}

/// Maps a point anywhere in space (not the origin) to the cube face it projects onto and the point
/// of the cube surface whose image under [`cube_to_sphere`] is its direction.
///
/// Returns `None` for the origin and for non-finite input.
pub fn sphere_to_cube(p: DVec3) -> Option<(Face, DVec3)> {
    let len = p.length();
    if !len.is_finite() || len == 0.0 {
        return None;
    }
    let d = p / len;
    let face = Face::containing(d)?;
    let fr = face.frame();
    // Work in the face's world axes: `m` is the major (normal) component, `a`, `b` the others.
    let n = fr.n.as_dvec3();
    let (ia, ib) = match fr.n.abs() {
        glam::IVec3 { x: 1, .. } => (1usize, 2usize),
        glam::IVec3 { y: 1, .. } => (2, 0),
        _ => (0, 1),
    };
    let sa = d[ia];
    let sb = d[ib];
    let (a2, b2) = (sa * sa, sb * sb);
    let mut c = n;
    c[ia] = inverse_component(sa, a2, b2);
    c[ib] = inverse_component(sb, b2, a2);
    Some((face, c))
}

/// The point of the cube surface for face coordinates `(u, v)` in `[-1, 1]^2` of `face`.
#[inline]
pub fn face_uv_to_cube(face: Face, u: f64, v: f64) -> DVec3 {
    let fr = face.frame();
    fr.n.as_dvec3() + u * fr.u.as_dvec3() + v * fr.v.as_dvec3()
}

/// The unit-sphere direction for face coordinates `(u, v)` in `[-1, 1]^2` of `face`.
#[inline]
pub fn face_uv_to_sphere(face: Face, u: f64, v: f64) -> DVec3 {
    cube_to_sphere(face_uv_to_cube(face, u, v))
}

/// The face and face coordinates `(u, v)` in `[-1, 1]^2` of the direction of `p`.
///
/// Exact inverse of [`face_uv_to_sphere`] to within 1e-12. Returns `None` for the origin and for
/// non-finite input.
pub fn sphere_to_face_uv(p: DVec3) -> Option<(Face, f64, f64)> {
    let (face, c) = sphere_to_cube(p)?;
    let fr = face.frame();
    Some((face, c.dot(fr.u.as_dvec3()), c.dot(fr.v.as_dvec3())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn paper_example_corner() {
        let s = cube_to_sphere(DVec3::ONE);
        let e = 1.0 / 3f64.sqrt();
        // The paper prints (sqrt2/2, ...); Eq. (1) itself gives 1/sqrt(3), on the unit sphere.
        assert!((s - DVec3::splat(e)).length() < 1e-15);
        assert!((s.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn face_centres_map_to_axes() {
        for f in Face::ALL {
            assert_eq!(face_uv_to_sphere(f, 0.0, 0.0), f.normal());
            let (g, u, v) = sphere_to_face_uv(f.normal() * 7.0).unwrap();
            assert_eq!((g, u, v), (f, 0.0, 0.0));
        }
    }

    #[test]
    fn rejects_degenerate_points() {
        assert!(sphere_to_cube(DVec3::ZERO).is_none());
        assert!(sphere_to_cube(DVec3::new(f64::NAN, 0.0, 1.0)).is_none());
        assert!(sphere_to_cube(DVec3::new(f64::INFINITY, 0.0, 1.0)).is_none());
    }

    proptest! {
        #[test]
        fn forward_lands_on_unit_sphere(fi in 0usize..6, u in -1.0f64..=1.0, v in -1.0f64..=1.0) {
            let s = face_uv_to_sphere(Face::ALL[fi], u, v);
            prop_assert!((s.length() - 1.0).abs() < 1e-14);
        }

        #[test]
        fn round_trip_face_uv(fi in 0usize..6, u in -1.0f64..=1.0, v in -1.0f64..=1.0, r in 1e-3f64..1e7) {
            let f = Face::ALL[fi];
            let s = face_uv_to_sphere(f, u, v) * r;
            let (g, u2, v2) = sphere_to_face_uv(s).unwrap();
            let back = face_uv_to_cube(g, u2, v2);
            prop_assert!((back - face_uv_to_cube(f, u, v)).length() < 1e-12,
                "{f} {u} {v} -> {g} {u2} {v2}");
            if g == f {
                prop_assert!((u - u2).abs() < 1e-12 && (v - v2).abs() < 1e-12);
            }
        }

        #[test]
        fn round_trip_sphere(x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0) {
            let p = DVec3::new(x, y, z);
            prop_assume!(p.length() > 1e-6);
            let (_, c) = sphere_to_cube(p).unwrap();
            let s = cube_to_sphere(c);
            prop_assert!((s - p.normalize()).length() < 1e-12);
        }
    }

    #[test]
    fn round_trip_near_edges_and_corners() {
        let vals = [
            -1.0,
            -1.0 + 1e-15,
            -0.999999,
            -0.5,
            0.0,
            1e-300,
            0.5,
            0.999999,
            1.0 - 1e-15,
            1.0,
        ];
        for f in Face::ALL {
            for &u in &vals {
                for &v in &vals {
                    let s = face_uv_to_sphere(f, u, v);
                    let (g, u2, v2) = sphere_to_face_uv(s).unwrap();
                    let d = (face_uv_to_cube(g, u2, v2) - face_uv_to_cube(f, u, v)).length();
                    assert!(d < 1e-12, "{f} ({u},{v}) -> {g} ({u2},{v2}) off by {d}");
                }
            }
        }
    }
}
