//! The sea surface: a cube-sphere at sea-level radius, one mesh per cube face.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{face_uv_to_sphere, Face};

/// Quads per face axis of the sea sphere.
pub(crate) const SEA_QUADS: u32 = 48;

/// The sea mesh of one cube face. Positions are relative to `centre` (the face centre on the
/// sphere), which keeps them small enough for `f32` at any radius.
#[derive(Clone, Debug)]
pub(crate) struct SeaFace {
    /// The face.
    pub face: Face,
    /// World position the positions are relative to: the face's normal times the radius.
    pub centre: DVec3,
    /// Vertex positions relative to `centre`, metres.
    pub positions: Vec<[f32; 3]>,
    /// Unit radial normals.
    pub normals: Vec<[f32; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

/// The six faces of a sea sphere of `radius` metres with `quads` x `quads` quads per face.
pub(crate) fn sea_faces(radius: f64, quads: u32) -> Vec<SeaFace> {
    Face::ALL
        .into_iter()
        .map(|f| sea_face(f, radius, quads.max(1)))
        .collect()
}

fn sea_face(face: Face, radius: f64, q: u32) -> SeaFace {
    let centre = face.normal() * radius;
    let side = q + 1;
    let mut positions = Vec::with_capacity((side * side) as usize);
    let mut normals = Vec::with_capacity((side * side) as usize);
    for j in 0..side {
        let v = -1.0 + 2.0 * f64::from(j) / f64::from(q);
        for i in 0..side {
            let u = -1.0 + 2.0 * f64::from(i) / f64::from(q);
            let d = face_uv_to_sphere(face, u, v);
            let p = d * radius - centre;
            positions.push([p.x as f32, p.y as f32, p.z as f32]);
            let n = d.normalize();
            normals.push([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    // Face frames are right-handed (u x v = outward), so counter-clockwise in (u, v) faces outward.
    let mut indices = Vec::with_capacity((q * q * 6) as usize);
    for j in 0..q {
        for i in 0..q {
            let a = j * side + i;
            let b = a + 1;
            let c = a + side + 1;
            let d = a + side;
            indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    SeaFace {
        face,
        centre,
        positions,
        normals,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_lie_on_the_sphere_and_triangles_face_outward() {
        let r = 6_371_000.0;
        for f in sea_faces(r, 8) {
            assert_eq!(f.positions.len(), 81);
            assert_eq!(f.indices.len(), 8 * 8 * 6);
            for (p, n) in f.positions.iter().zip(&f.normals) {
                let w = f.centre + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                assert!((w.length() - r).abs() < 1.0, "{w}");
                let nl = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                assert!((nl - 1.0).abs() < 1e-6);
            }
            for t in f.indices.chunks_exact(3) {
                let p = |i: u32| {
                    let p = f.positions[i as usize];
                    f.centre + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
                };
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let normal = (b - a).cross(c - a);
                assert!(normal.dot(a + b + c) > 0.0, "{} triangle {t:?} faces inward", f.face);
            }
        }
    }

    #[test]
    fn faces_meet_without_gaps() {
        // Corners of neighbouring faces coincide: every face corner is some other face's corner.
        let faces = sea_faces(1000.0, 4);
        let corners: Vec<DVec3> = faces
            .iter()
            .flat_map(|f| {
                [0usize, 4, 20, 24].map(|i| {
                    let p = f.positions[i];
                    f.centre + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
                })
            })
            .collect();
        for c in &corners {
            let same = corners.iter().filter(|d| (**d - *c).length() < 1e-3).count();
            assert_eq!(same, 3, "{c}");
        }
    }
}
