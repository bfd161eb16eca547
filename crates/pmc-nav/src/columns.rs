//! Voxel columns of the whole planet: one per point of the cube-surface lattice, numbered, with
//! their neighbours across chunk borders, face edges and cube corners.
//!
//! A column is a canonical lattice point (see [`Layout::lattice`]): points on a face edge or a
//! cube corner belong to two or three faces but are one column. Its four neighbours are the
//! lattice points one grid step away along the axes of every face that holds it; on a face edge
//! the step off one face is the step onto the other (Algorithm 1 unfolds the faces the same way),
//! and a cube corner has three neighbours, one along each edge.

use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{sphere_to_face_uv, Face, Layout};

/// The columns of a layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Columns {
    layout: Layout,
    /// Grid steps along a face side, `N = n_c n_t`.
    n: i64,
}

/// A column's canonical place: the first face of [`Face::ALL`] that holds it, and its grid
/// indices `(i, j)` on that face, each in `0..=N`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ColumnPlace {
    /// The face.
    pub face: Face,
    /// Grid index along the face's `u` axis.
    pub i: i64,
    /// Grid index along the face's `v` axis.
    pub j: i64,
}

impl Columns {
    /// The columns of `layout`.
    pub fn new(layout: &Layout) -> Columns {
        Columns {
            layout: *layout,
            n: layout.face_tiles(),
        }
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Grid steps along a face side, `N`.
    pub fn face_tiles(&self) -> i64 {
        self.n
    }

    /// Size of the column index space: `6 (N + 1)^2` (edge and corner columns use the slot of
    /// their canonical face; the other slots stay unused).
    pub fn index_count(&self) -> usize {
        6 * ((self.n + 1) * (self.n + 1)) as usize
    }

    /// The index of the canonical column at `place`.
    pub fn index_of(&self, place: ColumnPlace) -> u32 {
        let side = self.n + 1;
        (place.face.index() as i64 * side * side + place.j * side + place.i) as u32
    }

    /// The place of column `index` (which must be canonical: from [`Columns::index_of`]).
    pub fn place_of(&self, index: u32) -> ColumnPlace {
        let side = self.n + 1;
        let i64i = i64::from(index);
        let face = Face::from_index((i64i / (side * side)) as usize).unwrap_or(Face::Top);
        let rest = i64i % (side * side);
        ColumnPlace {
            face,
            i: rest % side,
            j: rest / side,
        }
    }

    /// The canonical place of a lattice point (which must lie on the cube surface).
    pub fn place_of_lattice(&self, p: IVec3) -> ColumnPlace {
        let n = self.n as i32;
        let face = Face::ALL
            .into_iter()
            .find(|f| p.dot(f.frame().n) == n)
            .unwrap_or(Face::Top);
        let fr = face.frame();
        ColumnPlace {
            face,
            i: i64::from((p.dot(fr.u) + n) / 2),
            j: i64::from((p.dot(fr.v) + n) / 2),
        }
    }

    /// The lattice point of a place.
    pub fn lattice(&self, place: ColumnPlace) -> IVec3 {
        // In range by construction, so `lattice` cannot fail.
        self.layout.lattice(place.face, place.i, place.j).unwrap_or(IVec3::ZERO)
    }

    /// The index of the column at lattice point `p`.
    pub fn index_of_lattice(&self, p: IVec3) -> u32 {
        self.index_of(self.place_of_lattice(p))
    }

    /// Whether `place` is the canonical place of its column (edge and corner columns also appear
    /// on faces later in [`Face::ALL`]).
    pub fn is_canonical(&self, place: ColumnPlace) -> bool {
        self.place_of_lattice(self.lattice(place)) == place
    }

    /// The unit direction of column `index`: exactly the direction the mesher samples.
    pub fn direction(&self, index: u32) -> DVec3 {
        self.layout.lattice_direction(self.lattice(self.place_of(index)))
    }

    /// The neighbours of column `index` (4; 3 at a cube corner), as column indices, in a fixed
    /// order.
    pub fn neighbours(&self, index: u32) -> Neighbours {
        let p = self.lattice(self.place_of(index));
        let n = self.n as i32;
        let mut out = Neighbours { list: [0; 4], len: 0 };
        for face in Face::ALL {
            let fr = face.frame();
            if p.dot(fr.n) != n {
                continue;
            }
            for d in [fr.u, -fr.u, fr.v, -fr.v] {
                let q = p + d * 2;
                if q.dot(fr.u).abs() > n || q.dot(fr.v).abs() > n {
                    continue;
                }
                let qi = self.index_of_lattice(q);
                if !out.list[..out.len].contains(&qi) {
                    out.list[out.len] = qi;
                    out.len += 1;
                }
            }
        }
        out
    }

    /// The column nearest to direction `dir` (any non-zero vector), or `None` for the zero or a
    /// non-finite vector.
    pub fn nearest(&self, dir: DVec3) -> Option<u32> {
        let (face, u, v) = sphere_to_face_uv(dir)?;
        let n = self.n as f64;
        let grid = |x: f64| ((x + 1.0) * 0.5 * n).round().clamp(0.0, n) as i64;
        let place = ColumnPlace {
            face,
            i: grid(u),
            j: grid(v),
        };
        Some(self.index_of_lattice(self.lattice(place)))
    }
}

/// Up to four neighbouring columns.
#[derive(Clone, Copy, Debug)]
pub struct Neighbours {
    list: [u32; 4],
    len: usize,
}

impl std::ops::Deref for Neighbours {
    type Target = [u32];
    fn deref(&self) -> &[u32] {
        &self.list[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Columns {
        Columns::new(&Layout::new(2, 4, 100.0, 2.0, 1).unwrap())
    }

    #[test]
    fn every_column_has_four_neighbours_but_the_eight_corners_three_and_the_relation_is_symmetric() {
        let c = small();
        let n = c.face_tiles();
        let mut columns = 0;
        let mut corners = 0;
        for face in Face::ALL {
            for j in 0..=n {
                for i in 0..=n {
                    let place = ColumnPlace { face, i, j };
                    if !c.is_canonical(place) {
                        continue;
                    }
                    columns += 1;
                    let me = c.index_of(place);
                    assert_eq!(c.place_of(me), place);
                    let nb = c.neighbours(me);
                    if nb.len() == 3 {
                        corners += 1;
                    } else {
                        assert_eq!(nb.len(), 4, "{place:?}");
                    }
                    for q in nb.iter() {
                        assert!(c.neighbours(*q).contains(&me), "{place:?} -> {:?}", c.place_of(*q));
                        // Neighbours are one grid step apart: close in direction.
                        let angle = c.direction(me).angle_between(c.direction(*q));
                        assert!(angle > 0.0 && angle < 0.4, "{angle}");
                    }
                }
            }
        }
        // 6 N^2 + 2 distinct lattice points on the cube surface.
        assert_eq!(columns, 6 * n * n + 2);
        assert_eq!(corners, 8);
    }

    #[test]
    fn nearest_finds_the_column_of_its_own_direction() {
        let c = small();
        for index in 0..c.index_count() as u32 {
            if !c.is_canonical(c.place_of(index)) {
                continue;
            }
            assert_eq!(c.nearest(c.direction(index) * 7.0), Some(index));
        }
        assert_eq!(c.nearest(DVec3::ZERO), None);
        assert_eq!(c.nearest(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }
}
