//! Patch identity, stitching flags and errors.

use crate::lattice::{face_lattice, lattice_face_index, resolution, MAX_LEVEL, PATCH_SEGMENTS};
use pmc_geometry::glam::IVec3;
use pmc_geometry::Face;
use std::fmt;

/// One patch of a face's quadtree: `2^level` patches per face side, patch `(i, j)` along the
/// face's `(u, v)` axes.
///
/// Its 65 × 65 vertices are the lattice points of resolution `m = 64 · 2^level` with face indices
/// `(64 i + a, 64 j + b)`, `a, b` in `0..=64` (see [`PatchKey::vertex_lattice`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PatchKey {
    /// The cube face (and quadtree) the patch belongs to.
    pub face: Face,
    /// Quadtree depth: 0 is the whole face.
    pub level: u8,
    /// Patch index along the face's `u` axis, `0..2^level`.
    pub i: u32,
    /// Patch index along the face's `v` axis, `0..2^level`.
    pub j: u32,
}

/// Why a patch, a planet or a view was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum PatchError {
    /// The level is deeper than [`MAX_LEVEL`] (or than the planet's `max_level`).
    LevelTooDeep {
        /// The level asked for.
        level: u8,
        /// The deepest level allowed.
        max: u8,
    },
    /// A patch index is not below `2^level`.
    IndexOutOfRange(PatchKey),
    /// A planet or view parameter is unusable (non-finite, negative, inverted bounds...).
    InvalidParameter(&'static str),
}

impl fmt::Display for PatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PatchError::LevelTooDeep { level, max } => {
                write!(f, "patch level {level} is deeper than the maximum level {max}")
            }
            PatchError::IndexOutOfRange(k) => write!(
                f,
                "patch index ({}, {}) is out of range for level {} (a face side has {} patches)",
                k.i,
                k.j,
                k.level,
                1u64 << k.level.min(63)
            ),
            PatchError::InvalidParameter(what) => write!(f, "invalid parameter: {what}"),
        }
    }
}

impl std::error::Error for PatchError {}

impl fmt::Display for PatchKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}/{}/{}", self.face, self.level, self.i, self.j)
    }
}

impl PatchKey {
    /// The root patch of a face (level 0, the whole face).
    pub fn root(face: Face) -> PatchKey {
        PatchKey {
            face,
            level: 0,
            i: 0,
            j: 0,
        }
    }

    /// A checked key: refuses levels past [`MAX_LEVEL`] and indices not below `2^level`.
    pub fn new(face: Face, level: u8, i: u32, j: u32) -> Result<PatchKey, PatchError> {
        let key = PatchKey { face, level, i, j };
        key.validate()?;
        Ok(key)
    }

    /// Checks the level and the indices (see [`PatchKey::new`]).
    pub fn validate(&self) -> Result<(), PatchError> {
        if self.level > MAX_LEVEL {
            return Err(PatchError::LevelTooDeep {
                level: self.level,
                max: MAX_LEVEL,
            });
        }
        let n = 1u64 << self.level;
        if u64::from(self.i) >= n || u64::from(self.j) >= n {
            return Err(PatchError::IndexOutOfRange(*self));
        }
        Ok(())
    }

    /// Patches per face side at this level, `2^level`.
    pub fn patches_per_side(&self) -> u32 {
        1 << self.level
    }

    /// The face resolution of this level, `64 · 2^level` segments per face side.
    pub fn resolution(&self) -> i64 {
        resolution(self.level)
    }

    /// The patch one level up that contains this one (`None` for a root).
    pub fn parent(&self) -> Option<PatchKey> {
        (self.level > 0).then(|| PatchKey {
            face: self.face,
            level: self.level - 1,
            i: self.i / 2,
            j: self.j / 2,
        })
    }

    /// The ancestor at `level` (itself when `level == self.level`; `None` when deeper).
    pub fn ancestor(&self, level: u8) -> Option<PatchKey> {
        (level <= self.level).then(|| {
            let k = self.level - level;
            PatchKey {
                face: self.face,
                level,
                i: self.i >> k,
                j: self.j >> k,
            }
        })
    }

    /// The four patches one level down, in order `(0,0), (1,0), (0,1), (1,1)` along `(u, v)`;
    /// `None` at [`MAX_LEVEL`].
    pub fn children(&self) -> Option<[PatchKey; 4]> {
        (self.level < MAX_LEVEL).then(|| {
            let c = |di: u32, dj: u32| PatchKey {
                face: self.face,
                level: self.level + 1,
                i: 2 * self.i + di,
                j: 2 * self.j + dj,
            };
            [c(0, 0), c(1, 0), c(0, 1), c(1, 1)]
        })
    }

    /// The canonical lattice point (resolution [`PatchKey::resolution`]) of vertex `(a, b)`,
    /// `a, b` in `-64..=128` with at most one of them outside `0..=64` when the patch touches a face
    /// edge there (points past a face edge are unfolded onto the neighbouring face). `None` past a
    /// cube corner.
    pub fn vertex_lattice(&self, a: i64, b: i64) -> Option<IVec3> {
        let s = i64::from(PATCH_SEGMENTS);
        face_lattice(
            self.face,
            s * i64::from(self.i) + a,
            s * i64::from(self.j) + b,
            self.resolution(),
        )
    }

    /// The patch of the same level beyond `side`, across face edges by the unfolding of
    /// Algorithm 1. Every side has one.
    pub fn neighbour(&self, side: Side) -> PatchKey {
        let (di, dj) = side.offset();
        self.offset(di, dj).expect("every side of a patch has a neighbour")
    }

    /// The patch of the same level at offset `(di, dj)` (each in `-1..=1`) in cells of this level,
    /// across a face edge by unfolding; `None` for the diagonal beyond a cube corner (where only
    /// three patches meet).
    pub fn offset(&self, di: i32, dj: i32) -> Option<PatchKey> {
        let n = 1i64 << self.level;
        let (i, j) = (i64::from(self.i) + i64::from(di), i64::from(self.j) + i64::from(dj));
        if (0..n).contains(&i) && (0..n).contains(&j) {
            return Some(PatchKey {
                face: self.face,
                level: self.level,
                i: i as u32,
                j: j as u32,
            });
        }
        // The cell's centre at resolution 2n has odd indices; unfold it and read it back.
        let m = 2 * n;
        let p = face_lattice(self.face, 2 * i + 1, 2 * j + 1, m)?;
        let (face, ci, cj) = lattice_face_index(p, m)?;
        Some(PatchKey {
            face,
            level: self.level,
            i: ((ci - 1) / 2) as u32,
            j: ((cj - 1) / 2) as u32,
        })
    }

    /// The patch's four corners as lattice points of its resolution.
    pub(crate) fn corner_lattice(&self, corner: Corner) -> IVec3 {
        let (a, b) = corner.vertex();
        self.vertex_lattice(i64::from(a), i64::from(b))
            .expect("patch corners lie on the face")
    }
}

/// A side of a patch, named by the face-index coordinate that is constant along it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// `a = 0` (towards `-u`).
    MinU,
    /// `a = 64` (towards `+u`).
    MaxU,
    /// `b = 0` (towards `-v`).
    MinV,
    /// `b = 64` (towards `+v`).
    MaxV,
}

impl Side {
    /// The four sides.
    pub const ALL: [Side; 4] = [Side::MinU, Side::MaxU, Side::MinV, Side::MaxV];

    fn bit(self) -> u8 {
        1 << self as u8
    }

    /// The step `(di, dj)` to the neighbouring cell beyond this side.
    pub fn offset(self) -> (i32, i32) {
        match self {
            Side::MinU => (-1, 0),
            Side::MaxU => (1, 0),
            Side::MinV => (0, -1),
            Side::MaxV => (0, 1),
        }
    }

    /// The two corners at the ends of this side.
    pub fn corners(self) -> [Corner; 2] {
        match self {
            Side::MinU => [Corner::MinUMinV, Corner::MinUMaxV],
            Side::MaxU => [Corner::MaxUMinV, Corner::MaxUMaxV],
            Side::MinV => [Corner::MinUMinV, Corner::MaxUMinV],
            Side::MaxV => [Corner::MinUMaxV, Corner::MaxUMaxV],
        }
    }
}

/// A corner of a patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Corner {
    /// Vertex `(0, 0)`.
    MinUMinV,
    /// Vertex `(64, 0)`.
    MaxUMinV,
    /// Vertex `(0, 64)`.
    MinUMaxV,
    /// Vertex `(64, 64)`.
    MaxUMaxV,
}

impl Corner {
    /// The four corners.
    pub const ALL: [Corner; 4] = [Corner::MinUMinV, Corner::MaxUMinV, Corner::MinUMaxV, Corner::MaxUMaxV];

    fn bit(self) -> u8 {
        1 << self as u8
    }

    /// The corner's vertex `(a, b)`.
    pub fn vertex(self) -> (u32, u32) {
        let s = PATCH_SEGMENTS;
        match self {
            Corner::MinUMinV => (0, 0),
            Corner::MaxUMinV => (s, 0),
            Corner::MinUMaxV => (0, s),
            Corner::MaxUMaxV => (s, s),
        }
    }

    /// The steps `(di, dj)` to the three cells of this level that share the corner with the patch
    /// (two side neighbours and the diagonal).
    pub fn cells(self) -> [(i32, i32); 3] {
        let (di, dj) = match self {
            Corner::MinUMinV => (-1, -1),
            Corner::MaxUMinV => (1, -1),
            Corner::MinUMaxV => (-1, 1),
            Corner::MaxUMaxV => (1, 1),
        };
        [(di, 0), (0, dj), (di, dj)]
    }
}

/// Where a patch meets coarser patches (one level up), which changes its mesh and normals.
///
/// - A **side** flag: the neighbour beyond that side is one level coarser. The side's odd vertices
///   are skipped (the edge triangles fan to the even ones), so its edge polyline is exactly the
///   coarser patch's, and its even vertices take their normals at the coarser spacing.
/// - A **corner** flag: some patch touching that corner vertex (beyond a side, or diagonally, or
///   across a face edge or a cube corner) is one level coarser, so the corner vertex takes its
///   normal at the coarser spacing. Setting a side sets both its corners.
///
/// The selection ([`crate::select`]) computes both; a patch's mesh depends on nothing else.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Stitch {
    sides: u8,
    corners: u8,
}

impl Stitch {
    /// No coarser neighbour anywhere.
    pub const NONE: Stitch = Stitch { sides: 0, corners: 0 };

    /// Marks `side` as facing a coarser neighbour (and both its corners).
    #[must_use]
    pub fn with_side(self, side: Side) -> Stitch {
        let [c0, c1] = side.corners();
        Stitch {
            sides: self.sides | side.bit(),
            corners: self.corners | c0.bit() | c1.bit(),
        }
    }

    /// Marks `corner` as touching a coarser patch.
    #[must_use]
    pub fn with_corner(self, corner: Corner) -> Stitch {
        Stitch {
            sides: self.sides,
            corners: self.corners | corner.bit(),
        }
    }

    /// Whether `side` faces a coarser neighbour.
    pub fn side(self, side: Side) -> bool {
        self.sides & side.bit() != 0
    }

    /// Whether `corner` touches a coarser patch.
    pub fn corner(self, corner: Corner) -> bool {
        self.corners & corner.bit() != 0
    }

    /// The side flags as four bits (bit `s` for `Side::ALL[s]`).
    pub fn side_bits(self) -> u8 {
        self.sides
    }

    /// The corner flags as four bits (bit `c` for `Corner::ALL[c]`).
    pub fn corner_bits(self) -> u8 {
        self.corners
    }

    /// Whether no flag is set.
    pub fn is_none(self) -> bool {
        self.sides == 0 && self.corners == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_are_mutual_across_face_edges() {
        for level in 0..4u8 {
            let n = 1u32 << level;
            for face in Face::ALL {
                for i in 0..n {
                    for j in 0..n {
                        let k = PatchKey::new(face, level, i, j).unwrap();
                        for side in Side::ALL {
                            let nb = k.neighbour(side);
                            nb.validate().unwrap();
                            assert_ne!(nb, k);
                            // Some side of the neighbour leads back.
                            assert!(Side::ALL.iter().any(|s| nb.neighbour(*s) == k), "{k} {side:?} {nb}");
                            // They share the two end points of the side.
                            let shared = side
                                .corners()
                                .map(|c| k.corner_lattice(c))
                                .into_iter()
                                .filter(|p| Corner::ALL.iter().any(|c| nb.corner_lattice(*c) == *p))
                                .count();
                            assert_eq!(shared, 2, "{k} {side:?} {nb}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn diagonals_exist_except_past_cube_corners() {
        let k = PatchKey::new(Face::Top, 2, 0, 0).unwrap();
        assert_eq!(k.offset(-1, -1), None);
        let d = k.offset(-1, 1).unwrap();
        // The diagonal shares the corner vertex (0, 64) of k.
        let p = k.corner_lattice(Corner::MinUMaxV);
        assert!(Corner::ALL.iter().any(|c| d.corner_lattice(*c) == p));
    }

    #[test]
    fn bad_keys_are_refused_with_a_message() {
        let e = PatchKey::new(Face::East, 3, 8, 0).unwrap_err();
        assert_eq!(
            e,
            PatchError::IndexOutOfRange(PatchKey {
                face: Face::East,
                level: 3,
                i: 8,
                j: 0
            })
        );
        assert!(e.to_string().contains("out of range for level 3"), "{e}");
        let e = PatchKey::new(Face::East, MAX_LEVEL + 1, 0, 0).unwrap_err();
        assert!(e.to_string().contains("deeper than the maximum level 24"), "{e}");
    }

    #[test]
    fn stitch_side_sets_its_corners() {
        let s = Stitch::NONE.with_side(Side::MaxV);
        assert!(s.side(Side::MaxV) && !s.side(Side::MinV));
        assert!(s.corner(Corner::MinUMaxV) && s.corner(Corner::MaxUMaxV) && !s.corner(Corner::MinUMinV));
        assert!(Stitch::NONE.is_none() && !s.is_none());
    }
}
