//! Canonical lattice points of a face grid of any power-of-two resolution, with the unfolding of
//! Algorithm 1 past a face edge.

use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{cube_to_sphere, Face};

/// Segments (quads) along one side of a patch.
pub const PATCH_SEGMENTS: u32 = 64;

/// Vertices along one side of a patch (`PATCH_SEGMENTS + 1`).
pub const PATCH_SIDE: u32 = PATCH_SEGMENTS + 1;

/// The deepest patch level: a face side then holds `2^24` patches and `2^30` segments, so lattice
/// coordinates (within `±2^30`) still fit an `i32` and [`pmc_geometry::VoxelKey::pack`].
pub const MAX_LEVEL: u8 = 24;

/// The resolution of the finest level, `64 * 2^MAX_LEVEL = 2^30`: every lattice point of every
/// level is a lattice point of this resolution (see [`canonical_lattice`]).
pub const CANONICAL_RESOLUTION: i64 = (PATCH_SEGMENTS as i64) << MAX_LEVEL;

/// The face resolution (segments per face side) of patches of `level`: `64 * 2^level`.
pub fn resolution(level: u8) -> i64 {
    i64::from(PATCH_SEGMENTS) << level
}

pub use pmc_geometry::face_lattice;

/// The unit direction of lattice point `lattice` at resolution `m`: `cube_to_sphere(lattice / m)`.
///
/// For a power-of-two `m` the division is exact, so `(2 lattice, 2 m)` gives the same bits: a
/// point has one direction at every level.
///
/// `m` must be a power of two: the division is done as a multiplication by the exact reciprocal
/// `1 / m`, which gives the bits of the division only then.
#[inline]
pub fn lattice_direction(lattice: IVec3, m: i64) -> DVec3 {
    debug_assert!(m > 0 && m.count_ones() == 1, "resolution {m} is not a power of two");
    cube_to_sphere(lattice.as_dvec3() * (1.0 / m as f64))
}

/// The lattice point `lattice` of resolution `m` (a power of two, at most
/// [`CANONICAL_RESOLUTION`]) expressed at [`CANONICAL_RESOLUTION`]: one identity per point across
/// all levels and faces.
pub fn canonical_lattice(lattice: IVec3, m: i64) -> IVec3 {
    debug_assert!(m > 0 && m.count_ones() == 1 && m <= CANONICAL_RESOLUTION);
    lattice * (CANONICAL_RESOLUTION / m) as i32
}

/// The face that holds lattice point `p` of resolution `m` strictly inside along its normal
/// (`p · n = m`) and the point's face grid indices there; the first such face in [`Face::ALL`]
/// for points on edges and corners.
pub(crate) fn lattice_face_index(p: IVec3, m: i64) -> Option<(Face, i64, i64)> {
    let p = p.as_i64vec3();
    Face::ALL.into_iter().find_map(|f| {
        let fr = f.frame();
        (p.dot(fr.n.as_i64vec3()) == m).then(|| {
            let i = (p.dot(fr.u.as_i64vec3()) + m) / 2;
            let j = (p.dot(fr.v.as_i64vec3()) + m) / 2;
            (f, i, j)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Layout;

    #[test]
    fn unfolding_matches_the_layout() {
        // n_c * n_t = 64 tiles per face side.
        let layout = Layout::new(4, 16, 1000.0, 1.0, 1).unwrap();
        let m = layout.face_tiles();
        assert_eq!(m, 64);
        for face in Face::ALL {
            for i in -m..=2 * m {
                for j in [-m, -3, -1, 0, 1, 17, m, m + 1, m + 5, 2 * m] {
                    assert_eq!(
                        face_lattice(face, i, j, m),
                        layout.lattice(face, i, j),
                        "{face} {i} {j}"
                    );
                    assert_eq!(
                        face_lattice(face, j, i, m),
                        layout.lattice(face, j, i),
                        "{face} {j} {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn face_index_inverts_the_lattice() {
        let m = 256;
        for face in Face::ALL {
            for i in 1..m {
                for j in [1, 7, m / 2, m - 1] {
                    let p = face_lattice(face, i, j, m).unwrap();
                    assert_eq!(lattice_face_index(p, m), Some((face, i, j)));
                }
            }
        }
    }

    #[test]
    fn directions_do_not_depend_on_the_resolution() {
        let p = face_lattice(Face::East, 3, 61, 64).unwrap();
        let d = lattice_direction(p, 64);
        for k in 1..=MAX_LEVEL {
            let q = canonical_lattice(p, 64) / (CANONICAL_RESOLUTION / (64 << k)) as i32;
            assert_eq!(lattice_direction(q, 64 << k), d);
        }
        assert_eq!(lattice_direction(canonical_lattice(p, 64), CANONICAL_RESOLUTION), d);
        // The reciprocal gives the division's bits.
        assert_eq!(d, cube_to_sphere(p.as_dvec3() / 64.0));
    }
}
