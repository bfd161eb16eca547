//! The project's canonical cube lattice at a power-of-two resolution: face samples to lattice
//! points and back, unfolding past face edges as `Layout::lattice` does.

use pmc_geometry::glam::IVec3;
use pmc_geometry::Face;

/// The lattice point of sample `(i, j)` of `face` at resolution `r` (`i, j` in `0..=r`):
/// `r n + (2i - r) u + (2j - r) v`.
#[inline]
pub(crate) fn lattice_of(face: Face, r: i32, i: i32, j: i32) -> IVec3 {
    let f = face.frame();
    f.n * r + f.u * (2 * i - r) + f.v * (2 * j - r)
}

/// The face that a lattice point of resolution `r` is read from: the first of [`Face::ALL`]
/// whose plane holds it. A point on an edge or a corner lies on two or three faces; this rule
/// depends on the point alone, so every caller reads the same face.
#[inline]
pub(crate) fn home_face(p: IVec3, r: i32) -> Option<Face> {
    Face::ALL.into_iter().find(|f| f.frame().n.dot(p) == r)
}

/// Sample indices of lattice point `p` (resolution `r`) on `face`, which must hold it.
#[inline]
pub(crate) fn indices_on(face: Face, p: IVec3, r: i32) -> (i32, i32) {
    let f = face.frame();
    ((f.u.dot(p) + r) / 2, (f.v.dot(p) + r) / 2)
}

/// The lattice point of face indices `(i, j)` that may lie up to `r` past one edge of `face`
/// (unfolded onto the neighbouring face about the shared edge, Algorithm 1); `None` when both
/// indices are out of range. The same unfolding as `pmc_geometry::Layout::lattice`.
pub(crate) fn unfold(face: Face, r: i32, i: i32, j: i32) -> Option<IVec3> {
    pmc_geometry::face_lattice(face, i64::from(i), i64::from(j), i64::from(r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Layout;

    #[test]
    fn matches_the_layout_lattice() {
        let r = 8;
        let layout = Layout::new(8, 1, 1.0, 1.0, 1).unwrap();
        for face in Face::ALL {
            for i in -3..=11 {
                for j in -3..=11 {
                    let ours = unfold(face, r, i, j);
                    let theirs = layout.lattice(face, i64::from(i), i64::from(j));
                    assert_eq!(ours, theirs, "{face} {i} {j}");
                    if (0..=r).contains(&i) && (0..=r).contains(&j) {
                        let p = lattice_of(face, r, i, j);
                        assert_eq!(Some(p), ours);
                        let home = home_face(p, r).unwrap();
                        let (a, b) = indices_on(home, p, r);
                        assert_eq!(lattice_of(home, r, a, b), p);
                    }
                }
            }
        }
    }
}
